// The large arrays' allocator (host/util/huge_pages.h): what a std::vector needs of it, the
// 2 MiB alignment of a large array, and its mapping marked for huge pages before first touch.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "util/huge_pages.h"

namespace rtpg {
namespace {

// The VmFlags of the mapping holding `address` in /proc/self/smaps ("" where none holds it).
std::string vm_flags_of(const void* address) {
  std::ifstream smaps("/proc/self/smaps");
  const auto at = reinterpret_cast<std::uintptr_t>(address);
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t first = 0, end = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> first >> dash >> end && dash == '-' &&
        line.find(' ') != std::string::npos && line.find(':') > line.find(' ')) {
      inside = first <= at && at < end;
      continue;
    }
    if (inside && line.rfind("VmFlags:", 0) == 0) return line;
  }
  return "";
}

bool kernel_has_transparent_huge_pages() {
  std::ifstream enabled("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  return std::getline(enabled, modes) && modes.find("[never]") == std::string::npos;
}

TEST(HugePages, SmallArraysComeFromOperatorNewAndWork) {
  LargeVector<int> v(1000);
  for (int i = 0; i < 1000; ++i) v[i] = 3 * i;
  EXPECT_FALSE(is_large_allocation(v.capacity() * sizeof(int)));
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(v[i], 3 * i);
}

TEST(HugePages, LargeArraysAreAlignedToTwoMiBAndKeepTheirValuesAsTheyGrow) {
  // Grows from operator new's memory across the threshold into mappings of its own.
  LargeVector<std::uint32_t> v;
  const std::uint32_t n = 3u << 20;  // 12 MiB
  for (std::uint32_t i = 0; i < n; ++i) v.push_back(i * 2654435761u);
  ASSERT_TRUE(is_large_allocation(v.capacity() * sizeof(std::uint32_t)));
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % kHugePageBytes, 0u);
  for (std::uint32_t i = 0; i < n; ++i) ASSERT_EQ(v[i], i * 2654435761u) << i;
  // Copies, moves and shrinking back below the threshold.
  LargeVector<std::uint32_t> copy = v;
  EXPECT_EQ(copy, v);
  copy.resize(100);
  copy.shrink_to_fit();
  EXPECT_FALSE(is_large_allocation(copy.capacity() * sizeof(std::uint32_t)));
  for (std::uint32_t i = 0; i < 100; ++i) ASSERT_EQ(copy[i], i * 2654435761u);
  const LargeVector<std::uint32_t> moved = std::move(v);
  EXPECT_EQ(moved.size(), n);
  EXPECT_EQ(moved[n - 1], (n - 1) * 2654435761u);
}

TEST(HugePages, SizesNearTheLimitAreRefusedNotWrappedAround) {
  // Rounded up to whole huge pages such sizes would wrap around to a small mapping.
  const std::size_t max = std::numeric_limits<std::size_t>::max();
  for (const std::size_t bytes : {max, max - 1, max - kHugePageBytes, max - 2 * kHugePageBytes + 1})
    EXPECT_THROW(allocate_large(bytes, 16), std::bad_alloc) << bytes;
  LargeVector<double> v;
  EXPECT_THROW(v.resize(max / 16), std::bad_alloc);
}

TEST(HugePages, LargeArraysAreMarkedForHugePagesBeforeTheirFirstTouch) {
  if (!kernel_has_transparent_huge_pages())
    GTEST_SKIP() << "this kernel gives no transparent huge pages";
  // An odd size: the mapping is rounded up to whole huge pages, all of it marked.
  LargeVector<float> v(5'000'001, 1.0f);
  const std::string first = vm_flags_of(v.data()), last = vm_flags_of(&v.back());
  EXPECT_NE(first.find(" hg"), std::string::npos) << first;
  EXPECT_NE(last.find(" hg"), std::string::npos) << last;
}

}  // namespace
}  // namespace rtpg
