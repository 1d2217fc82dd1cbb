#include "render/image_io.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include "rtpg/errors.h"
#include "rtpg/image_size.h"
#include "util/atomic_file.h"

namespace rtpg {
namespace fs = std::filesystem;
namespace {

void write_atomically(const std::string& path, int width, int height, int channels,
                      OIIO::TypeDesc type, const void* data,
                      const std::map<std::string, std::string>& metadata) {
  const std::string tmp = temporary_path_for(path);
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw InputError(path, "cannot write this image format: " + OIIO::geterror());
  OIIO::ImageSpec spec(width, height, channels, type);
  for (const auto& [key, value] : metadata) spec.attribute("rtpg:" + key, value);
  if (!out->open(tmp, spec)) {
    const std::string err = out->geterror();
    std::remove(tmp.c_str());
    throw InputError(path, "cannot open for writing: " + err);
  }
  const bool ok = out->write_image(type, data) && out->close();
  if (!ok) {
    const std::string err = out->geterror();
    std::remove(tmp.c_str());
    throw InputError(path, "write failed: " + err);
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw InputError(path, "cannot move the finished file into place: " + ec.message());
  }
}

}  // namespace

void write_exr(const std::string& path, const ImageRgb& image,
               const std::map<std::string, std::string>& metadata) {
  write_atomically(path, image.width, image.height, 3, OIIO::TypeDesc::FLOAT, image.pixels.data(),
                   metadata);
}

void write_png(const std::string& path, int width, int height,
               const std::vector<std::uint8_t>& rgba8) {
  write_atomically(path, width, height, 4, OIIO::TypeDesc::UINT8, rgba8.data(), {});
}

ImageRgb read_image(const std::string& path, int expected_width, int expected_height) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path, "no such file");
  // A FIFO or a device would block the read or never end.
  if (!fs::is_regular_file(path, ec)) throw InputError(path, "not a file");
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw InputError(path, "cannot read image: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.depth > 1) throw InputError(path, "volume images are not supported");
  if (spec.nchannels <= 0) throw InputError(path, "image has no channels");
  // Radiance is linear and unbounded: an 8-bit image (a tonemapped PNG) is no reference, and its
  // relMSE against radiance would mean nothing.
  if (!spec.format.is_floating_point())
    throw InputError(path, "not a radiance image (stored as " + std::string(spec.format.c_str()) +
                               "; a reference is a float EXR, as rtpg reference writes)");
  // The header may claim any number of channels; only the first three are read, and a reference
  // has at most four (RGBA).
  if (spec.nchannels > 4)
    throw InputError(path, fmt::format("{} channels (a reference has 3 or 4)", spec.nchannels));
  if (expected_width > 0 && expected_height > 0 &&
      (spec.width != expected_width || spec.height != expected_height))
    throw InputError(path, fmt::format("image is {}x{}, expected {}x{}", spec.width, spec.height,
                                       expected_width, expected_height));
  const std::string size_problem = image_size_problem(spec.width, spec.height);
  if (!size_problem.empty()) throw InputError(path, "image size " + size_problem);
  ImageRgb image;
  image.width = spec.width;
  image.height = spec.height;
  std::vector<float> data(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, data.data()))
    throw InputError(path, "cannot decode image: " + in->geterror());
  image.pixels.resize(static_cast<std::size_t>(spec.width) * spec.height);
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    const float* px = &data[i * spec.nchannels];
    image.pixels[i] = spec.nchannels >= 3 ? glm::vec3(px[0], px[1], px[2]) : glm::vec3(px[0]);
    const glm::vec3& v = image.pixels[i];
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
      throw InputError(path, fmt::format("pixel ({}, {}) is not finite", i % spec.width,
                                         i / static_cast<std::size_t>(spec.width)));
  }
  return image;
}

double relative_mse(const ImageRgb& image, const ImageRgb& reference) {
  double sum = 0.0;
  for (std::size_t i = 0; i < image.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double d = image.pixels[i][c] - reference.pixels[i][c];
      const double r = reference.pixels[i][c];
      sum += d * d / (r * r + 0.01);
    }
  return image.pixels.empty() ? 0.0 : sum / (3.0 * static_cast<double>(image.pixels.size()));
}

}  // namespace rtpg
