// What the host code knows of the CPU it runs on. Which code runs a host loop written in vector
// lanes (render/camera_rays.h, render/stream_starts.h): the baseline x86-64 build, or the same
// source built for AVX2 and chosen at run time where the CPU has it, so that the binary stays
// baseline x86-64. The variants perform the same operations in the same order (no FMA), so they
// give the same bits (docs/host-path-tracer.md, "Camera rays in vector lanes").
#pragma once

#include <cstddef>
#include <stdexcept>

#include <unistd.h>

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#define RTPG_HAS_AVX2_VARIANT 1
// Marks the AVX2 variant of a function (no FMA: a fused multiply-add would round differently).
#define RTPG_AVX2_VARIANT __attribute__((target("avx2")))
#else
#define RTPG_HAS_AVX2_VARIANT 0
#define RTPG_AVX2_VARIANT
#endif

namespace rtpg {

// automatic: the best this CPU runs; baseline or avx2: that variant (tests compare them).
enum class CpuCode { automatic, baseline, avx2 };

// Whether this CPU runs the avx2 variant.
inline bool cpu_runs_avx2() {
#if RTPG_HAS_AVX2_VARIANT
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

// The variant to run for `code`; throws std::invalid_argument where `code` names one this CPU
// does not run.
inline CpuCode resolve_cpu_code(CpuCode code) {
  if (code == CpuCode::automatic) return cpu_runs_avx2() ? CpuCode::avx2 : CpuCode::baseline;
  if (code == CpuCode::avx2 && !cpu_runs_avx2())
    throw std::invalid_argument("this CPU does not run AVX2 code");
  return code;
}

// The bytes of one core's own cache (L2), 1 MiB where the system does not say: the data the
// shading loop can expect to stay cached between two visits (render/surface.h,
// prefetch_surface_triangle).
inline std::size_t core_cache_bytes() {
#ifdef _SC_LEVEL2_CACHE_SIZE
  const long bytes = sysconf(_SC_LEVEL2_CACHE_SIZE);
  if (bytes > 0) return static_cast<std::size_t>(bytes);
#endif
  return std::size_t{1} << 20;
}

}  // namespace rtpg
