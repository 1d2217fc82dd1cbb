// Memory for the renderer's large arrays (the path tracer's per-path state and rays, the
// G-buffer, the VPLs, textures, the triangle table) in 2 MiB pages where the kernel gives
// transparent huge pages on request (THP "madvise", Debian's default; "always" gives them anyway):
// the shading loop and the passes after each vertex read these arrays at scattered places, and with
// 4 KiB pages most of those reads also miss the TLB (docs/host-path-tracer.md, "Large arrays in
// huge pages").
//
// An array of 2 MiB or more is its own mapping, 2 MiB aligned and rounded up to whole 2 MiB,
// marked MADV_HUGEPAGE before its first touch (after it, only the kernel's background
// collapsing would change its pages); a smaller one comes from operator new as before. Where the
// hint is unknown or refused the pages are ordinary ones and nothing else changes.
#pragma once

#include <cstddef>
#include <new>
#include <vector>

namespace rtpg {

inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;

// bytes of memory aligned to `alignment` (a power of two up to kHugePageBytes); throws
// std::bad_alloc, also where bytes rounded up to whole huge pages would not fit a size_t. Free
// with deallocate_large and the same byte count and alignment.
void* allocate_large(std::size_t bytes, std::size_t alignment);
void deallocate_large(void* p, std::size_t bytes, std::size_t alignment) noexcept;

// Whether an allocation of `bytes` is its own huge-page mapping (tests; the rule above).
inline bool is_large_allocation(std::size_t bytes) {
  return bytes >= kHugePageBytes;
}

template <class T>
struct HugePageAllocator {
  static_assert(alignof(T) <= kHugePageBytes);
  using value_type = T;
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(allocate_large(n * sizeof(T), alignof(T)));
  }
  void deallocate(T* p, std::size_t n) noexcept { deallocate_large(p, n * sizeof(T), alignof(T)); }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
  template <class U>
  bool operator!=(const HugePageAllocator<U>&) const noexcept {
    return false;
  }
};

// A std::vector whose storage follows the rule above.
template <class T>
using LargeVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace rtpg
