// What the tests that render one scene two ways (settings that must not change the result: the
// bounce rays' order, the surfaces loaded ahead, the training's place in the frame) assert of
// each frame: the two images equal to the bit, and the image lit, so that two black frames do
// not pass for equal ones.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rtpg {

// Whether a and b hold the same bits (a NaN equals its own bits, -0 differs from +0).
template <class T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// a and b the same to the bit, and more than half of a's pixels lit; `where` names the frame in
// the failure messages.
inline void expect_same_lit_image(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b,
                                  const std::string& where) {
  ASSERT_EQ(a.size(), b.size()) << where;
  std::size_t differ = 0, lit = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    differ += !same_bits(a[i], b[i]);
    lit += a[i] != glm::vec3(0.0f);
  }
  EXPECT_EQ(differ, 0u) << where;
  EXPECT_GT(lit, a.size() / 2) << where;
}

}  // namespace rtpg
