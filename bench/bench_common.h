// What the benchmark programs share: the scenes they load (the project's Cornell box, Crytek
// Sponza from ../shared/scenes through a small scene file written at run time), the rays they
// build from a real camera and real first hits, and a main() that runs medians of 3
// repetitions unless told otherwise.
#pragma once

#include <benchmark/benchmark.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "render/camera_rays.h"
#include "render/lights.h"
#include "render/surface.h"
#include "scene/camera.h"
#include "scene/scene.h"
#include "scene/scene_loader.h"
#include "shared/compat.h"
#include "shared/rng.h"
#include "trace/embree_scene.h"

namespace rtpg::bench {

// ---- scenes ------------------------------------------------------------------------------

inline std::string cornell_path() {
  return std::string(RTPG_SOURCE_DIR) + "/scenes/cornell-box.json";
}

// $RTPG_ASSET_ROOT, else ../shared/scenes next to the source tree.
inline std::string shared_scenes_dir() {
  if (const char* env = std::getenv("RTPG_ASSET_ROOT"); env && *env) return env;
  return std::string(RTPG_SOURCE_DIR) + "/../shared/scenes";
}

inline std::string sponza_obj_path() {
  return shared_scenes_dir() + "/crytek-sponza/sponza.obj";
}

// The Cornell box, loaded once per process.
inline const Scene& cornell_scene() {
  static const Scene scene = load_scene(cornell_path());
  return scene;
}

// Crytek Sponza lit by a sun and a constant sky, camera in the court looking along its long
// axis; loaded once per process. nullptr when the asset is missing (*why says what to do).
inline const Scene* sponza_scene(std::string* why) {
  static std::unique_ptr<Scene> scene;
  static std::string missing;
  static bool tried = false;
  if (!tried) {
    tried = true;
    const std::string obj = sponza_obj_path();
    if (!std::filesystem::exists(obj)) {
      missing =
          "Crytek Sponza not found at " + obj +
          ": set RTPG_ASSET_ROOT to the folder holding crytek-sponza/ (default: ../shared/scenes"
          " next to the source tree)";
    } else {
      const std::filesystem::path json =
          std::filesystem::temp_directory_path() /
          ("rtpg_bench_sponza_" + std::to_string(::getpid()) + ".json");
      {
        std::ofstream out(json);
        out << "{\n"
               "  \"description\": \"rtpg benchmarks: Crytek Sponza, sun and sky\",\n"
               "  \"camera\": {\"position\": [-1100, 180, -40], \"look_at\": [1000, 420, 40], "
               "\"fov\": 60},\n"
               "  \"meshes\": [{\"file\": \""
            << obj
            << "\"}],\n"
               "  \"sun\": {\"direction\": [0.25, 1.0, 0.15], \"irradiance\": [10, 10, 10]},\n"
               "  \"environment\": {\"color\": [0.3, 0.4, 0.55]}\n"
               "}\n";
      }
      try {
        scene = std::make_unique<Scene>(load_scene(json.string()));
      } catch (const std::exception& e) {
        missing = std::string("Crytek Sponza failed to load: ") + e.what();
      }
      std::error_code ec;
      std::filesystem::remove(json, ec);
    }
  }
  if (!scene && why) *why = missing;
  return scene.get();
}

// The scene called `name` ("cornell" or "sponza"); nullptr (with *why) when unavailable.
inline const Scene* scene_by_name(const std::string& name, std::string* why) {
  if (name == "cornell") return &cornell_scene();
  return sponza_scene(why);
}

// ---- rays from a real camera and real first hits ----------------------------------------

// Representative ray sets of each kind for one scene, camera and resolution:
//   primary   : one camera ray per pixel through its centre;
//   secondary : from every primary hit, a cosine-distributed bounce about the geometric normal
//               (the first bounce of a diffuse path: the incoherent kind);
//   shadow    : from every primary hit, towards a light sample (NEE), as the path tracer makes
//               them (finite length to area lights, unbounded towards the sun and the sky).
struct RaySets {
  int width = 0, height = 0;  // primary[y * width + x] is pixel (x, y)'s ray
  std::vector<Ray> primary, secondary, shadow;
  std::vector<Hit> hits;          // scratch for intersect()
  std::vector<std::uint8_t> occ;  // scratch for occluded()
};

inline RaySets make_ray_sets(const Scene& scene, const EmbreeScene& tracer, int width, int height,
                             std::uint32_t seed = 7) {
  RaySets s;
  s.width = width;
  s.height = height;
  const std::size_t n = static_cast<std::size_t>(width) * height;
  const CameraFrame camera =
      make_camera_frame(scene.camera.view, static_cast<float>(width) / static_cast<float>(height));
  s.primary.resize(n);
  make_camera_rays(camera, width, height, CameraJitter{false, 0u, 0u}, s.primary.data());
  std::vector<Hit> hits(n);
  tracer.intersect_image(s.primary.data(), hits.data(), width, height);

  const Lights lights(scene);
  std::vector<Ray> bounce(n), shadow(n);
  std::vector<std::uint8_t> has_bounce(n, 0), has_shadow(n, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      if (!hits[i].valid()) continue;
      const SurfacePoint sp = make_surface_point(scene, s.primary[i], hits[i]);
      const glm::vec3 origin =
          offset_ray_origin(sp.position, sp.geometric_normal, sp.offset_distance);
      shared::pg_rng rng = shared::pg_rng_make(seed, static_cast<shared::uint>(i), 0u, 0u, 9u);
      const float u1 = shared::pg_rng_next(&rng), u2 = shared::pg_rng_next(&rng);
      const float r = std::sqrt(u1), phi = 2.0f * PG_PI * u2;
      const glm::vec3 local(r * std::cos(phi), r * std::sin(phi),
                            std::sqrt(std::max(0.0f, 1.0f - u1)));
      const shared::pg_frame frame = shared::pg_frame_from_normal(sp.geometric_normal);
      Ray b;
      b.origin = origin;
      b.direction = shared::pg_to_world(frame, local);
      bounce[i] = b;
      has_bounce[i] = 1;
      LightSample ls;
      const float us = shared::pg_rng_next(&rng), v1 = shared::pg_rng_next(&rng),
                  v2 = shared::pg_rng_next(&rng);
      if (!lights.empty() && lights.sample(sp.position, us, v1, v2, ls) &&
          glm::dot(ls.direction, sp.geometric_normal) > 0.0f) {
        shadow[i] = shadow_ray(origin, ls);
        has_shadow[i] = 1;
      }
    }
  });
  for (std::size_t i = 0; i < n; ++i) {
    if (has_bounce[i]) s.secondary.push_back(bounce[i]);
    if (has_shadow[i]) s.shadow.push_back(shadow[i]);
  }
  s.hits.resize(n);
  s.occ.resize(n);
  return s;
}

enum class RayKind { Primary, Secondary, Shadow };

inline const char* kind_name(RayKind k) {
  return k == RayKind::Primary ? "primary" : (k == RayKind::Secondary ? "secondary" : "shadow");
}

inline const std::vector<Ray>& rays_of(const RaySets& s, RayKind k) {
  return k == RayKind::Primary ? s.primary : (k == RayKind::Secondary ? s.secondary : s.shadow);
}

// The camera rays as the renderer traces them (EmbreeScene::intersect_image, packets of pixel
// tiles); wall seconds.
inline double trace_primary_image(const EmbreeScene& tracer, RaySets& s) {
  const auto start = std::chrono::steady_clock::now();
  tracer.intersect_image(s.primary.data(), s.hits.data(), s.width, s.height);
  const auto stop = std::chrono::steady_clock::now();
  benchmark::DoNotOptimize(s.hits.data());
  return std::chrono::duration<double>(stop - start).count();
}

// Traces one set (closest hit for primary and secondary, any hit for shadow); wall seconds.
inline double trace_set(const EmbreeScene& tracer, RaySets& s, RayKind kind, RayMode mode) {
  const std::vector<Ray>& rays = rays_of(s, kind);
  const auto start = std::chrono::steady_clock::now();
  if (kind == RayKind::Shadow)
    tracer.occluded(rays.data(), s.occ.data(), rays.size(), mode);
  else
    tracer.intersect(rays.data(), s.hits.data(), rays.size(), mode);
  const auto stop = std::chrono::steady_clock::now();
  benchmark::DoNotOptimize(s.hits.data());
  benchmark::DoNotOptimize(s.occ.data());
  return std::chrono::duration<double>(stop - start).count();
}

// ---- main ----------------------------------------------------------------------------------

// Runs the benchmarks that `register_all(full)` registers. Unless the command line says
// otherwise, every benchmark runs 3 repetitions and reports only their aggregates (median,
// mean, stddev, cv). `--rtpg_full` (removed before Google Benchmark sees the arguments) asks
// for the larger configurations that a plain run leaves out.
inline int bench_main(int argc, char** argv, const std::function<void(bool full)>& register_all) {
  std::vector<char*> args;
  bool full = false, reps = false, aggregates = false;
  for (int i = 0; i < argc; ++i) {
    if (std::strcmp(argv[i], "--rtpg_full") == 0) {
      full = true;
      continue;
    }
    if (std::strncmp(argv[i], "--benchmark_repetitions", 23) == 0) reps = true;
    if (std::strncmp(argv[i], "--benchmark_report_aggregates_only", 34) == 0 ||
        std::strncmp(argv[i], "--benchmark_display_aggregates_only", 35) == 0)
      aggregates = true;
    args.push_back(argv[i]);
  }
  static char default_reps[] = "--benchmark_repetitions=3";
  static char default_aggregates[] = "--benchmark_report_aggregates_only=true";
  if (!reps) args.push_back(default_reps);
  if (!aggregates) args.push_back(default_aggregates);
  int n = static_cast<int>(args.size());
  args.push_back(nullptr);
  benchmark::Initialize(&n, args.data());
  if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 1;
  register_all(full);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace rtpg::bench
