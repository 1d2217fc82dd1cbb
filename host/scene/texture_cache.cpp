// Texture de-duplication within one scene load.
#include "scene/texture_cache.h"

#include <filesystem>

#include "rtpg/errors.h"

namespace rtpg {

namespace {

// The same file reached through different relative paths must hit the same entry.
std::string canonical_key(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
  return ec ? path : absolute.lexically_normal().string();
}

// Re-throws a decoding error with the context appended, keeping the file as the subject.
template <typename Load>
Texture with_context(const std::string& subject, const std::string& context, Load load) {
  try {
    return load();
  } catch (const InputError& e) {
    if (context.empty()) throw;
    // what() is "<subject>: <problem>"; keep the problem and say who referenced the file.
    std::string problem = e.what();
    const std::string prefix = subject + ": ";
    if (problem.compare(0, prefix.size(), prefix) == 0) problem.erase(0, prefix.size());
    throw InputError(subject, problem + " (" + context + ")");
  }
}

}  // namespace

int TextureCache::file(const std::string& path, ImageDecode decode, const std::string& context) {
  const Key key{canonical_key(path), decode.srgb, decode.mask, decode.unit_range};
  const auto found = index_.find(key);
  if (found != index_.end()) return found->second;
  textures_.push_back(with_context(path, context, [&] { return load_image(path, decode); }));
  const int index = static_cast<int>(textures_.size() - 1);
  index_.emplace(key, index);
  return index;
}

int TextureCache::memory(const std::string& key_name, const void* data, std::size_t size,
                         ImageDecode decode, const std::string& context) {
  const Key key{"embedded:" + key_name, decode.srgb, decode.mask, decode.unit_range};
  const auto found = index_.find(key);
  if (found != index_.end()) return found->second;
  textures_.push_back(with_context(
      key_name, context, [&] { return load_image_from_memory(key_name, data, size, decode); }));
  const int index = static_cast<int>(textures_.size() - 1);
  index_.emplace(key, index);
  return index;
}

}  // namespace rtpg
