// assimp import: flattening, triangles only, sanitised normals and tangents.
#include "scene/mesh_loader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "scene/assimp_material.h"
#include "scene/mesh_check.h"
#include "scene/obj_check.h"
#include "scene/ply_check.h"
#include "rtpg/errors.h"

namespace rtpg {

namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// Normals from files can be unnormalised, zero or NaN (assimp writes NaN/zero for degenerate
// faces); shading would turn those into NaN radiance. Unusable ones take the geometric
// normal of a triangle that uses the vertex.
void sanitise_normals(Mesh& mesh) {
  if (mesh.normals.empty()) return;
  std::vector<bool> bad(mesh.normals.size(), false);
  bool any_bad = false;
  for (std::size_t i = 0; i < mesh.normals.size(); ++i) {
    glm::vec3& n = mesh.normals[i];
    const float len2 = glm::dot(n, n);
    if (!all_finite(n) || !(len2 > 1e-20f)) {
      bad[i] = any_bad = true;
    } else {
      n /= std::sqrt(len2);
    }
  }
  if (!any_bad) return;
  for (const glm::uvec3& t : mesh.triangles) {
    const glm::vec3 g = glm::cross(mesh.positions[t.y] - mesh.positions[t.x],
                                   mesh.positions[t.z] - mesh.positions[t.x]);
    const float len2 = glm::dot(g, g);
    if (!all_finite(g) || !(len2 > 0.0f)) continue;
    for (int k = 0; k < 3; ++k)
      if (bad[t[k]]) {
        mesh.normals[t[k]] = g / std::sqrt(len2);
        bad[t[k]] = false;
      }
  }
  for (std::size_t i = 0; i < bad.size(); ++i)
    if (bad[i]) mesh.normals[i] = glm::vec3(0.0f, 0.0f, 1.0f);  // only on degenerate triangles
}

// Any unit vector perpendicular to n (for tangents assimp could not derive).
glm::vec3 perpendicular(const glm::vec3& n) {
  const glm::vec3 a = std::abs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  return glm::normalize(glm::cross(a, n));
}

Mesh convert_mesh(const aiMesh& in, const std::string& fallback_name, const std::string& path,
                  const std::string& context, std::size_t& degenerate) {
  Mesh mesh;
  mesh.name = in.mName.length > 0 ? in.mName.C_Str() : fallback_name;
  mesh.positions.reserve(in.mNumVertices);
  for (unsigned i = 0; i < in.mNumVertices; ++i)
    mesh.positions.emplace_back(in.mVertices[i].x, in.mVertices[i].y, in.mVertices[i].z);
  if (in.HasNormals()) {
    mesh.normals.reserve(in.mNumVertices);
    for (unsigned i = 0; i < in.mNumVertices; ++i)
      mesh.normals.emplace_back(in.mNormals[i].x, in.mNormals[i].y, in.mNormals[i].z);
  }
  if (in.HasTextureCoords(0)) {
    mesh.uvs.reserve(in.mNumVertices);
    for (unsigned i = 0; i < in.mNumVertices; ++i)
      mesh.uvs.emplace_back(in.mTextureCoords[0][i].x, in.mTextureCoords[0][i].y);
  }
  for (unsigned f = 0; f < in.mNumFaces; ++f) {
    const aiFace& face = in.mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines left over after triangulation
    mesh.triangles.emplace_back(face.mIndices[0], face.mIndices[1], face.mIndices[2]);
  }
  check_mesh_values(mesh, path, context);
  degenerate += drop_degenerate_triangles(mesh);
  sanitise_normals(mesh);

  // Tangent frames for normal and bump mapping: xyz tangent, w = handedness of the
  // bitangent, as glTF stores them. Tangents assimp could not derive (no uvs on that face,
  // NaN) become any perpendicular of the normal.
  if (in.HasTangentsAndBitangents() && !mesh.normals.empty()) {
    mesh.tangents.reserve(in.mNumVertices);
    for (unsigned i = 0; i < in.mNumVertices; ++i) {
      const glm::vec3& n = mesh.normals[i];
      glm::vec3 t(in.mTangents[i].x, in.mTangents[i].y, in.mTangents[i].z);
      const glm::vec3 b(in.mBitangents[i].x, in.mBitangents[i].y, in.mBitangents[i].z);
      t -= n * glm::dot(n, t);  // Gram-Schmidt against the (sanitised) normal
      const float len2 = glm::dot(t, t);
      t = all_finite(t) && len2 > 1e-20f ? t / std::sqrt(len2) : perpendicular(n);
      const float w = all_finite(b) && glm::dot(glm::cross(n, t), b) < 0.0f ? -1.0f : 1.0f;
      mesh.tangents.emplace_back(t, w);
    }
  }
  return mesh;
}

}  // namespace

MeshFile load_mesh_file(const std::string& path, TextureCache* textures,
                        const std::string& context) {
  const std::string where = " (" + context + ")";
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path, "file not found" + where);
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "not a file" + where);
  const std::string ext = lower_extension(path);
  // Only the formats scenes/README.md names, by their extensions: for any other name assimp
  // picks a reader by the file's content, so an OBJ or PLY named .txt or .dat would skip the
  // checks below and reach readers that crash on malformed input (docs/robustness.md,
  // "Fuzzing"), and every other assimp reader would be reachable unchecked.
  if (ext != ".obj" && ext != ".ply" && ext != ".gltf" && ext != ".glb")
    throw InputError(path, "not a mesh format rtpg reads (.obj, .ply, .gltf or .glb)" + where);
  if (ext == ".obj") check_obj(path, context, textures != nullptr);
  if (ext == ".ply") check_ply(path, context);

  Assimp::Importer importer;
  // Drop point and line primitives entirely: only triangles are rendered.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  // File normals are kept; flat ones are generated only where a mesh has none. Pre-
  // transforming flattens the node hierarchy into world-space (file-space) meshes.
  const unsigned flags = aiProcess_Triangulate | aiProcess_GenNormals | aiProcess_CalcTangentSpace |
                         aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices |
                         aiProcess_SortByPType | aiProcess_ValidateDataStructure;
  const aiScene* scene = importer.ReadFile(path, flags);
  if (!scene) {
    std::string message = importer.GetErrorString();
    if (message.empty()) message = "assimp could not read the file";
    throw InputError(path, message + where);
  }
  if (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE)
    throw InputError(path, "incomplete scene (assimp)" + where);

  const MaterialConvention convention =
      ext == ".gltf" || ext == ".glb" ? MaterialConvention::Gltf : MaterialConvention::Mtl;
  const std::string stem = std::filesystem::path(path).stem().string();
  MeshFile out;
  std::map<unsigned, std::uint32_t> material_index;  // assimp index -> out.materials index
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& in = *scene->mMeshes[m];
    Mesh mesh =
        convert_mesh(in, stem + "#" + std::to_string(m), path, context, out.degenerate_triangles);
    if (mesh.triangles.empty()) continue;
    if (textures && in.mMaterialIndex < scene->mNumMaterials) {
      auto found = material_index.find(in.mMaterialIndex);
      if (found == material_index.end()) {
        if (ext == ".ply") {
          // PLY has no materials; assimp invents a white (albedo 1) shiny one. Use rtpg's
          // default material instead, named after the file for material_overrides.
          out.materials.emplace_back();
          out.materials.back().name = stem;
        } else {
          out.materials.push_back(convert_material(*scene, *scene->mMaterials[in.mMaterialIndex],
                                                   convention, path, *textures, context));
          check_material_values(out.materials.back(), path, context);
        }
        found =
            material_index
                .emplace(in.mMaterialIndex, static_cast<std::uint32_t>(out.materials.size() - 1))
                .first;
      }
      mesh.material = found->second;
    } else if (textures) {
      out.materials.emplace_back();  // assimp always assigns one; keep an index valid anyway
      mesh.material = static_cast<std::uint32_t>(out.materials.size() - 1);
    }
    out.meshes.push_back(std::move(mesh));
  }
  if (out.meshes.empty())
    throw InputError(
        path, (out.degenerate_triangles > 0
                   ? "all " + std::to_string(out.degenerate_triangles) + " triangles have zero area"
                   : std::string("the file holds no triangles")) +
                  where);
  return out;
}

}  // namespace rtpg
