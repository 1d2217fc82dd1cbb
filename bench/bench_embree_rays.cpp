// Embree alone: primary, secondary (incoherent first bounce) and shadow rays per second on the
// Cornell box and Crytek Sponza, one ray at a time, in 8-wide packets or in streams of 256
// (rtcIntersect1M / rtcOccluded1M) (RayMode), and camera rays also as the renderer traces
// them, in packets of pixel tiles (`tiles`: EmbreeScene::intersect_image). The rays
// come from the scene's camera and its real first hits and are built once, outside the timed
// loop (bench_common.h: make_ray_sets). Time is wall time of the whole batch (Embree over all
// cores with TBB), set as manual time.
//
//   bench_embree_rays                       Cornell and Sponza at 1920x1080
//   bench_embree_rays --rtpg_full           also 640x360 and 3840x2160
//   bench_embree_rays --benchmark_filter=sponza
//
// Packet8 and Stream benchmarks also trace the same set one ray at a time in every iteration
// (interleaved, not timed) and report packet_speedup or stream_speedup = single time / their
// time: the host
// drifts by 10-30% within minutes (docs/design.md, "PoCL and OpenCL facts"), so ratios are taken
// inside one iteration.
#include "bench_common.h"

#include <map>
#include <tuple>

namespace rtpg::bench {
namespace {

struct Setup {
  std::unique_ptr<EmbreeScene> tracer;
  RaySets rays;
};

// One BVH and one set of rays per (scene, resolution), built on first use.
Setup* setup_for(const std::string& scene_name, int w, int h, std::string* why) {
  static std::map<std::tuple<std::string, int, int>, std::unique_ptr<Setup>> cache;
  const auto key = std::make_tuple(scene_name, w, h);
  if (auto it = cache.find(key); it != cache.end()) return it->second.get();
  const Scene* scene = scene_by_name(scene_name, why);
  if (!scene) return nullptr;
  auto s = std::make_unique<Setup>();
  s->tracer = std::make_unique<EmbreeScene>(*scene);
  s->rays = make_ray_sets(*scene, *s->tracer, w, h);
  // Warm the BVH and the TBB arena once per kind, outside any timed loop.
  for (RayKind k : {RayKind::Primary, RayKind::Secondary, RayKind::Shadow})
    trace_set(*s->tracer, s->rays, k, RayMode::Single);
  return (cache[key] = std::move(s)).get();
}

// image_tiles: camera rays by EmbreeScene::intersect_image (mode is then Packet8, the
// comparison's name for packets).
void BM_EmbreeRays(benchmark::State& state, const std::string& scene_name, int w, int h,
                   RayKind kind, RayMode mode, bool image_tiles) {
  std::string why;
  Setup* s = setup_for(scene_name, w, h, &why);
  if (!s) {
    state.SkipWithError(why.c_str());
    return;
  }
  const double count = static_cast<double>(rays_of(s->rays, kind).size());
  double mode_s = 0.0, single_s = 0.0;
  for (auto _ : state) {
    const double t = image_tiles ? trace_primary_image(*s->tracer, s->rays)
                                 : trace_set(*s->tracer, s->rays, kind, mode);
    state.SetIterationTime(t);
    if (mode != RayMode::Single) {
      mode_s += t;
      single_s += trace_set(*s->tracer, s->rays, kind, RayMode::Single);
    }
  }
  state.counters["rays"] = count;
  state.counters["rays_per_s"] =
      benchmark::Counter(count, benchmark::Counter::kIsIterationInvariantRate);
  if (mode != RayMode::Single && mode_s > 0.0)
    state.counters[mode == RayMode::Packet8 ? "packet_speedup" : "stream_speedup"] =
        single_s / mode_s;
  if (kind != RayKind::Shadow) {
    std::size_t hit = 0;
    for (std::size_t i = 0; i < static_cast<std::size_t>(count); ++i)
      hit += s->rays.hits[i].valid();
    state.counters["hit_fraction"] = static_cast<double>(hit) / std::max(count, 1.0);
  } else {
    std::size_t blocked = 0;
    for (std::size_t i = 0; i < static_cast<std::size_t>(count); ++i) blocked += s->rays.occ[i];
    state.counters["occluded_fraction"] = static_cast<double>(blocked) / std::max(count, 1.0);
  }
}

void register_all(bool full) {
  std::vector<std::pair<int, int>> sizes = {{1920, 1080}};
  if (full) sizes = {{640, 360}, {1920, 1080}, {3840, 2160}};
  for (const char* scene : {"cornell", "sponza"})
    for (auto [w, h] : sizes)
      for (RayKind kind : {RayKind::Primary, RayKind::Secondary, RayKind::Shadow})
        for (int m = 0; m < 4; ++m) {
          // Modes 0-2: RayMode; 3: pixel tiles, for camera rays only.
          if (m == 3 && kind != RayKind::Primary) continue;
          const RayMode mode = m == 0   ? RayMode::Single
                               : m == 2 ? RayMode::Stream
                                        : RayMode::Packet8;
          const char* mode_name = m == 0   ? "single"
                                  : m == 1 ? "packet8"
                                  : m == 2 ? "stream"
                                           : "tiles";
          const std::string name = std::string("EmbreeRays/") + scene + "/" + kind_name(kind) +
                                   "/" + mode_name + "/" + std::to_string(w) + "x" +
                                   std::to_string(h);
          benchmark::RegisterBenchmark(name.c_str(), BM_EmbreeRays, std::string(scene), w, h, kind,
                                       mode, m == 3)
              ->UseManualTime()
              ->Unit(benchmark::kMillisecond)
              ->MinTime(0.3);
        }
}

}  // namespace
}  // namespace rtpg::bench

int main(int argc, char** argv) {
  return rtpg::bench::bench_main(argc, argv, rtpg::bench::register_all);
}
