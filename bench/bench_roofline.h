// The roofline's yardsticks, shared by the kernel benchmarks (bench_guiding_kernels,
// bench_svgf): the OpenCL runtime they all launch on, the float4 copy kernel (the memory roof)
// and the multiply-add chains of kernels/fma_peak.cl (the arithmetic roof). A kernel's roofline
// bound is max(bytes / copy bandwidth, flops / float16 multiply-add rate), both measured in the
// same iterations as the kernel (docs/guiding.md, "The roofline").
#pragma once

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstddef>
#include <string>

#include "rtpg/cl_runtime.h"

namespace rtpg::bench {

inline ClRuntime& runtime() {
  static ClRuntime rt;
  return rt;
}

// A 1D launch of `items` work-items, driver-chosen work-groups: its profiled time in ms.
inline double run_1d(cl::Kernel& kernel, std::size_t items) {
  cl::Event done;
  runtime().queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(items), cl::NullRange,
                                         nullptr, &done);
  done.wait();
  return ClRuntime::event_ms(done);
}

// ---- the copy yardstick ----------------------------------------------------------------------

struct Copy {
  static constexpr std::size_t kElements = 4u << 20;  // 64 MiB each way: far beyond the caches
  cl::Kernel kernel;
  cl::Buffer src, dst;
  Copy() {
    kernel = runtime().kernel("copy_float4.cl", "copy_float4");
    src = cl::Buffer(runtime().context(), CL_MEM_READ_WRITE, kElements * 16);
    dst = cl::Buffer(runtime().context(), CL_MEM_READ_WRITE, kElements * 16);
    const cl_float4 one = {{1.0f, 2.0f, 3.0f, 4.0f}};
    runtime().queue().enqueueFillBuffer(src, one, 0, kElements * 16);
    runtime().queue().enqueueFillBuffer(dst, one, 0, kElements * 16);
    kernel.setArg(0, src);
    kernel.setArg(1, dst);
    kernel.setArg(2, static_cast<cl_uint>(kElements));
    run();  // first launch: compile the work-group function
  }
  static double bytes() { return 2.0 * kElements * 16; }
  double run() { return run_1d(kernel, kElements); }
};

inline Copy& copy() {
  static Copy c;
  return c;
}

// ---- the arithmetic yardstick ----------------------------------------------------------------

// kernels/fma_peak.cl at one vector width: the device's multiply-add rate, the compute side of
// the roofline the kernels are compared with.
struct FmaPeak {
  static constexpr std::size_t kItems = 1u << 16;
  static constexpr cl_uint kRounds = 1024;
  static constexpr int kChains = 8;  // PG_FMA_CHAINS
  int width;
  cl::Kernel kernel;
  cl::Buffer out;
  explicit FmaPeak(int w) : width(w) {
    kernel = runtime().kernel("fma_peak.cl", "fma_peak", "-DPG_FMA_WIDTH=" + std::to_string(w));
    out = cl::Buffer(runtime().context(), CL_MEM_WRITE_ONLY, kItems * 4);
    kernel.setArg(0, out);
    kernel.setArg(1, kRounds);
    kernel.setArg(2, 0.999f);
    kernel.setArg(3, 0.001f);
    run();  // first launch: compile the work-group function
  }
  double flops() const { return 2.0 * kItems * kRounds * kChains * width; }
  double run() { return run_1d(kernel, kItems); }
};

inline FmaPeak& fma_peak16() {  // the vector rate, the compute roof of the kernels
  static FmaPeak f(16);
  return f;
}

inline void BM_FmaPeak(benchmark::State& state, int width) {
  FmaPeak f(width);
  double ms = 0.0;
  for (auto _ : state) {
    const double t = f.run();
    state.SetIterationTime(t * 1e-3);
    ms += t;
  }
  state.counters["gflops"] = f.flops() * static_cast<double>(state.iterations()) / (ms * 1e6);
}

inline void BM_CopyFloat4(benchmark::State& state) {
  Copy& c = copy();
  for (auto _ : state) state.SetIterationTime(c.run() * 1e-3);
  state.SetBytesProcessed(static_cast<std::int64_t>(Copy::bytes()) * state.iterations());
}

// A kernel's roofline bound in ms, from its bytes and flops per launch and the yardsticks'
// accumulated times over the same iterations (it of them).
inline double roofline_ms(double bytes, double flops, double copy_ms, double fma_ms, double it) {
  const double copy_bw = Copy::bytes() * it / (copy_ms * 1e-3);     // bytes/s
  const double peak = fma_peak16().flops() * it / (fma_ms * 1e-3);  // flop/s
  return 1e3 * std::max(bytes / copy_bw, flops / peak);
}

}  // namespace rtpg::bench
