#include "cl/program_cache.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <utility>

#include <unistd.h>

namespace rtpg {
namespace {

// Bumped whenever the file layout changes; old files then read as misses.
constexpr char kMagic[8] = {'R', 'T', 'P', 'G', 'C', 'L', 'B', '1'};
// Anything larger is not one of our binaries (PoCL's are a few hundred KiB).
constexpr std::uint64_t kMaxBinaryBytes = std::uint64_t(1) << 30;

std::uint64_t fnv1a64(const unsigned char* data, std::size_t size) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (std::size_t i = 0; i < size; ++i) h = (h ^ data[i]) * 0x100000001b3ull;
  return h;
}

// A second hash unrelated to FNV (multiply-rotate per byte, splitmix64 finaliser), so the
// pair behaves as 128 bits.
std::uint64_t mix64(const unsigned char* data, std::size_t size) {
  std::uint64_t h = 0x9e3779b97f4a7c15ull ^ size;
  for (std::size_t i = 0; i < size; ++i) {
    h = (h + data[i] + 1) * 0xff51afd7ed558ccdull;
    h ^= h >> 29;
  }
  h ^= h >> 30;
  h *= 0xbf58476d1ce4e5b9ull;
  h ^= h >> 27;
  h *= 0x94d049bb133111ebull;
  return h ^ (h >> 31);
}

std::string hex64(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

template <class T>
bool read_pod(std::istream& in, T& value) {
  return static_cast<bool>(in.read(reinterpret_cast<char*>(&value), sizeof value));
}

template <class T>
void write_pod(std::ostream& out, const T& value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof value);
}

}  // namespace

std::string content_hash(const std::string& data) {
  const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
  return hex64(fnv1a64(bytes, data.size())) + hex64(mix64(bytes, data.size()));
}

DiskProgramCache::DiskProgramCache(std::string dir) : dir_(std::move(dir)) {}

std::string DiskProgramCache::path_for(const std::string& key) const {
  if (!enabled()) return {};
  return dir_ + "/programs/" + content_hash(key) + ".clbin";
}

std::optional<std::vector<unsigned char>> DiskProgramCache::load(const std::string& key) const {
  if (!enabled()) return std::nullopt;
  std::ifstream in(path_for(key), std::ios::binary);
  if (!in) return std::nullopt;
  char magic[sizeof kMagic];
  std::uint32_t key_size = 0;
  if (!in.read(magic, sizeof magic) || !std::equal(magic, magic + sizeof magic, kMagic) ||
      !read_pod(in, key_size) || key_size != key.size()) {
    return std::nullopt;
  }
  std::string stored_key(key_size, '\0');
  if (!in.read(stored_key.data(), key_size) || stored_key != key) return std::nullopt;
  std::uint64_t size = 0, checksum = 0;
  if (!read_pod(in, size) || !read_pod(in, checksum) || size == 0 || size > kMaxBinaryBytes)
    return std::nullopt;
  std::vector<unsigned char> binary(size);
  if (!in.read(reinterpret_cast<char*>(binary.data()), static_cast<std::streamsize>(size)) ||
      fnv1a64(binary.data(), binary.size()) != checksum) {
    return std::nullopt;
  }
  return binary;
}

void DiskProgramCache::store(const std::string& key,
                             const std::vector<unsigned char>& binary) const {
  if (!enabled() || binary.empty()) return;
  static std::atomic<unsigned> counter{0};
  const std::string path = path_for(key);
  const std::string temp =
      path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(counter.fetch_add(1));
  std::error_code ec;
  std::filesystem::create_directories(dir_ + "/programs", ec);
  if (ec) return;
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) return;
    out.write(kMagic, sizeof kMagic);
    write_pod(out, static_cast<std::uint32_t>(key.size()));
    out.write(key.data(), static_cast<std::streamsize>(key.size()));
    write_pod(out, static_cast<std::uint64_t>(binary.size()));
    write_pod(out, fnv1a64(binary.data(), binary.size()));
    out.write(reinterpret_cast<const char*>(binary.data()),
              static_cast<std::streamsize>(binary.size()));
    out.close();
    if (!out) {
      std::filesystem::remove(temp, ec);
      return;
    }
  }
  std::filesystem::rename(temp, path, ec);
  if (ec) std::filesystem::remove(temp, ec);
}

}  // namespace rtpg
