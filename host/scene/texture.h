// A decoded image, sampled bilinearly with repeat wrapping. 8-bit sources stay 8-bit in memory
// (4 bytes a texel instead of 16: Sponza's textures are fetched from memory, not cache, and the
// fetches were a sixth of a frame) and are decoded on fetch by table, to exactly the floats a
// decode at load time gave.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "util/huge_pages.h"

namespace rtpg {

// The sRGB transfer function's inverse: an encoded value in [0, 1] to linear.
float srgb_to_linear(float c);

// Decode tables of 8-bit channels: value i to linear (sRGB transfer function) and to i / 255.
const std::array<float, 256>& srgb_decode_table();
const std::array<float, 256>& unorm_decode_table();

struct Texture {
  std::string path;  // where it was read from (for messages and `rtpg info`)
  int width = 0, height = 0;
  // The texels, row 0 = top of the image, in one of two forms:
  LargeVector<glm::vec4> texels;  // linear floats (float images, textures built in code), or
  LargeVector<std::array<std::uint8_t, 4>> texels8;  // 8-bit RGBA as stored, decoded on fetch:
  bool srgb = false;  // texels8's RGB through the sRGB table (else / 255); alpha always / 255
  // Bump maps only (prepare_bump_slopes): per texel, the difference of channel 0 to the next
  // texel along +u and along +v (the row above), so that a bump's gradient is one bilinear
  // lookup of 4 texels instead of three lookups of 12.
  LargeVector<glm::vec2> slopes;
  glm::vec4 fetch(int x, int y) const;
  // uv in texture space with (0,0) = bottom-left (OBJ/glTF convention after loading), repeat.
  glm::vec4 sample(glm::vec2 uv) const;
  // The same, repeating in u only and clamping v to the first and last rows: a latitude-longitude
  // map, whose top and bottom rows are the two poles and must not blend with each other
  // (docs/robustness.md, "The environment map's poles").
  glm::vec4 sample_lat_long(glm::vec2 uv) const;
  // d(channel 0)/du and d/dv at uv per unit of uv, as one-texel forward differences of the
  // bilinear sample: from `slopes` when prepared, else from three samples.
  glm::vec2 sample_gradient(glm::vec2 uv) const;
  // Starts loading the cache lines of the texels (and slopes) that sample and sample_gradient
  // read at uv; changes nothing.
  void prefetch(glm::vec2 uv) const;
};

// Fills t.slopes (8 bytes a texel) for a texture used as a bump map.
void prepare_bump_slopes(Texture& t);

}  // namespace rtpg
