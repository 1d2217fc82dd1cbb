// The order in which a batch of incoherent rays goes to Embree: grouped by the octant of the
// direction, then by the cell of a coarse grid over the scene that holds the origin, in slot
// order inside a group, so that consecutive rays walk the same parts of the BVH while those are
// in the caches (docs/host-path-tracer.md, "Bounce rays traced in groups"). Hits do not depend
// on the order; the time does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace rtpg {

class RayOrder {
 public:
  // Cells per axis of the origin grid: 2^kCellBits; with the octant, kGroups groups (few
  // enough for a counting sort with a histogram per chunk of lists that stays in the caches).
  static constexpr int kCellBits = 3;
  static constexpr std::uint32_t kGroups = 8u << (3 * kCellBits);

  // The grid spans [bounds_min, bounds_max] (the scene's bounds); an origin outside it, or with
  // a NaN coordinate, falls into an edge cell.
  RayOrder(const glm::vec3& bounds_min, const glm::vec3& bounds_max);

  // A ray's group: its direction's octant (the high bits), then its origin's cell in Morton
  // order.
  std::uint16_t group(const glm::vec3& origin, const glm::vec3& direction) const;

  // The slots of `lists` lists laid out `stride` apart (list l is slots l * stride .. l * stride
  // + counts[l] - 1, as the path tracer lists its bounce rays), ordered by groups[slot] and,
  // inside a group, by slot. The same whatever the thread count; the vector is reused by the
  // next call.
  const std::vector<std::uint32_t>& order(const std::uint16_t* groups, std::size_t stride,
                                          const std::uint32_t* counts, std::size_t lists);

 private:
  glm::vec3 min_, cells_per_unit_;
  std::vector<std::uint32_t> starts_;  // [chunk * kGroups + group]: counts, then where they go
  std::vector<std::uint32_t> order_;
};

}  // namespace rtpg
