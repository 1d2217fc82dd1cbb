// Converts materials imported by assimp (OBJ/MTL, glTF 2.0, others) to rtpg's Material.
#pragma once

#include <string>

#include "scene/scene.h"
#include "scene/texture_cache.h"

struct aiMaterial;
struct aiScene;

namespace rtpg {

// Which convention the file's materials follow: MTL's Phong-era parameters or glTF's PBR.
enum class MaterialConvention { Mtl, Gltf };

// `mesh_path` is the mesh file: relative texture paths resolve against its folder and
// embedded textures ("*0") are looked up in `scene`. `context` ends every error message.
Material convert_material(const aiScene& scene, const aiMaterial& material,
                          MaterialConvention convention, const std::string& mesh_path,
                          TextureCache& textures, const std::string& context);

}  // namespace rtpg
