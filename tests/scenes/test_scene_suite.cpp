// The scene suite (scenes/*.json): every scene loads with the expected size and lights, has
// its named camera path, and renders a few small frames with and without guiding to finite,
// plausibly bright images. Real assets come from ../shared/scenes; without them the tests skip.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <ostream>
#include <memory>
#include <string>
#include <vector>

#include "rtpg/cl_runtime.h"
#include "render/guided_first_bounce.h"
#include "render/renderer.h"
#include "scene/scene_loader.h"

namespace rtpg {
namespace {

// What `rtpg info` prints for each scene file (triangles, the zero-area triangles the loader
// dropped, materials, textures, lights). The
// texture count is that of distinct (file, decoding) pairs: each is decoded once (Sponza's 25
// materials name 37 distinct maps; sponza-sky adds its environment map).
struct Expected {
  const char* file;
  std::size_t triangles, degenerate, materials, textures, emissive_triangles;
  bool sun;
  Environment::Kind environment;
  const char* camera_path;
};

const Expected kScenes[] = {
    {"cornell-box.json", 36, 0, 4, 0, 2, false, Environment::Kind::None, "pan"},
    {"cornell-indirect.json", 38, 0, 4, 0, 2, false, Environment::Kind::None, "pan"},
    {"cornell-glossy.json", 1112, 0, 8, 0, 2, false, Environment::Kind::None, "pan"},
    {"slit-room.json", 62, 0, 3, 0, 2, false, Environment::Kind::None, "pan"},
    {"corridor.json", 22, 0, 3, 0, 2, false, Environment::Kind::None, "pan"},
    {"sunlit-room.json", 42, 0, 2, 0, 0, true, Environment::Kind::Constant, "pan"},
    {"sponza.json", 262035, 232, 25, 37, 0, true, Environment::Kind::Constant, "walk"},
    {"sponza-glossy.json", 262035, 232, 25, 37, 0, true, Environment::Kind::Constant, "walk"},
    {"sponza-sky.json", 262035, 232, 25, 38, 0, false, Environment::Kind::Map, "walk"},
    {"veach-ajar.json", 382628, 62, 13, 3, 2, false, Environment::Kind::None, "pan"},
};

// gtest prints a parameter in test listings: the file name, not its bytes.
void PrintTo(const Expected& e, std::ostream* os) {
  *os << e.file;
}

std::string scene_path(const char* file) {
  return std::string(RTPG_SOURCE_DIR) + "/scenes/" + file;
}

// Every scene here draws on ../shared/scenes (the Cornell boxes built from shapes do not, but
// the suite is one unit: it runs whole or not at all).
bool assets_available(std::string& why) {
  const std::string root = resolve_asset_root(scene_path("sponza.json"), {});
  std::error_code ec;
  if (root.empty() || !std::filesystem::is_directory(root, ec)) {
    why = "scene assets not found: " +
          (root.empty() ? std::string("no ../shared/scenes next to the project")
                        : "asset root '" + root + "' is not a folder") +
          " (set RTPG_ASSET_ROOT to a copy of shared/scenes to run the scene suite)";
    return false;
  }
  return true;
}

// Each scene is loaded once per test process (Sponza takes about 2 s).
const Scene& cached_scene(const char* file) {
  static std::map<std::string, std::unique_ptr<Scene>> cache;
  std::unique_ptr<Scene>& slot = cache[file];
  if (!slot) slot = std::make_unique<Scene>(load_scene(scene_path(file)));
  return *slot;
}

ClRuntime& cl_runtime() {
  static ClRuntime runtime;
  return runtime;
}

// Solid-angle mean of an equirectangular map (rows weighted by sin(theta)).
glm::vec3 map_mean(const Texture& map) {
  glm::dvec3 sum(0.0);
  double weight = 0.0;
  for (int y = 0; y < map.height; ++y) {
    const double w = std::sin(M_PI * (y + 0.5) / map.height);
    for (int x = 0; x < map.width; ++x) sum += w * glm::dvec3(glm::vec3(map.fetch(x, y)));
    weight += w * map.width;
  }
  return glm::vec3(sum / weight);
}

// Upper bound of a plausible image mean: the radiance of a white Lambertian surface that sees
// every light at once, fully and unshadowed. The sun adds E / pi; the environment adds at most
// 4 times its spherical mean (E <= the integral over the whole sphere = 4 pi mean); an area
// light adds at most its radiance (E <= pi L_max). Surfaces have albedo <= 1 and in these
// scenes see only part of their lights, so the true image mean lies well below this; the
// sky or a light seen directly covers too few pixels to lift the mean above it.
double radiance_bound(const Scene& scene) {
  double bound = 0.0;
  auto max3 = [](const glm::vec3& v) { return std::max({v.x, v.y, v.z}); };
  if (scene.sun.enabled) bound += max3(scene.sun.irradiance) / M_PI;
  if (scene.environment.kind == Environment::Kind::Constant)
    bound += 4.0 * max3(scene.environment.color);
  if (scene.environment.kind == Environment::Kind::Map)
    bound += 4.0 * max3(scene.environment.color *
                        map_mean(scene.textures.at(scene.environment.map_texture)));
  float emission = 0.0f;
  for (const Mesh& m : scene.meshes)
    if (!m.triangles.empty())
      emission = std::max(emission, max3(scene.materials[m.material].emission));
  return bound + emission;
}

class SceneSuite : public ::testing::TestWithParam<Expected> {
 protected:
  void SetUp() override {
    std::string why;
    if (!assets_available(why)) GTEST_SKIP() << why;
  }
};

// One test per scene (ctest runs each test in its own process: the scene is loaded once).
TEST_P(SceneSuite, LoadsAndRenders) {
  const Expected& e = GetParam();
  const Scene& scene = cached_scene(e.file);

  // Contents, as `rtpg info` prints them.
  std::size_t emissive = 0;
  for (const Mesh& m : scene.meshes)
    if (scene.materials[m.material].is_emissive()) emissive += m.triangles.size();
  EXPECT_EQ(scene.triangle_count(), e.triangles) << e.file;
  EXPECT_EQ(scene.degenerate_triangles, e.degenerate) << e.file;
  EXPECT_EQ(scene.materials.size(), e.materials) << e.file;
  EXPECT_EQ(scene.textures.size(), e.textures) << e.file;
  EXPECT_EQ(emissive, e.emissive_triangles) << e.file;
  EXPECT_EQ(scene.sun.enabled, e.sun) << e.file;
  EXPECT_EQ(scene.environment.kind, e.environment) << e.file;
  EXPECT_EQ(scene.camera.paths.count(e.camera_path), 1u)
      << e.file << " has no camera path '" << e.camera_path << "'";
  // Every alpha mask cuts something: a mask read from a channel that is opaque everywhere (Crytek
  // Sponza's grey + alpha masks, read by their alpha) would leave its leaves solid cards.
  for (const Material& m : scene.materials) {
    if (m.alpha_texture < 0) continue;
    const Texture& mask = scene.textures.at(static_cast<std::size_t>(m.alpha_texture));
    std::size_t cut = 0;
    for (int y = 0; y < mask.height; ++y)
      for (int x = 0; x < mask.width; ++x) cut += mask.fetch(x, y).w < m.alpha_cutoff;
    EXPECT_GT(cut, 0u) << e.file << ": the mask " << mask.path << " cuts no texel";
  }

  // 3 frames at 48x27: plain path tracing from the static camera, then guided along the path.
  const double bound = radiance_bound(scene);
  ASSERT_GT(bound, 0.0) << e.file;
  const int width = 48, height = 27, frames = 3;
  for (int guided = 0; guided < 2; ++guided) {
    RenderSettings settings;
    settings.width = width;
    settings.height = height;
    settings.seed = 7u + static_cast<std::uint32_t>(guided);
    settings.camera_path = guided ? e.camera_path : "";
    settings.path_tracer.max_bounces = scene.max_bounces > 0 ? scene.max_bounces : 8;
    Renderer renderer(scene, settings);
    if (guided)
      renderer.set_first_bounce_sampler(
          std::make_unique<GuidedFirstBounce>(cl_runtime(), width, height, GuidingSettings{}));
    double mean = 0.0;
    for (int f = 0; f < frames; ++f) {
      const FrameStats stats = renderer.render_frame(f);
      EXPECT_EQ(stats.nonfinite_samples, 0u) << e.file << " frame " << f;
      std::size_t nonfinite = 0;
      for (const glm::vec3& c : renderer.image()) {
        if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) {
          ++nonfinite;
          continue;
        }
        EXPECT_GE(std::min({c.x, c.y, c.z}), 0.0f) << e.file;
        mean += (0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z) / (double(width) * height * frames);
      }
      EXPECT_EQ(nonfinite, 0u) << e.file << " frame " << f << (guided ? " (guided)" : " (PT)");
    }
    EXPECT_GT(mean, 0.0) << e.file << (guided ? " guided" : " PT");
    EXPECT_LT(mean, bound) << e.file << (guided ? " guided" : " PT");
    std::printf("%-20s %-6s mean luminance %.4f (bound %.1f)\n", e.file, guided ? "guided" : "PT",
                mean, bound);
  }
}

std::string scene_name(const ::testing::TestParamInfo<Expected>& info) {
  std::string name = info.param.file;
  name = name.substr(0, name.find('.'));
  std::replace(name.begin(), name.end(), '-', '_');
  return name;
}

INSTANTIATE_TEST_SUITE_P(Scenes, SceneSuite, ::testing::ValuesIn(kScenes), scene_name);

}  // namespace
}  // namespace rtpg
