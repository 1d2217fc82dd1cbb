// Image decoding with OpenImageIO: channel expansion, sRGB decoding, errors as InputError.
#include "scene/image_loader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "rtpg/errors.h"
#include "rtpg/image_size.h"

namespace rtpg {

namespace {

// The largest texture or environment map rtpg reads: a 16384x16384 image (a 16K
// equirectangular map is 16384x8192), 4 GiB of float texels at four channels; a side of up to
// 65536 pixels.
constexpr int kMaxTextureSide = 65536;
constexpr std::uint64_t kMaxTextureTexels = 16384ull * 16384ull;

// The OIIO message, or a fallback when it set none.
std::string reason(std::string message, const char* fallback) {
  while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
  return message.empty() ? fallback : message;
}

Texture read_opened(OIIO::ImageInput& in, const std::string& name, ImageDecode decode) {
  const OIIO::ImageSpec spec = in.spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
    throw InputError(name, "image has no pixels");
  if (spec.depth > 1) throw InputError(name, "volume images are not supported");
  // Checked on the header, before the pixels are allocated: a header may claim any size.
  const std::string size_problem =
      image_size_problem(spec.width, spec.height, kMaxTextureSide, kMaxTextureTexels);
  if (!size_problem.empty()) throw InputError(name, "image size " + size_problem);

  const int nch = std::min(spec.nchannels, 4);
  const bool eight_bit = spec.format == OIIO::TypeDesc::UINT8;
  const std::size_t count = static_cast<std::size_t>(spec.width) *
                            static_cast<std::size_t>(spec.height) * static_cast<std::size_t>(nch);
  // One of the two holds the texels: an 8-bit image never touches the floats (4 bytes a
  // channel, 4 GiB for a 16384^2 RGBA PNG the size limits accept).
  std::vector<float> values(eight_bit ? 0 : count);
  std::vector<unsigned char> bytes;
  bool ok;
  if (eight_bit) {
    bytes.resize(count);
    ok = in.read_image(0, 0, 0, nch, OIIO::TypeDesc::UINT8, bytes.data());
  } else {
    ok = in.read_image(0, 0, 0, nch, OIIO::TypeDesc::FLOAT, values.data());
  }
  if (!ok) throw InputError(name, reason(in.geterror(), "could not read the pixels"));
  // Float images (EXR, HDR) can hold NaN and infinities; OIIO passes them on and one such texel
  // would make every path that sees it NaN. Negative values are clamped to 0: filtering leaves
  // tiny ones in real maps (hotel_room_1k_blender_interior.exr holds -2e-6).
  if (!eight_bit)
    for (std::size_t i = 0; i < count; ++i) {
      if (!std::isfinite(values[i])) {
        const std::size_t pixel = i / static_cast<std::size_t>(nch);
        throw InputError(name, "pixel (" + std::to_string(pixel % spec.width) + ", " +
                                   std::to_string(pixel / spec.width) + ") channel " +
                                   std::to_string(i % nch) + " is not finite");
      }
      values[i] = std::max(values[i], 0.0f);
      // A material's map above 1 (a float texture in [0, 1] with some rounding, up to 1 + 2^-10,
      // is read as 1).
      if (decode.unit_range && values[i] > 1.0f) {
        if (values[i] > 1.0f + 0x1p-10f) {
          const std::size_t pixel = i / static_cast<std::size_t>(nch);
          throw InputError(name, "pixel (" + std::to_string(pixel % spec.width) + ", " +
                                     std::to_string(pixel / spec.width) + ") channel " +
                                     std::to_string(i % nch) + " is " + std::to_string(values[i]) +
                                     ", above 1 (a material's texture holds values in [0, 1])");
        }
        values[i] = 1.0f;
      }
    }

  // Which input channel holds alpha: OIIO knows for most formats; a 2- or 4-channel image
  // without that metadata is grey+alpha or RGBA by convention.
  int alpha = spec.alpha_channel;
  if (alpha >= nch || (alpha < 0 && (nch == 2 || nch == 4))) alpha = nch - 1;
  const int colour_channels = alpha >= 0 ? alpha : nch;
  // A mask whose alpha channel is opaque everywhere holds its mask in the first channel, as a
  // mask without alpha does: Crytek Sponza's leaf, chain and plant masks are grey + alpha PNGs
  // with alpha 255 in every texel, and read by their alpha they cut nothing (docs/robustness.md,
  // "Masks with an opaque alpha channel").
  if (decode.mask && alpha >= 0) {
    bool opaque = true;
    const std::size_t stride = static_cast<std::size_t>(nch);
    for (std::size_t i = static_cast<std::size_t>(alpha); opaque && i < count; i += stride)
      opaque = eight_bit ? bytes[i] == 255 : values[i] >= 1.0f;
    if (opaque) alpha = -1;
  }
  const bool linearise = decode.srgb && !spec.format.is_floating_point();

  Texture texture;
  texture.path = name;
  texture.width = spec.width;
  texture.height = spec.height;
  const std::size_t pixels = static_cast<std::size_t>(spec.width) * spec.height;
  if (eight_bit) {
    // Kept as stored (texture.h); RGB decoded by table on fetch, alpha as / 255.
    texture.srgb = linearise;
    texture.texels8.resize(pixels);
    for (std::size_t p = 0; p < pixels; ++p) {
      const std::size_t base = p * static_cast<std::size_t>(nch);
      std::array<std::uint8_t, 4> t;
      if (colour_channels >= 3) {
        t = {bytes[base], bytes[base + 1], bytes[base + 2], 255};
      } else {  // grey (or grey + alpha), expanded to RGB
        t = {bytes[base], bytes[base], bytes[base], 255};
      }
      if (alpha >= 0)
        t[3] = bytes[base + static_cast<std::size_t>(alpha)];
      else if (decode.mask)
        t[3] = bytes[base];
      texture.texels8[p] = t;
    }
    return texture;
  }
  auto colour = [&](std::size_t i) { return linearise ? srgb_to_linear(values[i]) : values[i]; };
  texture.texels.resize(pixels);
  for (std::size_t p = 0; p < pixels; ++p) {
    const std::size_t base = p * static_cast<std::size_t>(nch);
    glm::vec4 t;
    if (colour_channels >= 3) {
      t = glm::vec4(colour(base), colour(base + 1), colour(base + 2), 1.0f);
    } else {  // grey (or grey + alpha), expanded to RGB
      const float g = colour(base);
      t = glm::vec4(g, g, g, 1.0f);
    }
    if (alpha >= 0)
      t.w = values[base + static_cast<std::size_t>(alpha)];
    else if (decode.mask)
      t.w = values[base];
    texture.texels[p] = t;
  }
  return texture;
}

// Colour channels as stored, not multiplied by alpha: OIIO premultiplies PNG/TGA by default,
// which would darken the colour around alpha-masked leaves.
OIIO::ImageSpec read_config() {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  return config;
}

}  // namespace

Texture load_image(const std::string& path, ImageDecode decode) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path, "file not found");
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, "is a directory");
  // A FIFO or a device would block the read or never end.
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "not a file");
  const OIIO::ImageSpec config = read_config();
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path, &config);
  if (!in) throw InputError(path, reason(OIIO::geterror(), "not a readable image"));
  return read_opened(*in, path, decode);
}

Texture load_image_from_memory(const std::string& name, const void* data, std::size_t size,
                               ImageDecode decode) {
  OIIO::Filesystem::IOMemReader proxy(data, size);
  // With a config, OIIO 2.4 takes the proxy from the config's "oiio:ioproxy" attribute and
  // ignores the open() argument (it then looks for a file named `name`): give it both.
  OIIO::ImageSpec config = read_config();
  OIIO::Filesystem::IOProxy* proxy_pointer = &proxy;
  config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy_pointer);
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(name, &config, &proxy);
  if (!in) throw InputError(name, reason(OIIO::geterror(), "not a readable image"));
  return read_opened(*in, name, decode);
}

}  // namespace rtpg
