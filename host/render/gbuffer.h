// The G-buffer of one frame on the host: what the camera rays hit, per pixel, structure of
// arrays. The channels the guiding kernels read come from PG_GBUFFER_CHANNELS (their layout
// and meaning: include/rtpg/guiding_layout.h), so the buffer uploads without repacking
// (enqueue_upload in include/rtpg/guider.h); two more channels only the path tracer needs.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "render/camera_rays.h"
#include "rtpg/guiding_layout.h"
#include "scene/camera.h"
#include "shared/bsdf.h"
#include "shared/compat.h"
#include "util/huge_pages.h"

namespace rtpg {

struct GBuffer {
  int width = 0, height = 0;
#define RTPG_HOST_CHANNEL(name, type, bytes) LargeVector<shared::type> name;
  PG_GBUFFER_CHANNELS(RTPG_HOST_CHANNEL)
#undef RTPG_HOST_CHANNEL
  LargeVector<glm::vec4> geometric_normal;  // xyz, facing the camera; w the offset distance
                                            // (SurfacePoint::offset_distance)
  LargeVector<glm::vec4> emission;          // rgb emitted towards the camera (or sky radiance)
  CameraFrame camera;                       // the camera the primary rays came from
  // Last frame's camera, which the motion vectors point into, and whether the camera moved
  // (where it did not, every motion vector is zero whatever the jitter).
  CameraFrame previous_camera;
  bool camera_moved = false;
  CameraJitter jitter;  // the primary rays' sub-pixel jitter (render/camera_rays.h)

  void resize(int w, int h);  // every pixel sky
  std::size_t pixel_count() const {
    return static_cast<std::size_t>(width) * height;
  }
  bool has_surface(std::size_t i) const {
    return (flags[i] & PG_GBUF_SKY) == 0;
  }
};

// Pixel i's material in the shared BSDF's terms and its shading frame (the frame the guiding
// distribution of that pixel lives in).
shared::pg_material gbuffer_material(const GBuffer& g, std::size_t i);
shared::pg_frame gbuffer_frame(const GBuffer& g, std::size_t i);
// The G-buffer's two cameras, size and jitter as the kernels take them (include/rtpg/
// guiding_layout.h, "Cameras"): what a packed G-buffer's positions, view directions and motion
// follow from.
pg_gbuffer_cameras gbuffer_cameras(const GBuffer& g);

}  // namespace rtpg
