// Compiled OpenCL program binaries on disk (CL_PROGRAM_BINARIES), so that a second run
// skips the front-end compile. Entries are keyed by a text that names everything the binary
// depends on (source hash, build options, device and driver); the file repeats the key and
// a checksum, so a collision, a truncated write or a stale format reads as a miss.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace rtpg {

// 128-bit content hash as 32 hex digits (two independent 64-bit hashes): stable across
// runs, compilers and machines, unlike std::hash.
std::string content_hash(const std::string& data);

class DiskProgramCache {
 public:
  // Entries live in <dir>/programs; an empty dir turns the cache off.
  explicit DiskProgramCache(std::string dir);

  bool enabled() const { return !dir_.empty(); }
  // The file an entry for key lives in ("" when off).
  std::string path_for(const std::string& key) const;

  // The binary stored under key, or nullopt when absent, unreadable or corrupt.
  std::optional<std::vector<unsigned char>> load(const std::string& key) const;
  // Best effort (a full disk or read-only home only costs the next run a compile). Writes a
  // temporary file and renames it, so concurrent processes never read half an entry.
  void store(const std::string& key, const std::vector<unsigned char>& binary) const;

 private:
  std::string dir_;
};

}  // namespace rtpg
