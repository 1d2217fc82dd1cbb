// Material conversion rules (documented in scenes/README.md, "Materials from mesh files").
#include "scene/assimp_material.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

#include <assimp/GltfMaterial.h>
#include <assimp/ObjMaterial.h>
#include <assimp/material.h>
#include <assimp/scene.h>

#include "rtpg/errors.h"

namespace rtpg {

namespace {

class MaterialReader {
 public:
  MaterialReader(const aiScene& scene, const aiMaterial& material, const std::string& mesh_path,
                 TextureCache& textures, const std::string& context)
      : scene_(scene),
        material_(material),
        mesh_path_(mesh_path),
        textures_(textures),
        context_(context) {}

  std::string name() const {
    aiString name;
    return material_.Get(AI_MATKEY_NAME, name) == AI_SUCCESS ? std::string(name.C_Str()) : "";
  }

  bool color(const char* key, unsigned type, unsigned index, glm::vec3& out) const {
    aiColor4D c;
    if (material_.Get(key, type, index, c) != AI_SUCCESS) return false;
    out = glm::vec3(c.r, c.g, c.b);
    return true;
  }

  bool number(const char* key, unsigned type, unsigned index, float& out) const {
    ai_real v;
    if (material_.Get(key, type, index, v) != AI_SUCCESS) return false;
    out = static_cast<float>(v);
    return true;
  }

  bool integer(const char* key, unsigned type, unsigned index, int& out) const {
    return material_.Get(key, type, index, out) == AI_SUCCESS;
  }

  bool text(const char* key, unsigned type, unsigned index, std::string& out) const {
    aiString s;
    if (material_.Get(key, type, index, s) != AI_SUCCESS) return false;
    out = s.C_Str();
    return true;
  }

  bool has_texture(aiTextureType type) const { return material_.GetTextureCount(type) > 0; }

  // Scene::textures index of the first texture of `type`, or -1. `what` names the slot
  // (e.g. "map_Kd") for error messages.
  int texture(aiTextureType type, ImageDecode decode, const char* what) {
    aiString file;
    if (material_.GetTexture(type, 0, &file) != AI_SUCCESS || file.length == 0) return -1;
    std::string written = file.C_Str();
    const std::string context =
        std::string(what) + " of material '" + name() + "' in " + mesh_path_ + ", " + context_;
    if (const aiTexture* embedded = scene_.GetEmbeddedTexture(file.C_Str())) {
      const std::string key = mesh_path_ + "[" + written + "]";
      if (embedded->mHeight != 0)
        throw InputError(key, "uncompressed embedded textures are not supported (" + context + ")");
      // The hint is the compressed format's extension ("png", "jpg"): OIIO picks its decoder
      // from the name.
      const std::string hint(embedded->achFormatHint,
                             strnlen(embedded->achFormatHint, HINTMAXTEXTURELEN));
      return textures_.memory(key + "." + (hint.empty() ? "png" : hint), embedded->pcData,
                              embedded->mWidth, decode, context);
    }
    // Exporters from Windows write backslashes; the folder separator here is '/'.
    std::replace(written.begin(), written.end(), '\\', '/');
    const std::filesystem::path path(written);
    const std::filesystem::path resolved =
        path.is_absolute()
            ? path
            : (std::filesystem::path(mesh_path_).parent_path() / path).lexically_normal();
    return textures_.file(resolved.string(), decode, context);
  }

 private:
  const aiScene& scene_;
  const aiMaterial& material_;
  const std::string& mesh_path_;
  TextureCache& textures_;
  const std::string& context_;
};

constexpr ImageDecode kColour{true, false};
constexpr ImageDecode kData{false, false};
constexpr ImageDecode kMask{false, true};

// Wavefront MTL: Phong-era parameters mapped onto Lambert + GGX.
Material convert_mtl(MaterialReader& in) {
  Material m;
  m.name = in.name();
  in.color(AI_MATKEY_COLOR_DIFFUSE, m.base_color);
  m.base_color_texture = in.texture(aiTextureType_DIFFUSE, kColour, "map_Kd");

  // Ks = 0 is how MTL says "no highlight": keep it pure Lambert. Otherwise a dielectric
  // lobe whose width follows the Phong exponent: roughness = sqrt(2 / (Ns + 2)). (The
  // Beckmann-Phong correspondence is alpha = sqrt(2 / (Ns + 2)); with alpha = roughness^2
  // this rule's alpha is that one squared: a lobe 2.4x narrower at Ns = 10, 7x at Ns = 100.
  // Kept: the scenes' looks and figures were made with it.)
  glm::vec3 ks(0.0f);
  in.color(AI_MATKEY_COLOR_SPECULAR, ks);
  if (std::max({ks.x, ks.y, ks.z}) <= 0.0f) {
    m.specular = 0.0f;
  } else {
    float ns = 0.0f;
    in.number(AI_MATKEY_SHININESS, ns);
    m.specular = 0.04f;
    m.roughness = std::clamp(std::sqrt(2.0f / (std::max(ns, 0.0f) + 2.0f)), 0.05f, 1.0f);
  }
  in.color(AI_MATKEY_COLOR_EMISSIVE, m.emission);

  // OBJ bump maps are grey height maps (Sponza's *_bump.png), not normal maps; `norm` is
  // the normal-map slot.
  m.bump_texture = in.texture(aiTextureType_HEIGHT, kData, "map_bump");
  if (m.bump_texture >= 0) {
    float scale = 1.0f;
    if (in.number(AI_MATKEY_OBJ_BUMPMULT_HEIGHT(0), scale)) m.bump_scale = scale;
  }
  m.normal_texture = in.texture(aiTextureType_NORMALS, kData, "norm");
  m.alpha_texture = in.texture(aiTextureType_OPACITY, kMask, "map_d");

  // Glass only when the file clearly says so: a dissolve below 1 that is not an alpha
  // mask, or a refractive illumination model (4, 6, 7) with an index of refraction.
  float opacity = 1.0f, ior = 1.0f;
  in.number(AI_MATKEY_OPACITY, opacity);
  in.number(AI_MATKEY_REFRACTI, ior);
  int illum = 2;
  in.integer(AI_MATKEY_OBJ_ILLUM, illum);
  const bool refractive_model = illum == 4 || illum == 6 || illum == 7;
  m.transmissive = (opacity < 1.0f && m.alpha_texture < 0) || (refractive_model && ior > 1.0f);
  return m;
}

// glTF 2.0 metallic-roughness.
Material convert_gltf(MaterialReader& in) {
  Material m;
  m.name = in.name();
  if (!in.color(AI_MATKEY_BASE_COLOR, m.base_color))
    in.color(AI_MATKEY_COLOR_DIFFUSE, m.base_color);
  m.base_color_texture = in.texture(aiTextureType_BASE_COLOR, kColour, "baseColorTexture");
  if (m.base_color_texture < 0)
    m.base_color_texture = in.texture(aiTextureType_DIFFUSE, kColour, "baseColorTexture");
  m.roughness = 1.0f;
  m.metallic = 1.0f;  // glTF defaults
  in.number(AI_MATKEY_ROUGHNESS_FACTOR, m.roughness);
  in.number(AI_MATKEY_METALLIC_FACTOR, m.metallic);
  // One texture, G = roughness and B = metallic (the Material defaults for the channels).
  const int mr = in.texture(aiTextureType_UNKNOWN, kData, "metallicRoughnessTexture");
  m.roughness_texture = mr;
  m.metallic_texture = mr;
  m.specular = 0.04f;
  m.normal_texture = in.texture(aiTextureType_NORMALS, kData, "normalTexture");

  // Emission: the factor only (an emissive texture is not evaluated), times the
  // KHR_materials_emissive_strength multiplier.
  in.color(AI_MATKEY_COLOR_EMISSIVE, m.emission);
  float strength = 1.0f;
  if (in.number(AI_MATKEY_EMISSIVE_INTENSITY, strength)) m.emission *= strength;

  std::string alpha_mode;
  if (in.text(AI_MATKEY_GLTF_ALPHAMODE, alpha_mode) && alpha_mode == "MASK" &&
      m.base_color_texture >= 0) {
    m.alpha_texture = m.base_color_texture;  // alpha lives in the base colour's A channel
    in.number(AI_MATKEY_GLTF_ALPHACUTOFF, m.alpha_cutoff);
  }
  float transmission = 0.0f;
  m.transmissive = in.number(AI_MATKEY_TRANSMISSION_FACTOR, transmission) && transmission > 0.0f;
  return m;
}

}  // namespace

Material convert_material(const aiScene& scene, const aiMaterial& material,
                          MaterialConvention convention, const std::string& mesh_path,
                          TextureCache& textures, const std::string& context) {
  MaterialReader reader(scene, material, mesh_path, textures, context);
  return convention == MaterialConvention::Gltf ? convert_gltf(reader) : convert_mtl(reader);
}

}  // namespace rtpg
