// Imports triangle meshes with assimp: OBJ/MTL, PLY, glTF 2.0 (and whatever else assimp reads).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "scene/texture_cache.h"

namespace rtpg {

struct MeshFile {
  // In the file's own coordinates, node transforms applied; Mesh::material indexes `materials`.
  std::vector<Mesh> meshes;
  // The file's materials that some mesh uses (unused ones are dropped so their textures are
  // never read). Empty when the caller asked for no materials.
  std::vector<Material> materials;
  // Triangles of zero area the loader dropped (mesh_check.h); a mesh left without triangles
  // is dropped with them.
  std::size_t degenerate_triangles = 0;
};

// Reads `path`. With `textures` null the file's materials are ignored (the caller assigns its
// own) and every Mesh::material is 0. Throws InputError(path, problem (context)) when the file
// is missing, unreadable, corrupt, holds a value out of range (obj_check.h, mesh_check.h) or
// no triangle of non-zero area, and InputError(texture, ...) for a texture a used material
// names that is missing or corrupt.
MeshFile load_mesh_file(const std::string& path, TextureCache* textures,
                        const std::string& context);

}  // namespace rtpg
