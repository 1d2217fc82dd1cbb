#include "trace/ray_order.h"

#include <array>
#include <utility>

#include <tbb/parallel_for.h>

namespace rtpg {
namespace {

constexpr std::uint32_t kCells = 1u << RayOrder::kCellBits;

// kMorton[v]: the bits of v < kCells spread to every third bit.
constexpr std::array<std::uint32_t, kCells> morton_table() {
  std::array<std::uint32_t, kCells> table{};
  for (std::uint32_t v = 0; v < kCells; ++v)
    for (int b = 0; b < RayOrder::kCellBits; ++b) table[v] |= ((v >> b) & 1u) << (3 * b);
  return table;
}
constexpr std::array<std::uint32_t, kCells> kMorton = morton_table();

std::uint32_t cell_of(float x, float min, float cells_per_unit) {
  const float c = (x - min) * cells_per_unit;
  if (!(c >= 0.0f)) return 0u;  // below the grid, or NaN
  return c < static_cast<float>(kCells) ? static_cast<std::uint32_t>(c) : kCells - 1u;
}

}  // namespace

RayOrder::RayOrder(const glm::vec3& bounds_min, const glm::vec3& bounds_max) : min_(bounds_min) {
  const glm::vec3 extent = bounds_max - bounds_min;
  for (int a = 0; a < 3; ++a)
    cells_per_unit_[a] = extent[a] > 0.0f ? static_cast<float>(kCells) / extent[a] : 0.0f;
}

std::uint16_t RayOrder::group(const glm::vec3& origin, const glm::vec3& direction) const {
  const std::uint32_t octant = (direction.x < 0.0f ? 1u : 0u) | (direction.y < 0.0f ? 2u : 0u) |
                               (direction.z < 0.0f ? 4u : 0u);
  const std::uint32_t cell = kMorton[cell_of(origin.x, min_.x, cells_per_unit_.x)] |
                             kMorton[cell_of(origin.y, min_.y, cells_per_unit_.y)] << 1 |
                             kMorton[cell_of(origin.z, min_.z, cells_per_unit_.z)] << 2;
  return static_cast<std::uint16_t>(octant << (3 * kCellBits) | cell);
}

std::size_t RayOrder::count_starts(const std::uint16_t* groups, std::size_t stride,
                                   const std::uint32_t* counts, std::size_t lists) {
  const std::size_t chunks = chunks_of(lists);
  // A counting sort: each chunk's count of each group ...
  starts_.assign(chunks * kGroups, 0u);
  tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t c) {
    std::uint32_t* count = starts_.data() + c * kGroups;
    each_listed_slot(c, stride, counts, lists, [&](std::size_t s) { ++count[groups[s]]; });
  });
  // ... made into where its slots of that group start (group by group, chunk by chunk inside a
  // group, so that a group keeps slot order); arrange() then writes each slot there.
  std::uint32_t total = 0;
  for (std::uint32_t g = 0; g != kGroups; ++g)
    for (std::size_t c = 0; c != chunks; ++c) {
      std::uint32_t& entry = starts_[c * kGroups + g];
      total += std::exchange(entry, total);
    }
  return total;
}

const std::vector<std::uint32_t>& RayOrder::order(const std::uint16_t* groups, std::size_t stride,
                                                  const std::uint32_t* counts, std::size_t lists) {
  order_.resize(stride * lists);
  const std::size_t total =
      arrange(groups, stride, counts, lists, [&](std::size_t slot, std::size_t place) {
        order_[place] = static_cast<std::uint32_t>(slot);
      });
  order_.resize(total);
  return order_;
}

}  // namespace rtpg
