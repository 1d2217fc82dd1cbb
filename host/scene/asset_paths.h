// Where the files a scene names are found: next to the scene file, else under the asset root.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace rtpg {

class AssetPaths {
 public:
  // `asset_root` may be "" (none).
  AssetPaths(const std::string& scene_path, std::string asset_root);

  // The file `written` names: itself if absolute, else the first existing of <scene dir>/written
  // and <asset root>/written. Empty when none exists; `searched` then lists the candidates.
  std::optional<std::string> find(const std::string& written,
                                  std::vector<std::string>& searched) const;

  const std::string& asset_root() const { return asset_root_; }

 private:
  std::string scene_dir_;
  std::string asset_root_;
};

}  // namespace rtpg
