// A decoded image in linear float RGBA, sampled bilinearly with repeat wrapping.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rtpg {

struct Texture {
  std::string path;  // where it was read from (for messages and `rtpg info`)
  int width = 0, height = 0;
  std::vector<glm::vec4> texels;  // row 0 = top of the image; linear values
  glm::vec4 fetch(int x, int y) const;
  // uv in texture space with (0,0) = bottom-left (OBJ/glTF convention after loading), repeat.
  glm::vec4 sample(glm::vec2 uv) const;
};

}  // namespace rtpg
