#include "render/temporal_flicker.h"

#include <cmath>
#include <stdexcept>
#include <string>

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

}  // namespace

ReprojectedFlicker::Frame ReprojectedFlicker::add(const std::vector<glm::vec3>& image,
                                                  const GBuffer& g, float exposure) {
  const std::size_t n = g.pixel_count();
  if (image.size() != n)
    throw std::invalid_argument("flicker: image of " + std::to_string(image.size()) +
                                " pixels for a G-buffer of " + std::to_string(n));
  std::vector<glm::vec3> shown(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i)
                        shown[i] = displayed(image[i], exposure);
                    });
  Frame out;
  const bool have_previous = previous_.size() == n && width_ == g.width && height_ == g.height;
  if (have_previous) {
    // The history test's thresholds are guiding's defaults (the denoiser's are the same).
    const GuidingSettings tests;
    struct Sum {
      double squared = 0.0;
      std::size_t pixels = 0;
    };
    const Sum sum = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, n, 4096), Sum{},
        [&](const tbb::blocked_range<std::size_t>& r, Sum s) {
          for (std::size_t i = r.begin(); i != r.end(); ++i) {
            if (!g.has_surface(i)) continue;
            const int x = static_cast<int>(i % static_cast<std::size_t>(g.width));
            const int y = static_cast<int>(i / static_cast<std::size_t>(g.width));
            const int px =
                static_cast<int>(std::floor(static_cast<float>(x) + g.motion[i].x + 0.5f));
            const int py =
                static_cast<int>(std::floor(static_cast<float>(y) + g.motion[i].y + 0.5f));
            if (px < 0 || py < 0 || px >= width_ || py >= height_) continue;
            const std::size_t j = static_cast<std::size_t>(py) * width_ + px;
            if ((previous_flags_[j] & PG_GBUF_SKY) != 0 ||
                !shared::pg_same_surface(g.position_depth[i], glm::vec3(g.shading_normal[i]),
                                         g.material[i], previous_position_depth_[j],
                                         glm::vec3(previous_normal_[j]), previous_material_[j],
                                         tests.reproject_position, tests.reproject_normal))
              continue;
            const glm::vec3 d = shown[i] - previous_[j];
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
    out.tracked_fraction = static_cast<double>(sum.pixels) / static_cast<double>(n);
    if (sum.pixels > 0) out.mse = sum.squared / (3.0 * static_cast<double>(sum.pixels));
  }
  width_ = g.width;
  height_ = g.height;
  previous_ = std::move(shown);
  previous_position_depth_ = g.position_depth;
  previous_normal_ = g.shading_normal;
  previous_material_ = g.material;
  previous_flags_ = g.flags;
  return out;
}

}  // namespace rtpg
