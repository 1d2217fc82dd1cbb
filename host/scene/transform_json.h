// Reads the "transform" of a mesh or shape entry (format: scenes/README.md).
#pragma once

#include <glm/glm.hpp>

#include "scene/json_reader.h"

namespace rtpg {

// {"matrix": [16 numbers, row-major]} or any of {"translate", "rotate", "scale"}, applied as
// scale, then the rotations in list order, then translate. Fails on a singular or
// non-affine matrix.
glm::mat4 read_transform(const JsonNode& node);

}  // namespace rtpg
