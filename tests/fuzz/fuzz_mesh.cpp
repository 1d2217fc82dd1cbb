// Fuzz targets of the mesh loading path (host/scene/mesh_loader.h): the OBJ and PLY pre-checks,
// assimp's import, the value checks and the material conversion. One source, three targets:
// RTPG_FUZZ_FILE is the file the input becomes (m.obj with its MTL, an MTL named by a fixed
// OBJ, or a PLY).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fuzz_files.h"
#include "rtpg/errors.h"
#include "scene/mesh_loader.h"
#include "scene/texture_cache.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string input = RTPG_FUZZ_FILE;
  const std::string written = rtpg::fuzz::write_input(data, size, input.c_str());
  // A fuzzed MTL is read through the OBJ that names it.
  static const std::string kObjOfMtl =
      "mtllib f.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl grey\nf 1/1 2/1 3/1\n";
  const std::string mesh =
      input == "f.mtl"
          ? rtpg::fuzz::write_input(reinterpret_cast<const std::uint8_t*>(kObjOfMtl.data()),
                                    kObjOfMtl.size(), "f_mtl.obj")
          : written;
  std::vector<rtpg::Texture> textures;
  rtpg::TextureCache cache(textures);
  try {
    rtpg::load_mesh_file(mesh, &cache, "fuzz");
  } catch (const rtpg::InputError&) {
  }
  // Again as a scene that overrides the mesh's materials reads it (no texture cache): assimp
  // still parses the MTL there.
  try {
    rtpg::load_mesh_file(mesh, nullptr, "fuzz");
  } catch (const rtpg::InputError&) {
  }
  return 0;
}
