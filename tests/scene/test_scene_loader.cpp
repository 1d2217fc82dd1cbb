// Scene loading: camera math, textures, image decoding, mesh import, the JSON format and
// every kind of bad input. All files are written by the tests into a temporary folder.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <iterator>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include "scene/camera.h"
#include "scene/image_loader.h"
#include "scene/scene.h"
#include "scene/scene_loader.h"
#include "scene/texture.h"
#include "rtpg/errors.h"
#include "support/scene_files.h"

namespace fs = std::filesystem;

namespace rtpg {
namespace {

using test::expect_input_error;
using test::TempDir;
using test::write_file;

// ---- helpers -------------------------------------------------------------------------------

// An 8-bit image with `channels` channels; pixel(x, y, c) gives the byte values.
void write_png(const std::string& path, int w, int h, int channels,
               const std::function<unsigned char(int, int, int)>& pixel) {
  fs::create_directories(fs::path(path).parent_path());
  std::vector<unsigned char> data(static_cast<std::size_t>(w * h * channels));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c)
        data[static_cast<std::size_t>((y * w + x) * channels + c)] = pixel(x, y, c);
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out) << OIIO::geterror();
  OIIO::ImageSpec spec(w, h, channels, OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:UnassociatedAlpha", 1);  // write the bytes as given, not un-premultiplied
  ASSERT_TRUE(out->open(path, spec)) << out->geterror();
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, data.data())) << out->geterror();
  out->close();
}

void write_float_image(const std::string& path, int w, int h, float value) {
  std::vector<float> data(static_cast<std::size_t>(w * h * 3), value);
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out) << OIIO::geterror();
  const OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::FLOAT);
  ASSERT_TRUE(out->open(path, spec)) << out->geterror();
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, data.data())) << out->geterror();
  out->close();
}

void expect_vec3_near(const glm::vec3& a, const glm::vec3& b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

const char* kLightSource = R"("sun": {"direction": [0, 1, 0], "irradiance": [1, 1, 1]})";
const char* kCamera = R"("camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 40})";

// A scene with one quad, a sun and `extra` (JSON members, comma-terminated if non-empty);
// `materials` (comma-terminated) joins the material "white".
std::string simple_scene(const std::string& extra, const std::string& materials = "") {
  return std::string("{") + kCamera + ", " + extra + kLightSource + R"(, "materials": {)" +
         materials + R"("white": {"base_color": [0.5, 0.5, 0.5]}},
            "shapes": [{"type": "quad", "corner": [0,0,0], "edge1": [1,0,0], "edge2": [0,1,0],
                        "material": "white"}]})";
}

// An OBJ (two triangles per material group) with an MTL using every supported feature.
void write_obj_with_mtl(const TempDir& dir) {
  write_file(dir / "model/box.obj", R"(mtllib box.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
usemtl textured
f 1/1/1 2/2/1 3/3/1
f 1/1/1 3/3/1 4/4/1
usemtl light
f 1/1/1 2/2/1 3/3/1
usemtl glass
f 1/1/1 3/3/1 4/4/1
)");
  write_file(dir / "model/box.mtl", R"(newmtl textured
Kd 1 1 1
Ks 0.5 0.5 0.5
Ns 98
map_Kd tex/albedo.png
map_bump -bm 0.5 tex/height.png
map_d tex/mask.png
newmtl light
Kd 0.2 0.2 0.2
Ks 0 0 0
Ke 10 8 6
newmtl glass
Kd 1 1 1
Ks 1 1 1
Ns 1000
Ni 1.5
illum 7
)");
  write_png(dir / "model/tex/albedo.png", 4, 4, 3,
            [](int, int, int c) { return c == 0 ? 255 : 0; });
  write_png(dir / "model/tex/height.png", 4, 4, 1, [](int x, int, int) { return x * 60; });
  write_png(dir / "model/tex/mask.png", 4, 4, 1, [](int x, int, int) { return x < 2 ? 0 : 255; });
}

void write_ply(const std::string& path) {
  write_file(path, R"(ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
element face 2
property list uchar int vertex_indices
end_header
0 0 0
2 0 0
2 2 0
0 2 0
3 0 1 2
3 0 2 3
)");
}

// ---- camera --------------------------------------------------------------------------------

CameraView view_at(glm::vec3 position, glm::vec3 look_at, float fov) {
  CameraView v;
  v.position = position;
  v.look_at = look_at;
  v.fov_y = fov;
  return v;
}

TEST(CameraPath, InterpolatesThroughKeysAndClampsAtTheEnds) {
  CameraPath path;
  path.times = {0.0f, 1.0f, 3.0f};
  path.views = {view_at({0, 0, 0}, {0, 0, -1}, 0.5f), view_at({1, 0, 0}, {1, 0, -1}, 0.7f),
                view_at({1, 2, 0}, {1, 2, -1}, 1.1f)};
  expect_vec3_near(path.at(0.0f).position, {0, 0, 0});
  expect_vec3_near(path.at(-5.0f).position, {0, 0, 0});
  expect_vec3_near(path.at(1.0f).position, {1, 0, 0});
  expect_vec3_near(path.at(3.0f).position, {1, 2, 0});
  expect_vec3_near(path.at(10.0f).look_at, {1, 2, -1});
  EXPECT_NEAR(path.at(2.0f).fov_y, 0.9f, 1e-6f);  // fov linear between keys
  // Between keys, the cubic Hermite curve whose tangents are the keys' central differences in
  // time (one-sided at the ends), scaled by the segment's duration (scenes/README.md), worked
  // out by hand: tangents (1, 0, 0), (1/3, 2/3, 0), (0, 1, 0) per second; at s = 1/2 the basis is
  // (1/2, 1/8, 1/2, -1/8), at s = 1/4 (27/32, 9/64, 5/32, -3/64). Tangents taken per key
  // instead of per second (uniform Catmull-Rom) give x = 0.5625 at t = 0.5, unscaled by the
  // second segment's 2 s (1.0417, 0.9583) at t = 2.
  expect_vec3_near(path.at(0.5f).position, {0.125f + 0.5f - 0.125f / 3.0f, -0.25f / 3.0f, 0.0f});
  expect_vec3_near(path.at(0.25f).position,
                   {9.0f / 64.0f + 5.0f / 32.0f - 1.0f / 64.0f, -1.0f / 32.0f, 0.0f});
  expect_vec3_near(path.at(2.0f).position,
                   {0.5f + 0.25f / 3.0f + 0.5f, 0.5f / 3.0f + 1.0f - 0.25f, 0.0f});
  expect_vec3_near(path.at(0.5f).look_at, {0.125f + 0.5f - 0.125f / 3.0f, -0.25f / 3.0f, -1.0f});
}

TEST(CameraFrame, TopLeftIsUpLeftAndProjectInvertsRayDirection) {
  const CameraFrame frame = make_camera_frame(view_at({0, 0, 5}, {0, 0, 0}, 1.0f), 2.0f);
  expect_vec3_near(frame.ray_direction(0.5f, 0.5f), {0, 0, -1});
  const glm::vec3 top_left = frame.ray_direction(0.0f, 0.0f);
  EXPECT_LT(top_left.x, 0.0f);
  EXPECT_GT(top_left.y, 0.0f);
  // The top edge of the film is fov/2 above the axis.
  const glm::vec3 top = frame.ray_direction(0.5f, 0.0f);
  EXPECT_NEAR(std::atan2(top.y, -top.z), 0.5f, 1e-5f);
  for (float sx : {0.1f, 0.5f, 0.93f})
    for (float sy : {0.0f, 0.4f, 1.0f}) {
      float px = -1, py = -1;
      ASSERT_TRUE(frame.project(frame.position + 3.0f * frame.ray_direction(sx, sy), px, py));
      EXPECT_NEAR(px, sx, 1e-5f);
      EXPECT_NEAR(py, sy, 1e-5f);
    }
  float px, py;
  EXPECT_FALSE(frame.project({0, 0, 6}, px, py));  // behind the camera
}

// ---- textures and images -------------------------------------------------------------------

TEST(Texture, UvOriginIsBottomLeftAndWrapsWithRepeat) {
  Texture t;
  t.width = t.height = 2;
  // Row 0 is the top row of the image.
  t.texels = {glm::vec4(1, 0, 0, 1), glm::vec4(0, 1, 0, 1), glm::vec4(0, 0, 1, 1),
              glm::vec4(1, 1, 1, 1)};
  expect_vec3_near(glm::vec3(t.sample({0.25f, 0.75f})), {1, 0, 0});       // top-left texel
  expect_vec3_near(glm::vec3(t.sample({0.25f, 0.25f})), {0, 0, 1});       // bottom-left
  expect_vec3_near(glm::vec3(t.sample({1.25f, -0.75f})), {0, 0, 1});      // repeat
  expect_vec3_near(glm::vec3(t.sample({0.5f, 0.75f})), {0.5f, 0.5f, 0});  // bilinear
  expect_vec3_near(glm::vec3(t.fetch(-3, 7)), {0, 0, 1});                 // fetch clamps
}

// The bilinear lookup's four taps wrap as repeat wrapping's modulo does, for every image size
// from one texel up (where the taps fall off either edge), at uv on a grid across several
// periods, at 0, just below 1 and at huge and non-finite values: sample() equals the same mix of
// the texels at the taps' indices taken modulo the size.
TEST(Texture, BilinearTapsWrapAsTheModulo) {
  const auto unit = [](float t) {
    if (!std::isfinite(t)) return 0.0f;
    const float f = t - std::floor(t);
    return f < 1.0f ? f : 0.0f;
  };
  const auto modulo = [](int x, int n) { return ((x % n) + n) % n; };
  std::mt19937 gen(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int w : {1, 2, 3, 7})
    for (int h : {1, 2, 5}) {
      Texture t;
      t.width = w;
      t.height = h;
      for (int i = 0; i < w * h; ++i) t.texels.push_back(glm::vec4(u(gen), u(gen), u(gen), 1.0f));
      std::vector<float> coords = {0.0f,
                                   0.99999994f,
                                   -0.99999994f,
                                   1e9f,
                                   -1e9f,
                                   std::numeric_limits<float>::infinity(),
                                   std::numeric_limits<float>::quiet_NaN()};
      for (int k = -40; k <= 40; ++k) coords.push_back(k / 16.0f + 1.0f / 64.0f);
      for (float a : coords)
        for (float b : coords) {
          const float x = unit(a) * static_cast<float>(w) - 0.5f;
          const float y = (1.0f - unit(b)) * static_cast<float>(h) - 0.5f;
          const int fx = static_cast<int>(std::floor(x)), fy = static_cast<int>(std::floor(y));
          const float tx = x - std::floor(x), ty = y - std::floor(y);
          const auto at = [&](int i, int j) { return t.fetch(modulo(i, w), modulo(j, h)); };
          const glm::vec4 want = glm::mix(glm::mix(at(fx, fy), at(fx + 1, fy), tx),
                                          glm::mix(at(fx, fy + 1), at(fx + 1, fy + 1), tx), ty);
          ASSERT_EQ(t.sample({a, b}), want) << w << "x" << h << " at " << a << ", " << b;
        }
    }
}

// A bump map's gradient from its precomputed per-texel slopes equals the one-texel forward
// differences of the bilinear sample it replaces (three lookups), up to float rounding, at
// random points, across the wrapping edges too.
TEST(Texture, BumpSlopesGiveTheFiniteDifferenceGradient) {
  Texture t;
  t.width = 7;
  t.height = 5;
  std::mt19937 gen(8);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int i = 0; i < t.width * t.height; ++i) {
    const float h = u(gen);
    t.texels.push_back(glm::vec4(h, h, h, 1.0f));
  }
  Texture prepared = t;
  prepare_bump_slopes(prepared);
  ASSERT_EQ(prepared.slopes.size(), 35u);
  for (int i = 0; i < 2000; ++i) {
    const glm::vec2 uv(4.0f * u(gen) - 2.0f, 4.0f * u(gen) - 2.0f);
    const glm::vec2 want = t.sample_gradient(uv), got = prepared.sample_gradient(uv);
    // Gradients are up to 7 per unit uv here; the three-lookup form loses about 1e-6 * 7 to
    // the rounding of uv + 1 / width.
    ASSERT_NEAR(got.x, want.x, 2e-4f) << uv.x << ", " << uv.y;
    ASSERT_NEAR(got.y, want.y, 2e-4f) << uv.x << ", " << uv.y;
  }
}

// An 8-bit texture samples exactly as the same texels decoded to floats (the 8-bit path reads
// its four taps without fetch()'s per-texel checks), sRGB and linear, at random points across
// the wrapping edges, far outside [0, 1), and on texel centres and edges.
TEST(Texture, EightBitSamplesEqualTheirDecodedFloats) {
  std::mt19937 gen(21);
  std::uniform_int_distribution<int> byte(0, 255);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (bool srgb : {false, true}) {
    Texture eight;
    eight.width = 5;
    eight.height = 3;
    eight.srgb = srgb;
    for (int i = 0; i < eight.width * eight.height; ++i)
      eight.texels8.push_back(
          {static_cast<std::uint8_t>(byte(gen)), static_cast<std::uint8_t>(byte(gen)),
           static_cast<std::uint8_t>(byte(gen)), static_cast<std::uint8_t>(byte(gen))});
    Texture decoded;
    decoded.width = eight.width;
    decoded.height = eight.height;
    for (int y = 0; y < eight.height; ++y)
      for (int x = 0; x < eight.width; ++x) decoded.texels.push_back(eight.fetch(x, y));
    std::vector<glm::vec2> points;
    for (int i = 0; i < 3000; ++i) points.emplace_back(8.0f * u(gen) - 4.0f, 8.0f * u(gen) - 4.0f);
    for (int x = 0; x <= 2 * eight.width; ++x)
      for (int y = 0; y <= 2 * eight.height; ++y)
        points.emplace_back(0.5f * static_cast<float>(x) / static_cast<float>(eight.width),
                            0.5f * static_cast<float>(y) / static_cast<float>(eight.height));
    points.emplace_back(0.99999994f, 0.99999994f);
    points.emplace_back(-1e-30f, 1e6f);
    for (const glm::vec2& uv : points) {
      const glm::vec4 got = eight.sample(uv), want = decoded.sample(uv);
      for (int c = 0; c < 4; ++c)
        ASSERT_EQ(got[c], want[c]) << "srgb " << srgb << " uv " << uv.x << ", " << uv.y;
    }
  }
}

TEST(ImageLoader, DecodesSrgbOnlyForColourAndExpandsGrey) {
  TempDir dir;
  write_png(dir / "grey.png", 2, 2, 1, [](int, int, int) { return 128; });
  const Texture colour = load_image(dir / "grey.png", ImageDecode{true, false});
  const Texture data = load_image(dir / "grey.png", ImageDecode{false, false});
  const Texture mask = load_image(dir / "grey.png", ImageDecode{false, true});
  ASSERT_EQ(colour.width, 2);
  EXPECT_NEAR(colour.fetch(0, 0).x, 0.2158605f, 1e-4f);
  EXPECT_NEAR(colour.fetch(0, 0).z, 0.2158605f, 1e-4f);
  EXPECT_FLOAT_EQ(colour.fetch(0, 0).w, 1.0f);
  EXPECT_NEAR(data.fetch(0, 0).y, 128.0f / 255.0f, 1e-6f);
  EXPECT_NEAR(mask.fetch(0, 0).w, 128.0f / 255.0f, 1e-6f);  // grey mask becomes alpha
  // 8-bit sources stay 8-bit in memory and decode on fetch to what a decode at load gave:
  // the sRGB transfer function, and i / 255 for data and alpha, exactly.
  EXPECT_EQ(colour.texels8.size(), 4u);
  EXPECT_TRUE(colour.texels.empty());
  EXPECT_EQ(colour.fetch(1, 1).x, srgb_to_linear(128.0f / 255.0f));
  EXPECT_EQ(data.fetch(1, 1).x, 128.0f / 255.0f);
  EXPECT_EQ(colour.fetch(1, 1).w, 1.0f);

  write_png(dir / "rgba.png", 1, 1, 4, [](int, int, int c) { return c == 3 ? 51 : 128; });
  const Texture rgba = load_image(dir / "rgba.png", ImageDecode{true, false});
  EXPECT_NEAR(rgba.fetch(0, 0).x, 0.2158605f, 1e-4f);  // colour not premultiplied by alpha
  EXPECT_NEAR(rgba.fetch(0, 0).w, 0.2f, 1e-6f);        // alpha never sRGB-decoded

  // An environment map's radiance is unbounded; a material's float texture lies in [0, 1].
  write_float_image(dir / "env.exr", 2, 1, 7.5f);
  EXPECT_FLOAT_EQ(load_image(dir / "env.exr", ImageDecode{true, false, false}).texels[1].y, 7.5f);
  expect_input_error(
      [&] {
        load_image(dir / "env.exr", ImageDecode{true, false});
      },
      {"env.exr", "pixel (0, 0) channel 0 is 7.5", "above 1"});
  write_float_image(dir / "rounded.exr", 2, 1, 1.0f + 0x1p-12f);  // rounding above 1: read as 1
  EXPECT_EQ(load_image(dir / "rounded.exr", ImageDecode{false, false}).texels[1].y, 1.0f);
}

// A mask stored as grey + alpha with the alpha opaque in every texel (Crytek Sponza's leaf, chain
// and plant masks) holds its mask in the grey channel: read by its alpha it cut nothing, and the
// leaves rendered as solid cards. A mask whose alpha varies is read by its alpha, and a colour
// texture keeps its opaque alpha.
TEST(ImageLoader, AMaskWithAnOpaqueAlphaChannelIsItsGreyChannel) {
  TempDir dir;
  write_png(dir / "grey_alpha.png", 4, 4, 2,
            [](int x, int, int c) { return c == 1 ? 255 : (x < 2 ? 0 : 255); });
  const Texture mask = load_image(dir / "grey_alpha.png", ImageDecode{false, true});
  EXPECT_EQ(mask.fetch(0, 0).w, 0.0f);
  EXPECT_EQ(mask.fetch(3, 0).w, 1.0f);
  const Texture colour = load_image(dir / "grey_alpha.png", ImageDecode{true, false});
  EXPECT_EQ(colour.fetch(0, 0).w, 1.0f);
  write_png(dir / "varying.png", 4, 4, 2,
            [](int x, int, int c) { return c == 1 ? (x < 2 ? 255 : 0) : 255; });
  const Texture varying = load_image(dir / "varying.png", ImageDecode{false, true});
  EXPECT_EQ(varying.fetch(0, 0).w, 1.0f);
  EXPECT_EQ(varying.fetch(3, 0).w, 0.0f);
}

// ---- a valid scene with every feature ------------------------------------------------------

TEST(SceneLoader, LoadsEveryFeature) {
  TempDir dir;
  write_obj_with_mtl(dir);
  write_ply(dir / "floor.ply");
  write_png(dir / "tex/rough.png", 2, 2, 1, [](int, int, int) { return 200; });
  write_png(dir / "tex/normal.png", 2, 2, 3, [](int, int, int c) { return c == 2 ? 255 : 128; });
  write_float_image(dir / "sky.hdr", 8, 4, 2.0f);
  write_file(dir / "scene.json", R"({
    "description": "every feature",
    "camera": {"position": [0, 1, 5], "look_at": [0, 1, 0], "up": [0, 1, 0], "fov": 39.3},
    "camera_paths": {"orbit": {"fps": 24, "keys": [
        {"time": 0, "position": [0, 1, 5], "look_at": [0, 1, 0]},
        {"time": 2, "position": [5, 1, 0], "look_at": [0, 1, 0], "fov": 60}]}},
    "materials": {
      "red": {"base_color": [0.8, 0.1, 0.1], "roughness": 0.3, "metallic": 1, "specular": 0.5},
      "lamp": {"emission": [4, 4, 4]},
      "fancy": {"base_color_texture": "model/tex/albedo.png", "roughness_texture": "tex/rough.png",
                "normal_texture": "tex/normal.png", "bump_texture": "model/tex/height.png",
                "bump_scale": 2, "alpha_texture": "model/tex/mask.png", "transmissive": true}
    },
    "meshes": [
      {"file": "model/box.obj", "transform": {"translate": [10, 0, 0]}},
      {"file": "floor.ply", "material": "red",
       "transform": {"scale": [1, 1, -1], "rotate": [{"axis": [0, 0, 1], "angle_deg": 90}]}}
    ],
    "shapes": [
      {"type": "quad", "corner": [0, 3, 0], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "material": "lamp"},
      {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 1], "material": "fancy",
       "transform": {"matrix": [1,0,0,0, 0,1,0,-20, 0,0,1,0, 0,0,0,1]}},
      {"type": "sphere", "center": [0, 0, 0], "radius": 2, "subdivisions": 1, "inward": true,
       "material": "red"}
    ],
    "material_overrides": [
      {"match": "textured", "set": {"roughness": 0.25}},
      {"match": "*", "set": {"bump_scale": 3}}
    ],
    "sun": {"direction": [0, 2, 0], "irradiance": [3, 2, 1]},
    "environment": {"file": "sky.hdr", "intensity": 0.5, "rotation_deg": 90}
  })");

  const Scene scene = load_scene(dir / "scene.json");
  EXPECT_EQ(scene.source_path, dir / "scene.json");

  // Geometry: OBJ (3 materials, 4 triangles), PLY (2), quad (2), box (12), sphere (80).
  EXPECT_EQ(scene.triangle_count(), 4u + 2u + 2u + 12u + 80u);
  expect_vec3_near(scene.bounds_min(), {-2, -21, -2});
  expect_vec3_near(scene.bounds_max(), {11, 3, 2});

  auto material = [&](const std::string& name) -> const Material& {
    for (const Material& m : scene.materials)
      if (m.name == name) return m;
    ADD_FAILURE() << "no material " << name;
    return scene.materials.front();
  };
  const Material& textured = material("textured");
  EXPECT_GE(textured.base_color_texture, 0);
  EXPECT_GE(textured.bump_texture, 0);
  EXPECT_GE(textured.alpha_texture, 0);
  EXPECT_FLOAT_EQ(textured.bump_scale, 3.0f);  // -bm 0.5, then the "*" override
  EXPECT_FLOAT_EQ(textured.specular, 0.04f);
  EXPECT_FLOAT_EQ(textured.roughness, 0.25f);  // the named override
  EXPECT_FALSE(textured.transmissive);
  const Material& light = material("light");
  expect_vec3_near(light.emission, {10, 8, 6});
  EXPECT_FLOAT_EQ(light.specular, 0.0f);  // Ks 0: pure Lambert
  EXPECT_FLOAT_EQ(light.roughness, 1.0f);
  const Material& glass = material("glass");
  EXPECT_TRUE(glass.transmissive);
  EXPECT_FLOAT_EQ(glass.roughness, 0.05f);  // sqrt(2/1002) clamped
  const Material& fancy = material("fancy");
  EXPECT_GE(fancy.roughness_texture, 0);
  EXPECT_GE(fancy.normal_texture, 0);
  EXPECT_TRUE(fancy.transmissive);
  // The same file with the same decoding is decoded once.
  EXPECT_EQ(fancy.base_color_texture, textured.base_color_texture);
  EXPECT_EQ(fancy.alpha_texture, textured.alpha_texture);
  EXPECT_EQ(fancy.bump_texture, textured.bump_texture);
  // albedo (colour), height, mask (OBJ) + rough, normal (JSON) + sky = 6 textures.
  EXPECT_EQ(scene.textures.size(), 6u);
  // The grey mask: black left half is alpha 0.
  const Texture& mask = scene.textures.at(static_cast<std::size_t>(textured.alpha_texture));
  EXPECT_FLOAT_EQ(mask.fetch(0, 0).w, 0.0f);
  EXPECT_FLOAT_EQ(mask.fetch(3, 0).w, 1.0f);

  // The PLY: no normals in the file, so flat ones; mirrored by scale z = -1 and rotated.
  const Mesh* floor = nullptr;
  for (const Mesh& m : scene.meshes)
    if (scene.materials[m.material].name == "red" && m.triangles.size() == 2) floor = &m;
  ASSERT_NE(floor, nullptr);
  for (const glm::uvec3& t : floor->triangles) {
    const glm::vec3 g = glm::cross(floor->positions[t.y] - floor->positions[t.x],
                                   floor->positions[t.z] - floor->positions[t.x]);
    // Winding flipped with the mirror: geometric and shading normals still agree.
    EXPECT_GT(glm::dot(g, floor->normals[t.x]), 0.0f);
  }
  expect_vec3_near(floor->normals[0], {0, 0, -1});

  // The inward sphere: normals point to the centre and agree with the winding.
  const Mesh& sphere = scene.meshes.back();
  ASSERT_EQ(sphere.triangles.size(), 80u);
  for (const glm::uvec3& t : sphere.triangles) {
    const glm::vec3 g = glm::cross(sphere.positions[t.y] - sphere.positions[t.x],
                                   sphere.positions[t.z] - sphere.positions[t.x]);
    EXPECT_LT(glm::dot(g, sphere.positions[t.x]), 0.0f);
    EXPECT_GT(glm::dot(g, sphere.normals[t.x]), 0.0f);
  }

  // Camera and camera path.
  EXPECT_NEAR(scene.camera.view.fov_y, glm::radians(39.3f), 1e-6f);
  ASSERT_EQ(scene.camera.paths.count("orbit"), 1u);
  const CameraPath& orbit = scene.camera.paths.at("orbit");
  EXPECT_FLOAT_EQ(orbit.fps, 24.0f);
  expect_vec3_near(orbit.at(0.0f).position, {0, 1, 5});
  expect_vec3_near(orbit.at(2.0f).position, {5, 1, 0});
  EXPECT_NEAR(orbit.at(0.0f).fov_y, glm::radians(39.3f), 1e-6f);  // default from the camera
  EXPECT_NEAR(orbit.at(2.0f).fov_y, glm::radians(60.0f), 1e-6f);

  // Lights.
  EXPECT_TRUE(scene.sun.enabled);
  expect_vec3_near(scene.sun.direction, {0, 1, 0});
  EXPECT_NEAR(scene.sun.angular_radius, glm::radians(0.27f), 1e-7f);
  EXPECT_EQ(scene.environment.kind, Environment::Kind::Map);
  expect_vec3_near(scene.environment.color, glm::vec3(0.5f));
  EXPECT_NEAR(scene.environment.rotation, glm::radians(90.0f), 1e-6f);
  EXPECT_FLOAT_EQ(
      scene.textures.at(static_cast<std::size_t>(scene.environment.map_texture)).texels[0].x, 2.0f);

  const SceneFeatures f = scene.features();
  EXPECT_TRUE(f.textures && f.normal_maps && f.bump_maps && f.alpha_masks);
  EXPECT_TRUE(f.area_lights && f.sun && f.environment && f.environment_map);
  EXPECT_TRUE(f.glossy && f.metallic && f.transmission && f.camera_paths);
}

TEST(SceneLoader, GltfMetallicRoughnessAndAlphaMask) {
  TempDir dir;
  // One triangle: positions (3 x vec3) then uvs (3 x vec2), float32 little-endian.
  const float data[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1};
  write_file(dir / "tri.bin", std::string(reinterpret_cast<const char*>(data), sizeof(data)));
  write_png(dir / "base.png", 2, 2, 4, [](int, int, int c) { return c == 3 ? 0 : 200; });
  write_png(dir / "mr.png", 2, 2, 3, [](int, int, int c) { return c * 100; });
  write_file(dir / "tri.gltf", R"({"asset": {"version": "2.0"},
    "buffers": [{"uri": "tri.bin", "byteLength": 60}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                    {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}],
    "images": [{"uri": "base.png"}, {"uri": "mr.png"}],
    "textures": [{"source": 0}, {"source": 1}],
    "materials": [{"name": "leafy", "pbrMetallicRoughness": {
        "baseColorFactor": [0.5, 0.6, 0.7, 1], "baseColorTexture": {"index": 0},
        "metallicFactor": 0.3, "roughnessFactor": 0.4, "metallicRoughnessTexture": {"index": 1}},
      "emissiveFactor": [1, 2, 3], "alphaMode": "MASK", "alphaCutoff": 0.3}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
    "nodes": [{"mesh": 0, "translation": [0, 0, 5]}], "scenes": [{"nodes": [0]}], "scene": 0})");
  write_file(dir / "scene.json",
             std::string("{") + kCamera + R"(, "meshes": [{"file": "tri.gltf"}]})");
  const Scene scene = load_scene(dir / "scene.json");
  ASSERT_EQ(scene.meshes.size(), 1u);
  expect_vec3_near(scene.meshes[0].positions[0], {0, 0, 5});  // node transform applied
  const Material& m = scene.materials.at(scene.meshes[0].material);
  EXPECT_EQ(m.name, "leafy");
  expect_vec3_near(m.base_color, {0.5f, 0.6f, 0.7f});
  EXPECT_FLOAT_EQ(m.roughness, 0.4f);
  EXPECT_FLOAT_EQ(m.metallic, 0.3f);
  EXPECT_GE(m.roughness_texture, 0);
  EXPECT_EQ(m.metallic_texture, m.roughness_texture);
  EXPECT_EQ(m.roughness_channel, 1);
  EXPECT_EQ(m.metallic_channel, 2);
  EXPECT_EQ(m.alpha_texture, m.base_color_texture);
  EXPECT_FLOAT_EQ(m.alpha_cutoff, 0.3f);
  expect_vec3_near(m.emission, {1, 2, 3});
  // glTF's uv origin is the top-left; after import (0,0) is the bottom-left: v flipped.
  EXPECT_NEAR(scene.meshes[0].uvs[0].y, 1.0f, 1e-6f);
}

TEST(SceneLoader, GlbWithEmbeddedTexture) {
  TempDir dir;
  write_png(dir / "emb.png", 2, 2, 4, [](int, int, int c) { return c == 3 ? 51 : 128; });
  std::ifstream png_file(dir / "emb.png", std::ios::binary);
  const std::string png((std::istreambuf_iterator<char>(png_file)),
                        std::istreambuf_iterator<char>());
  const float data[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1};
  std::string bin(reinterpret_cast<const char*>(data), sizeof(data));
  bin += png;
  while (bin.size() % 4) bin += '\0';
  std::string json = R"({"asset": {"version": "2.0"}, "buffers": [{"byteLength": )" +
                     std::to_string(bin.size()) + R"(}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                    {"buffer": 0, "byteOffset": 36, "byteLength": 24},
                    {"buffer": 0, "byteOffset": 60, "byteLength": )" +
                     std::to_string(png.size()) + R"(}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                   "min": [0, 0, 0], "max": [1, 1, 0]},
                  {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}],
    "images": [{"bufferView": 2, "mimeType": "image/png"}], "textures": [{"source": 0}],
    "materials": [{"name": "e", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
                   "emissiveFactor": [1, 1, 1]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
    "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0})";
  while (json.size() % 4) json += ' ';
  auto u32 = [](std::uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::string glb =
      "glTF" + u32(2) + u32(static_cast<std::uint32_t>(28 + json.size() + bin.size())) +
      u32(static_cast<std::uint32_t>(json.size())) + "JSON" + json +
      u32(static_cast<std::uint32_t>(bin.size())) + std::string("BIN\0", 4) + bin;
  write_file(dir / "emb.glb", glb);
  write_file(dir / "scene.json",
             std::string("{") + kCamera + R"(, "meshes": [{"file": "emb.glb"}]})");
  const Scene scene = load_scene(dir / "scene.json");
  const Material& m = scene.materials.at(scene.meshes.at(0).material);
  ASSERT_GE(m.base_color_texture, 0);
  const Texture& t = scene.textures.at(static_cast<std::size_t>(m.base_color_texture));
  EXPECT_NEAR(t.fetch(0, 0).x, 0.2158605f, 1e-4f);
  EXPECT_NEAR(t.fetch(0, 0).w, 0.2f, 1e-6f);
}

TEST(SceneLoader, TransformsApplyScaleThenRotateThenTranslate) {
  TempDir dir;
  write_file(dir / "scene.json", std::string("{") + kCamera + ", " + kLightSource + R"(,
    "materials": {"m": {}},
    "shapes": [{"type": "quad", "corner": [1, 0, 0], "edge1": [1, 0, 0], "edge2": [0, 1, 0],
                "material": "m", "transform": {"scale": 2,
                "rotate": {"axis": [0, 0, 1], "angle_deg": 90}, "translate": [0, 0, 3]}}]})");
  const Scene scene = load_scene(dir / "scene.json");
  // (1,0,0) -> scale (2,0,0) -> rotate (0,2,0) -> translate (0,2,3).
  expect_vec3_near(scene.meshes[0].positions[0], {0, 2, 3});
  expect_vec3_near(glm::vec3(scene.meshes[0].tangents[0]), {0, 1, 0});
  expect_vec3_near(scene.meshes[0].normals[0], {0, 0, 1});
}

TEST(SceneLoader, OverridesCanRemoveTexturesAndMustMatchSomething) {
  TempDir dir;
  write_png(dir / "a.png", 1, 1, 3, [](int, int, int) { return 10; });
  write_file(dir / "ok.json", simple_scene(R"("material_overrides": [
      {"match": "white", "set": {"base_color_texture": "a.png", "emission": [1, 1, 1]}},
      {"match": "white", "set": {"base_color_texture": null}}],)"));
  const Scene scene = load_scene(dir / "ok.json");
  EXPECT_EQ(scene.materials[0].base_color_texture, -1);
  EXPECT_TRUE(scene.materials[0].is_emissive());

  write_file(dir / "typo.json",
             simple_scene(R"("material_overrides": [{"match": "whit", "set": {}}],)"));
  expect_input_error([&] { load_scene(dir / "typo.json"); },
                     {"typo.json", "material_overrides[0].match", "whit"});
}

TEST(SceneLoader, AssetsFallBackToTheAssetRoot) {
  TempDir dir;
  write_ply(dir / "assets/shared/floor.ply");
  write_file(dir / "scenes/s.json", std::string("{") + kCamera + ", " + kLightSource +
                                        R"(, "meshes": [{"file": "shared/floor.ply"}]})");
  SceneLoadSettings options;
  options.asset_root = dir / "assets";
  const Scene scene = load_scene(dir / "scenes/s.json", options);
  EXPECT_EQ(scene.triangle_count(), 2u);
  // PLY has no materials: rtpg's default, named after the file.
  ASSERT_EQ(scene.materials.size(), 1u);
  EXPECT_EQ(scene.materials[0].name, "floor");
  expect_vec3_near(scene.materials[0].base_color, glm::vec3(Material{}.base_color));
  EXPECT_EQ(resolve_asset_root(dir / "scenes/s.json", options), dir / "assets");
  // Without the root: the message names the path as written and where it looked.
  options.asset_root = dir / "elsewhere";
  expect_input_error([&] { load_scene(dir / "scenes/s.json", options); },
                     {"s.json", "meshes[0].file", "'shared/floor.ply'",
                      (dir.path() / "scenes/shared/floor.ply").string(),
                      (dir.path() / "elsewhere/shared/floor.ply").string()});
}

// The shared Cornell box, when ../shared/scenes is there (not in every checkout).
TEST(SceneLoader, SharedCornellBox) {
  const char* candidates[] = {"../shared/scenes", "/work/shared/scenes"};
  std::string root;
  for (const char* c : candidates)
    if (fs::exists(fs::path(c) / "cornell-box/CornellBox-Original.obj")) root = c;
  if (root.empty()) GTEST_SKIP() << "../shared/scenes not found";
  TempDir dir;
  write_file(dir / "cornell.json",
             std::string("{") + kCamera +
                 R"(, "meshes": [{"file": "cornell-box/CornellBox-Original.obj"}]})");
  SceneLoadSettings options;
  options.asset_root = root;
  const Scene scene = load_scene(dir / "cornell.json", options);
  EXPECT_EQ(scene.triangle_count(), 36u);
  EXPECT_TRUE(scene.features().area_lights);
  EXPECT_FALSE(scene.features().glossy);
}

// Scene files comment their parts through "description" keys (scenes/*.json); only strings.
TEST(SceneLoader, DescriptionsAreCommentsOnEveryEntry) {
  TempDir dir;
  write_ply(dir / "floor.ply");
  write_file(dir / "described.json", R"({
    "description": "top",
    "camera": {"description": "c", "position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 40},
    "camera_paths": {"p": {"description": "p", "keys": [
        {"time": 0, "position": [0, 0, 5], "look_at": [0, 0, 0]},
        {"time": 1, "position": [1, 0, 5], "look_at": [0, 0, 0]}]}},
    "materials": {"lamp": {"description": "m", "emission": [1, 1, 1]}},
    "meshes": [{"description": "mesh", "file": "floor.ply", "material": "lamp"}],
    "shapes": [
      {"description": "q", "type": "quad", "corner": [0,0,0], "edge1": [1,0,0], "edge2": [0,1,0],
       "material": "lamp"},
      {"description": "b", "type": "box", "min": [0,0,0], "max": [1,1,1], "material": "lamp"},
      {"description": "s", "type": "sphere", "center": [0,0,0], "radius": 1, "material": "lamp"}],
    "material_overrides": [{"description": "o", "match": "*", "set": {"roughness": 0.5}}]
  })");
  const Scene scene = load_scene(dir / "described.json");
  EXPECT_EQ(scene.materials.size(), 1u);
  EXPECT_FLOAT_EQ(scene.materials[0].roughness, 0.5f);
  write_file(
      dir / "number.json",
      simple_scene(R"("material_overrides": [{"description": 3, "match": "*", "set": {}}],)"));
  expect_input_error([&] { load_scene(dir / "number.json"); },
                     {"number.json", "material_overrides[0].description"});
}

// ---- bad input: every error names the offending file ---------------------------------------

TEST(SceneLoaderErrors, MissingSceneFile) {
  TempDir dir;
  expect_input_error([&] { load_scene(dir / "nope.json"); }, {"nope.json", "not found"});
}

TEST(SceneLoaderErrors, MalformedJsonGivesLineAndColumn) {
  TempDir dir;
  write_file(dir / "bad.json", "{\n  \"camera\": {\n    \"fov\": 40,,\n  }\n}\n");
  expect_input_error([&] { load_scene(dir / "bad.json"); }, {"bad.json", "line 3", "column"});
}

// nlohmann reports a number beyond the double range as out_of_range, not parse_error (found by
// fuzzing): still a one-line InputError, not an escaped exception.
TEST(SceneLoaderErrors, NumberBeyondTheDoubleRange) {
  TempDir dir;
  write_file(dir / "huge.json", "{\"camera\": {\"fov\": 5E5555}}");
  expect_input_error([&] { load_scene(dir / "huge.json"); },
                     {"huge.json", "invalid JSON", "number overflow"});
}

TEST(SceneLoaderErrors, UnknownKeyIsNamed) {
  TempDir dir;
  write_file(dir / "unknown.json", simple_scene(R"("meshes": [{"fiel": "x.obj"}],)"));
  expect_input_error([&] { load_scene(dir / "unknown.json"); },
                     {"unknown.json", "meshes[0].fiel", "unknown key"});
  write_file(dir / "top.json", simple_scene(R"("lights": 1,)"));
  expect_input_error([&] { load_scene(dir / "top.json"); }, {"top.json", "lights", "unknown key"});
}

TEST(SceneLoaderErrors, DuplicateKeyIsNamed) {
  TempDir dir;
  write_file(dir / "dup.json", simple_scene(R"("shapes": [], "materials": {},)"));
  expect_input_error([&] { load_scene(dir / "dup.json"); },
                     {"dup.json", "materials: duplicate key"});
  write_file(dir / "dup2.json",
             simple_scene(R"("camera_paths": {"p": {"keys": [{}, {"time": 1, "time": 2}]}},)"));
  expect_input_error([&] { load_scene(dir / "dup2.json"); },
                     {"dup2.json", "camera_paths.p.keys[1].time: duplicate key"});
}

TEST(SceneLoaderErrors, WrongTypeNamesTheKeyPath) {
  TempDir dir;
  write_ply(dir / "floor.ply");
  write_file(dir / "wrong.json",
             simple_scene(R"("meshes": [{"file": "floor.ply", "transform": {"scale": "big"}}],)"));
  expect_input_error([&] { load_scene(dir / "wrong.json"); },
                     {"wrong.json: meshes[0].transform.scale: expected a number or an array of 3 "
                      "numbers"});
}

TEST(SceneLoaderErrors, MissingRequiredKeyAndBadValues) {
  TempDir dir;
  write_file(dir / "nocam.json", std::string("{") + kLightSource + "}");
  expect_input_error([&] { load_scene(dir / "nocam.json"); }, {"nocam.json", "camera", "missing"});
  write_file(dir / "fov.json",
             R"({"camera": {"position": [0,0,1], "look_at": [0,0,0], "fov": 180}})");
  expect_input_error([&] { load_scene(dir / "fov.json"); }, {"fov.json", "camera.fov"});
  write_file(dir / "times.json", simple_scene(R"("camera_paths": {"p": {"keys": [
      {"time": 1, "position": [0,0,1], "look_at": [0,0,0]},
      {"time": 1, "position": [0,0,2], "look_at": [0,0,0]}]}},)"));
  expect_input_error([&] { load_scene(dir / "times.json"); },
                     {"times.json", "camera_paths.p.keys[1].time", "increasing"});
}

// Every range check of the scene file's values, each failing with the file and the key path
// named (docs/robustness.md, "Input validation"): a zero sun direction (NaN everywhere after
// normalising), a sun cone of 90 degrees, negative light, a bounce count outside [1, 64], a
// colour above 1 (energy from nowhere), a roughness above 1, degenerate shapes, a zero scale and
// a singular matrix. And the one integrator value a scene sets is kept.
TEST(SceneLoaderErrors, ValuesOutOfRangeNameTheirKey) {
  TempDir dir;
  const auto scene_text = [](const std::string& light, const std::string& white,
                             const std::string& shape, const std::string& extra) {
    return std::string("{") + kCamera + ", " + light + R"(, "materials": {"white": )" + white +
           R"(}, "shapes": [)" + shape + "]" + extra + "}";
  };
  const std::string sun = kLightSource, white = R"({"base_color": [0.5, 0.5, 0.5]})",
                    quad = R"({"type": "quad", "corner": [0,0,0], "edge1": [1,0,0],
                               "edge2": [0,1,0], "material": "white"})";
  struct Case {
    std::string text;
    std::vector<std::string> expected;  // what the message must hold besides the file name
  };
  const std::vector<Case> cases = {
      {scene_text(R"("sun": {"direction": [0, 0, 0], "irradiance": [1, 1, 1]})", white, quad, ""),
       {"sun.direction", "zero"}},
      {scene_text(R"("sun": {"direction": [0, 1, 0], "irradiance": [1, 1, 1],
                             "angular_radius_deg": 90})",
                  white, quad, ""),
       {"sun.angular_radius_deg"}},
      {scene_text(R"("sun": {"direction": [0, 1, 0], "irradiance": [1, -1, 1]})", white, quad, ""),
       {"sun.irradiance", "negative"}},
      {scene_text(R"("environment": {"color": [0.5, -0.5, 0.5]})", white, quad, ""),
       {"environment.color", "negative"}},
      {scene_text(sun, white, quad, R"(, "integrator": {"max_bounces": 0})"),
       {"integrator.max_bounces", "[1, 64]"}},
      {scene_text(sun, white, quad, R"(, "integrator": {"max_bounces": 65})"),
       {"integrator.max_bounces", "[1, 64]"}},
      {scene_text(sun, R"({"base_color": [1.5, 0.5, 0.5]})", quad, ""),
       {"materials.white.base_color", "[0, 1]"}},
      {scene_text(sun, R"({"roughness": 2})", quad, ""), {"materials.white.roughness", "[0, 1]"}},
      {scene_text(sun, white,
                  R"({"type": "quad", "corner": [0,0,0], "edge1": [1,0,0], "edge2": [2,0,0],
                      "material": "white"})",
                  ""),
       {"shapes[0]", "parallelogram"}},
      {scene_text(sun, white,
                  R"({"type": "box", "min": [0,0,0], "max": [1,0,1], "material": "white"})", ""),
       {"shapes[0].max", "exceed"}},
      {scene_text(sun, white,
                  R"({"type": "sphere", "center": [0,0,0], "radius": 0, "material": "white"})", ""),
       {"shapes[0].radius", "positive"}},
      {scene_text(sun, white,
                  R"({"type": "box", "min": [0,0,0], "max": [1,1,1], "material": "white",
                      "transform": {"scale": [1, 0, 1]}})",
                  ""),
       {"shapes[0].transform.scale", "zero"}},
      {scene_text(sun, white,
                  R"({"type": "box", "min": [0,0,0], "max": [1,1,1], "material": "white",
                      "transform": {"matrix": [1,0,0,0, 0,1,0,0, 2,0,0,0, 0,0,0,1]}})",
                  ""),
       {"shapes[0].transform", "singular"}},
  };
  for (std::size_t k = 0; k < cases.size(); ++k) {
    SCOPED_TRACE(cases[k].text);
    const std::string name = "bad" + std::to_string(k) + ".json";
    write_file(dir / name, cases[k].text);
    std::vector<std::string> expected = cases[k].expected;
    expected.push_back(name);
    expect_input_error([&] { load_scene(dir / name); }, expected);
  }
  write_file(dir / "three.json",
             scene_text(sun, white, quad, R"(, "integrator": {"max_bounces": 3})"));
  EXPECT_EQ(load_scene(dir / "three.json").max_bounces, 3);
}

// The display exposure (PNG output, the benchmarks' LDR-FLIP): 1 by default, a positive finite
// number when given.
TEST(SceneLoader, ExposureDefaultsToOneAndMustBePositive) {
  TempDir dir;
  write_file(dir / "plain.json", simple_scene(""));
  EXPECT_EQ(load_scene(dir / "plain.json").exposure, 1.0f);
  write_file(dir / "bright.json", simple_scene(R"("exposure": 32,)"));
  EXPECT_EQ(load_scene(dir / "bright.json").exposure, 32.0f);
  for (const char* bad : {"0", "-2", "1e7", "\"high\""}) {
    write_file(dir / "bad.json", simple_scene(std::string("\"exposure\": ") + bad + ","));
    expect_input_error([&] { load_scene(dir / "bad.json"); }, {"bad.json", "exposure"});
  }
}

TEST(SceneLoaderErrors, NoLightSources) {
  TempDir dir;
  write_file(dir / "dark.json", std::string("{") + kCamera + R"(, "materials": {"m": {}},
    "shapes": [{"type": "box", "min": [0,0,0], "max": [1,1,1], "material": "m"}]})");
  expect_input_error([&] { load_scene(dir / "dark.json"); }, {"dark.json", "no light sources"});
}

// An environment map black in every texel lights nothing, like a black constant sky: with no
// other light the scene is refused.
TEST(SceneLoaderErrors, BlackEnvironmentMapIsNoLight) {
  TempDir dir;
  write_float_image(dir / "black.exr", 4, 2, 0.0f);
  write_file(dir / "s.json", std::string("{") + kCamera + R"(,
    "environment": {"file": "black.exr"}, "materials": {"m": {}},
    "shapes": [{"type": "box", "min": [0,0,0], "max": [1,1,1], "material": "m"}]})");
  expect_input_error([&] { load_scene(dir / "s.json"); }, {"s.json", "no light sources"});
  write_float_image(dir / "black.exr", 4, 2, 0.5f);
  EXPECT_NO_THROW(load_scene(dir / "s.json"));
}

// An environment map's rotation is kept in [0, 360) degrees before it becomes radians: a turn of
// 3,600,090 degrees is 90, where the float of its radians (62,833) would leave the map's azimuth
// only to about 0.004 rad.
TEST(SceneLoader, EnvironmentRotationIsReducedToOneTurn) {
  TempDir dir;
  write_float_image(dir / "sky.exr", 4, 2, 0.5f);
  for (const char* degrees : {"90", "3600090", "-270"}) {
    write_file(dir / "s.json", std::string("{") + kCamera + R"(,
      "environment": {"file": "sky.exr", "rotation_deg": )" +
                                   degrees + R"(}, "materials": {"m": {}},
      "shapes": [{"type": "box", "min": [0,0,0], "max": [1,1,1], "material": "m"}]})");
    const Scene scene = load_scene(dir / "s.json");
    const float r = scene.environment.rotation;
    EXPECT_NEAR(std::remainder(r - glm::radians(90.0f), 2.0f * 3.14159265f), 0.0f, 1e-6f)
        << degrees;
    EXPECT_LT(std::fabs(r), 6.2832f) << degrees;
  }
}

// A sun direction whose components square beyond float's range is still a direction: its
// normalisation used to give the zero vector, a sun that lit nothing.
TEST(SceneLoader, SunDirectionOfHugeComponentsNormalises) {
  TempDir dir;
  write_file(dir / "s.json", std::string("{") + kCamera + R"(,
    "sun": {"direction": [1e20, 2e20, 1e20], "irradiance": [1, 1, 1]}, "materials": {"m": {}},
    "shapes": [{"type": "box", "min": [0,0,0], "max": [1,1,1], "material": "m"}]})");
  const Scene scene = load_scene(dir / "s.json");
  const glm::vec3 expected = glm::normalize(glm::vec3(1.0f, 2.0f, 1.0f));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(scene.sun.direction[c], expected[c], 1e-6f);
}

TEST(SceneLoaderErrors, MissingMesh) {
  TempDir dir;
  write_file(dir / "s.json", simple_scene(R"("meshes": [{"file": "gone.obj"}],)"));
  expect_input_error([&] { load_scene(dir / "s.json"); },
                     {"s.json", "meshes[0].file", "gone.obj", "not found"});
}

TEST(SceneLoaderErrors, CorruptMesh) {
  TempDir dir;
  write_file(dir / "bad.ply", std::string("ply\nformat ascii 1.0\nelement vertex 3\n") +
                                  "property float x\n\x01\x02\xff garbage\n");
  write_file(dir / "s.json", simple_scene(R"("meshes": [{"file": "bad.ply"}],)"));
  expect_input_error([&] { load_scene(dir / "s.json"); }, {"bad.ply", "s.json"});

  // assimp 5.2.5 crashes on a truncated binary body and reads indices out of range.
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const std::string vertices(reinterpret_cast<const char*>(xyz), sizeof(xyz));
  write_file(dir / "short.ply", header + vertices.substr(0, 20));
  write_file(dir / "short.json", simple_scene(R"("meshes": [{"file": "short.ply"}],)"));
  expect_input_error([&] { load_scene(dir / "short.json"); }, {"short.ply", "ends inside"});
  const std::int32_t face[3] = {0, 1, 7};
  write_file(dir / "index.ply", header + vertices + std::string(1, '\3') +
                                    std::string(reinterpret_cast<const char*>(face), sizeof(face)));
  write_file(dir / "index.json", simple_scene(R"("meshes": [{"file": "index.ply"}],)"));
  expect_input_error([&] { load_scene(dir / "index.json"); }, {"index.ply", "vertex range"});
  // ... and aborts the process on faces of fewer than 3 vertices.
  write_file(dir / "line.ply", header.substr(0, header.find("binary_little_endian")) + "ascii 1.0" +
                                   header.substr(header.find("binary_little_endian") + 24) +
                                   "0 0 0\n1 0 0\n0 1 0\n2 0 1\n");
  write_file(dir / "line.json", simple_scene(R"("meshes": [{"file": "line.ply"}],)"));
  expect_input_error([&] { load_scene(dir / "line.json"); }, {"line.ply", "fewer than 3"});
  const std::int32_t good_face[3] = {0, 1, 2};
  write_file(dir / "good.ply", header + vertices + std::string(1, '\3') +
                                   std::string(reinterpret_cast<const char*>(good_face), 12));
  write_file(dir / "good.json", simple_scene(R"("meshes": [{"file": "good.ply"}],)"));
  EXPECT_EQ(load_scene(dir / "good.json").triangle_count(), 3u);  // 1 + the quad's 2

  write_file(dir / "bad.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [");
  write_file(dir / "t.json", simple_scene(R"("meshes": [{"file": "bad.gltf"}],)"));
  expect_input_error([&] { load_scene(dir / "t.json"); }, {"bad.gltf", "t.json"});

  // Parses, but holds no triangles.
  write_file(dir / "empty.obj", "v 0 0 0\nv 1 0 0\n");
  write_file(dir / "u.json", simple_scene(R"("meshes": [{"file": "empty.obj"}],)"));
  expect_input_error([&] { load_scene(dir / "u.json"); }, {"empty.obj"});
}

// The value checks after assimp's import (host/scene/mesh_check.h), which OBJ and PLY files
// never reach with bad values (their text checks come first): a glTF's non-finite vertex, a
// base colour above 1 and a negative emission each name the file, the mesh or material, and
// the value.
TEST(SceneLoaderErrors, GltfValuesOutOfRangeNameTheFile) {
  TempDir dir;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // A triangle whose positions are `vertices` (3 x vec3, float32), its material `material`.
  const auto gltf_scene = [&](const std::string& name, const float(&vertices)[9],
                              const std::string& material) {
    write_file(dir / (name + ".bin"),
               std::string(reinterpret_cast<const char*>(vertices), sizeof(vertices)));
    write_file(dir / (name + ".gltf"), R"({"asset": {"version": "2.0"},
      "buffers": [{"uri": ")" + name + R"(.bin", "byteLength": 36}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                     "min": [0, 0, 0], "max": [1, 1, 0]}],
      "materials": [)" + material + R"(],
      "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
      "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0})");
    write_file(dir / (name + ".json"),
               std::string("{") + kCamera + R"(, "meshes": [{"file": ")" + name + R"(.gltf"}]})");
    return dir / (name + ".json");
  };
  const float good[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const float with_nan[9] = {0, 0, 0, nan, 0, 0, 0, 1, 0};
  const std::string lamp = R"({"name": "lamp", "emissiveFactor": [1, 1, 1]})";
  EXPECT_EQ(load_scene(gltf_scene("good", good, lamp)).triangle_count(), 1u);
  expect_input_error([&] { load_scene(gltf_scene("nan", with_nan, lamp)); },
                     {"nan.gltf", "mesh 'tri'", "vertex 1", "not finite"});
  expect_input_error(
      [&] {
        load_scene(gltf_scene(
            "bright", good,
            R"({"name": "bright", "pbrMetallicRoughness": {"baseColorFactor": [1.5, 0.5, 0.5, 1]}})"));
      },
      {"bright.gltf", "material 'bright'", "base colour", "not in [0, 1]"});
  expect_input_error(
      [&] {
        load_scene(gltf_scene("dark", good, R"({"name": "dark", "emissiveFactor": [-1, 0, 0]})"));
      },
      {"dark.gltf", "material 'dark'", "emission", "non-negative"});
}

TEST(SceneLoaderErrors, MissingMtlFile) {
  TempDir dir;
  write_file(dir / "m.obj", "mtllib lost.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  write_file(dir / "s.json", simple_scene(R"("meshes": [{"file": "m.obj"}],)"));
  expect_input_error([&] { load_scene(dir / "s.json"); }, {"lost.mtl", "not found", "s.json"});
}

// A scene that replaces a mesh's materials still has assimp parse the MTL the OBJ names, so the
// library is checked all the same (assimp 5.2 crashed on this one, a texture before any newmtl:
// tests/fuzz/corpus/mtl/texture-before-newmtl.mtl); a missing one stays harmless there.
TEST(SceneLoaderErrors, AMaterialOverrideStillChecksTheMtl) {
  TempDir dir;
  write_file(dir / "m.obj", "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  write_file(dir / "bad.mtl", "map_d9\n\n");
  write_file(dir / "s.json",
             simple_scene(R"("meshes": [{"file": "m.obj", "material": "white"}],)"));
  expect_input_error([&] { load_scene(dir / "s.json"); }, {"bad.mtl", "s.json"});
  fs::remove(dir / "bad.mtl");
  EXPECT_NO_THROW(load_scene(dir / "s.json"));
}

// Meshes are read only in the formats scenes/README.md names, by extension: for another name
// assimp would pick a reader by the content, past the OBJ and PLY checks (a PLY named .dat that
// trips assimp's triangulation assert: tests/fuzz/corpus/ply/two-format-lines-triangulation-
// assert.ply), or reach any of its other readers.
TEST(SceneLoaderErrors, MeshesOnlyInTheFormatsNamed) {
  TempDir dir;
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n"
      "0 1 0\n3 0 1 2\n";
  for (const char* name : {"m.dat", "m.txt", "m.stl", "m"}) {
    write_file(dir / name, ply);
    write_file(dir / "s.json", simple_scene(std::string(R"("meshes": [{"file": ")") + name +
                                            R"(", "material": "white"}],)"));
    expect_input_error([&] { load_scene(dir / "s.json"); }, {name, "not a mesh format", "s.json"});
  }
  write_file(dir / "m.ply", ply);
  write_file(dir / "s.json",
             simple_scene(R"("meshes": [{"file": "m.ply", "material": "white"}],)"));
  EXPECT_NO_THROW(load_scene(dir / "s.json"));
}

TEST(SceneLoaderErrors, MissingTexture) {
  TempDir dir;
  write_file(dir / "s.json", simple_scene("", R"("t": {"base_color_texture": "tex/absent.png"},)"));
  expect_input_error([&] { load_scene(dir / "s.json"); },
                     {"s.json", "materials.t.base_color_texture", "absent.png", "not found"});
  // Named by an MTL: the texture file is the subject.
  write_obj_with_mtl(dir);
  fs::remove(dir / "model/tex/height.png");
  write_file(dir / "o.json", simple_scene(R"("meshes": [{"file": "model/box.obj"}],)"));
  expect_input_error([&] { load_scene(dir / "o.json"); },
                     {"height.png", "not found", "map_bump", "textured", "o.json"});
}

TEST(SceneLoaderErrors, CorruptTexture) {
  TempDir dir;
  write_file(dir / "broken.png", "\x89PNG\r\n\x1a\n this is not a png at all");
  write_file(dir / "s.json", simple_scene("", R"("t": {"normal_texture": "broken.png"},)"));
  expect_input_error([&] { load_scene(dir / "s.json"); },
                     {"broken.png", "materials.t.normal_texture", "s.json"});
  // Named by an MTL: the texture file is the subject, and the problem is said once, with the
  // material and the scene that referenced it (host/scene/texture_cache.cpp).
  write_obj_with_mtl(dir);
  write_file(dir / "model/tex/height.png", "\x89PNG\r\n\x1a\n not a png either");
  write_file(dir / "o.json", simple_scene(R"("meshes": [{"file": "model/box.obj"}],)"));
  const std::string message = expect_input_error([&] { load_scene(dir / "o.json"); },
                                                 {"height.png", "map_bump", "textured", "o.json"});
  const std::string subject = (dir / "model/tex/height.png") + ": ";
  EXPECT_EQ(message.rfind(subject, 0), 0u) << message;  // the subject first, and once
  EXPECT_EQ(message.find(subject, 1), std::string::npos) << message;
}

// A texture or an environment map that is a FIFO would block the read for good: refused before
// it is opened (the asset lookup takes regular files only, and load_image checks the kind too).
TEST(SceneLoaderErrors, ATextureThatIsNoFile) {
  TempDir dir;
  ASSERT_EQ(::mkfifo((dir / "pipe.png").c_str(), 0600), 0);
  write_file(dir / "s.json", simple_scene("", R"("t": {"base_color_texture": "pipe.png"},)"));
  expect_input_error([&] { load_scene(dir / "s.json"); }, {"pipe.png", "s.json"});
}

TEST(SceneLoaderErrors, MissingEnvironmentMap) {
  TempDir dir;
  write_file(dir / "s.json", std::string("{") + kCamera + R"(,
    "environment": {"file": "envmaps/none.hdr"}, "materials": {"m": {}},
    "shapes": [{"type": "box", "min": [0,0,0], "max": [1,1,1], "material": "m"}]})");
  expect_input_error([&] { load_scene(dir / "s.json"); },
                     {"s.json", "environment.file", "envmaps/none.hdr", "not found"});
}

// OIIO hands float images over as stored: a NaN or infinite texel must be refused, a tiny
// negative one (filtering leftovers in real EXRs) clamped to 0.
TEST(SceneLoaderErrors, NonFiniteEnvironmentMapTexel) {
  for (const float bad :
       {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    TempDir dir;
    write_float_image(dir / "sky.exr", 4, 2, bad);
    write_file(dir / "s.json", std::string("{") + kCamera + R"(,
      "environment": {"file": "sky.exr"}, "materials": {"m": {}},
      "shapes": [{"type": "box", "min": [0,0,0], "max": [1,1,1], "material": "m"}]})");
    expect_input_error([&] { load_scene(dir / "s.json"); },
                       {"sky.exr", "pixel (0, 0) channel 0 is not finite"});
  }
  TempDir dir;
  write_float_image(dir / "sky.exr", 4, 2, -1e-6f);
  const Texture t = load_image(dir / "sky.exr", ImageDecode{false, false});
  for (const glm::vec4& texel : t.texels) EXPECT_EQ(texel.x, 0.0f);
}

}  // namespace
}  // namespace rtpg
