// The host's G-buffer packer (host/render/gbuffer_packer.h) on one core: what --host-transfer
// packed costs the host per pixel, against a copy of the 96-byte layout (what pinned staging
// does instead), at 1920x1080 on the Cornell box's real G-buffer. Packing pays where its time is
// below the copy's plus the bus time of the 72 bytes it saves (docs/guiding.md, "The G-buffer
// packed for the bus", "The bus at 46 bytes a pixel").
//   bench_gbuffer_packer [--benchmark_repetitions=5 --benchmark_report_aggregates_only=true]
#include <benchmark/benchmark.h>

#include <cstring>
#include <vector>

#include "render/gbuffer_packer.h"
#include "render/renderer.h"
#include "scene/scene_loader.h"

namespace rtpg {
namespace {

const GBuffer& cornell_gbuffer() {
  static const GBuffer g = [] {
    const Scene scene = load_scene(std::string(RTPG_SOURCE_DIR) + "/scenes/cornell-box.json");
    RenderSettings settings;
    settings.width = 1920;
    settings.height = 1080;
    Renderer renderer(scene, settings);
    renderer.render_frame(0);
    return renderer.gbuffer();
  }();
  return g;
}

struct Packed {
  std::vector<shared::uint4> surface;
  std::vector<shared::uint2> shading;
  explicit Packed(std::size_t n) : surface(n), shading(n) {}
  PackedGBufferView view() { return {surface.data(), shading.data()}; }
};

void Pack(benchmark::State& state, CpuCode code) {
  if (code == CpuCode::avx2 && !cpu_runs_gbuffer_packer_lanes()) {
    state.SkipWithError("this CPU has no AVX2 and F16C");
    return;
  }
  const GBuffer& g = cornell_gbuffer();
  const std::size_t n = g.pixel_count();
  Packed out(n);
  for (auto _ : state) {
    benchmark::DoNotOptimize(pack_gbuffer(g, 0, n, out.view(), code));
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_pixel"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate |
                                                     benchmark::Counter::kInvert);
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(n) * 24);
}

// The G-buffer's layout copied channel by channel (what PinnedStaging::stage does per channel).
void CopyLayout(benchmark::State& state) {
  const GBuffer& g = cornell_gbuffer();
  const std::size_t n = g.pixel_count();
  std::vector<unsigned char> to(n * 96);
  for (auto _ : state) {
    unsigned char* at = to.data();
#define RTPG_COPY(name, type, bytes)         \
  std::memcpy(at, g.name.data(), n*(bytes)); \
  at += n * (bytes);
    PG_GBUFFER_CHANNELS(RTPG_COPY)
#undef RTPG_COPY
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_pixel"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate |
                                                     benchmark::Counter::kInvert);
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(n) * 96);
}

BENCHMARK_CAPTURE(Pack, baseline, CpuCode::baseline)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(Pack, lanes, CpuCode::avx2)->Unit(benchmark::kMillisecond);
BENCHMARK(CopyLayout)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace rtpg

BENCHMARK_MAIN();
