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
#include <tbb/parallel_for.h>

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
  // The same order handed out instead of stored: move(slot, place) for every listed slot, place
  // its position in order()'s vector, each slot once, from several threads; returns how many
  // slots are listed. A caller that moves its slots' data into that order saves the order's
  // own pass (the path tracer's rays and pixels: PathTracer::group_rays).
  template <class Move>
  std::size_t arrange(const std::uint16_t* groups, std::size_t stride, const std::uint32_t* counts,
                      std::size_t lists, const Move& move);

 private:
  // Lists are split into at most this many chunks, each counted and written by one task: a fixed
  // number, so that the order does not depend on the thread count.
  static constexpr std::size_t kChunks = 4;
  static std::size_t chunks_of(std::size_t lists) { return lists < kChunks ? lists : kChunks; }
  // visit(slot) for the listed slots of chunk c, in slot order.
  template <class Visit>
  static void each_listed_slot(std::size_t c, std::size_t stride, const std::uint32_t* counts,
                               std::size_t lists, const Visit& visit) {
    const std::size_t chunks = chunks_of(lists);
    for (std::size_t l = lists * c / chunks, end = lists * (c + 1) / chunks; l != end; ++l)
      for (std::size_t s = l * stride, last = s + (counts[l] < stride ? counts[l] : stride);
           s != last; ++s)
        visit(s);
  }
  // starts_ made into where each chunk's slots of each group go; returns the listed slots.
  std::size_t count_starts(const std::uint16_t* groups, std::size_t stride,
                           const std::uint32_t* counts, std::size_t lists);

  glm::vec3 min_, cells_per_unit_;
  std::vector<std::uint32_t> starts_;  // [chunk * kGroups + group]: counts, then where they go
  std::vector<std::uint32_t> order_;
};

template <class Move>
std::size_t RayOrder::arrange(const std::uint16_t* groups, std::size_t stride,
                              const std::uint32_t* counts, std::size_t lists, const Move& move) {
  const std::size_t total = count_starts(groups, stride, counts, lists);
  tbb::parallel_for(std::size_t{0}, chunks_of(lists), [&](std::size_t c) {
    std::uint32_t* next = starts_.data() + c * kGroups;
    each_listed_slot(c, stride, counts, lists,
                     [&](std::size_t s) { move(s, static_cast<std::size_t>(next[groups[s]]++)); });
  });
  return total;
}

}  // namespace rtpg
