// Whole path-traced frames (Renderer::render_frame, 1 spp) per stage, guiding off and pmm,
// and how far they are from what Embree alone needs for the same rays.
//
//   bench_frame                   Cornell 640x360, 960x540 and 1920x1080, Sponza 640x360 and
//                                 960x540
//   bench_frame --rtpg_full       also Sponza 1920x1080 (about a minute more)
//   bench_frame --benchmark_filter='cornell/1920'
//
// Counters (means over the iterations of a repetition; the aggregates give their medians):
//   frame_ms              FrameStats "total" (also the manual time of the iteration)
//   primary_ms, gbuffer_ms, first_bounce_ms, trace_ms, shade_ms, compact_ms   stages of the frame
//                         (guiding off: first_bounce_ms 0, the BSDF's first bounce is drawn in
//                         shade)
//   guiding_ms            pmm: begin_frame (upload, reproject, state readback) + sample +
//                         end_frame (VPL upload, train); reproject/sample/train_kernel_ms are
//                         their kernels' profiling-event times
//   embree_only_ms        sum over ray kinds of (rays of that kind in the frame, from
//                         FrameStats) x (Embree's time per ray on a representative set of that
//                         kind: camera rays, cosine bounces and NEE shadow rays from the real
//                         first hits, each in the RayMode the renderer uses for it:
//                         camera rays by EmbreeScene::intersect_image, the others by
//                         kBounceRayMode and kShadowRayMode in host/render/path_tracer.h),
//                         timed in the same iteration as the frame
//   ratio                 frame_ms / embree_only_ms
//   guiding_overhead      pmm only: (pmm frame - off frame) / off frame, with an off frame
//                         rendered in every iteration next to the pmm one
// The renderers are built and warmed up (kernel compiles, a few frames of training, and the
// frames in which BounceRayOrder::automatic times the two orders of the bounce rays) once per
// scene and resolution, outside the timed loops. The Embree-alone yardstick traces its bounce
// rays in pixel order, as Embree is handed them without the renderer's grouping
// (docs/host-path-tracer.md, "Bounce rays traced in groups").
#include "bench_common.h"
#include "bench_roofline.h"

#include <map>
#include <tuple>

#include "rtpg/cl_runtime.h"
#include "render/guided_first_bounce.h"
#include "render/renderer.h"
#include "util/timed_choice.h"

namespace rtpg::bench {
namespace {

struct FrameSetup {
  std::unique_ptr<Renderer> off, pmm;
  GuidedFirstBounce* guided = nullptr;
  RaySets rays;
  int next_off = 0, next_pmm = 0;
};

// Past the frames in which the bounce rays' order is chosen by timing (TimedChoice).
constexpr int kWarmupOff = 1 + 2 * TimedChoice::kTrials, kWarmupPmm = kWarmupOff;

FrameSetup* setup_for(const std::string& scene_name, int w, int h, std::string* why) {
  static std::map<std::tuple<std::string, int, int>, std::unique_ptr<FrameSetup>> cache;
  const auto key = std::make_tuple(scene_name, w, h);
  if (auto it = cache.find(key); it != cache.end()) return it->second.get();
  const Scene* scene = scene_by_name(scene_name, why);
  if (!scene) return nullptr;
  auto s = std::make_unique<FrameSetup>();
  RenderSettings settings;
  settings.width = w;
  settings.height = h;
  settings.path_tracer.max_bounces = scene->max_bounces > 0 ? scene->max_bounces : 8;
  s->off = std::make_unique<Renderer>(*scene, settings);
  s->pmm = std::make_unique<Renderer>(*scene, settings);
  auto guided = std::make_unique<GuidedFirstBounce>(runtime(), w, h, GuidingSettings{});
  s->guided = guided.get();
  s->pmm->set_first_bounce_sampler(std::move(guided));
  s->rays = make_ray_sets(*scene, s->off->tracer(), w, h);
  for (; s->next_off < kWarmupOff; ++s->next_off) s->off->render_frame(s->next_off);
  for (; s->next_pmm < kWarmupPmm; ++s->next_pmm) s->pmm->render_frame(s->next_pmm);
  for (RayKind k : {RayKind::Primary, RayKind::Secondary, RayKind::Shadow})
    trace_set(s->off->tracer(), s->rays, k, RayMode::Single);
  return (cache[key] = std::move(s)).get();
}

// Embree alone for the rays of one frame: ms.
double embree_only_ms(FrameSetup& s, const FrameStats& stats) {
  const EmbreeScene& tracer = s.off->tracer();
  auto per_ray = [&](RayKind k, RayMode mode) {
    const std::size_t n = rays_of(s.rays, k).size();
    return n ? trace_set(tracer, s.rays, k, mode) / static_cast<double>(n) : 0.0;
  };
  const double p = trace_primary_image(tracer, s.rays) /
                   static_cast<double>(std::max<std::size_t>(s.rays.primary.size(), 1));
  const double b = per_ray(RayKind::Secondary, kBounceRayMode);
  const double sh = per_ray(RayKind::Shadow, kShadowRayMode);
  return 1e3 * (static_cast<double>(stats.primary_rays) * p +
                static_cast<double>(stats.secondary_rays) * b +
                static_cast<double>(stats.shadow_rays) * sh);
}

double stage(const FrameStats& s, const char* name) {
  const auto it = s.time_ms.find(name);
  return it == s.time_ms.end() ? 0.0 : it->second;
}

void BM_Frame(benchmark::State& state, const std::string& scene_name, int w, int h, bool guided) {
  std::string why;
  FrameSetup* s = setup_for(scene_name, w, h, &why);
  if (!s) {
    state.SkipWithError(why.c_str());
    return;
  }
  std::map<std::string, double> sum;
  double rays_p = 0, rays_s = 0, rays_sh = 0;
  for (auto _ : state) {
    const FrameStats st =
        guided ? s->pmm->render_frame(s->next_pmm++) : s->off->render_frame(s->next_off++);
    const double total = stage(st, "total");
    state.SetIterationTime(total * 1e-3);
    sum["frame_ms"] += total;
    for (const char* k : {"primary", "gbuffer", "first_bounce", "trace", "shade", "compact"})
      sum[std::string(k) + "_ms"] += stage(st, k);
    if (guided) {
      sum["guiding_ms"] +=
          stage(st, "guiding_begin") + stage(st, "first_bounce") + stage(st, "guiding_end");
      sum["reproject_kernel_ms"] += stage(st, "reproject");
      sum["sample_kernel_ms"] += stage(st, "sample");
      sum["train_kernel_ms"] += stage(st, "train");
      sum["upload_ms"] += stage(st, "upload");
      sum["readback_ms"] += stage(st, "readback");
      sum["guided_fraction"] +=
          st.extra.count("guided_fraction") ? st.extra.at("guided_fraction") : 0.0;
      // The same frame without guiding, interleaved (drift cancels in the ratio).
      const FrameStats off = s->off->render_frame(s->next_off++);
      sum["off_frame_ms"] += stage(off, "total");
    }
    sum["embree_only_ms"] += embree_only_ms(*s, st);
    rays_p += static_cast<double>(st.primary_rays);
    rays_s += static_cast<double>(st.secondary_rays);
    rays_sh += static_cast<double>(st.shadow_rays);
  }
  const double it = static_cast<double>(state.iterations());
  if (it <= 0) return;
  for (const auto& [k, v] : sum) state.counters[k] = v / it;
  state.counters["ratio"] = sum["frame_ms"] / sum["embree_only_ms"];
  if (guided)
    state.counters["guiding_overhead"] =
        (sum["frame_ms"] - sum["off_frame_ms"]) / sum["off_frame_ms"];
  state.counters["primary_rays"] = rays_p / it;
  state.counters["secondary_rays"] = rays_s / it;
  state.counters["shadow_rays"] = rays_sh / it;
  state.counters["paths_per_s"] =
      benchmark::Counter(static_cast<double>(w) * h, benchmark::Counter::kIsIterationInvariantRate);
}

void register_all(bool full) {
  benchmark::AddCustomContext("opencl_device", runtime().info().device_name);
  struct Config {
    const char* scene;
    int w, h, iterations;
  };
  // 960x540 and 1920x1080: the sizes issue 14's bound is stated at; 640x360 for the figures
  // measured before 960x540 was here (docs/host-path-tracer.md).
  std::vector<Config> configs = {{"cornell", 640, 360, 3},
                                 {"cornell", 960, 540, 3},
                                 {"cornell", 1920, 1080, 1},
                                 {"sponza", 640, 360, 3},
                                 {"sponza", 960, 540, 2}};
  if (full) configs.push_back({"sponza", 1920, 1080, 1});
  for (const Config& c : configs)
    for (bool guided : {false, true}) {
      const std::string name = std::string("Frame/") + c.scene + "/" + std::to_string(c.w) + "x" +
                               std::to_string(c.h) + "/guiding:" + (guided ? "pmm" : "off");
      benchmark::RegisterBenchmark(name.c_str(), BM_Frame, std::string(c.scene), c.w, c.h, guided)
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond)
          ->Iterations(c.iterations);
    }
}

}  // namespace
}  // namespace rtpg::bench

int main(int argc, char** argv) {
  rtpg::request_pinned_cpu_device_threads();  // as rtpg itself, before any OpenCL call
  return rtpg::bench::bench_main(argc, argv, rtpg::bench::register_all);
}
