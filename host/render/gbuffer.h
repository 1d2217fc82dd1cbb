// The G-buffer of one frame: what the camera rays hit, per pixel, structure of arrays in the
// layouts the OpenCL kernels read (float4 / uint), so it uploads without repacking.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "shared/bsdf.h"
#include "shared/gbuffer.h"

namespace rtpg {

struct GBuffer {
  int width = 0, height = 0;
  std::vector<glm::vec4> position_depth;        // xyz world position, w linear depth (0 on sky)
  std::vector<glm::vec4> shading_normal;        // xyz, facing the camera; w unused
  std::vector<glm::vec4> geometric_normal;      // xyz, facing the camera; w unused
  std::vector<glm::vec4> view_dir;              // xyz unit vector from the surface to the camera
  std::vector<glm::vec2> motion;                // pixel offset to where the point was last frame
  std::vector<glm::vec4> base_color_roughness;  // rgb base colour, a perceptual roughness
  std::vector<glm::vec4> metallic_specular;     // x metallic, y dielectric F0
  std::vector<glm::vec4> emission;              // rgb emitted towards the camera (or sky radiance)
  std::vector<std::uint32_t> material_id;
  std::vector<std::uint32_t> flags;  // PG_GBUF_* bits

  void resize(int w, int h);
  std::size_t pixel_count() const { return static_cast<std::size_t>(width) * height; }
  bool has_surface(std::size_t i) const { return (flags[i] & PG_GBUF_SKY) == 0; }
};

// Pixel i's material in the shared BSDF's terms and its shading frame (the frame the guiding
// distribution of that pixel lives in).
shared::pg_material gbuffer_material(const GBuffer& g, std::size_t i);
shared::pg_frame gbuffer_frame(const GBuffer& g, std::size_t i);

}  // namespace rtpg
