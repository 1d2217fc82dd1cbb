#include "render/camera_rays.h"

#include <algorithm>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "rtpg/guiding_layout.h"
#include "shared/rng.h"

namespace rtpg {
namespace {

// Pixels per step of a row: the lane loops below have this fixed trip count, so the compiler
// turns each into vector instructions (two AVX2 registers of 8 floats; four SSE2 ones).
constexpr int kLanes = 16;

// One row of rays. Each loop is the scalar code's arithmetic lane by lane (the jitter's hash
// and draws, CameraFrame::ray_direction), so that vectorised it rounds exactly as the scalar
// code does. Inlined into each variant's row loop, where it takes that variant's instruction
// set. The hash's per-lane shifts need AVX2; SSE2 vectorises the film points and directions.
[[gnu::always_inline]] inline void camera_row(const CameraFrame& camera, int y, int width,
                                              int height, const CameraJitter& jitter, Ray* row) {
  const float film_w = static_cast<float>(width), film_h = static_cast<float>(height);
  const std::uint32_t row_start = static_cast<std::uint32_t>(y) * static_cast<std::uint32_t>(width);
  for (int x0 = 0; x0 < width; x0 += kLanes) {
    float jx[kLanes], jy[kLanes];
    if (jitter.enabled) {
      for (int k = 0; k < kLanes; ++k) {
        shared::pg_rng rng =
            shared::pg_rng_make(jitter.seed, row_start + static_cast<std::uint32_t>(x0 + k),
                                jitter.frame, 0u, PG_RNG_STREAM_CAMERA);
        jx[k] = shared::pg_rng_next(&rng);
        jy[k] = shared::pg_rng_next(&rng);
      }
    } else {
      std::fill(jx, jx + kLanes, 0.5f);
      std::fill(jy, jy + kLanes, 0.5f);
    }
    float dx[kLanes], dy[kLanes], dz[kLanes];
    for (int k = 0; k < kLanes; ++k) {
      const glm::vec3 d = camera.ray_direction((static_cast<float>(x0 + k) + jx[k]) / film_w,
                                               (static_cast<float>(y) + jy[k]) / film_h);
      dx[k] = d.x;
      dy[k] = d.y;
      dz[k] = d.z;
    }
    const int lanes = std::min(kLanes, width - x0);
    for (int k = 0; k < lanes; ++k)
      set_ray(row[x0 + k], camera.position, glm::vec3(dx[k], dy[k], dz[k]), 0.0f, 1e30f);
  }
}

void camera_rows_baseline(const CameraFrame& camera, int y0, int y1, int width, int height,
                          const CameraJitter& jitter, Ray* rays) {
  for (int y = y0; y < y1; ++y)
    camera_row(camera, y, width, height, jitter,
               rays + static_cast<std::size_t>(y) * static_cast<std::size_t>(width));
}

#if RTPG_HAS_AVX2_VARIANT
RTPG_AVX2_VARIANT void camera_rows_avx2(const CameraFrame& camera, int y0, int y1, int width,
                                        int height, const CameraJitter& jitter, Ray* rays) {
  for (int y = y0; y < y1; ++y)
    camera_row(camera, y, width, height, jitter,
               rays + static_cast<std::size_t>(y) * static_cast<std::size_t>(width));
}
#endif

}  // namespace

void make_camera_rays(const CameraFrame& camera, int width, int height, const CameraJitter& jitter,
                      Ray* rays, CpuCode code) {
  code = resolve_cpu_code(code);
  const int rows_per_task = std::max(1, 4096 / std::max(width, 1));
  tbb::parallel_for(tbb::blocked_range<int>(0, height, rows_per_task), [&](const auto& rows) {
#if RTPG_HAS_AVX2_VARIANT
    if (code == CpuCode::avx2) {
      camera_rows_avx2(camera, rows.begin(), rows.end(), width, height, jitter, rays);
      return;
    }
#endif
    camera_rows_baseline(camera, rows.begin(), rows.end(), width, height, jitter, rays);
  });
}

}  // namespace rtpg
