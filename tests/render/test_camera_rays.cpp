// The frame's camera rays (host/render/camera_rays.h), computed in vector lanes a row at a time:
// every variant (baseline x86-64, AVX2) gives, pixel by pixel and to the bit, the ray of the
// scalar definition (the pixel's jitter stream, CameraFrame::ray_direction through the jittered
// film point), at sizes whose rows end inside a step of lanes; and each ray passes through its
// own pixel.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "render/camera_rays.h"
#include "rtpg/guiding_layout.h"
#include "shared/rng.h"

namespace rtpg {
namespace {

CameraFrame tilted_camera(float aspect) {
  CameraView view;
  view.position = {0.3f, 1.1f, 4.7f};
  view.look_at = {-0.2f, 0.4f, 0.1f};
  view.up = {0.1f, 1.0f, 0.0f};
  view.fov_y = 0.9f;
  return make_camera_frame(view, aspect);
}

// The scalar definition, pixel by pixel.
Ray expected_ray(const CameraFrame& camera, int x, int y, int width, int height,
                 const CameraJitter& jitter) {
  float jx = 0.5f, jy = 0.5f;
  if (jitter.enabled) {
    shared::pg_rng rng = shared::pg_rng_make(jitter.seed, static_cast<std::uint32_t>(y * width + x),
                                             jitter.frame, 0u, PG_RNG_STREAM_CAMERA);
    jx = shared::pg_rng_next(&rng);
    jy = shared::pg_rng_next(&rng);
  }
  Ray r;
  r.origin = camera.position;
  r.direction = camera.ray_direction((static_cast<float>(x) + jx) / static_cast<float>(width),
                                     (static_cast<float>(y) + jy) / static_cast<float>(height));
  return r;
}

std::vector<CpuCode> codes_this_cpu_runs() {
  std::vector<CpuCode> codes = {CpuCode::automatic, CpuCode::baseline};
  if (cpu_runs_avx2()) codes.push_back(CpuCode::avx2);
  return codes;
}

bool same_bits(const Ray& a, const Ray& b) {
  return std::memcmp(&a, &b, sizeof(Ray)) == 0;
}

TEST(CameraRays, EveryVariantGivesTheScalarRaysToTheBit) {
  // 1x1, widths below, at and past one step of 16 lanes, a tall thin frame, a 960-wide row.
  const int sizes[][2] = {{1, 1}, {15, 3}, {16, 2}, {17, 5}, {37, 23}, {3, 41}, {960, 4}};
  const CameraJitter jitters[] = {{true, 7u, 0u}, {true, 1u, 31u}, {false, 7u, 3u}};
  for (const CpuCode code : codes_this_cpu_runs())
    for (const auto& size : sizes)
      for (const CameraJitter& jitter : jitters) {
        const int w = size[0], h = size[1];
        const CameraFrame camera = tilted_camera(static_cast<float>(w) / static_cast<float>(h));
        std::vector<Ray> rays(static_cast<std::size_t>(w) * h);
        make_camera_rays(camera, w, h, jitter, rays.data(), code);
        int differing = 0;
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w; ++x)
            differing += !same_bits(rays[static_cast<std::size_t>(y) * w + x],
                                    expected_ray(camera, x, y, w, h, jitter));
        EXPECT_EQ(differing, 0) << "variant " << static_cast<int>(code) << ", " << w << "x" << h
                                << ", jitter " << jitter.enabled << " seed " << jitter.seed
                                << " frame " << jitter.frame;
      }
}

TEST(CameraRays, EachRayPassesThroughItsOwnPixel) {
  const int w = 53, h = 29;
  const CameraFrame camera = tilted_camera(static_cast<float>(w) / static_cast<float>(h));
  std::vector<Ray> rays(static_cast<std::size_t>(w) * h);
  make_camera_rays(camera, w, h, CameraJitter{true, 3u, 5u}, rays.data());
  double mean_x = 0.0, mean_y = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Ray& r = rays[static_cast<std::size_t>(y) * w + x];
      EXPECT_NEAR(glm::length(r.direction), 1.0f, 1e-6f);
      float sx = 0.0f, sy = 0.0f;
      ASSERT_TRUE(camera.project(r.origin + 2.5f * r.direction, sx, sy));
      const float fx = sx * w - static_cast<float>(x), fy = sy * h - static_cast<float>(y);
      EXPECT_GT(fx, -1e-3f) << x << "," << y;
      EXPECT_LT(fx, 1.0f + 1e-3f) << x << "," << y;
      EXPECT_GT(fy, -1e-3f) << x << "," << y;
      EXPECT_LT(fy, 1.0f + 1e-3f) << x << "," << y;
      mean_x += fx;
      mean_y += fy;
    }
  // The jitter is spread over the pixel: its mean over 1537 pixels is near the centre (the
  // standard error of a uniform's mean is 0.29 / sqrt(1537) = 0.007).
  EXPECT_NEAR(mean_x / (w * h), 0.5, 0.03);
  EXPECT_NEAR(mean_y / (w * h), 0.5, 0.03);
}

}  // namespace
}  // namespace rtpg
