// Reads a JSON scene description (format: scenes/README.md) into a Scene.
#pragma once

#include <string>

#include "scene/scene.h"

namespace rtpg {

struct SceneLoadSettings {
  // Where asset paths that are not found next to the scene file are looked up. Empty: the
  // RTPG_ASSET_ROOT environment variable, else ../shared/scenes relative to the working
  // directory and to the scene file's folder, when that exists.
  std::string asset_root;
};

// Throws InputError naming the file (scene, mesh, texture, environment map) and the problem.
Scene load_scene(const std::string& json_path, const SceneLoadSettings& settings = {});

// The asset root load_scene would use with these settings ("" when none exists).
std::string resolve_asset_root(const std::string& json_path, const SceneLoadSettings& settings);

}  // namespace rtpg
