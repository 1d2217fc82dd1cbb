// Texel access and bilinear filtering of decoded textures.
#include "scene/texture.h"

#include <algorithm>
#include <cmath>

namespace rtpg {

namespace {

// Texel index modulo n, also for negative x (repeat wrapping). A bilinear lookup's taps lie at
// most one texel outside the image, where a comparison gives the same index as the division,
// which cost four integer divisions a lookup (docs/host-path-tracer.md, "Surfaces loaded ahead").
int wrap(int x, int n) {
  if (x >= 0 && x < n) return x;
  if (x < 0 && x >= -n) return x + n;
  if (x >= n && x - n < n) return x - n;
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

namespace {

// The four texels around uv and their bilinear weights (v = 0 is the bottom of the image but
// texel row 0 is its top: v is flipped; texel centres sit at half-integer positions).
struct Bilinear {
  int x0, x1, y0, y1;
  float tx, ty;
};

Bilinear bilinear_at(glm::vec2 uv, int width, int height) {
  const float x = wrap_unit(uv.x) * static_cast<float>(width) - 0.5f;
  const float y = (1.0f - wrap_unit(uv.y)) * static_cast<float>(height) - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  return {wrap(static_cast<int>(fx), width),
          wrap(static_cast<int>(fx) + 1, width),
          wrap(static_cast<int>(fy), height),
          wrap(static_cast<int>(fy) + 1, height),
          x - fx,
          y - fy};
}

// bilinear_at for a latitude-longitude map: u repeats, v is clamped to [0, 1] (a non-finite v
// to 0) and the taps beyond the first and last rows' centres take those rows.
Bilinear bilinear_lat_long_at(glm::vec2 uv, int width, int height) {
  Bilinear b = bilinear_at({uv.x, 0.5f}, width, height);
  const float v = std::isfinite(uv.y) ? std::clamp(uv.y, 0.0f, 1.0f) : 0.0f;
  const float y = (1.0f - v) * static_cast<float>(height) - 0.5f;
  const float fy = std::floor(y);
  b.y0 = std::clamp(static_cast<int>(fy), 0, height - 1);
  b.y1 = std::clamp(static_cast<int>(fy) + 1, 0, height - 1);
  b.ty = y - fy;
  return b;
}

// The bilinear sample of t's four texels named by b (t not empty).
glm::vec4 sample_taps(const Texture& t, const Bilinear& b) {
  const std::size_t w = static_cast<std::size_t>(t.width);
  if (t.texels8.size() == w * static_cast<std::size_t>(t.height)) {
    // What fetch() does for the four taps, which the Bilinear has put inside the image: no
    // clamps or size tests per texel, the decode tables chosen once (Sponza's textures took a
    // fifth of a path-traced frame; docs/host-path-tracer.md).
    const std::array<float, 256>& rgb = t.srgb ? srgb_decode_table() : unorm_decode_table();
    const std::array<float, 256>& unorm = unorm_decode_table();
    const auto texel = [&](int x, int y) {
      const std::array<std::uint8_t, 4>& c =
          t.texels8[static_cast<std::size_t>(y) * w + static_cast<std::size_t>(x)];
      return glm::vec4(rgb[c[0]], rgb[c[1]], rgb[c[2]], unorm[c[3]]);
    };
    const glm::vec4 top = glm::mix(texel(b.x0, b.y0), texel(b.x1, b.y0), b.tx);
    const glm::vec4 bottom = glm::mix(texel(b.x0, b.y1), texel(b.x1, b.y1), b.tx);
    return glm::mix(top, bottom, b.ty);
  }
  const glm::vec4 top = glm::mix(t.fetch(b.x0, b.y0), t.fetch(b.x1, b.y0), b.tx);
  const glm::vec4 bottom = glm::mix(t.fetch(b.x0, b.y1), t.fetch(b.x1, b.y1), b.tx);
  return glm::mix(top, bottom, b.ty);
}

}  // namespace

glm::vec4 Texture::sample(glm::vec2 uv) const {
  if (width <= 0 || height <= 0 || (texels.empty() && texels8.empty())) return glm::vec4(1.0f);
  return sample_taps(*this, bilinear_at(uv, width, height));
}

glm::vec4 Texture::sample_lat_long(glm::vec2 uv) const {
  if (width <= 0 || height <= 0 || (texels.empty() && texels8.empty())) return glm::vec4(1.0f);
  return sample_taps(*this, bilinear_lat_long_at(uv, width, height));
}

void Texture::prefetch(glm::vec2 uv) const {
  if (width <= 0 || height <= 0) return;
  const Bilinear b = bilinear_at(uv, width, height);
  const std::size_t w = static_cast<std::size_t>(width), n = w * static_cast<std::size_t>(height);
  const std::size_t taps[4] = {static_cast<std::size_t>(b.y0) * w + static_cast<std::size_t>(b.x0),
                               static_cast<std::size_t>(b.y0) * w + static_cast<std::size_t>(b.x1),
                               static_cast<std::size_t>(b.y1) * w + static_cast<std::size_t>(b.x0),
                               static_cast<std::size_t>(b.y1) * w + static_cast<std::size_t>(b.x1)};
  for (std::size_t t : taps) {
    if (texels8.size() == n) __builtin_prefetch(texels8.data() + t);
    if (texels.size() == n) __builtin_prefetch(texels.data() + t);
    if (slopes.size() == n) __builtin_prefetch(slopes.data() + t);
  }
}

glm::vec2 Texture::sample_gradient(glm::vec2 uv) const {
  const float w = static_cast<float>(std::max(width, 1)),
              h = static_cast<float>(std::max(height, 1));
  if (slopes.empty() || width <= 0 || height <= 0) {
    const float du = 1.0f / w, dv = 1.0f / h;
    const float h0 = sample(uv).x;
    return {(sample(uv + glm::vec2(du, 0.0f)).x - h0) / du,
            (sample(uv + glm::vec2(0.0f, dv)).x - h0) / dv};
  }
  // The bilinear sample one texel further is the same weights on the shifted texels: its
  // difference is the bilinear sample of the per-texel differences.
  const Bilinear b = bilinear_at(uv, width, height);
  const auto at = [&](int x, int y) {
    return slopes[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                  static_cast<std::size_t>(x)];
  };
  const glm::vec2 top = glm::mix(at(b.x0, b.y0), at(b.x1, b.y0), b.tx);
  const glm::vec2 bottom = glm::mix(at(b.x0, b.y1), at(b.x1, b.y1), b.tx);
  return glm::mix(top, bottom, b.ty) * glm::vec2(w, h);
}

void prepare_bump_slopes(Texture& t) {
  if (t.width <= 0 || t.height <= 0 || !t.slopes.empty()) return;
  t.slopes.resize(static_cast<std::size_t>(t.width) * static_cast<std::size_t>(t.height));
  for (int y = 0; y < t.height; ++y)
    for (int x = 0; x < t.width; ++x) {
      const float here = t.fetch(x, y).x;
      // +u is the next column; +v the row above (row 0 is the top), both with repeat.
      t.slopes[static_cast<std::size_t>(y) * static_cast<std::size_t>(t.width) +
               static_cast<std::size_t>(x)] = glm::vec2(t.fetch(wrap(x + 1, t.width), y).x - here,
                                                        t.fetch(x, wrap(y - 1, t.height)).x - here);
    }
}

}  // namespace rtpg
