// Transform parsing and validation.
#include "scene/transform_json.h"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace rtpg {

namespace {

glm::mat4 read_matrix(const JsonNode& node) {
  if (!node.is_array() || node.size() != 16) node.fail_type("an array of 16 numbers (row-major)");
  glm::mat4 m(1.0f);
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col)
      m[col][row] = node[static_cast<std::size_t>(row * 4 + col)].number();  // glm: column-major
  if (m[0][3] != 0.0f || m[1][3] != 0.0f || m[2][3] != 0.0f || m[3][3] != 1.0f)
    node.fail("the last row must be 0 0 0 1 (an affine transform)");
  return m;
}

glm::mat4 read_rotation(const JsonNode& node) {
  node.check_object({"axis", "angle_deg"});
  const glm::vec3 axis = node.child("axis").vec3();
  if (!(glm::dot(axis, axis) > 0.0f)) node.child("axis").fail("the axis must not be zero");
  const float angle = node.child("angle_deg").number();
  return glm::rotate(glm::mat4(1.0f), glm::radians(angle), glm::normalize(axis));
}

glm::vec3 read_scale(const JsonNode& node) {
  if (node.is_number()) return glm::vec3(node.number());
  if (node.is_array() && node.size() == 3) return node.vec3();
  node.fail_type("a number or an array of 3 numbers");
}

}  // namespace

glm::mat4 read_transform(const JsonNode& node) {
  node.check_object({"matrix", "translate", "rotate", "scale"});
  glm::mat4 m(1.0f);
  if (node.has("matrix")) {
    if (node.has("translate") || node.has("rotate") || node.has("scale"))
      node.fail("\"matrix\" cannot be combined with translate, rotate or scale");
    m = read_matrix(node.child("matrix"));
  } else {
    if (node.has("scale")) {
      const JsonNode scale_node = node.child("scale");
      const glm::vec3 s = read_scale(scale_node);
      if (s.x == 0.0f || s.y == 0.0f || s.z == 0.0f) scale_node.fail("scale must not be zero");
      m = glm::scale(glm::mat4(1.0f), s);
    }
    if (node.has("rotate")) {
      const JsonNode rotate = node.child("rotate");
      if (rotate.is_array()) {
        for (std::size_t i = 0; i < rotate.size(); ++i) m = read_rotation(rotate[i]) * m;
      } else if (rotate.is_object()) {
        m = read_rotation(rotate) * m;
      } else {
        rotate.fail_type("{\"axis\": [x,y,z], \"angle_deg\": a} or an array of such");
      }
    }
    if (node.has("translate"))
      m = glm::translate(glm::mat4(1.0f), node.child("translate").vec3()) * m;
  }
  const float det = glm::determinant(glm::mat3(m));
  if (!std::isfinite(det) || !(std::abs(det) > 0.0f)) node.fail("the transform is singular");
  return m;
}

}  // namespace rtpg
