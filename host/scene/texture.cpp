// Texel access and bilinear filtering of decoded textures.
#include "scene/texture.h"

#include <algorithm>
#include <cmath>

namespace rtpg {

namespace {

// Texel index modulo n, also for negative x (repeat wrapping).
int wrap(int x, int n) {
  const int r = x % n;
  return r < 0 ? r + n : r;
}

// Wraps a texture coordinate into [0, 1) before it is scaled to texels, so that huge or
// non-finite coordinates can never overflow the int conversion.
float wrap_unit(float t) {
  if (!std::isfinite(t)) return 0.0f;
  const float f = t - std::floor(t);
  return f < 1.0f ? f : 0.0f;
}

}  // namespace

float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

const std::array<float, 256>& srgb_decode_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[i] = srgb_to_linear(static_cast<float>(i) / 255.0f);
    return t;
  }();
  return table;
}

const std::array<float, 256>& unorm_decode_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[i] = static_cast<float>(i) / 255.0f;
    return t;
  }();
  return table;
}

glm::vec4 Texture::fetch(int x, int y) const {
  // An empty texture is neutral for the multiplicative uses (colour, roughness, alpha).
  if (width <= 0 || height <= 0) return glm::vec4(1.0f);
  x = std::clamp(x, 0, width - 1);
  y = std::clamp(y, 0, height - 1);
  const std::size_t i =
      static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
  if (i < texels8.size()) {
    const std::array<std::uint8_t, 4>& b = texels8[i];
    const std::array<float, 256>& rgb = srgb ? srgb_decode_table() : unorm_decode_table();
    const std::array<float, 256>& unorm = unorm_decode_table();
    return glm::vec4(rgb[b[0]], rgb[b[1]], rgb[b[2]], unorm[b[3]]);
  }
  if (i < texels.size()) return texels[i];
  return glm::vec4(1.0f);
}

glm::vec4 Texture::sample(glm::vec2 uv) const {
  if (width <= 0 || height <= 0 || (texels.empty() && texels8.empty())) return glm::vec4(1.0f);
  // v = 0 is the bottom of the image but texel row 0 is its top: flip v. Texel centres sit
  // at half-integer positions.
  const float x = wrap_unit(uv.x) * static_cast<float>(width) - 0.5f;
  const float y = (1.0f - wrap_unit(uv.y)) * static_cast<float>(height) - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float tx = x - fx, ty = y - fy;
  const int x0 = wrap(static_cast<int>(fx), width), x1 = wrap(static_cast<int>(fx) + 1, width);
  const int y0 = wrap(static_cast<int>(fy), height), y1 = wrap(static_cast<int>(fy) + 1, height);
  const glm::vec4 top = glm::mix(fetch(x0, y0), fetch(x1, y0), tx);
  const glm::vec4 bottom = glm::mix(fetch(x0, y1), fetch(x1, y1), tx);
  return glm::mix(top, bottom, ty);
}

}  // namespace rtpg
