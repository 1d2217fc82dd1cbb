#include "cl/cache_dir.h"

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <system_error>

namespace rtpg {
namespace {

// An empty variable counts as unset, as shells make it easy to export one by accident.
const char* env_or_null(const char* name) {
  const char* value = std::getenv(name);
  return (value != nullptr && value[0] != '\0') ? value : nullptr;
}

}  // namespace

std::string rtpg_cache_dir() {
  if (const char* dir = env_or_null("RTPG_CACHE_DIR")) return dir;
  if (const char* xdg = env_or_null("XDG_CACHE_HOME")) return std::string(xdg) + "/rtpg";
  if (const char* home = env_or_null("HOME")) return std::string(home) + "/.cache/rtpg";
  return {};
}

void prepare_opencl_environment() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (env_or_null("POCL_CACHE_DIR") != nullptr) return;
    const std::string dir = rtpg_cache_dir();
    if (dir.empty()) return;
    const std::string pocl_dir = dir + "/pocl";
    std::error_code ec;  // an unwritable folder only costs PoCL its cache: not an error
    std::filesystem::create_directories(pocl_dir, ec);
    if (!ec) setenv("POCL_CACHE_DIR", pocl_dir.c_str(), 0);
  });
}

}  // namespace rtpg
