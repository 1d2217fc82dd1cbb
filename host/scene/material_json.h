// Reads material fields of a scene file: entries of "materials" and the "set" of
// "material_overrides" share one set of keys (format: scenes/README.md).
#pragma once

#include <functional>

#include "scene/image_loader.h"
#include "scene/json_reader.h"
#include "scene/scene.h"

namespace rtpg {

// Scene::textures index for a texture key's value (a path string); the scene loader
// resolves the path and decodes the image.
using TextureResolver = std::function<int(const JsonNode& value, ImageDecode decode)>;

// Sets the fields present in `node` on `material`, leaving the others as they are. A texture
// key set to null removes that texture.
void apply_material_fields(const JsonNode& node, Material& material,
                           const TextureResolver& texture);

}  // namespace rtpg
