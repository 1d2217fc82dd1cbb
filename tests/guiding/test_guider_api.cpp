// The guider as a user sees it: the public headers under include/rtpg/ and nothing else of the
// library (its own translation unit, so that no private header is visible; the tests' own
// support headers aside). Buffer layouts and bit values are the ones
// include/rtpg/guiding_layout.h documents.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "rtpg/cl_runtime.h"
#include "rtpg/guider.h"
#include "rtpg/guiding_distribution.h"
#include "rtpg/image_size.h"
#include "rtpg/vpl_packing.h"
#include "support/settings_rows.h"

namespace {

constexpr std::uint32_t kSky = PG_GBUF_SKY;
constexpr std::uint32_t kValidBsdfVpl = PG_VPL_VALID | (PG_STRATEGY_BSDF << PG_VPL_STRATEGY_SHIFT);
constexpr std::uint32_t kNone = PG_STRATEGY_NONE, kBsdf = PG_STRATEGY_BSDF,
                        kGuide = PG_STRATEGY_GUIDE;

template <typename T>
cl::Buffer upload(rtpg::ClRuntime& rt, const std::vector<T>& v) {
  return cl::Buffer(rt.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, v.size() * sizeof(T),
                    const_cast<T*>(v.data()));
}

// A rough floor (normal +z) seen from above; the first row is sky. Host arrays, 4 or 2 floats
// per pixel for the vector channels.
struct FloorHost {
  std::vector<float> position, normal, view, bcr, ms, motion;
  std::vector<std::uint32_t> flags, material;
};

FloorHost floor_host(int w, int h) {
  const std::size_t n = static_cast<std::size_t>(w) * h;
  FloorHost f{std::vector<float>(4 * n),         std::vector<float>(4 * n),
              std::vector<float>(4 * n),         std::vector<float>(4 * n),
              std::vector<float>(4 * n),         std::vector<float>(2 * n, 0.0f),
              std::vector<std::uint32_t>(n, 0u), std::vector<std::uint32_t>(n, 1u)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const float px = 0.1f * x, py = 0.1f * y;
      const float v[4] = {-px, -py, 3.0f, 0.0f};
      const float len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      for (int c = 0; c < 4; ++c) {
        f.position[4 * i + c] = c == 0 ? px : c == 1 ? py : c == 2 ? 0.0f : len;
        f.normal[4 * i + c] = c == 2 ? 1.0f : 0.0f;
        f.view[4 * i + c] = v[c] / len;
        f.bcr[4 * i + c] = c == 3 ? 0.6f : 0.7f;
        f.ms[4 * i + c] = c == 1 ? 0.04f : 0.0f;
      }
      if (y == 0) f.flags[i] = kSky;
    }
  return f;
}

rtpg::GuiderGBuffer floor_gbuffer(rtpg::ClRuntime& rt, const FloorHost& f) {
  rtpg::GuiderGBuffer g;
  g.position_depth = upload(rt, f.position);
  g.shading_normal = upload(rt, f.normal);
  g.view_dir = upload(rt, f.view);
  g.base_color_roughness = upload(rt, f.bcr);
  g.metallic_specular = upload(rt, f.ms);
  g.flags = upload(rt, f.flags);
  g.material = upload(rt, f.material);
  g.motion = upload(rt, f.motion);
  return g;
}

rtpg::GuiderGBuffer floor_gbuffer(rtpg::ClRuntime& rt, int w, int h) {
  return floor_gbuffer(rt, floor_host(w, h));
}

}  // namespace

// Create, reset, write/read the state, reproject onto the same frame, sample, train: every
// entry point of the header, checked for what it documents.
TEST(GuiderApi, CreateResetReprojectSampleTrainAndStateRoundTrip) {
  rtpg::ClRuntime rt;
  const bool small = rt.info().platform_name.find("Oclgrind") != std::string::npos;
  const int w = small ? 11 : 37, h = small ? 7 : 23;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  rtpg::Guider guider(rt, w, h);
  EXPECT_EQ(guider.width(), w);
  EXPECT_EQ(guider.height(), h);

  // A new guider holds the initial state: all zeros.
  std::vector<float> state;
  guider.read_state(state);
  ASSERT_EQ(state.size(), 8 * n);
  for (float v : state) ASSERT_EQ(v, 0.0f);

  // The state round-trips bit for bit, and reset() clears it.
  std::mt19937 gen(9);
  std::uniform_real_distribution<float> u(-10.0f, 10.0f);
  std::vector<float> junk(8 * n);
  for (float& v : junk) v = u(gen);
  guider.write_state(junk);
  guider.read_state(state);
  ASSERT_EQ(std::memcmp(state.data(), junk.data(), junk.size() * sizeof(float)), 0);
  guider.reset();
  guider.read_state(state);
  for (float v : state) ASSERT_EQ(v, 0.0f);

  // A lobe straight up at every pixel (mean (0.5, 0.5): the normal), pi = 0.4, k = 5.
  std::vector<float> lobe(8 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const float s0 = 1.0f, pi = 0.4f, var = 0.004f;
    const float v[8] = {
        s0 / pi,    s0,  0.5f * s0, 0.5f * s0, s0 * (var + 0.25f), s0 * (var + 0.25f),
        0.25f * s0, 5.0f};
    std::memcpy(&lobe[8 * i], v, sizeof v);
  }
  guider.write_state(lobe);

  // Reprojecting a static frame onto itself (zero motion) keeps every surface pixel's state
  // bit for bit (same normal: no change of frame) and clears the sky.
  const rtpg::GuiderGBuffer g = floor_gbuffer(rt, w, h);
  guider.reproject(g, g);
  guider.read_state(state);
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 8; ++c)
      ASSERT_EQ(state[8 * i + c], i < static_cast<std::size_t>(w) ? 0.0f : lobe[8 * i + c])
          << i << "," << c;

  // Sampling: sky pixels produce nothing; surface pixels a unit direction above the floor with a
  // positive pdf (or pdf 0 for a Gaussian sample that left the square), by the Gaussian with
  // probability pi = 0.4 (binomial: 5 standard deviations).
  const rtpg::GuiderSamples samples = rtpg::make_guider_samples(rt.context(), w, h);
  std::size_t guided = 0, surface = 0;
  for (std::uint32_t frame = 0; frame < 4; ++frame) {
    guider.sample(g, 42u, frame, 0u, samples);
    std::vector<float> d(4 * n);
    std::vector<std::uint32_t> st(n);
    rt.queue().enqueueReadBuffer(samples.direction_pdf, CL_TRUE, 0, n * 16, d.data());
    rt.queue().enqueueReadBuffer(samples.strategy, CL_TRUE, 0, n * 4, st.data());
    for (std::size_t i = 0; i < n; ++i) {
      if (i < static_cast<std::size_t>(w)) {
        EXPECT_EQ(st[i], kNone);
        EXPECT_EQ(d[4 * i + 3], 0.0f);
        continue;
      }
      ASSERT_TRUE(st[i] == kBsdf || st[i] == kGuide) << st[i];
      ++surface;
      guided += st[i] == kGuide;
      if (d[4 * i + 3] == 0.0f) continue;
      EXPECT_GT(d[4 * i + 3], 0.0f);
      EXPECT_NEAR(std::sqrt(d[4 * i] * d[4 * i] + d[4 * i + 1] * d[4 * i + 1] +
                            d[4 * i + 2] * d[4 * i + 2]),
                  1.0f, 1e-5f);
      EXPECT_GT(d[4 * i + 2], 0.0f);
    }
  }
  const double sd = std::sqrt(0.4 * 0.6 * surface);
  EXPECT_NEAR(static_cast<double>(guided), 0.4 * surface, 5.0 * sd);
  EXPECT_GE(guider.last_times().sample_ms, 0.0);

  // Training from bright VPLs 2 units above every pixel (valid, BSDF strategy): every surface
  // pixel takes an EM step (k: 5 -> 6); the sky does not.
  std::vector<float> vp(4 * n);
  std::vector<std::uint32_t> vnr(4 * n);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const float pos[4] = {0.1f * x + 0.3f, 0.1f * y, 2.0f, 1.0f};  // w: area density
      // Facing down, the mixture's area density 1, radiance 5, packed (rtpg/vpl_packing.h).
      const std::array<std::uint32_t, 4> packed = rtpg::pack_vpl_normal_radiance(
          {0.0f, 0.0f, -1.0f}, 1.0f, {5.0f, 5.0f, 5.0f}, y == 0 ? 0u : kValidBsdfVpl);
      std::memcpy(&vp[4 * i], pos, sizeof pos);
      std::memcpy(&vnr[4 * i], packed.data(), sizeof packed);
    }
  guider.train(g, {upload(rt, vp), upload(rt, vnr)}, 42u, 4u);
  EXPECT_EQ(guider.count_trained(), n - static_cast<std::size_t>(w));
  guider.read_state(state);
  for (std::size_t i = 0; i < n; ++i) {
    const bool sky = i < static_cast<std::size_t>(w);
    EXPECT_EQ(state[8 * i + 7], sky ? 0.0f : 6.0f) << i;
    for (int c = 0; c < 8; ++c) ASSERT_TRUE(std::isfinite(state[8 * i + c]));
  }
  EXPECT_GE(guider.last_times().train_ms, 0.0);
}

// Kernels enqueued with Wait::later compute what they compute waited for: a second guider
// given the same state, G-buffer and frames, its reproject and sample enqueued one after the
// other without waiting, ends with the same samples and state to the bit once wait_for_kernels()
// returns, which has then recorded both kernels' times.
TEST(GuiderApi, KernelsLeftRunningComputeTheSame) {
  rtpg::ClRuntime rt;
  const bool small = rt.info().platform_name.find("Oclgrind") != std::string::npos;
  const int w = small ? 11 : 37, h = small ? 7 : 23;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  const rtpg::GuiderGBuffer g = floor_gbuffer(rt, w, h);
  std::mt19937 gen(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  // Lobes of random centres and widths, pi 0.3, k 4 (the state layout of the test above).
  std::vector<float> lobe(8 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const float s0 = 1.0f, pi = 0.3f, var = 0.002f + 0.01f * u(gen);
    const float mx = 0.3f + 0.4f * u(gen), my = 0.3f + 0.4f * u(gen);
    const float v[8] = {
        s0 / pi,      s0,  mx * s0, my * s0, s0 * (var + mx * mx), s0 * (var + my * my),
        mx * my * s0, 4.0f};
    std::memcpy(&lobe[8 * i], v, sizeof v);
  }
  std::vector<float> d[2], state[2];
  for (int later = 0; later < 2; ++later) {
    rtpg::Guider guider(rt, w, h);
    guider.write_state(lobe);
    const rtpg::GuiderSamples samples = rtpg::make_guider_samples(rt.context(), w, h);
    const rtpg::Guider::Wait wait = later ? rtpg::Guider::Wait::later : rtpg::Guider::Wait::finish;
    guider.reproject(g, g, wait);
    guider.sample(g, 7u, 1u, 0u, samples, rtpg::SampleOutputs::directions, wait);
    guider.wait_for_kernels();
    EXPECT_GT(guider.last_times().reproject_ms, 0.0);
    EXPECT_GT(guider.last_times().sample_ms, 0.0);
    d[later].resize(4 * n);
    rt.queue().enqueueReadBuffer(samples.direction_pdf, CL_TRUE, 0, n * 16, d[later].data());
    guider.read_state(state[later]);
  }
  EXPECT_EQ(std::memcmp(d[0].data(), d[1].data(), n * 16), 0);
  EXPECT_EQ(state[0], state[1]);
}

// With models shared by rows, which pixels share is decided once a frame and read by the frame's
// later calls (include/rtpg/guider.h, above reproject()): a frame's own decision is what counts,
// never another frame's. Two floors: on A a pixel shares its pair's model (rows 3, 5, ...: row 1's
// model row is sky); on B the lower row of every pair is another material, so none does. A
// pixel that shares is seen by the sample kernel carrying its model pixel's state.
TEST(GuiderApi, EachFrameDecidesWhichPixelsShareFromItsOwnGBuffer) {
  rtpg::ClRuntime rt;
  const bool small = rt.info().platform_name.find("Oclgrind") != std::string::npos;
  const int w = small ? 11 : 37, h = small ? 7 : 23;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  const FloorHost host_a = floor_host(w, h);
  FloorHost host_b = host_a;
  for (int y = 1; y < h; y += 2)
    for (int x = 0; x < w; ++x) host_b.material[static_cast<std::size_t>(y) * w + x] = 2u;
  const rtpg::GuiderGBuffer a = floor_gbuffer(rt, host_a), b = floor_gbuffer(rt, host_b);
  // A state of its own at every pixel (k = 5 + the pixel's index), so that a carried one shows.
  std::vector<float> own(8 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const float s0 = 1.0f, pi = 0.4f, var = 0.004f;
    const float v[8] = {s0 / pi,
                        s0,
                        0.5f * s0,
                        0.5f * s0,
                        s0 * (var + 0.25f),
                        s0 * (var + 0.25f),
                        0.25f * s0,
                        5.0f + static_cast<float>(i)};
    std::memcpy(&own[8 * i], v, sizeof v);
  }
  // Pixels whose state is not their own after sampling: the shared ones on floor A. (Not the sky
  // row, whose state reproject() resets.)
  const auto carried = [&](rtpg::Guider& guider) {
    std::vector<float> state;
    guider.read_state(state);
    std::size_t count = 0;
    for (std::size_t i = static_cast<std::size_t>(w); i < n; ++i) {
      const std::size_t y = i / static_cast<std::size_t>(w);
      const std::size_t from = y >= 3 && y % 2 == 1 ? i - static_cast<std::size_t>(w) : i;
      EXPECT_EQ(state[8 * i + 7], own[8 * from + 7]) << "pixel " << i;
      count += from != i && state[8 * i + 7] == own[8 * from + 7];
    }
    return count;
  };
  const auto kept_own = [&](rtpg::Guider& guider) {
    std::vector<float> state;
    guider.read_state(state);
    std::size_t changed = 0;
    for (std::size_t i = 0; i < n; ++i) changed += state[8 * i + 7] != own[8 * i + 7];
    return changed == 0;
  };
  const std::size_t shared_on_a = static_cast<std::size_t>((h - 2) / 2) * w;
  rtpg::GuidingSettings settings;
  settings.rows_per_model = 2;
  rtpg::Guider guider(rt, w, h, settings);
  const rtpg::GuiderSamples samples = rtpg::make_guider_samples(rt.context(), w, h);

  // Frame 0 samples floor A, deciding: the shared pixels carry their models.
  guider.write_state(own);
  guider.sample(a, 1u, 0u, 0u, samples);
  EXPECT_EQ(carried(guider), shared_on_a);
  // Frame 1, floor B, with no reproject() and no train() between: its first sample decides again
  // (none shares), and its second sample reads that decision.
  guider.write_state(own);
  guider.sample(b, 1u, 1u, 0u, samples);
  EXPECT_TRUE(kept_own(guider));
  guider.sample(b, 1u, 1u, 1u, samples);
  EXPECT_TRUE(kept_own(guider));
  // Frame 2 on floor A: reproject() decides, the frame's sample reads it.
  guider.write_state(own);
  guider.reproject(a, a);
  guider.sample(a, 1u, 2u, 0u, samples);
  EXPECT_EQ(carried(guider), shared_on_a);
  // A train() of another frame on floor B decides for itself: every surface pixel trains (from
  // bright VPLs above it), the lower rows too, which floor A's decision would have skipped.
  std::vector<float> vp(4 * n);
  std::vector<std::uint32_t> vnr(4 * n);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      const float pos[4] = {0.1f * x + 0.3f, 0.1f * y, 2.0f, 1.0f};
      const std::array<std::uint32_t, 4> packed = rtpg::pack_vpl_normal_radiance(
          {0.0f, 0.0f, -1.0f}, 1.0f, {5.0f, 5.0f, 5.0f}, y == 0 ? 0u : kValidBsdfVpl);
      std::memcpy(&vp[4 * i], pos, sizeof pos);
      std::memcpy(&vnr[4 * i], packed.data(), sizeof packed);
    }
  std::vector<float> young = own;  // k = 0: young pixels, which train in every frame
  for (std::size_t i = 0; i < n; ++i) young[8 * i + 7] = 0.0f;
  guider.write_state(young);
  guider.train(b, {upload(rt, vp), upload(rt, vnr)}, 1u, 5u);
  EXPECT_EQ(guider.count_trained(), n - static_cast<std::size_t>(w));
}

// The host distribution (include/rtpg/guiding_distribution.h) is the device sampler's: for every
// direction the sample kernel drew, its density is the kernel's, whether it is built from the
// pixel's state (init) or from the mixture the kernel wrote (init_mixture), and its own samples
// carry their own density.
TEST(GuiderApi, HostDistributionHasTheSampleKernelsDensity) {
  rtpg::ClRuntime rt;
  const int w = 13, h = 9;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  rtpg::Guider guider(rt, w, h);
  // A tilted, correlated lobe (mean (0.62, 0.41)), pi = 0.5, k = 7.
  std::vector<float> lobe(8 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const float s0 = 2.0f, pi = 0.5f, mx = 0.62f, my = 0.41f;
    const float v[8] = {s0 / pi,
                        s0,
                        mx * s0,
                        my * s0,
                        s0 * (0.01f + mx * mx),
                        s0 * (0.006f + my * my),
                        s0 * (0.003f + mx * my),
                        7.0f};
    std::memcpy(&lobe[8 * i], v, sizeof v);
  }
  guider.write_state(lobe);
  const FloorHost f = floor_host(w, h);
  const rtpg::GuiderGBuffer g = floor_gbuffer(rt, f);
  rtpg::GuiderSamples samples = rtpg::make_guider_samples(rt.context(), w, h);
  rtpg::GuidingDistribution d(guider.kernel_settings()), from_mixture(guider.kernel_settings());
  std::size_t checked = 0, guided_pixels = 0;
  for (std::uint32_t frame = 0; frame < 3; ++frame) {
    guider.sample(g, 7u, frame, 0u, samples);
    std::vector<float> dir(4 * n), mixture_a(4 * n), mixture_b(2 * n);
    rt.queue().enqueueReadBuffer(samples.direction_pdf, CL_TRUE, 0, n * 16, dir.data());
    rt.queue().enqueueReadBuffer(samples.mixture_a, CL_TRUE, 0, n * 16, mixture_a.data());
    rt.queue().enqueueReadBuffer(samples.mixture_b, CL_TRUE, 0, n * 8, mixture_b.data());
    for (std::size_t i = static_cast<std::size_t>(w); i < n; ++i) {
      d.init(&lobe[8 * i], &f.normal[4 * i], &f.view[4 * i], &f.bcr[4 * i], &f.ms[4 * i],
             f.flags[i]);
      // The same pixel from the mixture the kernel wrote (no state on the host).
      from_mixture.init_mixture(&mixture_a[4 * i], &mixture_b[2 * i], &f.normal[4 * i],
                                &f.view[4 * i], &f.bcr[4 * i], &f.ms[4 * i]);
      guided_pixels += d.guided();
      EXPECT_FLOAT_EQ(d.mixing_weight(), 0.5f);
      EXPECT_TRUE(from_mixture.guided()) << i;
      EXPECT_FLOAT_EQ(from_mixture.mixing_weight(), 0.5f) << i;
      if (dir[4 * i + 3] <= 0.0f) continue;
      EXPECT_NEAR(d.pdf(&dir[4 * i]), dir[4 * i + 3], 1e-5f * dir[4 * i + 3]) << i;
      EXPECT_NEAR(from_mixture.pdf(&dir[4 * i]), dir[4 * i + 3], 1e-5f * dir[4 * i + 3]) << i;
      ++checked;
      const rtpg::GuidingDirection s = d.sample(0.3f, 0.25f + 0.5f * (i % 2), 0.6f);
      if (s.pdf > 0.0f) {
        EXPECT_NEAR(d.pdf(s.direction), s.pdf, 1e-5f * s.pdf) << i;
      }
    }
  }
  EXPECT_EQ(guided_pixels, 3 * (n - static_cast<std::size_t>(w)));
  EXPECT_GT(checked, 2 * (n - static_cast<std::size_t>(w)));
  // A sky pixel gets the BSDF alone: no Gaussian.
  d.init(&lobe[0], &f.normal[0], &f.view[0], &f.bcr[0], &f.ms[0], f.flags[0]);
  EXPECT_FALSE(d.guided());
  EXPECT_EQ(d.mixing_weight(), 0.0f);
}

// The settings table is the one place ranges live: the defaults pass, and every row refuses
// NaN, infinities and the first values outside its range, naming itself.
TEST(GuidingSettingsTable, DefaultsPassAndEveryRowRefusesItsOutsideValues) {
  EXPECT_NO_THROW(rtpg::validate(rtpg::GuidingSettings{}));
  const auto& table = rtpg::guiding_settings_table();
  EXPECT_EQ(table.size(), 28u);
  for (const rtpg::GuidingSettingInfo& row : table) {
    ASSERT_TRUE((row.float_field != nullptr) != (row.int_field != nullptr)) << row.name;
    EXPECT_TRUE(row.in_range(row.get(rtpg::GuidingSettings{}))) << row.name;
    std::vector<double> bad;
    if (row.float_field) {
      bad = {std::nan(""), INFINITY, -INFINITY};
      bad.push_back(row.min_exclusive ? row.min : row.min - 1.0);
      if (std::isfinite(row.max)) bad.push_back(row.max_exclusive ? row.max : row.max + 1.0);
    } else {
      bad = {row.min - 1.0, row.max + 1.0};
    }
    for (double v : bad) {
      rtpg::GuidingSettings s;
      row.set(s, v);
      try {
        rtpg::validate(s);
        ADD_FAILURE() << row.name << " = " << v << " passed";
      } catch (const rtpg::GuiderError& e) {
        EXPECT_NE(std::string(e.what()).find(row.name), std::string::npos) << e.what();
      }
    }
  }
  rtpg::GuidingSettings s;
  s.n_min = 9;
  s.n_max = 8;
  EXPECT_THROW(rtpg::validate(s), rtpg::GuiderError);
  // Pixels per work-item of the train and sample kernels: a vector width of OpenCL C, or 0
  // (auto).
  for (int lanes = 0; lanes <= 16; ++lanes)
    for (int kernel = 0; kernel < 2; ++kernel) {
      s = rtpg::GuidingSettings{};
      (kernel == 0 ? s.train_lanes : s.sample_lanes) = lanes;
      const bool valid =
          lanes == 0 || lanes == 1 || lanes == 2 || lanes == 4 || lanes == 8 || lanes == 16;
      if (valid) {
        EXPECT_NO_THROW(rtpg::validate(s)) << lanes;
      } else {
        EXPECT_THROW(rtpg::validate(s), rtpg::GuiderError) << lanes;
      }
    }
  // Rows per shared model: a power of two (the kernels find a row's group by y - y % R), or 0
  // (by the image's height).
  for (int rows = 0; rows <= 8; ++rows) {
    s = rtpg::GuidingSettings{};
    s.rows_per_model = rows;
    if (rows == 0 || rows == 1 || rows == 2 || rows == 4 || rows == 8) {
      EXPECT_NO_THROW(rtpg::validate(s)) << rows;
    } else {
      EXPECT_THROW(rtpg::validate(s), rtpg::GuiderError) << rows;
    }
  }
  // The kernels' block carries the values (integers as floats where the kernels want them).
  s = rtpg::GuidingSettings{};
  s.k_max = 17;
  s.apron = 3;
  s.rows_per_model = 4;
  const rtpg::pg_kernel_settings k = rtpg::to_kernel_settings(s);
  EXPECT_EQ(k.k_max, 17.0f);
  EXPECT_EQ(k.apron, 3);
  EXPECT_EQ(k.rows_per_model, 4);
  EXPECT_EQ(k.reproject_position, s.reproject_position);
  // The window walk's stride visits all 49 cells of a 7x7 window: coprime with 49.
  EXPECT_GT(k.stride, 0);
  EXPECT_NE(k.stride % 7, 0);
  // Settings out of range are refused before the block is built (an apron of 2^30 overflowed
  // the window's size, undefined behaviour, before the Guider validated its settings), and an
  // enumerator that is none of the three.
  s = rtpg::GuidingSettings{};
  s.apron = 1 << 30;
  EXPECT_THROW(rtpg::to_kernel_settings(s), rtpg::GuiderError);
  rtpg::ClRuntime rt;
  EXPECT_THROW(rtpg::Guider(rt, 8, 8, s), rtpg::GuiderError);
  s = rtpg::GuidingSettings{};
  s.train_memory = static_cast<rtpg::GuidingSettings::TrainMemory>(7);
  EXPECT_THROW(rtpg::validate(s), rtpg::GuiderError);
}

// Every row of the settings table that the kernels use reaches their block: changed alone to a
// valid value away from its default, it changes the block's bytes (the kernels' host reference
// reads the same block, so a field the conversion forgot would pass every kernel test). The
// work-group sizes and lane counts choose how the kernels are launched and built, not what they
// compute: they stay out of the block.
TEST(GuidingSettingsTable, EveryKernelSettingReachesTheKernelsBlock) {
  const std::vector<std::string> host_only = {"local_x", "local_y", "train_lanes", "sample_lanes"};
  const rtpg::pg_kernel_settings defaults = rtpg::to_kernel_settings(rtpg::GuidingSettings{}, 540);
  for (const rtpg::GuidingSettingInfo& row : rtpg::guiding_settings_table()) {
    SCOPED_TRACE(row.name);
    const auto s = rtpg::test::with_row_changed<rtpg::GuidingSettings>(row, [](const auto& c) {
      try {
        rtpg::validate(c);
        return true;
      } catch (const rtpg::GuiderError&) {
        return false;  // a value the other settings do not allow with it (n_min above n_max)
      }
    });
    ASSERT_TRUE(s.has_value()) << "no valid value away from the default";
    const rtpg::pg_kernel_settings k = rtpg::to_kernel_settings(*s, 540);
    const bool differs = std::memcmp(&k, &defaults, sizeof k) != 0;
    const bool is_host_only =
        std::find(host_only.begin(), host_only.end(), row.name) != host_only.end();
    EXPECT_EQ(differs, !is_host_only) << "at " << row.get(*s);
  }
}

// rows_per_model 0 (the default) shares a model over at most 1/135 of the image's height, in
// groups of 1, 2, 4 or 8 rows; an explicit value is kept whatever the height.
// The Guider refuses the image sizes the renderer refuses (rtpg/image_size.h), before it
// allocates anything: a side of zero or beyond 65536 pixels, more than 8192^2 pixels in all.
TEST(GuiderApi, RefusesImageSizesOutOfRange) {
  rtpg::ClRuntime rt;
  for (const auto& [w, h] :
       std::vector<std::pair<int, int>>{{0, 8}, {8, -1}, {70000, 1}, {1, 70000}, {16384, 8193}}) {
    try {
      rtpg::Guider guider(rt, w, h);
      ADD_FAILURE() << w << "x" << h << " accepted";
    } catch (const rtpg::GuiderError& e) {
      EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(rtpg::image_size_problem(65536, 1024), "");
  EXPECT_NE(rtpg::image_size_problem(65537, 1), "");
}

TEST(GuidingSettingsTable, RowsPerModelByTheImagesHeight) {
  EXPECT_EQ(rtpg::GuidingSettings{}.rows_per_model, 0);
  const std::pair<int, int> heights[] = {{0, 1},    {1, 1},    {135, 1},  {269, 1},
                                         {270, 2},  {539, 2},  {540, 4},  {720, 4},
                                         {1079, 4}, {1080, 8}, {2160, 8}, {4320, 8}};
  for (const auto& [height, rows] : heights) {
    EXPECT_EQ(rtpg::rows_per_model_for_height(height), rows) << height;
    EXPECT_EQ(rtpg::to_kernel_settings(rtpg::GuidingSettings{}, height).rows_per_model, rows)
        << height;
  }
  rtpg::GuidingSettings one;
  one.rows_per_model = 1;
  EXPECT_EQ(rtpg::to_kernel_settings(one, 1080).rows_per_model, 1);
  rtpg::GuidingSettings eight;
  eight.rows_per_model = 8;
  EXPECT_EQ(rtpg::to_kernel_settings(eight, 135).rows_per_model, 8);
  // The guider runs, and reports, the value for its own image.
  rtpg::ClRuntime rt;
  const rtpg::Guider tall(rt, 8, 540, rtpg::GuidingSettings{});
  EXPECT_EQ(tall.settings().rows_per_model, 4);
  EXPECT_EQ(tall.kernel_settings().rows_per_model, 4);
  const rtpg::Guider short_image(rt, 8, 300, rtpg::GuidingSettings{});
  EXPECT_EQ(short_image.settings().rows_per_model, 2);
}
