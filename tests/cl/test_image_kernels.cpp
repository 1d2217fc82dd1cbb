// tonemap.cl and accumulate.cl against the host reference: the same functions from
// kernels/shared/tonemap.h, compiled as C++.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render/image_kernels.h"
#include "shared/tonemap.h"

namespace rtpg {
namespace {

namespace sh = rtpg::shared;

struct Size {
  int w, h;
};

// Sizes include ones that are not a multiple of the local size (the kernels must skip the
// padding work-items) and a single pixel.
const Size kSizes[] = {{1, 1}, {17, 13}, {64, 4}, {33, 65}, {257, 3}};
// 0 = driver's choice; 64 = the default; 1 and 7 to exercise odd group shapes.
const std::size_t kLocalSizes[] = {0, 1, 7, 64, 256};

// Oclgrind simulates each work-item (about 100x slower than PoCL): keep its images small.
bool simulated(const ClRuntime& rt) {
  return rt.info().platform_name.find("Oclgrind") != std::string::npos;
}

// Radiance as a renderer produces it, plus what it should not but might: negative, NaN,
// infinite, denormal, huge.
float random_radiance(std::mt19937& rng) {
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const float u = unit(rng);
  const float v = unit(rng);
  if (u < 0.50f) return 2.0f * v;                            // ordinary
  if (u < 0.80f) return std::pow(10.0f, -6.0f + 10.0f * v);  // log-uniform 1e-6..1e4
  if (u < 0.86f) return -3.0f * v;                           // negative
  if (u < 0.89f) return std::numeric_limits<float>::quiet_NaN();
  if (u < 0.92f) return std::numeric_limits<float>::infinity();
  if (u < 0.94f) return -std::numeric_limits<float>::infinity();
  if (u < 0.96f) return 1e-40f * v;  // denormal
  if (u < 0.98f) return 1e30f * v;   // huge, finite
  return 0.0f;
}

std::vector<glm::vec4> random_image(std::mt19937& rng, std::size_t count) {
  std::vector<glm::vec4> image(count);
  for (auto& p : image)
    p = glm::vec4(random_radiance(rng), random_radiance(rng), random_radiance(rng),
                  random_radiance(rng));
  return image;
}

std::vector<std::uint8_t> host_tonemap(const std::vector<glm::vec4>& radiance, float exposure) {
  std::vector<std::uint8_t> out(4 * radiance.size());
  for (std::size_t i = 0; i < radiance.size(); ++i) {
    const std::uint32_t p = sh::pg_tonemap_to_srgb8(radiance[i], exposure);
    for (int c = 0; c < 4; ++c) out[4 * i + c] = static_cast<std::uint8_t>(p >> (8 * c));
  }
  return out;
}

// Bitwise equality (so -0 != +0), except that any NaN equals any NaN: IEEE 754 leaves the
// sign and payload of a computed NaN to the hardware (x86 SSE gives -nan for inf - inf).
bool same_value(float a, float b) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// The host functions against a double-precision evaluation of the documented formula.
TEST(TonemapHost, MatchesTheDocumentedFormula) {
  const auto reference = [](double x) -> int {
    if (!std::isfinite(x)) return 0;
    x = std::fmin(std::fmax(x, 0.0), 1e4);
    double y = (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
    y = std::fmin(std::fmax(y, 0.0), 1.0);
    const double c = y <= 0.0031308 ? 12.92 * y : 1.055 * std::pow(y, 1.0 / 2.4) - 0.055;
    return static_cast<int>(std::floor(c * 255.0 + 0.5));
  };
  for (float x = 0.0f; x < 20.0f; x += 0.001f) {
    const int got = static_cast<int>(sh::pg_tonemap_channel8(x, 1.0f));
    EXPECT_NEAR(got, reference(x), 1) << x;  // float vs double rounding near a .5 boundary
  }
  EXPECT_EQ(sh::pg_tonemap_channel8(0.0f, 1.0f), 0u);
  EXPECT_EQ(sh::pg_tonemap_channel8(-5.0f, 1.0f), 0u);
  EXPECT_EQ(sh::pg_tonemap_channel8(std::numeric_limits<float>::quiet_NaN(), 1.0f), 0u);
  EXPECT_EQ(sh::pg_tonemap_channel8(std::numeric_limits<float>::infinity(), 1.0f), 0u);
  EXPECT_EQ(sh::pg_tonemap_channel8(1e30f, 1e30f), 255u);  // overflow to +inf saturates
  EXPECT_EQ(sh::pg_tonemap_channel8(100.0f, 1.0f), 255u);
  EXPECT_EQ(sh::pg_tonemap_to_srgb8(glm::vec4(0.0f, 0.0f, 100.0f, -1.0f), 1.0f), 0xffff0000u);
}

// Device and host agree exactly, except that OpenCL lets exp/log be 3 ulp off: where 255 c
// falls within that of a .5 rounding boundary one channel may differ by one. That needs
// |255 c - k - 0.5| < ~1e-4, so well under 0.1% of pixels.
TEST(TonemapDevice, EqualsHostReference) {
  ClRuntime rt;
  std::mt19937 rng(1234);
  std::size_t pixels = 0, off_by_one = 0;
  const auto compare = [&](const std::vector<glm::vec4>& radiance,
                           const std::vector<std::uint8_t>& device, float exposure,
                           const std::string& what) {
    const std::vector<std::uint8_t> host = host_tonemap(radiance, exposure);
    ASSERT_EQ(device.size(), host.size()) << what;
    for (std::size_t i = 0; i < radiance.size(); ++i) {
      bool differs = false;
      for (int c = 0; c < 4; ++c) {
        const int d = device[4 * i + c], h = host[4 * i + c];
        ASSERT_LE(std::abs(d - h), 1) << what << " pixel " << i << " channel " << c;
        differs |= d != h;
      }
      off_by_one += differs;
    }
    pixels += radiance.size();
  };

  const float exposures[] = {1.0f, 0.25f, 8.0f};
  for (const Size s : kSizes) {
    for (const std::size_t local : kLocalSizes) {
      const std::size_t count = static_cast<std::size_t>(s.w) * s.h;
      const std::vector<glm::vec4> radiance = random_image(rng, count);
      const float exposure = exposures[(pixels / 7) % 3];
      cl::Buffer in(rt.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                    count * sizeof(glm::vec4), const_cast<glm::vec4*>(radiance.data()));
      // One spare pixel past the end, filled with a marker: the padding work-items of the
      // last group must not write it.
      cl::Buffer out(rt.context(), CL_MEM_READ_WRITE, 4 * (count + 1));
      rt.queue().enqueueFillBuffer(out, cl_uchar(0xab), 0, 4 * (count + 1));
      enqueue_tonemap(rt, in, out, s.w, s.h, exposure, local);
      std::vector<std::uint8_t> device(4 * (count + 1));
      rt.queue().enqueueReadBuffer(out, CL_TRUE, 0, device.size(), device.data());
      const std::string what =
          std::to_string(s.w) + "x" + std::to_string(s.h) + " local " + std::to_string(local);
      for (int c = 0; c < 4; ++c) EXPECT_EQ(device[4 * count + c], 0xab) << what;
      device.resize(4 * count);
      compare(radiance, device, exposure, what);
    }
  }

  // One larger image through the blocking convenience call, for the statistics.
  const Size big = simulated(rt) ? Size{64, 48} : Size{512, 512};
  const std::vector<glm::vec4> radiance =
      random_image(rng, static_cast<std::size_t>(big.w) * big.h);
  std::vector<std::uint8_t> device;
  tonemap_on_device(rt, radiance, big.w, big.h, 1.5f, device);
  compare(radiance, device, 1.5f, "big");

  EXPECT_LE(off_by_one * 1000, pixels) << off_by_one << " of " << pixels << " pixels differ";
  std::printf("[ info     ] %zu of %zu pixels off by one\n", off_by_one, pixels);
}

TEST(TonemapDevice, RejectsAWrongSize) {
  ClRuntime rt;
  std::vector<std::uint8_t> out;
  EXPECT_THROW(tonemap_on_device(rt, std::vector<glm::vec4>(5), 2, 2, 1.0f, out),
               std::invalid_argument);
  EXPECT_THROW(tonemap_on_device(rt, {}, 0, 0, 1.0f, out), std::invalid_argument);
}

// The running mean on the device is bit for bit the host's: the same two roundings per
// channel (FP contraction is off in the kernel), NaN and Inf propagating alike.
TEST(AccumulateDevice, EqualsHostReference) {
  ClRuntime rt;
  std::mt19937 rng(99);
  // All accumulators stay alive to the end: Oclgrind 21.10 --uninitialized keeps the shadow
  // state of a released buffer for the next buffer that reuses its id, sized as the old one,
  // and then reports reads past that size as uninitialised (false positives).
  std::vector<std::unique_ptr<Accumulator>> accumulators;
  for (const Size s : kSizes) {
    for (const std::size_t local : kLocalSizes) {
      const std::size_t count = static_cast<std::size_t>(s.w) * s.h;
      Accumulator& acc =
          *accumulators.emplace_back(std::make_unique<Accumulator>(rt, s.w, s.h, local));
      std::vector<glm::vec4> host(count, glm::vec4(0.0f));
      for (int frame = 0; frame < 4; ++frame) {
        const std::vector<glm::vec4> input = random_image(rng, count);
        const float weight = 1.0f / static_cast<float>(frame + 1);
        for (std::size_t i = 0; i < count; ++i)
          host[i] = sh::pg_accumulate(host[i], input[i], weight);
        acc.add(input);
      }
      EXPECT_EQ(acc.frames(), 4);
      const std::vector<glm::vec4> device = acc.read();
      for (std::size_t i = 0; i < count; ++i)
        for (int c = 0; c < 4; ++c)
          ASSERT_TRUE(same_value(device[i][c], host[i][c]))
              << s.w << "x" << s.h << " local " << local << " pixel " << i << " channel " << c
              << ": device " << device[i][c] << " host " << host[i][c];
    }
  }
}

TEST(AccumulateDevice, IsTheMeanAndResets) {
  ClRuntime rt;
  Accumulator acc(rt, 5, 3);
  for (const glm::vec4& p : acc.read()) EXPECT_EQ(p, glm::vec4(0.0f));
  const float values[] = {1.0f, 2.0f, 6.0f, 3.0f};  // mean 3
  for (const float v : values) acc.add(std::vector<glm::vec4>(15, glm::vec4(v, -v, 0.0f, 1.0f)));
  for (const glm::vec4& p : acc.read()) {
    EXPECT_FLOAT_EQ(p.x, 3.0f);
    EXPECT_FLOAT_EQ(p.y, -3.0f);
    EXPECT_EQ(p.z, 0.0f);
    EXPECT_EQ(p.w, 1.0f);
  }
  acc.reset();
  EXPECT_EQ(acc.frames(), 0);
  acc.add(std::vector<glm::vec4>(15, glm::vec4(std::numeric_limits<float>::quiet_NaN())));
  acc.reset();  // a NaN frame poisons the mean until the next reset, no further
  acc.add(std::vector<glm::vec4>(15, glm::vec4(7.0f)));
  for (const glm::vec4& p : acc.read()) EXPECT_EQ(p, glm::vec4(7.0f));
  EXPECT_THROW(acc.add(std::vector<glm::vec4>(14)), std::invalid_argument);
}

}  // namespace
}  // namespace rtpg
