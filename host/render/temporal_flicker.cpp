#include "render/temporal_flicker.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "rtpg/guiding_settings.h"
#include "shared/same_surface.h"
#include "shared/tonemap.h"

namespace rtpg {
namespace {

// The display transform of one channel without the final rounding (kernels/shared/tonemap.h).
float displayed(float radiance, float exposure) {
  if (!std::isfinite(radiance)) return 0.0f;
  return shared::pg_srgb_encode(shared::pg_tonemap_aces(radiance * exposure));
}

glm::vec3 displayed(const glm::vec3& radiance, float exposure) {
  return {displayed(radiance.x, exposure), displayed(radiance.y, exposure),
          displayed(radiance.z, exposure)};
}

// Pixels per block of the flicker sums: each block's sum is one task's, the blocks' sums are
// added in order.
constexpr std::size_t kBlock = 4096;

}  // namespace

double flicker_mse(const std::vector<glm::vec3>& image, const std::vector<glm::vec3>& previous) {
  if (previous.size() != image.size() || image.empty()) return -1.0;
  const std::size_t blocks = (image.size() + kBlock - 1) / kBlock;
  std::vector<double> block_sums(blocks, 0.0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t b = r.begin(); b != r.end(); ++b) {
                        const std::size_t end = std::min(image.size(), (b + 1) * kBlock);
                        double sum = 0.0;
                        for (std::size_t i = b * kBlock; i != end; ++i) {
                          const glm::vec3 d = image[i] - previous[i];
                          sum += static_cast<double>(glm::dot(d, d));
                        }
                        block_sums[b] = sum;
                      }
                    });
  double sum = 0.0;
  for (const double s : block_sums) sum += s;
  return sum / (3.0 * static_cast<double>(image.size()));
}

ReprojectedFlicker::Frame ReprojectedFlicker::add(const std::vector<glm::vec3>& image,
                                                  const GBuffer& g, float exposure) {
  const std::size_t n = g.pixel_count();
  if (image.size() != n)
    throw std::invalid_argument("flicker: image of " + std::to_string(image.size()) +
                                " pixels for a G-buffer of " + std::to_string(n));
  const bool have_previous =
      previous_.shown.size() == n && width_ == g.width && height_ == g.height;
  // This frame's history, written in the same pass that compares with the last one's (which
  // it reads at the pixels the motion vectors name, so into buffers of its own, swapped after).
  // A pixel without a surface keeps only its flags: the test reads nothing else of it.
  next_.shown.resize(n);
  next_.position_depth.resize(n);
  next_.normal.resize(n);
  next_.material.resize(n);
  next_.flags.resize(n);
  // The history test's thresholds are guiding's defaults (the denoiser's are the same).
  const GuidingSettings tests;
  struct Sum {
    double squared = 0.0;
    std::size_t pixels = 0;
  };
  // By rows: a pixel's coordinates without a division.
  const Sum sum = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, g.height), Sum{},
      [&](const tbb::blocked_range<int>& rows, Sum s) {
        for (int y = rows.begin(); y != rows.end(); ++y)
          for (int x = 0; x < g.width; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(g.width) +
                                  static_cast<std::size_t>(x);
            next_.flags[i] = g.flags[i];
            if (!g.has_surface(i)) continue;
            const glm::vec3 shown = displayed(image[i], exposure);
            next_.shown[i] = shown;
            next_.position_depth[i] = g.position_depth[i];
            next_.normal[i] = g.shading_normal[i];
            next_.material[i] = g.material[i];
            if (!have_previous) continue;
            const int px =
                static_cast<int>(std::floor(static_cast<float>(x) + g.motion[i].x + 0.5f));
            const int py =
                static_cast<int>(std::floor(static_cast<float>(y) + g.motion[i].y + 0.5f));
            if (px < 0 || py < 0 || px >= width_ || py >= height_) continue;
            const std::size_t j = static_cast<std::size_t>(py) * width_ + px;
            if ((previous_.flags[j] & PG_GBUF_SKY) != 0 ||
                !shared::pg_same_surface(g.position_depth[i], glm::vec3(g.shading_normal[i]),
                                         g.material[i], previous_.position_depth[j],
                                         glm::vec3(previous_.normal[j]), previous_.material[j],
                                         tests.reproject_position, tests.reproject_normal))
              continue;
            const glm::vec3 d = shown - previous_.shown[j];
            s.squared += static_cast<double>(glm::dot(d, d));
            ++s.pixels;
          }
        return s;
      },
      [](Sum a, const Sum& b) {
        a.squared += b.squared;
        a.pixels += b.pixels;
        return a;
      });
  Frame out;
  if (have_previous) {
    out.tracked_fraction = static_cast<double>(sum.pixels) / static_cast<double>(n);
    if (sum.pixels > 0) out.mse = sum.squared / (3.0 * static_cast<double>(sum.pixels));
  }
  width_ = g.width;
  height_ = g.height;
  std::swap(previous_, next_);
  return out;
}

}  // namespace rtpg
