// The alpha test of a masked mesh, in one place for everything that asks whether a point of a
// triangle is there: the ray queries' filter (trace/embree_scene.cpp), which lets rays through
// the transparent texels, and light sampling (render/lights.cpp), which must not draw emission
// from them.
#pragma once

#include <cstdint>

#include "scene/scene.h"

namespace rtpg {

// Whether `mesh` is alpha-tested: its material has an alpha texture and the mesh has texture
// coordinates to read it with (a mesh without them is opaque).
bool has_alpha_mask(const Scene& scene, const Mesh& mesh);

// Whether the point (1 - u - v) p0 + u p1 + v p2 of triangle `triangle` of `mesh` (Embree's
// barycentrics) is there under the alpha mask `mask`: its alpha at the interpolated uv is at
// least `cutoff`. True for a mesh without texture coordinates.
// Inline: Embree's filter callbacks call it for every candidate hit on a masked mesh.
inline bool passes_alpha_test(const Mesh& mesh, const Texture& mask, float cutoff,
                              std::uint32_t triangle, float u, float v) {
  if (mesh.uvs.empty()) return true;
  const glm::uvec3 tri = mesh.triangles[triangle];
  const glm::vec2 uv = (1.0f - u - v) * mesh.uvs[tri.x] + u * mesh.uvs[tri.y] + v * mesh.uvs[tri.z];
  return mask.sample(uv).w >= cutoff;
}

}  // namespace rtpg
