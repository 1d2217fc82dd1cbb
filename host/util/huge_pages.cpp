#include "util/huge_pages.h"

#include <cstdint>
#include <limits>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace rtpg {
namespace {

std::size_t round_up(std::size_t bytes, std::size_t to) {
  return (bytes + to - 1) / to * to;
}

// The small arrays' memory: operator new's, with the type's alignment where it asks for more.
void* allocate_small(std::size_t bytes, std::size_t alignment) {
  if (alignment > __STDCPP_DEFAULT_NEW_ALIGNMENT__)
    return ::operator new (bytes, std::align_val_t{alignment});
  return ::operator new(bytes);
}

void deallocate_small(void* p, std::size_t alignment) noexcept {
  if (alignment > __STDCPP_DEFAULT_NEW_ALIGNMENT__) {
    ::operator delete (p, std::align_val_t{alignment});
    return;
  }
  ::operator delete(p);
}

}  // namespace

void* allocate_large(std::size_t bytes, std::size_t alignment) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (!is_large_allocation(bytes)) return allocate_small(bytes, alignment);
  // The rounding and the extra huge page below must not wrap around.
  if (bytes > std::numeric_limits<std::size_t>::max() - 2 * kHugePageBytes) throw std::bad_alloc();
  const std::size_t size = round_up(bytes, kHugePageBytes);
  // One huge page more than needed, so that a 2 MiB boundary lies inside; the slack on either
  // side is given back.
  const std::size_t mapped = size + kHugePageBytes;
  void* p = mmap(nullptr, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) throw std::bad_alloc();
  const auto base = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t aligned = round_up(base, kHugePageBytes);
  if (aligned > base) munmap(p, aligned - base);
  const std::uintptr_t end = aligned + size;
  if (base + mapped > end) munmap(reinterpret_cast<void*>(end), base + mapped - end);
  // A hint: EINVAL where the kernel has no transparent huge pages leaves ordinary ones.
  madvise(reinterpret_cast<void*>(aligned), size, MADV_HUGEPAGE);
  return reinterpret_cast<void*>(aligned);
#else
  return allocate_small(bytes, alignment);
#endif
}

void deallocate_large(void* p, std::size_t bytes, std::size_t alignment) noexcept {
  if (p == nullptr) return;
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (is_large_allocation(bytes)) {
    munmap(p, round_up(bytes, kHugePageBytes));
    return;
  }
#endif
  deallocate_small(p, alignment);
}

}  // namespace rtpg
