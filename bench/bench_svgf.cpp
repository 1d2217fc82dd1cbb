// SVGF's kernels (kernels/svgf_*.cl through SvgfDenoiser; docs/denoising.md) on real frames: the
// Cornell box and Crytek Sponza path-traced at 1 spp (guiding off, static camera, no jitter, so
// one G-buffer serves every frame), denoised frame after frame, in two states:
//   history:full   the history is full (the steady state of a still camera: variance from the
//                  temporal moments, no disocclusions);
//   history:none   every frame starts without history (a camera cut, the first frames, and the
//                  price of every disoccluded pixel: the 7x7 spatial variance everywhere).
//
//   bench_svgf                  960x540 and 1920x1080, the variance and a-trous kernels one
//                               pixel per work-item (lanes:1) and in the device's SIMD lanes
//                               (lanes:auto), in the device's own work-groups (rows on CPUs,
//                               filters included) and, with the lanes, every kernel in 16x16
//                               tiles (local:16x16)
//   bench_svgf --benchmark_filter='cornell/960'
//
// Time is the sum of the kernels' OpenCL profiling-event times of one denoise() (manual time).
// Counters (means over the iterations of a repetition; the aggregates give their medians):
//   <stage>_ms           temporal, variance, atrous (all iterations), remodulate, and upload and
//                        download (host <-> device copies, wall time)
//   svgf_ms              every stage, copies included: what a frame pays for the denoiser
//   pt_frame_ms          the path-traced frame (median of the frames rendered for the inputs)
//   frame_fraction       svgf_ms / pt_frame_ms (issue 11's target: at most 0.1 at 960x540)
//   <kernel>_flops_px, <kernel>_bytes_px   per pixel per launch (atrous: per iteration),
//                        counted along each pixel's path from the hand counts beside the kernels
//                        (bench_roofline.h's rules: docs/guiding.md, "The roofline")
//   <kernel>_roofline    the kernel's roofline bound / its time (1: at the roof), the copy
//                        and multiply-add yardsticks launched in the same iterations
//   surface_fraction     the share of pixels with a surface: the filters skip the others, so
//                        their times scale with it (0.53 on the Cornell box's 16:9 frame, 0.99
//                        on Sponza; docs/denoising.md, "The three rooms")
//   atrous_ms_per_surface_mpx  the a-trous time per million pixels with a surface: the figure
//                        to compare across scenes
//   lanes                pixels per work-item of the variance and a-trous kernels
//   row_work_groups      1 where the temporal and remodulate kernels run in work-groups along
//                        rows, 0 for tiles
//   filter_row_work_groups  the same for the variance and a-trous filters
#include "bench_common.h"
#include "bench_roofline.h"

#include <map>
#include <tuple>

#include "denoise/svgf_denoiser.h"
#include "render/renderer.h"
#include "shared/svgf.h"

namespace rtpg::bench {
namespace {

namespace sh = rtpg::shared;

constexpr int kFrames = 4;  // noisy frames cycled through (different seeds, same camera)

struct Frames {
  GBuffer gbuffer;
  std::vector<std::vector<glm::vec3>> colour;
  double pt_frame_ms = 0.0;
};

Frames* frames_for(const std::string& scene_name, int w, int h, std::string* why) {
  static std::map<std::tuple<std::string, int, int>, std::unique_ptr<Frames>> cache;
  const auto key = std::make_tuple(scene_name, w, h);
  if (auto it = cache.find(key); it != cache.end()) return it->second.get();
  const Scene* scene = scene_by_name(scene_name, why);
  if (!scene) return nullptr;
  RenderSettings settings;
  settings.width = w;
  settings.height = h;
  settings.jitter = false;
  settings.path_tracer.max_bounces = scene->max_bounces > 0 ? scene->max_bounces : 8;
  Renderer renderer(*scene, settings);
  auto f = std::make_unique<Frames>();
  std::vector<double> times;
  for (int k = 0; k < kFrames; ++k) {
    times.push_back(renderer.render_frame(k).time_ms.at("total"));
    f->colour.push_back(renderer.image());
  }
  f->gbuffer = renderer.gbuffer();
  std::sort(times.begin(), times.end());
  f->pt_frame_ms = times[times.size() / 2];
  return (cache[key] = std::move(f)).get();
}

// Flops and bytes per launch of each kernel along each pixel's path, from the counts beside the
// kernels (kernels/svgf_temporal.cl, svgf_variance.cl, svgf_atrous.cl, svgf_remodulate.cl), for
// the state the denoiser is in after the frame (history lengths, depths).
struct Counts {
  double temporal_flops = 0, variance_flops = 0, atrous_flops = 0, remodulate_flops = 0;
  double temporal_bytes = 0, variance_bytes = 0, atrous_bytes = 0, remodulate_bytes = 0;
  double surface_pixels = 0;
};

// x^n by repeated squaring as the kernels unroll it (PG_SVGF_CONSTANT_POWER, kernels/shared/
// svgf.h): a squaring per bit of n below its top one, a multiply per set bit after the first
// (which is x itself); 7 for the paper's 128.
double power_flops(int n) {
  int bits = 0, ones = 0;
  for (; n != 0; n >>= 1) {
    ++bits;
    ones += n & 1;
  }
  return bits == 0 ? 0 : (bits - 1) + (ones - 1);
}

Counts count(const GBuffer& g, const std::vector<glm::vec4>& moments, const SvgfSettings& s) {
  const int w = g.width, h = g.height;
  const double power = power_flops(s.phi_normal);
  // A tap does not compute its phi_z: each pass takes 1 / phi_z once per pixel for each squared
  // tap distance, 5 flops each (kernels/svgf_atrous.cl, svgf_variance.cl).
  const double atrous_tap = 38 + power, atrous_inverse_phi_z = 6 * 5;
  const double variance_tap = 36 + power, variance_inverse_phi_z = 10 * 5;
  auto taps_inside = [&](int x, int y, int radius, int step) {
    int nx = 0, ny = 0;
    for (int d = -radius; d <= radius; ++d) {
      nx += x + d * step >= 0 && x + d * step < w;
      ny += y + d * step >= 0 && y + d * step < h;
    }
    return static_cast<double>(nx) * ny;
  };
  Counts c;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      if (!g.has_surface(i)) {
        c.temporal_bytes += 40 + 88;  // the surface kept for next frame: 36 read, 36 written
        c.variance_bytes += 16 + 16;
        c.variance_flops += 1;
        c.atrous_bytes += s.iterations * 48.0;
        c.atrous_flops += s.iterations * 1.0;
        c.remodulate_bytes += 4 + 12 + 12;  // the colour in and out, three floats each
        continue;
      }
      c.surface_pixels += 1;
      // temporal, static camera: one bilinear tap of weight 1 (the others have weight 0),
      // tested and accepted.
      c.temporal_bytes += 92 + 68 + 88;
      c.temporal_flops += 41 + 4 * 8 + 19 + 15 + 30;
      const bool spatial = moments[i].z < static_cast<float>(s.min_history);
      c.variance_bytes += 16 + 16 + 16 + 16 + (spatial ? 4 : 0);
      c.variance_flops +=
          spatial ? 15 + variance_inverse_phi_z + variance_tap * taps_inside(x, y, 3, 1) : 5;
      for (int k = 0; k < s.iterations; ++k)
        c.atrous_flops += 11 + 3 * taps_inside(x, y, 1, 1) + atrous_inverse_phi_z +
                          atrous_tap * taps_inside(x, y, 2, 1 << k) + 5;
      c.atrous_bytes += s.iterations * 52.0;
      c.remodulate_bytes += 4 + 16 + 16 + 16 + 12;
      c.remodulate_flops += 9;
    }
  return c;
}

struct Setup {
  std::unique_ptr<SvgfDenoiser> denoiser;
  Counts counts;
  int next = 0;
};

// young: every frame starts without history (a camera cut, the first frame; what disoccluded
// pixels cost), so every pixel takes the variance pass's 7x7 spatial estimate.
// tile: 0 for the device's own work-groups (rows on CPUs: host/cl/work_groups.h), else a tile
// of tile x tile work-items.
Setup* setup_for(const std::string& scene_name, int w, int h, int lanes, int tile, bool young,
                 std::string* why) {
  static std::map<std::tuple<std::string, int, int, int, int, bool>, std::unique_ptr<Setup>> cache;
  const auto key = std::make_tuple(scene_name, w, h, lanes, tile, young);
  if (auto it = cache.find(key); it != cache.end()) return it->second.get();
  Frames* f = frames_for(scene_name, w, h, why);
  if (!f) return nullptr;
  auto s = std::make_unique<Setup>();
  SvgfSettings settings;
  settings.lanes = lanes;
  settings.local_x = settings.local_y = tile;
  s->denoiser = std::make_unique<SvgfDenoiser>(runtime(), w, h, settings);
  // Two passes over the frames: the history is past min_history everywhere (steady state).
  for (int k = 0; k < 2 * kFrames; ++k) {
    if (young) s->denoiser->reset();
    s->denoiser->denoise(f->colour[k % kFrames], f->gbuffer);
  }
  s->counts = count(f->gbuffer, s->denoiser->read(SvgfStage::Moments), settings);
  return (cache[key] = std::move(s)).get();
}

void BM_Svgf(benchmark::State& state, const std::string& scene_name, int w, int h, int lanes,
             int tile, bool young) {
  std::string why;
  Setup* s = nullptr;
  try {
    s = setup_for(scene_name, w, h, lanes, tile, young, &why);
  } catch (const std::exception& e) {
    why = e.what();
  }
  if (!s) {
    state.SkipWithError(why.c_str());
    return;
  }
  Frames& f = *frames_for(scene_name, w, h, &why);
  Copy& copy_kernel = copy();
  FmaPeak& fma = fma_peak16();
  std::map<std::string, double> sum;
  double copy_ms = 0.0, fma_ms = 0.0;
  const char* kernels[] = {"temporal", "variance", "atrous", "remodulate"};
  for (auto _ : state) {
    if (young) s->denoiser->reset();
    s->denoiser->denoise(f.colour[s->next++ % kFrames], f.gbuffer);
    const std::map<std::string, double>& t = s->denoiser->times_ms();
    double kernel_ms = 0.0;
    for (const char* k : kernels) {
      const double ms = t.at(std::string("svgf_") + k);
      sum[k] += ms;
      kernel_ms += ms;
    }
    sum["upload"] += t.at("svgf_upload");
    sum["download"] += t.at("svgf_download");
    sum["svgf"] += t.at("svgf_total");
    state.SetIterationTime(kernel_ms * 1e-3);
    copy_ms += copy_kernel.run();
    fma_ms += fma.run();
  }
  const double it = static_cast<double>(state.iterations());
  const double n = static_cast<double>(w) * h;
  const Counts& c = s->counts;
  const double flops[] = {c.temporal_flops, c.variance_flops, c.atrous_flops, c.remodulate_flops};
  const double bytes[] = {c.temporal_bytes, c.variance_bytes, c.atrous_bytes, c.remodulate_bytes};
  for (int k = 0; k < 4; ++k) {
    const std::string name = kernels[k];
    const double ms = sum[name] / it;
    state.counters[name + "_ms"] = ms;
    state.counters[name + "_flops_px"] = flops[k] / n;
    state.counters[name + "_bytes_px"] = bytes[k] / n;
    state.counters[name + "_roofline"] = roofline_ms(bytes[k], flops[k], copy_ms, fma_ms, it) / ms;
  }
  state.counters["surface_fraction"] = c.surface_pixels / n;
  state.counters["atrous_ms_per_surface_mpx"] =
      c.surface_pixels > 0 ? sum["atrous"] / it / (c.surface_pixels * 1e-6) : 0.0;
  state.counters["upload_ms"] = sum["upload"] / it;
  state.counters["download_ms"] = sum["download"] / it;
  state.counters["svgf_ms"] = sum["svgf"] / it;
  state.counters["pt_frame_ms"] = f.pt_frame_ms;
  state.counters["frame_fraction"] = sum["svgf"] / it / f.pt_frame_ms;
  state.counters["lanes"] = s->denoiser->lanes();
  state.counters["row_work_groups"] = s->denoiser->pixel_work_groups().rows ? 1.0 : 0.0;
  state.counters["filter_row_work_groups"] = s->denoiser->filter_work_groups().rows ? 1.0 : 0.0;
  state.SetItemsProcessed(static_cast<std::int64_t>(n) * state.iterations());
}

void register_all(bool /*full*/) {
  benchmark::AddCustomContext("opencl_device", runtime().info().device_name);
  for (const char* scene : {"cornell", "sponza"})
    for (auto [w, h] : {std::pair{960, 540}, std::pair{1920, 1080}})
      for (auto [lanes, tile] : {std::pair{1, 0}, std::pair{0, 0}, std::pair{0, 16}})
        for (bool young : {false, true}) {
          const std::string name =
              std::string(scene) + "/" + std::to_string(w) + "x" + std::to_string(h) +
              "/lanes:" + (lanes == 0 ? std::string("auto") : std::to_string(lanes)) +
              (tile == 0 ? std::string()
                         : "/local:" + std::to_string(tile) + "x" + std::to_string(tile)) +
              "/history:" + (young ? "none" : "full");
          benchmark::RegisterBenchmark(name.c_str(), BM_Svgf, std::string(scene), w, h, lanes, tile,
                                       young)
              ->UseManualTime()
              ->Unit(benchmark::kMillisecond)
              ->MinTime(0.5);
        }
}

}  // namespace
}  // namespace rtpg::bench

int main(int argc, char** argv) {
  rtpg::request_pinned_cpu_device_threads();  // as rtpg itself, before any OpenCL call
  return rtpg::bench::bench_main(argc, argv, rtpg::bench::register_all);
}
