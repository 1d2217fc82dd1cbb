#include "util/atomic_file.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "rtpg/errors.h"

namespace rtpg {

namespace fs = std::filesystem;

std::string temporary_path_for(const std::string& path) {
  const fs::path p(path);
  const std::string name =
      "." + p.stem().string() + ".tmp-" + std::to_string(::getpid()) + p.extension().string();
  return (p.parent_path() / name).string();
}

void check_can_create(const std::string& path) {
  const std::string tmp = temporary_path_for(path);
  std::FILE* file = std::fopen(tmp.c_str(), "wb");
  if (!file) throw InputError(path, "cannot create a file in its folder");
  std::fclose(file);
  std::remove(tmp.c_str());
}

void write_text_atomically(const std::string& path, const std::string& text) {
  const fs::path target(path);
  const fs::path tmp = temporary_path_for(path);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path, "cannot open for writing");
    out << text;
    out.close();
    if (!out) {
      std::remove(tmp.c_str());
      throw InputError(path, "write failed");
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw InputError(path, "cannot move the finished file into place: " + ec.message());
  }
}

}  // namespace rtpg
