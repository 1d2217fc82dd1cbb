// Reading and writing frames. Every write goes to a temporary file in the target's folder and
// is renamed into place, so a failure never leaves a half-written or clobbered output.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rtpg {

struct ImageRgb {
  int width = 0, height = 0;
  std::vector<glm::vec3> pixels;  // row 0 = top
};

// Linear HDR radiance as 32-bit float EXR; metadata become string attributes "rtpg:<key>".
void write_exr(const std::string& path, const ImageRgb& image,
               const std::map<std::string, std::string>& metadata);
// 8-bit RGBA (row 0 = top) as PNG.
void write_png(const std::string& path, int width, int height,
               const std::vector<std::uint8_t>& rgba8);
// Reads any image OpenImageIO can (EXR for references); throws InputError(path, problem): no
// such file, not an image, a volume, a size other than expected_width x expected_height (where
// those are positive; checked before the pixels are allocated, so a header that claims a huge
// image is refused, not allocated), a size rtpg refuses (rtpg/image_size.h), or a pixel that is
// not finite (a NaN reference would make every relMSE NaN).
ImageRgb read_image(const std::string& path, int expected_width = 0, int expected_height = 0);

// relMSE = mean over pixels and channels of (I - R)^2 / (R^2 + 0.01) (docs/design.md, "Metrics").
double relative_mse(const ImageRgb& image, const ImageRgb& reference);

}  // namespace rtpg
