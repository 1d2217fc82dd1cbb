// Checks of imported meshes and materials, whatever format they came from: the values the
// renderer will use are finite and in range (docs/robustness.md, "Input validation"), and
// triangles of zero area are dropped, since no normal and no light pdf exists for them.
#pragma once

#include <cstddef>
#include <string>

#include "scene/scene.h"

namespace rtpg {

// Every component finite (no NaN, no infinity).
bool all_finite(const glm::vec3& v);

// Drops the triangles whose edge cross product is zero or not finite (repeated or collinear
// vertices); returns how many it dropped.
std::size_t drop_degenerate_triangles(Mesh& mesh);

// Throws InputError(file, "mesh '<name>': ... (context)") unless every position and uv of
// the mesh is finite and every triangle index names a vertex.
void check_mesh_values(const Mesh& mesh, const std::string& file, const std::string& context);

// Throws InputError(file, "material '<name>': ... (context)") unless the material's values
// lie in the ranges the JSON materials accept (scenes/README.md, "Materials"): base colour
// and the factors in [0, 1], emission finite and not negative, bump scale finite.
void check_material_values(const Material& material, const std::string& file,
                           const std::string& context);

}  // namespace rtpg
