// What the integrator needs to know about a ray's hit point: geometry, shading frame and
// material parameters with textures applied.
#pragma once

#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"
#include "shared/bsdf.h"
#include "trace/ray.h"
#include "util/huge_pages.h"

namespace rtpg {

struct SurfacePoint {
  glm::vec3 position{0.0f};
  // How far along geometric_normal a ray origin must move to clear the rounding error of
  // `position` (offset_ray_origin); scales with the coordinates' magnitude.
  float offset_distance = 0.0f;
  glm::vec3 geometric_normal{0.0f, 0.0f, 1.0f};  // flipped to face the incoming ray
  glm::vec3 shading_normal{0.0f, 0.0f, 1.0f};    // same side as geometric_normal
  glm::vec3 emission{0.0f};  // radiance emitted back along the ray (0 from the back side)
  shared::pg_material material{};
  std::uint32_t material_id = 0;
  bool transmissive = false;
};

// What a surface point needs of its triangle and not of the hit, the same for every hit on it,
// so the renderer computes it once per scene (TriangleTable) instead of per hit, with the
// triangle's vertex positions copied in: one cache line is all a hit on an untextured,
// flat-shaded triangle reads, where the mesh's arrays are an index triple and three positions at
// scattered places (docs/host-path-tracer.md, "Triangles read as one record").
struct alignas(64) TriangleFacts {
  glm::vec3 position[3]{};  // the mesh's positions of its vertices, in its winding's order
  glm::vec3 normal{0.0f, 0.0f, 1.0f};  // normalize(cross(p1 - p0, p2 - p0)), facing no ray yet
  // dot(|normal|, gamma(7) * max|p_i|): SurfacePoint::offset_distance of every point on it
  float offset_distance = 0.0f;
  // The shading normal wherever it is the same over the whole triangle, on normal's side:
  // normalize(normal) for a mesh without vertex normals (normalised once more, as the per-hit
  // code does), and for a triangle whose three vertex normals are the same vector, that vector
  // normalised (then interpolating it would only round it; docs/host-path-tracer.md, "What a
  // scene does not use, skipped"). The zero vector where the shading normal is interpolated per
  // hit from TriangleVertices::normal.
  glm::vec3 flat_shading_normal{0.0f, 0.0f, 1.0f};
  bool constant_shading_normal() const { return flat_shading_normal != glm::vec3(0.0f); }
};
// The per-vertex attributes a hit on the triangle interpolates, copied from the mesh: the second
// cache line of a triangle, read only where the shading normal varies over it or its material
// has a texture.
struct alignas(64) TriangleVertices {
  glm::vec3 normal[3]{};  // the mesh's vertex normals; zero where it has none
  glm::vec2 uv[3]{};      // the mesh's texture coordinates; zero where it has none
};
// The facts and the vertices of triangle `triangle` of `mesh`, from its positions, vertex normals
// and texture coordinates.
TriangleFacts triangle_facts(const Mesh& mesh, std::uint32_t triangle);
TriangleVertices triangle_vertices(const Mesh& mesh, std::uint32_t triangle);
// Whether a hit on `mesh` can read its triangles' TriangleVertices: its material has a texture,
// or some triangle's shading normal varies over it.
bool mesh_reads_triangle_vertices(const Scene& scene, const Mesh& mesh);

// The facts of every triangle of a scene, and the vertices of those whose mesh reads them, from
// the meshes as they are when the table is built (the renderer builds it with its BVH; a scene
// changed afterwards needs both rebuilt). Each kind in one array over all meshes, so that the
// scene's surfaces share huge pages (util/huge_pages.h).
class TriangleTable {
 public:
  explicit TriangleTable(const Scene& scene);
  const TriangleFacts& at(std::uint32_t mesh, std::uint32_t triangle) const {
    return mesh_facts_[mesh][triangle];
  }
  // nullptr where mesh_reads_triangle_vertices is false for the mesh.
  const TriangleVertices* vertices(std::uint32_t mesh, std::uint32_t triangle) const {
    const TriangleVertices* v = mesh_vertices_[mesh];
    return v != nullptr ? v + triangle : nullptr;
  }
  std::size_t bytes() const {
    return facts_.size() * sizeof(TriangleFacts) + vertices_.size() * sizeof(TriangleVertices);
  }

 private:
  LargeVector<TriangleFacts> facts_;
  LargeVector<TriangleVertices> vertices_;
  std::vector<const TriangleFacts*> mesh_facts_;
  std::vector<const TriangleVertices*> mesh_vertices_;
};

// Interpolates and textures the hit of `ray`; `hit` must be valid. The first form computes the
// triangle's facts for this hit, the second reads them from `triangles`: the same bits.
SurfacePoint make_surface_point(const Scene& scene, const Ray& ray, const Hit& hit);
SurfacePoint make_surface_point(const Scene& scene, const TriangleTable& triangles, const Ray& ray,
                                const Hit& hit);

// make_surface_point's reads for a valid hit, started a few vertices before the shading loop
// gets there, in three stages that each need the one before to have arrived: a bounce lands
// anywhere in a scene's meshes and textures, and on Sponza those reads, cold, were a quarter of
// a path-traced frame (docs/host-path-tracer.md, "Surfaces loaded ahead"). None changes anything.
// The stages pay only where that data does not stay in a core's cache (on the Cornell box and
// the sunlit room they cost 4-6% of the shading): scene_surface_bytes says how much there is.
// 1. the triangle's facts and vertices, and its vertex indices where its mesh has tangents;
void prefetch_surface_triangle(const Scene& scene, const TriangleTable& triangles, const Hit& hit);
// 2. its vertices' tangents, where its mesh has them (reads the indices);
void prefetch_surface_vertices(const Scene& scene, const Hit& hit);
// 3. the texels of every texture of its material at the hit's uv (reads the triangle's vertices).
void prefetch_surface_texels(const Scene& scene, const TriangleTable& triangles, const Hit& hit);
// The bytes make_surface_point can read over a scene: the triangle table's facts and vertices,
// the meshes' tangents with their index arrays, and the textures' texels and slopes.
std::size_t scene_surface_bytes(const Scene& scene);

// Whether a pass over hits loads their surfaces ahead (the stages above): automatic where the
// scene's surface data is larger than a core's cache (core_cache_bytes, render/cpu_code.h).
// Images are the same either way.
enum class SurfacePrefetch { automatic, always, never };
bool loads_surfaces_ahead(SurfacePrefetch setting, const Scene& scene);
// The three stages for the hits a pass over hits[0, end) will shade after hits[j]: the texels
// `spacing` hits ahead of j, the vertices twice and the triangle three times as far, so that each
// stage's loads have arrived when the next stage, or the shading, reads them. Invalid hits are
// skipped. 4 measured best in both the bounce loop (texels 2, 4, 8 ahead alike) and the G-buffer
// pass (spacings 4, 8, 16, 32: 14.4, 14.7, 15.2, 15.3 ms on Sponza at 640x360).
inline void prefetch_surfaces_ahead(const Scene& scene, const TriangleTable& triangles,
                                    const Hit* hits, std::size_t j, std::size_t end,
                                    std::size_t spacing = 4) {
  const std::size_t texel = j + spacing, vertex = j + 2 * spacing, triangle = j + 3 * spacing;
  if (triangle < end && hits[triangle].valid())
    prefetch_surface_triangle(scene, triangles, hits[triangle]);
  if (vertex < end && hits[vertex].valid()) prefetch_surface_vertices(scene, hits[vertex]);
  if (texel < end && hits[texel].valid()) prefetch_surface_texels(scene, triangles, hits[texel]);
}

// std::nextafter(x, +infinity) and std::nextafter(x, -infinity), to the bit for every float
// (zeros, subnormals, infinities and NaN included), inline: offset_ray_origin takes up to three a
// vertex, and the library calls were 1.5% of a path-traced frame (docs/host-path-tracer.md,
// "Rays written in place").
inline float next_float_up(float x) {
  if (!(x < std::numeric_limits<float>::infinity())) return x;  // +inf and NaN
  if (x == 0.0f) return std::numeric_limits<float>::denorm_min();
  std::uint32_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  bits = x > 0.0f ? bits + 1u : bits - 1u;
  std::memcpy(&x, &bits, sizeof bits);
  return x;
}
inline float next_float_down(float x) {
  return -next_float_up(-x);
}

// Origin for rays leaving p on the side of the unit normal n: p moved offset_distance along n
// (SurfacePoint::offset_distance, an error bound of p), then one float further from p in each
// moved coordinate, so rounding the sum cannot land it back inside the error box. No
// scene-dependent epsilon: the offset follows the hit's magnitude (docs/robustness.md).
glm::vec3 offset_ray_origin(const glm::vec3& p, const glm::vec3& n, float offset_distance);

}  // namespace rtpg
