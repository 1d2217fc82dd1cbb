// Surface points from the renderer's triangle table (host/render/surface.h, TriangleTable) equal,
// to the bit, those computed from the hit alone, and both keep SurfacePoint's promises (normals
// facing the ray, emission only from the front): for hits on flat meshes and on meshes with
// vertex normals, from the front and from behind, at ordinary and at extreme coordinate
// magnitudes (the offset distance scales with them; docs/robustness.md).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "render/renderer.h"
#include "render/surface.h"
#include "same_image.h"
#include "scene/scene_loader.h"
#include "scene/shapes.h"
#include "trace/embree_scene.h"

namespace rtpg {
namespace {

Scene scene_at_scale(float scale) {
  Scene scene;
  scene.materials.push_back(Material{});
  Material light;
  light.emission = glm::vec3(2.0f);
  scene.materials.push_back(light);
  // The box and the quad flat (no vertex normals), the sphere with them.
  Mesh box = make_box(glm::vec3(-1.0f) * scale, glm::vec3(1.0f) * scale);
  box.normals.clear();
  box.material = 1;
  scene.meshes.push_back(box);
  scene.meshes.push_back(make_sphere(glm::vec3(0.2f) * scale, 0.5f * scale, 3, false));
  // Through the middle, tilted: the origins lie on both of its sides.
  Mesh quad = make_quad(glm::vec3(-0.9f, -0.05f, -0.9f) * scale,
                        glm::vec3(1.8f, 0.1f, 0.0f) * scale, glm::vec3(0.0f, 0.0f, 1.8f) * scale);
  quad.normals.clear();
  scene.meshes.push_back(quad);
  return scene;
}

TEST(SurfacePoint, TheTriangleTableGivesThePerHitBits) {
  for (const float scale : {1.0f, 1e-4f, 3e4f}) {
    const Scene scene = scene_at_scale(scale);
    const EmbreeScene tracer(scene);
    const TriangleTable table(scene);
    std::mt19937 gen(11);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    int hits = 0, differing = 0, wrong_side = 0;
    int flat_front = 0, flat_back = 0, smooth_front = 0, smooth_back = 0;
    for (int k = 0; k < 4000; ++k) {
      Ray ray;
      // Inside the box: rays hit the sphere (vertex normals), the quad (either side) or the box
      // from within (its back faces).
      ray.origin = glm::vec3(0.8f * u(gen), 0.8f * u(gen), 0.8f * u(gen)) * scale;
      ray.direction = glm::vec3(u(gen), u(gen), u(gen));
      Hit hit;
      tracer.intersect(&ray, &hit, 1);
      if (!hit.valid()) continue;
      ++hits;
      const SurfacePoint a = make_surface_point(scene, ray, hit);
      const SurfacePoint b = make_surface_point(scene, table, ray, hit);
      // What SurfacePoint promises on either side: the geometric normal faces the ray, the
      // shading normal lies on its side, the emission leaves only the front.
      const bool facing = glm::dot(table.at(hit.mesh, hit.triangle).normal, ray.direction) < 0.0f;
      wrong_side += !(glm::dot(b.geometric_normal, ray.direction) < 0.0f) ||
                    !(glm::dot(b.shading_normal, b.geometric_normal) > 0.0f) ||
                    (!facing && b.emission != glm::vec3(0.0f));
      const bool flat = scene.meshes[hit.mesh].normals.empty();
      flat_front += flat && facing;
      flat_back += flat && !facing;
      smooth_front += !flat && facing;
      smooth_back += !flat && !facing;
      differing += !same_bits(a.position, b.position) ||
                   !same_bits(a.geometric_normal, b.geometric_normal) ||
                   !same_bits(a.shading_normal, b.shading_normal) ||
                   !same_bits(a.emission, b.emission) ||
                   std::memcmp(&a.offset_distance, &b.offset_distance, sizeof(float)) != 0 ||
                   a.material_id != b.material_id;
    }
    EXPECT_GT(hits, 3000) << "scale " << scale;
    // Both sides of the triangles' winding, on flat and on smooth meshes.
    EXPECT_GT(flat_front, 50) << "scale " << scale;
    EXPECT_GT(flat_back, 50) << "scale " << scale;
    EXPECT_GT(smooth_front, 50) << "scale " << scale;
    EXPECT_GT(smooth_back, 50) << "scale " << scale;
    EXPECT_EQ(differing, 0) << "scale " << scale;
    EXPECT_EQ(wrong_side, 0) << "scale " << scale;
  }
}

// Triangles whose three vertex normals are one vector take their shading normal from the table
// (TriangleFacts::constant_shading_normal) instead of interpolating it: the same normal up to the
// interpolation's rounding, on the same side, from the front and from behind. Four quads: normals
// along the winding's normal, against it (the interpolating code turns those to the ray's side),
// tilted by 30 degrees, and within 0.01 degrees of the plane (left to the interpolating code,
// where its rounding could decide the side); the same quads with their normals differing in the
// last bit of one vertex interpolate as before.
TEST(SurfacePoint, ConstantVertexNormalsAreTheInterpolatedOnes) {
  Scene scene;
  scene.materials.push_back(Material{});
  const glm::vec3 tilted = glm::normalize(glm::vec3(0.5f, 0.0f, 0.866f));
  const glm::vec3 grazing = glm::normalize(glm::vec3(1.0f, 0.0f, 1.7e-4f));
  const glm::vec3 normals[] = {glm::vec3(0.0f, 0.0f, 1.0f), glm::vec3(0.0f, 0.0f, -1.0f), tilted,
                               grazing};
  for (int copy = 0; copy < 2; ++copy) {
    for (int k = 0; k < 4; ++k) {
      // Quads in z = const planes, the winding's normal +z (make_quad: edge1 x edge2).
      Mesh quad = make_quad(glm::vec3(-1.0f, -1.0f, -3.0f + 2.0f * k + 0.5f * copy),
                            glm::vec3(2.0f, 0.0f, 0.0f), glm::vec3(0.0f, 2.0f, 0.0f));
      for (glm::vec3& n : quad.normals) n = normals[k];
      if (copy == 1) quad.normals[0].x = std::nextafter(quad.normals[0].x, 2.0f);
      scene.meshes.push_back(quad);
    }
  }
  const TriangleTable table(scene);
  for (std::uint32_t m = 0; m < scene.meshes.size(); ++m) {
    const bool constant = m < 4 && m != 3;  // not the grazing one, nor the last-bit copies
    for (std::uint32_t t = 0; t < 2; ++t) {
      ASSERT_NEAR(table.at(m, t).normal.z, 1.0f, 1e-6f) << m;
      EXPECT_EQ(table.at(m, t).constant_shading_normal(), constant) << m << " " << t;
    }
  }
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> u(0.02f, 0.98f);
  for (std::uint32_t m = 0; m < 4; ++m) {
    for (const float side : {1.0f, -1.0f}) {  // the ray from above (behind the winding) or below
      for (int k = 0; k < 200; ++k) {
        Hit hit;
        hit.mesh = m;
        hit.triangle = static_cast<std::uint32_t>(k % 2);
        hit.u = 0.5f * u(gen);
        hit.v = 0.5f * u(gen);
        Ray ray;
        ray.origin = glm::vec3(0.0f, 0.0f, 10.0f * side);
        ray.direction = glm::vec3(0.1f, -0.2f, -side);
        const SurfacePoint a = make_surface_point(scene, table, ray, hit);
        // The interpolating code: the same triangle with its normals one bit apart.
        hit.mesh = m + 4;
        const SurfacePoint b = make_surface_point(scene, table, ray, hit);
        EXPECT_LT(glm::length(a.shading_normal - b.shading_normal), 1e-6f) << m << " " << side;
        EXPECT_GT(glm::dot(a.shading_normal, a.geometric_normal), 0.0f) << m << " " << side;
        EXPECT_TRUE(same_bits(a.geometric_normal, b.geometric_normal)) << m;
      }
    }
  }
}

// The table's records are the meshes' arrays read through the index, triangle by triangle:
// positions in the facts, vertex normals and texture coordinates in the vertices of every mesh
// whose hits read them (a sphere with vertex normals; a textured box, flat), and none for a flat
// untextured box. Each of the three meshes placed after a mesh of another size, so that the
// records of a mesh start at its own place in the scene's arrays.
TEST(SurfacePoint, TheTriangleTableHoldsEachTrianglesVertices) {
  Scene scene;
  scene.materials.push_back(Material{});
  Material textured;
  textured.base_color_texture = 0;
  scene.materials.push_back(textured);
  Texture texture;
  texture.width = texture.height = 1;
  texture.texels.assign(1, glm::vec4(1.0f));
  scene.textures.push_back(texture);
  Mesh flat = make_box(glm::vec3(-1.0f), glm::vec3(1.0f));
  flat.normals.clear();
  Mesh sphere = make_sphere(glm::vec3(0.5f), 0.25f, 2, false);
  Mesh textured_box = make_box(glm::vec3(2.0f), glm::vec3(3.0f, 4.0f, 5.0f));
  textured_box.normals.clear();
  textured_box.material = 1;
  scene.meshes = {flat, sphere, textured_box};
  ASSERT_FALSE(sphere.normals.empty());
  ASSERT_FALSE(textured_box.uvs.empty());
  const TriangleTable table(scene);
  for (std::uint32_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    EXPECT_EQ(table.vertices(m, 0) != nullptr, m != 0) << m;
    for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
      const glm::uvec3 tri = mesh.triangles[t];
      const TriangleFacts& facts = table.at(m, t);
      const TriangleVertices* vertices = table.vertices(m, t);
      for (int k = 0; k < 3; ++k) {
        EXPECT_TRUE(same_bits(facts.position[k], mesh.positions[tri[k]])) << m << " " << t;
        if (vertices == nullptr) continue;
        const glm::vec3 normal = mesh.normals.empty() ? glm::vec3(0.0f) : mesh.normals[tri[k]];
        EXPECT_TRUE(same_bits(vertices->normal[k], normal)) << m << " " << t;
        const glm::vec2 uv = mesh.uvs.empty() ? glm::vec2(0.0f) : mesh.uvs[tri[k]];
        EXPECT_EQ(vertices->uv[k], uv) << m << " " << t;
      }
    }
  }
  EXPECT_EQ(table.bytes(), (flat.triangles.size() + 2 * sphere.triangles.size() +
                            2 * textured_box.triangles.size()) *
                               64);
}

// next_float_up and next_float_down against std::nextafter: zeros, subnormals, the extremes,
// infinities, NaN (compared as NaN) and a million random bit patterns.
// The surface point that a ray straight down from `origin` (straight up with `upwards`) hits,
// into `out`; false for a miss.
bool surface_below(const Scene& scene, const glm::vec3& origin, SurfacePoint& out,
                   bool upwards = false) {
  const EmbreeScene tracer(scene);
  Ray ray;
  ray.origin = origin;
  ray.direction = glm::vec3(0.0f, upwards ? 1.0f : -1.0f, 0.0f);
  Hit hit;
  tracer.intersect(&ray, &hit, 1);
  if (!hit.valid()) return false;
  out = make_surface_point(scene, ray, hit);
  return true;
}

// What a surface's textures do to its surface point, against the directions worked out by hand
// (the other tests here compare two ways of computing the same point, which share this code): a
// tangent-space normal map tilts the shading normal towards the tangent (dP/du) or the bitangent
// (dP/dv) as its texel says, the bitangent follows the mesh tangents' handedness and, without
// tangents, the uv parameterisation; a height map rising along u tilts it back, by bump_scale;
// roughness and metallic textures scale the material by their chosen channels. A quad in y = 0
// facing +y, u along +z and v along +x, hit straight down at uv (0.5, 0.5).
TEST(SurfacePoint, TexturesTiltTheShadingNormalAndScaleTheMaterial) {
  const float s30 = 0.5f, c30 = std::sqrt(3.0f) / 2.0f;
  const auto texture_of = [](int width, int height, const std::vector<glm::vec4>& texels) {
    Texture t;
    t.width = width;
    t.height = height;
    t.texels.assign(texels.begin(), texels.end());
    return t;
  };
  const auto normal_texel = [](glm::vec3 tn) { return glm::vec4(0.5f * (tn + 1.0f), 1.0f); };
  struct Case {
    const char* what;
    Material material;
    Texture texture;
    float tangent_sign;  // 0: no tangents (the uv parameterisation's basis)
    glm::vec3 expected_normal;
  };
  std::vector<glm::vec4> ramp;  // height x / 8 along u (columns), the same in every row
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) ramp.push_back(glm::vec4(glm::vec3(x / 8.0f), 1.0f));
  std::vector<Case> cases;
  Material normal_mapped;
  normal_mapped.normal_texture = 0;
  cases.push_back({"normal map towards u",
                   normal_mapped,
                   texture_of(1, 1, {normal_texel({s30, 0.0f, c30})}),
                   1.0f,
                   {0.0f, c30, s30}});
  cases.push_back({"normal map towards v",
                   normal_mapped,
                   texture_of(1, 1, {normal_texel({0.0f, s30, c30})}),
                   1.0f,
                   {s30, c30, 0.0f}});
  cases.push_back({"normal map towards v, left-handed tangents",
                   normal_mapped,
                   texture_of(1, 1, {normal_texel({0.0f, s30, c30})}),
                   -1.0f,
                   {-s30, c30, 0.0f}});
  cases.push_back({"normal map towards v, no tangents",
                   normal_mapped,
                   texture_of(1, 1, {normal_texel({0.0f, s30, c30})}),
                   0.0f,
                   {s30, c30, 0.0f}});
  for (const float scale : {10.0f, 20.0f}) {
    Material bumped;
    bumped.bump_texture = 0;
    bumped.bump_scale = scale;
    // perturbed = n - bump_scale / 100 * (dh/du t + dh/dv b), dh/du = 1 per unit u.
    cases.push_back({scale == 10.0f ? "bump ramp, scale 10" : "bump ramp, scale 20", bumped,
                     texture_of(8, 8, ramp), 1.0f,
                     glm::normalize(glm::vec3(0.0f, 1.0f, -scale / 100.0f))});
  }
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    Scene scene;
    scene.textures.push_back(c.texture);
    scene.materials.push_back(c.material);
    Mesh quad = make_quad({-1, 0, -1}, {0, 0, 2}, {2, 0, 0});
    for (glm::vec4& t : quad.tangents) t.w = c.tangent_sign;
    if (c.tangent_sign == 0.0f) quad.tangents.clear();
    scene.meshes.push_back(quad);
    SurfacePoint sp;
    ASSERT_TRUE(surface_below(scene, glm::vec3(0.0f, 1.0f, 0.0f), sp));
    ASSERT_NEAR(sp.geometric_normal.y, 1.0f, 1e-6f);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(sp.shading_normal[k], c.expected_normal[k], 1e-5f) << "component " << k;
    // Seen from below (a two-sided leaf's back), the map tilts the surface the same way, so the
    // shading normal is the front's, negated (the tilt along u came out mirrored before).
    ASSERT_TRUE(surface_below(scene, glm::vec3(0.0f, -1.0f, 0.0f), sp, true));
    ASSERT_NEAR(sp.geometric_normal.y, -1.0f, 1e-6f);
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(sp.shading_normal[k], -c.expected_normal[k], 1e-5f) << "back, component " << k;
  }

  // Roughness from the texel's green channel, metallic from its blue one (glTF's layout), each
  // multiplying the material's value; the base colour untouched without a colour texture.
  Scene scene;
  scene.textures.push_back(texture_of(1, 1, {glm::vec4(0.1f, 0.5f, 0.9f, 1.0f)}));
  Material m;
  m.base_color = glm::vec3(0.3f, 0.4f, 0.5f);
  m.roughness = 0.8f;
  m.metallic = 1.0f;
  m.roughness_texture = 0;
  m.metallic_texture = 0;
  m.roughness_channel = 1;
  m.metallic_channel = 2;
  scene.materials.push_back(m);
  scene.meshes.push_back(make_quad({-1, 0, -1}, {0, 0, 2}, {2, 0, 0}));
  SurfacePoint sp;
  ASSERT_TRUE(surface_below(scene, glm::vec3(0.1f, 1.0f, 0.2f), sp));
  EXPECT_NEAR(sp.material.roughness, 0.4f, 1e-6f);
  EXPECT_NEAR(sp.material.metallic, 0.9f, 1e-6f);
  EXPECT_EQ(sp.material.base_color.x, 0.3f);
  EXPECT_EQ(sp.shading_normal, glm::vec3(0.0f, 1.0f, 0.0f));

  // A mesh without texture coordinates takes none of its textures (scenes/README.md, as it
  // takes no alpha mask): not the texel at uv (0, 0) for its colour, nor a tilt of its normal.
  Scene bare;
  bare.textures.push_back(texture_of(1, 1, {glm::vec4(0.0f, 0.0f, 0.0f, 1.0f)}));
  bare.textures.push_back(texture_of(1, 1, {normal_texel({s30, 0.0f, c30})}));
  Material textured;
  textured.base_color = glm::vec3(0.3f, 0.4f, 0.5f);
  textured.base_color_texture = 0;
  textured.normal_texture = 1;
  bare.materials.push_back(textured);
  Mesh no_uvs = make_quad({-1, 0, -1}, {0, 0, 2}, {2, 0, 0});
  no_uvs.uvs.clear();
  no_uvs.tangents.clear();
  bare.meshes.push_back(no_uvs);
  ASSERT_TRUE(surface_below(bare, glm::vec3(0.1f, 1.0f, 0.2f), sp));
  EXPECT_EQ(sp.material.base_color.x, 0.3f);
  EXPECT_EQ(sp.material.base_color.z, 0.5f);
  EXPECT_EQ(sp.shading_normal, glm::vec3(0.0f, 1.0f, 0.0f));
}

TEST(SurfacePoint, NextFloatIsStdNextafter) {
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> values = {0.0f,
                               -0.0f,
                               std::numeric_limits<float>::denorm_min(),
                               -std::numeric_limits<float>::denorm_min(),
                               std::numeric_limits<float>::min(),
                               -std::numeric_limits<float>::min(),
                               std::numeric_limits<float>::max(),
                               -std::numeric_limits<float>::max(),
                               inf,
                               -inf,
                               std::numeric_limits<float>::quiet_NaN(),
                               1.0f,
                               -1.0f};
  std::mt19937 gen(3);
  for (int k = 0; k < 1000000; ++k) {
    const std::uint32_t bits = static_cast<std::uint32_t>(gen());
    float x;
    std::memcpy(&x, &bits, sizeof x);
    values.push_back(x);
  }
  int differing = 0;
  for (const float x : values) {
    const float up = next_float_up(x), down = next_float_down(x);
    const float want_up = std::nextafter(x, inf), want_down = std::nextafter(x, -inf);
    if (std::isnan(x)) {
      differing += !std::isnan(up) || !std::isnan(down);
      continue;
    }
    differing += std::memcmp(&up, &want_up, sizeof up) != 0;
    differing += std::memcmp(&down, &want_down, sizeof down) != 0;
  }
  EXPECT_EQ(differing, 0);
}

// The surface data make_surface_point can read, counted array by array: the triangle table's 64
// bytes a triangle for a flat untextured box (whose tangents no hit reads), and 64 more of
// vertices for a bump-mapped sphere, whose tangents (with its index array) shading reads too; an
// 8-bit texture with bump slopes and a float texture.
TEST(SurfacePoint, SceneSurfaceBytesCountsEveryArrayShadingReads) {
  Scene scene;
  scene.materials.push_back(Material{});
  Mesh box = make_box(glm::vec3(-1.0f), glm::vec3(1.0f));
  box.normals.clear();
  Mesh sphere = make_sphere(glm::vec3(0.0f), 0.5f, 2, false);
  sphere.uvs.clear();
  sphere.tangents.assign(sphere.positions.size(), glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));
  Material bumped;
  bumped.bump_texture = 0;
  scene.materials.push_back(bumped);
  sphere.material = 1;
  scene.meshes = {box, sphere};
  Texture bytes8;
  bytes8.width = 5;
  bytes8.height = 3;
  bytes8.texels8.resize(15);
  bytes8.slopes.resize(15);
  Texture floats;
  floats.width = 2;
  floats.height = 7;
  floats.texels.resize(14);
  scene.textures = {bytes8, floats};
  std::size_t expected = 15 * 4 + 15 * 8 + 14 * 16;
  expected += box.triangles.size() * 64;
  expected += sphere.triangles.size() * (64 + 64 + 12) + sphere.tangents.size() * 16;
  EXPECT_EQ(sizeof(TriangleFacts), 64u);
  EXPECT_EQ(sizeof(TriangleVertices), 64u);
  EXPECT_GT(box.uvs.size(), 0u);
  EXPECT_GT(box.tangents.size(), 0u);
  EXPECT_FALSE(mesh_reads_triangle_vertices(scene, box));
  EXPECT_TRUE(mesh_reads_triangle_vertices(scene, sphere));
  EXPECT_EQ(TriangleTable(scene).bytes(),
            (box.triangles.size() + 2 * sphere.triangles.size()) * 64);
  EXPECT_EQ(scene_surface_bytes(scene), expected);
}

// The shading loop's loads ahead (PathTracerSettings::surface_prefetch) change nothing: the
// Cornell box with a texture on every material (base colour and bump, so that every stage has
// texels to load) over the uvs of its walls, two samples a pixel, a moving camera, an odd size:
// every frame the same to the bit with the loads ahead always and never.
TEST(SurfacePoint, LoadingSurfacesAheadLeavesTheImageAsItIs) {
  Scene scene = load_scene(std::string(RTPG_SOURCE_DIR) + "/scenes/cornell-box.json");
  Texture checker;
  checker.width = 64;
  checker.height = 48;
  for (int y = 0; y < checker.height; ++y)
    for (int x = 0; x < checker.width; ++x) {
      const std::uint8_t v = ((x / 4 + y / 4) % 2) ? 230 : 40;
      checker.texels8.push_back({v, static_cast<std::uint8_t>(255 - v), 128, 255});
    }
  checker.srgb = true;
  prepare_bump_slopes(checker);
  scene.textures.push_back(checker);
  for (Material& m : scene.materials) {
    m.base_color_texture = 0;
    m.bump_texture = 0;
  }
  for (const Mesh& m : scene.meshes) ASSERT_FALSE(m.uvs.empty()) << m.name;
  RenderSettings always;
  always.width = 23;
  always.height = 17;
  always.spp = 2;
  always.camera_path = "pan";
  RenderSettings never = always;
  always.path_tracer.surface_prefetch = SurfacePrefetch::always;
  never.path_tracer.surface_prefetch = SurfacePrefetch::never;
  Renderer a(scene, always), b(scene, never);
  for (int frame = 0; frame < 3; ++frame) {
    a.render_frame(frame);
    b.render_frame(frame);
    expect_same_lit_image(a.image(), b.image(), "frame " + std::to_string(frame));
  }
}

}  // namespace
}  // namespace rtpg
