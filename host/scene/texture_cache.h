// Decodes each distinct image once per scene load and hands out Scene::textures indices.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "scene/image_loader.h"
#include "scene/texture.h"

namespace rtpg {

class TextureCache {
 public:
  // Decoded textures are appended to `textures` (normally Scene::textures).
  explicit TextureCache(std::vector<Texture>& textures) : textures_(textures) {}

  // Index of the texture decoded from `path` with `decode`. `context` says who asked for it
  // (e.g. "map_Kd of material 'leaf' in sponza.obj") and is appended to errors, which are
  // InputError(path, ...).
  int file(const std::string& path, ImageDecode decode, const std::string& context);

  // The same for an image embedded in a mesh file; `key` identifies it (file + index).
  int memory(const std::string& key, const void* data, std::size_t size, ImageDecode decode,
             const std::string& context);

 private:
  using Key = std::tuple<std::string, bool, bool, bool>;  // path, srgb, mask, unit_range
  std::vector<Texture>& textures_;
  std::map<Key, int> index_;
};

}  // namespace rtpg
