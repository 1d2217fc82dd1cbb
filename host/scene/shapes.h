// Analytic shapes a scene file can place without a mesh file: quads, boxes, spheres.
// All are built in world space before the shape's transform; Mesh::material is left 0.
#pragma once

#include "scene/scene.h"

namespace rtpg {

// Two triangles corner, corner + edge1, corner + edge1 + edge2, corner + edge2; normal =
// normalize(cross(edge1, edge2)); uv (0,0) at corner, u along edge1, v along edge2.
Mesh make_quad(const glm::vec3& corner, const glm::vec3& edge1, const glm::vec3& edge2);

// Axis-aligned box, 12 triangles, flat outward normals, uvs per face.
Mesh make_box(const glm::vec3& min, const glm::vec3& max);

// Icosphere: the icosahedron subdivided `subdivisions` times (20 * 4^s triangles), smooth
// normals, no uvs. `inward` flips the winding and the normals (a sky dome, a room).
Mesh make_sphere(const glm::vec3& center, float radius, int subdivisions, bool inward);

}  // namespace rtpg
