// Asset lookup and the asset root (also resolve_asset_root of scene_loader.h).
#include "scene/asset_paths.h"

#include <cstdlib>
#include <filesystem>

#include "scene/scene_loader.h"

namespace fs = std::filesystem;

namespace rtpg {

namespace {

// Absolute and normalised, so that messages show where a file was really looked for.
fs::path absolute_normal(const fs::path& p) {
  std::error_code ec;
  const fs::path a = fs::absolute(p, ec);
  return (ec ? p : a).lexically_normal();
}

fs::path scene_folder(const std::string& scene_path) {
  const fs::path parent = fs::path(scene_path).parent_path();
  return absolute_normal(parent.empty() ? fs::path(".") : parent);
}

bool is_file(const fs::path& p) {
  std::error_code ec;
  return fs::is_regular_file(p, ec);
}

bool is_folder(const fs::path& p) {
  std::error_code ec;
  return fs::is_directory(p, ec);
}

}  // namespace

std::string resolve_asset_root(const std::string& json_path, const SceneLoadSettings& settings) {
  // An explicit choice is returned even when it does not exist, so that "not found"
  // messages show the folder the user pointed at instead of silently looking elsewhere.
  if (!settings.asset_root.empty()) return absolute_normal(settings.asset_root).string();
  if (const char* env = std::getenv("RTPG_ASSET_ROOT"); env && *env)
    return absolute_normal(env).string();
  std::error_code ec;
  const fs::path cwd = fs::current_path(ec);
  const fs::path dir = scene_folder(json_path);
  std::vector<fs::path> candidates;
  if (!ec) candidates.push_back(cwd / ".." / "shared" / "scenes");
  candidates.push_back(dir / ".." / ".." / "shared" / "scenes");
  candidates.push_back(dir / ".." / "shared" / "scenes");
  for (const fs::path& c : candidates)
    if (is_folder(c)) return absolute_normal(c).string();
  return "";
}

AssetPaths::AssetPaths(const std::string& scene_path, std::string asset_root)
    : scene_dir_(scene_folder(scene_path).string()), asset_root_(std::move(asset_root)) {}

std::optional<std::string> AssetPaths::find(const std::string& written,
                                            std::vector<std::string>& searched) const {
  searched.clear();
  const fs::path p(written);
  std::vector<fs::path> candidates;
  if (p.is_absolute()) {
    candidates.push_back(p.lexically_normal());
  } else {
    candidates.push_back((fs::path(scene_dir_) / p).lexically_normal());
    if (!asset_root_.empty()) candidates.push_back((fs::path(asset_root_) / p).lexically_normal());
  }
  for (const fs::path& c : candidates) {
    if (is_file(c)) return c.string();
    searched.push_back(c.string());
  }
  return std::nullopt;
}

}  // namespace rtpg
