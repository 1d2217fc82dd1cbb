// Fuzz target: the scene JSON loader (format: scenes/README.md), with the mesh files, textures
// and materials it can name.
#include <cstddef>
#include <cstdint>

#include "fuzz_files.h"
#include "rtpg/errors.h"
#include "scene/scene_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = rtpg::fuzz::write_input(data, size, "scene.json");
  rtpg::SceneLoadSettings settings;
  settings.asset_root = rtpg::fuzz::work_folder();
  try {
    rtpg::load_scene(path, settings);
  } catch (const rtpg::InputError&) {
  }
  return 0;
}
