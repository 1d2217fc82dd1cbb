#include "render/surface.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "render/cpu_code.h"

namespace rtpg {
namespace {

// The value at barycentrics (u, v) of a triangle's three vertex values.
template <class T>
T interpolate(const T (&a)[3], float u, float v) {
  return (1.0f - u - v) * a[0] + u * a[1] + v * a[2];
}

// Tangent-space basis at the hit: the mesh's tangents, else one derived from the uv
// parameterisation of the triangle, else any basis around n.
void tangent_basis(const Mesh& mesh, const TriangleFacts& facts, const TriangleVertices& vertices,
                   std::uint32_t triangle, float u, float v, const glm::vec3& n, glm::vec3& tangent,
                   glm::vec3& bitangent) {
  if (!mesh.tangents.empty()) {
    const glm::uvec3 tri = mesh.triangles[triangle];
    const glm::vec4 t4 =
        (1.0f - u - v) * mesh.tangents[tri.x] + u * mesh.tangents[tri.y] + v * mesh.tangents[tri.z];
    glm::vec3 t(t4);
    t = t - n * glm::dot(n, t);
    if (glm::dot(t, t) > 1e-12f) {
      tangent = glm::normalize(t);
      bitangent = glm::cross(n, tangent) * (t4.w < 0.0f ? -1.0f : 1.0f);
      return;
    }
  }
  if (!mesh.uvs.empty()) {
    const glm::vec3 e1 = facts.position[1] - facts.position[0];
    const glm::vec3 e2 = facts.position[2] - facts.position[0];
    const glm::vec2 d1 = vertices.uv[1] - vertices.uv[0];
    const glm::vec2 d2 = vertices.uv[2] - vertices.uv[0];
    const float det = d1.x * d2.y - d1.y * d2.x;
    if (std::fabs(det) > 1e-12f) {
      glm::vec3 t = (e1 * d2.y - e2 * d1.y) / det;
      t = t - n * glm::dot(n, t);
      if (glm::dot(t, t) > 1e-12f) {
        tangent = glm::normalize(t);
        bitangent = glm::cross(n, tangent) * (det < 0.0f ? -1.0f : 1.0f);
        return;
      }
    }
  }
  const shared::pg_frame f = shared::pg_frame_from_normal(n);
  tangent = f.t;
  bitangent = f.b;
}

float texture_channel(const glm::vec4& texel, int channel) {
  return channel == 0 ? texel.x : channel == 1 ? texel.y : channel == 2 ? texel.z : texel.w;
}

}  // namespace

glm::vec3 offset_ray_origin(const glm::vec3& p, const glm::vec3& n, float offset_distance) {
  const glm::vec3 offset = n * offset_distance;
  glm::vec3 out = p + offset;
  for (int i = 0; i < 3; ++i) {
    if (offset[i] > 0.0f)
      out[i] = next_float_up(out[i]);
    else if (offset[i] < 0.0f)
      out[i] = next_float_down(out[i]);
  }
  return out;
}

TriangleFacts triangle_facts(const Mesh& mesh, std::uint32_t triangle) {
  const glm::uvec3 tri = mesh.triangles[triangle];
  const glm::vec3 &p0 = mesh.positions[tri.x], &p1 = mesh.positions[tri.y],
                  &p2 = mesh.positions[tri.z];
  // The bound gamma(7) * max|p_i| per coordinate covers a hit's interpolation from its
  // barycentrics and their own rounding (b0 = 1 - u - v); the offset distance is its projection
  // on the normal (docs/robustness.md, "Scale invariance").
  constexpr float kEps = std::numeric_limits<float>::epsilon() * 0.5f;
  constexpr float kGamma7 = 7.0f * kEps / (1.0f - 7.0f * kEps);
  const glm::vec3 error = kGamma7 * glm::max(glm::max(glm::abs(p0), glm::abs(p1)), glm::abs(p2));
  TriangleFacts f;
  f.position[0] = p0;
  f.position[1] = p1;
  f.position[2] = p2;
  f.normal = glm::normalize(glm::cross(p1 - p0, p2 - p0));
  f.offset_distance = glm::dot(glm::abs(f.normal), error);
  f.flat_shading_normal = glm::normalize(f.normal);
  if (!mesh.normals.empty()) {
    // Three equal vertex normals (a flat quad or box face from scene/shapes.h, a flat-shaded
    // mesh): the shading normal is that normal, put on the side surface_point would put it. A
    // vertex normal too short to normalise, or one within about 0.06 degrees of the triangle's
    // plane (where the interpolated one's rounding could decide the side), stays per hit.
    f.flat_shading_normal = glm::vec3(0.0f);
    const glm::vec3 n = mesh.normals[tri.x];
    const float length2 = glm::dot(n, n);
    if (n == mesh.normals[tri.y] && n == mesh.normals[tri.z] && length2 >= 1e-10f &&
        std::isfinite(length2)) {
      const glm::vec3 shading = glm::normalize(n);
      const float side = glm::dot(shading, f.normal);
      if (std::fabs(side) > 1e-3f) f.flat_shading_normal = side < 0.0f ? -shading : shading;
    }
  }
  // A degenerate triangle's normal is NaN (the loader drops zero-area triangles;
  // docs/robustness.md): without vertex normals its flat shading normal is NaN too, not zero, so
  // constant; with them the side test fails and it stays per hit, as before.
  return f;
}

TriangleVertices triangle_vertices(const Mesh& mesh, std::uint32_t triangle) {
  const glm::uvec3 tri = mesh.triangles[triangle];
  TriangleVertices v;
  for (int k = 0; k < 3; ++k) {
    if (!mesh.normals.empty()) v.normal[k] = mesh.normals[tri[k]];
    if (!mesh.uvs.empty()) v.uv[k] = mesh.uvs[tri[k]];
  }
  return v;
}

bool mesh_reads_triangle_vertices(const Scene& scene, const Mesh& mesh) {
  if (scene.materials[mesh.material].has_textures()) return true;
  if (mesh.normals.empty()) return false;
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t)
    if (!triangle_facts(mesh, t).constant_shading_normal()) return true;
  return false;
}

TriangleTable::TriangleTable(const Scene& scene) {
  std::size_t facts = 0, vertices = 0;
  std::vector<bool> reads_vertices(scene.meshes.size());
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    reads_vertices[m] = mesh_reads_triangle_vertices(scene, scene.meshes[m]);
    facts += scene.meshes[m].triangles.size();
    if (reads_vertices[m]) vertices += scene.meshes[m].triangles.size();
  }
  facts_.resize(facts);
  vertices_.resize(vertices);
  mesh_facts_.resize(scene.meshes.size());
  mesh_vertices_.assign(scene.meshes.size(), nullptr);
  facts = vertices = 0;
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    mesh_facts_[m] = facts_.data() + facts;
    if (reads_vertices[m]) mesh_vertices_[m] = vertices_.data() + vertices;
    for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      facts_[facts++] = triangle_facts(mesh, t);
      if (reads_vertices[m]) vertices_[vertices++] = triangle_vertices(mesh, t);
    }
  }
}

namespace {

// The textures of `mat` at the hit: base colour, roughness and metallic scaled, the shading
// normal ns perturbed by a normal or bump map (kept on ng's side).
[[gnu::noinline]] void apply_textures(const Scene& scene, const Mesh& mesh, const Material& mat,
                                      const TriangleFacts& facts, const TriangleVertices& vertices,
                                      const Hit& hit, const glm::vec3& ng, glm::vec3& ns,
                                      glm::vec3& base, float& roughness, float& metallic) {
  const glm::vec2 uv = interpolate(vertices.uv, hit.u, hit.v);
  if (mat.base_color_texture >= 0)
    base *= glm::vec3(scene.textures[mat.base_color_texture].sample(uv));
  if (mat.roughness_texture >= 0)
    roughness *=
        texture_channel(scene.textures[mat.roughness_texture].sample(uv), mat.roughness_channel);
  if (mat.metallic_texture >= 0)
    metallic *=
        texture_channel(scene.textures[mat.metallic_texture].sample(uv), mat.metallic_channel);

  if (mat.normal_texture >= 0 || mat.bump_texture >= 0) {
    glm::vec3 t, b;
    tangent_basis(mesh, facts, vertices, hit.triangle, hit.u, hit.v, ns, t, b);
    // On a back face ns (and with it the bitangent, its cross product with t) is flipped to the
    // ray's side, the tangent is not: the map's tilt along u would come out mirrored. Its
    // perturbed normal is the front face's, negated, which the tangent's negation gives.
    if (glm::dot(facts.normal, ng) < 0.0f) t = -t;
    glm::vec3 perturbed = ns;
    if (mat.normal_texture >= 0) {
      const glm::vec3 tn = glm::vec3(scene.textures[mat.normal_texture].sample(uv)) * 2.0f - 1.0f;
      perturbed = tn.x * t + tn.y * b + tn.z * ns;
    } else {
      // Height map: finite differences over one texel give the slope in tangent space.
      const glm::vec2 slope = scene.textures[mat.bump_texture].sample_gradient(uv);
      // bump_scale converts height per unit uv into the normal's tilt.
      perturbed = ns - mat.bump_scale * 0.01f * (slope.x * t + slope.y * b);
    }
    if (glm::dot(perturbed, perturbed) > 1e-12f) {
      perturbed = glm::normalize(perturbed);
      // A perturbed normal below the geometric surface would leak light: keep it above.
      if (glm::dot(perturbed, ng) > 0.05f) ns = perturbed;
    }
  }
}

// `vertices` is read only where mesh_reads_triangle_vertices holds for the hit's mesh.
SurfacePoint surface_point(const Scene& scene, const TriangleFacts& facts,
                           const TriangleVertices* vertices, const Ray& ray, const Hit& hit) {
  const Mesh& mesh = scene.meshes[hit.mesh];
  const Material& mat = scene.materials[mesh.material];
  SurfacePoint sp;
  sp.material_id = mesh.material;
  // The hit from its barycentrics, not from origin + t * direction: its rounding error then
  // depends on the triangle's coordinates only, not on how far the ray came (TriangleFacts).
  sp.position = interpolate(facts.position, hit.u, hit.v);
  const bool front = glm::dot(facts.normal, ray.direction) < 0.0f;
  const glm::vec3 ng = front ? facts.normal : -facts.normal;
  glm::vec3 ns;
  if (facts.constant_shading_normal()) {
    // On normal's side (TriangleFacts): negation commutes with normalisation exactly.
    ns = front ? facts.flat_shading_normal : -facts.flat_shading_normal;
  } else {
    ns = interpolate(vertices->normal, hit.u, hit.v);
    if (glm::dot(ns, ns) < 1e-12f) ns = ng;
    ns = glm::normalize(ns);
    if (glm::dot(ns, ng) < 0.0f) ns = -ns;
  }

  glm::vec3 base = mat.base_color;
  float roughness = mat.roughness, metallic = mat.metallic;
  // Out of line: a material without textures pays one test (docs/host-path-tracer.md, "What a
  // scene does not use, skipped").
  // A mesh without texture coordinates takes none of its material's textures (scenes/README.md),
  // as it takes no alpha mask (scene/alpha_mask.h).
  if (mat.has_textures() && !mesh.uvs.empty())
    apply_textures(scene, mesh, mat, facts, *vertices, hit, ng, ns, base, roughness, metallic);
  sp.geometric_normal = ng;
  sp.offset_distance = facts.offset_distance;
  sp.shading_normal = ns;
  sp.material.base_color = shared::float3(base.x, base.y, base.z);
  sp.material.roughness = roughness;
  sp.material.metallic = metallic;
  sp.material.specular = mat.specular;
  sp.transmissive = mat.transmissive;
  if (front) sp.emission = mat.emission;
  return sp;
}

}  // namespace

namespace {

// Whether shading a hit on `mesh` reads its tangents (tangent_basis, for a normal or bump map).
bool reads_tangents(const Scene& scene, const Mesh& mesh) {
  const Material& mat = scene.materials[mesh.material];
  return !mesh.tangents.empty() && (mat.normal_texture >= 0 || mat.bump_texture >= 0);
}

}  // namespace

std::size_t scene_surface_bytes(const Scene& scene) {
  const auto bytes = [](const auto& v) { return v.size() * sizeof(v[0]); };
  std::size_t sum = 0;
  for (const Mesh& mesh : scene.meshes) {
    sum += mesh.triangles.size() * sizeof(TriangleFacts);
    if (mesh_reads_triangle_vertices(scene, mesh))
      sum += mesh.triangles.size() * sizeof(TriangleVertices);
    if (reads_tangents(scene, mesh)) sum += bytes(mesh.tangents) + bytes(mesh.triangles);
  }
  for (const Texture& t : scene.textures)
    sum += bytes(t.texels8) + bytes(t.texels) + bytes(t.slopes);
  return sum;
}

bool loads_surfaces_ahead(SurfacePrefetch setting, const Scene& scene) {
  return setting == SurfacePrefetch::always ||
         (setting == SurfacePrefetch::automatic && scene_surface_bytes(scene) > core_cache_bytes());
}

void prefetch_surface_triangle(const Scene& scene, const TriangleTable& triangles, const Hit& hit) {
  __builtin_prefetch(&triangles.at(hit.mesh, hit.triangle));
  if (const TriangleVertices* v = triangles.vertices(hit.mesh, hit.triangle)) __builtin_prefetch(v);
  const Mesh& mesh = scene.meshes[hit.mesh];
  if (reads_tangents(scene, mesh)) __builtin_prefetch(mesh.triangles.data() + hit.triangle);
}

void prefetch_surface_vertices(const Scene& scene, const Hit& hit) {
  const Mesh& mesh = scene.meshes[hit.mesh];
  if (!reads_tangents(scene, mesh)) return;
  const glm::uvec3 tri = mesh.triangles[hit.triangle];
  for (std::uint32_t v : {tri.x, tri.y, tri.z}) __builtin_prefetch(mesh.tangents.data() + v);
}

void prefetch_surface_texels(const Scene& scene, const TriangleTable& triangles, const Hit& hit) {
  const Mesh& mesh = scene.meshes[hit.mesh];
  const Material& mat = scene.materials[mesh.material];
  if (mesh.uvs.empty() || !mat.has_textures()) return;
  const glm::vec2 uv =
      interpolate(triangles.vertices(hit.mesh, hit.triangle)->uv, hit.u, hit.v);  // as shaded
  for (int texture : {mat.base_color_texture, mat.roughness_texture, mat.metallic_texture,
                      mat.normal_texture, mat.bump_texture})
    if (texture >= 0) scene.textures[texture].prefetch(uv);
}

SurfacePoint make_surface_point(const Scene& scene, const Ray& ray, const Hit& hit) {
  const Mesh& mesh = scene.meshes[hit.mesh];
  const TriangleVertices vertices = triangle_vertices(mesh, hit.triangle);
  return surface_point(scene, triangle_facts(mesh, hit.triangle), &vertices, ray, hit);
}

SurfacePoint make_surface_point(const Scene& scene, const TriangleTable& triangles, const Ray& ray,
                                const Hit& hit) {
  return surface_point(scene, triangles.at(hit.mesh, hit.triangle),
                       triangles.vertices(hit.mesh, hit.triangle), ray, hit);
}

}  // namespace rtpg
