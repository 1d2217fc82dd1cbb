#include "fuzz_files.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace rtpg::fuzz {
namespace {

void write(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
}

// A 1x1 RGBA PNG (the smallest valid one: signature, IHDR, IDAT, IEND).
const unsigned char kPng[] = {
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48,
    0x44, 0x52, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x06, 0x00, 0x00,
    0x00, 0x1f, 0x15, 0xc4, 0x89, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x44, 0x41, 0x54, 0x78,
    0x9c, 0x63, 0xf8, 0xcf, 0xc0, 0xf0, 0x1f, 0x00, 0x05, 0x00, 0x01, 0xff, 0x89, 0x99,
    0x3d, 0x1d, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};

std::string make_folder() {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("rtpg_fuzz_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string d = dir.string();
  write(d + "/m.mtl", "newmtl grey\nKd 0.5 0.5 0.5\nKs 0.2 0.2 0.2\nNs 50\nmap_Kd t.png\n");
  write(d + "/m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n"
        "usemtl grey\nf 1/1/1 2/2/1 3/3/1\n");
  write(d + "/t.png", std::string(reinterpret_cast<const char*>(kPng), sizeof(kPng)));
  write(d + "/p.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  return d;
}

}  // namespace

const std::string& work_folder() {
  static const std::string folder = make_folder();
  return folder;
}

std::string write_input(const std::uint8_t* data, std::size_t size, const char* name) {
  const std::string path = work_folder() + "/" + name;
  write(path, std::string(reinterpret_cast<const char*>(data), size));
  return path;
}

}  // namespace rtpg::fuzz
