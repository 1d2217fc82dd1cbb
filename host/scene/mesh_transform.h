// Moves a mesh by an affine transform, keeping its normals, tangents and winding consistent.
#pragma once

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace rtpg {

// Positions by `m`, normals by its inverse transpose, tangents by `m` (handedness
// recomputed). A mirroring transform (negative determinant) also reverses the triangle
// winding, so the geometric normal cross(p1 - p0, p2 - p0) keeps agreeing with the shading
// normals. `m` must be invertible (the scene loader checks).
void transform_mesh(Mesh& mesh, const glm::mat4& m);

}  // namespace rtpg
