// ReprojectedFlicker (host/render/temporal_flicker.h): the flicker of a moving camera's sequence
// measured through the motion vectors, on synthetic G-buffers whose answer is known.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "render/gbuffer.h"
#include "render/temporal_flicker.h"
#include "shared/tonemap.h"

namespace rtpg {
namespace {

// A wall at depth 4 seen by a camera panning shift pixels per frame: pixel x of frame f shows the
// wall point u = x + shift * f (the motion vector points shift pixels to the left in last frame);
// the wall's colour is a smooth function of u, so consecutive frames differ everywhere while
// each point keeps its colour. Column 0..width/8 is sky.
struct Pan {
  int width = 61, height = 23;
  float shift = 3.0f;
  GBuffer gbuffer(int frame) const {
    GBuffer g;
    g.resize(width, height);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * width + x;
        if (x < width / 8) continue;  // sky
        const float u = static_cast<float>(x) + shift * static_cast<float>(frame);
        g.flags[i] = 0;
        g.position_depth[i] = glm::vec4(0.01f * u, 0.01f * static_cast<float>(y), 4.0f, 4.0f);
        g.shading_normal[i] = glm::vec4(0.0f, 0.0f, -1.0f, 0.0f);
        g.material[i] = 1;
        g.motion[i] = glm::vec2(frame > 0 ? shift : 0.0f, 0.0f);
      }
    return g;
  }
  std::vector<glm::vec3> image(const GBuffer& g, int frame, float noise, std::mt19937& rng) const {
    std::normal_distribution<float> normal(0.0f, 1.0f);
    std::vector<glm::vec3> out(g.pixel_count(), glm::vec3(0.2f, 0.3f, 0.9f));
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * width + x;
        if (!g.has_surface(i)) continue;
        const float u = static_cast<float>(x) + shift * static_cast<float>(frame);
        const float base = 0.3f + 0.25f * std::sin(0.4f * u);
        out[i] = glm::vec3(base + noise * normal(rng), base, 0.5f * base);
      }
    return out;
  }
};

TEST(ReprojectedFlicker, AMovingPictureWithoutNoiseDoesNotFlicker) {
  const Pan pan;
  std::mt19937 rng(1);
  ReprojectedFlicker flicker;
  for (int f = 0; f < 4; ++f) {
    const GBuffer g = pan.gbuffer(f);
    const ReprojectedFlicker::Frame r = flicker.add(pan.image(g, f, 0.0f, rng), g, 1.0f);
    if (f == 0) {
      EXPECT_EQ(r.mse, -1.0);
      continue;
    }
    EXPECT_EQ(r.mse, 0.0) << "frame " << f;
    // Every wall pixel but the shift's columns on the right, which last frame did not see.
    const double wall = static_cast<double>(pan.width - pan.width / 8 - 3) * pan.height;
    EXPECT_NEAR(r.tracked_fraction, wall / (pan.width * pan.height), 1e-12);
  }
}

// With independent noise of standard deviation s on one channel, each tracked pixel's squared
// change of displayed value is about (slope s)^2 * 2 on that channel: the measure is the noise,
// not the motion.
TEST(ReprojectedFlicker, MeasuresTheNoiseOfAMovingPicture) {
  const Pan pan;
  std::mt19937 rng(2);
  ReprojectedFlicker flicker;
  const float s = 0.002f;  // small: the display transform is linear over it
  double sum = 0.0, expected = 0.0;
  int frames = 0;
  for (int f = 0; f < 6; ++f) {
    const GBuffer g = pan.gbuffer(f);
    const std::vector<glm::vec3> image = pan.image(g, f, s, rng);
    const ReprojectedFlicker::Frame r = flicker.add(image, g, 1.0f);
    if (f == 0) continue;
    sum += r.mse;
    ++frames;
    // Expected: 2 s^2 times the displayed slope squared, averaged over the tracked pixels, / 3.
    double e = 0.0;
    int n = 0;
    for (std::size_t i = 0; i < image.size(); ++i) {
      const int x = static_cast<int>(i % pan.width);
      if (!g.has_surface(i) || x + static_cast<int>(g.motion[i].x) >= pan.width) continue;
      const float v = image[i].y;  // the noiseless base
      const float h = 1e-3f;
      const float slope = (shared::pg_srgb_encode(shared::pg_tonemap_aces(v + h)) -
                           shared::pg_srgb_encode(shared::pg_tonemap_aces(v - h))) /
                          (2.0f * h);
      e += 2.0 * static_cast<double>(s) * s * slope * slope / 3.0;
      ++n;
    }
    expected += e / n;
  }
  EXPECT_NEAR(sum / frames, expected / frames, 0.1 * expected / frames);
}

TEST(ReprojectedFlicker, AnotherSurfaceIsNotCompared) {
  const Pan pan;
  std::mt19937 rng(3);
  ReprojectedFlicker flicker;
  GBuffer g0 = pan.gbuffer(0), g1 = pan.gbuffer(1);
  flicker.add(pan.image(g0, 0, 0.0f, rng), g0, 1.0f);
  // Frame 1's right half is another object (another material) that the motion vectors map onto
  // the wall: none of it may enter, and the rest still shows no flicker.
  for (std::size_t i = 0; i < g1.pixel_count(); ++i)
    if (static_cast<int>(i % pan.width) >= pan.width / 2 && g1.has_surface(i)) g1.material[i] = 2;
  std::vector<glm::vec3> image = pan.image(g1, 1, 0.0f, rng);
  for (std::size_t i = 0; i < image.size(); ++i)
    if (g1.material[i] == 2) image[i] = glm::vec3(5.0f);
  const ReprojectedFlicker::Frame r = flicker.add(image, g1, 1.0f);
  EXPECT_EQ(r.mse, 0.0);
  EXPECT_LT(r.tracked_fraction, 0.5);
  EXPECT_GT(r.tracked_fraction, 0.3);
}

// A size change (a new --res in one process, or a library user's resize) starts the history
// again: the frame after it has no flicker, the one after that has.
TEST(ReprojectedFlicker, ASizeChangeStartsTheHistoryAgain) {
  const Pan wide, narrow{33, 7};
  std::mt19937 rng(5);
  ReprojectedFlicker flicker;
  const GBuffer w0 = wide.gbuffer(0), n1 = narrow.gbuffer(1), n2 = narrow.gbuffer(2);
  EXPECT_EQ(flicker.add(wide.image(w0, 0, 0.0f, rng), w0, 1.0f).mse, -1.0);
  EXPECT_EQ(flicker.add(narrow.image(n1, 1, 0.0f, rng), n1, 1.0f).mse, -1.0);
  const ReprojectedFlicker::Frame r = flicker.add(narrow.image(n2, 2, 0.0f, rng), n2, 1.0f);
  EXPECT_NEAR(r.mse, 0.0, 1e-10);
  EXPECT_GT(r.tracked_fraction, 0.5);
}

// The plain flicker of consecutive frames: the mean squared change over pixels and channels,
// -1 without a previous frame of the same size, and the same bits whatever the thread count
// (the blocks' sums are added in order).
TEST(FlickerMse, IsTheMeanSquaredChangeWhateverTheThreadCount) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 2.0f);
  std::vector<glm::vec3> a(100003), b(100003);
  double serial = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    a[i] = glm::vec3(u(rng), u(rng), u(rng));
    b[i] = glm::vec3(u(rng), u(rng), u(rng));
    const glm::vec3 d = a[i] - b[i];
    serial += static_cast<double>(glm::dot(d, d));
  }
  serial /= 3.0 * static_cast<double>(a.size());
  const double many = flicker_mse(a, b);
  double one = 0.0;
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = flicker_mse(a, b);
  }
  EXPECT_EQ(many, one);
  EXPECT_NEAR(many, serial, 1e-12 * serial);
  EXPECT_EQ(flicker_mse(a, {}), -1.0);
  EXPECT_EQ(flicker_mse(a, std::vector<glm::vec3>(7)), -1.0);
}

TEST(ReprojectedFlicker, MismatchedSizesAreAClearError) {
  const Pan pan;
  ReprojectedFlicker flicker;
  const GBuffer g = pan.gbuffer(0);
  EXPECT_THROW(flicker.add(std::vector<glm::vec3>(5), g, 1.0f), std::invalid_argument);
}

}  // namespace
}  // namespace rtpg
