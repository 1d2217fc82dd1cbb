#include "render/world_guide.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <tbb/parallel_for.h>

namespace rtpg {
namespace {

constexpr int kAxisBits = 20;
constexpr std::uint64_t kAxisMask = (std::uint64_t{1} << kAxisBits) - 1;

// The normal's dominant axis and its sign: 0..5 = +x, -x, +y, -y, +z, -z. Selects, not branches:
// a bounce lands on any wall, so a branch here would go either way at random.
std::uint64_t normal_bin(const glm::vec3& n) {
  const float ax = std::fabs(n.x), ay = std::fabs(n.y), az = std::fabs(n.z);
  const bool x_major = ax >= ay && ax >= az, y_major = !x_major && ay >= az;
  const float major = x_major ? n.x : (y_major ? n.y : n.z);
  const std::uint64_t axis = x_major ? 0u : (y_major ? 1u : 2u);
  return 2u * axis + (major < 0.0f ? 1u : 0u);
}

// A grid position's bits (0 <= g < 2^20 on each axis, checked by the caller): through 32-bit
// integers, as a float's conversion to a 64-bit unsigned one takes a branch and two conversions
// on the x86-64 baseline.
std::uint64_t position_bits(const glm::vec3& g) {
  const auto x =
      static_cast<std::uint64_t>(static_cast<std::uint32_t>(static_cast<std::int32_t>(g.x)));
  const auto y =
      static_cast<std::uint64_t>(static_cast<std::uint32_t>(static_cast<std::int32_t>(g.y)));
  const auto z =
      static_cast<std::uint64_t>(static_cast<std::uint32_t>(static_cast<std::int32_t>(g.z)));
  return x | (y << kAxisBits) | (z << (2 * kAxisBits));
}

std::uint64_t mix(std::uint64_t x) {  // splitmix64's finaliser
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ull;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

// The six normal bins' hemisphere frames, made once (every guided vertex asks for one).
std::array<shared::pg_frame, 6> make_cell_frames() {
  std::array<shared::pg_frame, 6> frames;
  for (int bin = 0; bin < 6; ++bin) {
    glm::vec3 axis(0.0f);
    axis[bin / 2] = bin % 2 == 0 ? 1.0f : -1.0f;
    frames[static_cast<std::size_t>(bin)] = shared::pg_frame_from_normal(axis);
  }
  return frames;
}

const std::array<shared::pg_frame, 6> kCellFrames = make_cell_frames();

}  // namespace

WorldGuide::WorldGuide(const glm::vec3& bounds_min, const glm::vec3& bounds_max,
                       const WorldGuideSettings& settings)
    : settings_(settings) {
  const glm::vec3 extent = bounds_max - bounds_min;
  const float longest = std::max(extent.x, std::max(extent.y, extent.z));
  const float cell =
      longest > 0.0f ? longest / static_cast<float>(std::max(settings.resolution, 1)) : 1.0f;
  inverse_cell_ = 1.0f / cell;
  // Half a cell of margin: points on the bounds' faces stay inside.
  origin_ = bounds_min - glm::vec3(0.5f * cell);
  // 4096 slots to start with, fewer where at most 2^max_cells_log2 cells (half the slots) may be
  // made; the Renderer keeps max_cells_log2 in [0, kMaxCellsLog2].
  slots_.resize(std::size_t{2} << std::clamp(settings.max_cells_log2, 0, 11));
  states_.resize(slots_.size());
  mask_ = slots_.size() - 1;
}

std::uint64_t WorldGuide::cell_of(const glm::vec3& position, const glm::vec3& normal) const {
  const glm::vec3 g = (position - origin_) * inverse_cell_;
  if (!(g.x >= 0.0f && g.y >= 0.0f && g.z >= 0.0f)) return kNoCell;
  const float limit = static_cast<float>(kAxisMask);
  if (!(g.x < limit && g.y < limit && g.z < limit)) return kNoCell;
  return position_bits(g) | (normal_bin(normal) << (3 * kAxisBits));
}

shared::pg_frame WorldGuide::cell_frame(std::uint64_t cell) {
  return kCellFrames[cell >> (3 * kAxisBits)];
}

std::size_t WorldGuide::home(std::uint64_t cell) const {
  // The position alone: a position's cells (one per normal bin) share their first slot.
  const std::uint64_t position_bits = cell & ((std::uint64_t{1} << (3 * kAxisBits)) - 1);
  return static_cast<std::size_t>(mix(position_bits)) & mask_;
}

std::size_t WorldGuide::find(std::uint64_t cell) const {
  // kNoCell is also the empty slots' key: it has no slot.
  if (cell == kNoCell) return slots_.size();
  for (std::size_t s = home(cell);; s = (s + 1) & mask_) {
    if (slots_[s].cell == cell) return s;
    if (slots_[s].cell == kNoCell) return slots_.size();
  }
}

std::size_t WorldGuide::find_or_insert(std::uint64_t cell) {
  if (cell == kNoCell) return slots_.size();
  // A cell made earlier in this frame's training is found, not refused by a full table (the
  // samples after its first would be dropped) nor a reason to grow.
  const std::size_t found = find(cell);
  if (found != slots_.size()) return found;
  // Linear probing stays short while at most half the slots are used.
  if (2 * (used_ + 1) > slots_.size()) {
    if (slots_.size() >= (std::size_t{2} << settings_.max_cells_log2)) return slots_.size();
    grow();
  }
  std::size_t s = home(cell);
  while (slots_[s].cell != kNoCell) s = (s + 1) & mask_;
  slots_[s].cell = cell;
  states_[s] = shared::pg_pmm_initial_state();
  ++used_;
  return s;
}

void WorldGuide::grow() {
  std::vector<Slot> old_slots(slots_.size() * 2);
  std::vector<shared::pg_pmm_state> old_states(old_slots.size());
  old_slots.swap(slots_);
  old_states.swap(states_);
  mask_ = slots_.size() - 1;
  for (std::size_t o = 0; o < old_slots.size(); ++o) {
    if (old_slots[o].cell == kNoCell) continue;
    std::size_t s = home(old_slots[o].cell);
    while (slots_[s].cell != kNoCell) s = (s + 1) & mask_;
    slots_[s] = old_slots[o];
    states_[s] = old_states[o];
  }
}

bool WorldGuide::guide(std::uint64_t cell, PixelGuide& out) const {
  const std::size_t s = find(cell);
  if (s == slots_.size() || !slots_[s].model.valid ||
      !(slots_[s].model.pi > settings_.min_guiding_pi))
    return false;
  out.model = slots_[s].model;
  out.frame = cell_frame(cell);
  return true;
}

void WorldGuide::prefetch(const glm::vec3& position) const {
  const glm::vec3 g = (position - origin_) * inverse_cell_;
  const float limit = static_cast<float>(kAxisMask);
  if (g.x >= 0.0f && g.y >= 0.0f && g.z >= 0.0f && g.x < limit && g.y < limit && g.z < limit)
    __builtin_prefetch(&slots_[home(position_bits(g))]);
}

void WorldGuide::find_slots(const std::vector<std::vector<WorldTrainingSample>>& blocks) {
  misses_.assign(blocks.size(), 0);
  tbb::parallel_for(std::size_t{0}, blocks.size(), [&](std::size_t b) {
    const std::vector<WorldTrainingSample>& block = blocks[b];
    std::size_t missed = 0;
    for (std::size_t k = 0; k < block.size(); ++k) {
      const std::size_t s = find(block[k].cell);
      slot_of_[block_offset_[b] + k] = static_cast<std::uint32_t>(s);
      missed += s == slots_.size();
    }
    misses_[b] = missed;
  });
}

void WorldGuide::train(const std::vector<std::vector<WorldTrainingSample>>& blocks) {
  block_offset_.resize(blocks.size() + 1);
  block_offset_[0] = 0;
  for (std::size_t b = 0; b < blocks.size(); ++b)
    block_offset_[b + 1] = block_offset_[b] + blocks[b].size();
  const std::size_t total = block_offset_.back();
  samples_last_ = total;
  if (total == 0) return;
  slot_of_.resize(total);
  find_slots(blocks);
  // Cells seen for the first time are made in the samples' order (serially: the table's layout
  // is then the same on every run); if the table grew, every slot moved.
  const std::size_t slots_before = slots_.size();
  bool made = false;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    if (misses_[b] == 0) continue;
    for (std::size_t k = 0; k < blocks[b].size(); ++k)
      if (slot_of_[block_offset_[b] + k] == slots_before) {
        const std::size_t s = find_or_insert(blocks[b][k].cell);
        made = true;
        if (slots_.size() == slots_before && s != slots_.size())
          slot_of_[block_offset_[b] + k] = static_cast<std::uint32_t>(s);
      }
  }
  if (made && slots_.size() != slots_before) find_slots(blocks);
  // The samples grouped by slot, in their order within each slot (a counting sort that moves
  // what the E-step reads, so that each cell then reads its samples in one run). Groups of
  // consecutive blocks count and move their samples in parallel, each from its own offsets:
  // a slot's samples are group 0's in order, then group 1's, ..., the paths' order whatever
  // the number of groups.
  const std::size_t slot_count = slots_.size();
  const std::size_t groups = std::min<std::size_t>(blocks.size(), 8);
  const auto group_blocks = [&](std::size_t g) {
    return std::make_pair(g * blocks.size() / groups, (g + 1) * blocks.size() / groups);
  };
  group_next_.assign(groups * slot_count, 0);
  tbb::parallel_for(std::size_t{0}, groups, [&](std::size_t g) {
    std::uint32_t* count = &group_next_[g * slot_count];
    const auto [first, last] = group_blocks(g);
    for (std::size_t k = block_offset_[first]; k < block_offset_[last]; ++k)
      if (slot_of_[k] < slot_count) ++count[slot_of_[k]];
  });
  slot_begin_.resize(slot_count + 1);
  std::uint32_t at = 0;
  for (std::size_t s = 0; s < slot_count; ++s) {
    slot_begin_[s] = at;
    for (std::size_t g = 0; g < groups; ++g) {
      const std::uint32_t n = group_next_[g * slot_count + s];
      group_next_[g * slot_count + s] = at;
      at += n;
    }
  }
  slot_begin_[slot_count] = at;
  sorted_packed_.resize(at);
  sorted_density_.resize(at);
  tbb::parallel_for(std::size_t{0}, groups, [&](std::size_t g) {
    std::uint32_t* next = &group_next_[g * slot_count];
    const auto [first, last] = group_blocks(g);
    for (std::size_t b = first; b < last; ++b) {
      const std::uint32_t* slot = &slot_of_[block_offset_[b]];
      for (const WorldTrainingSample& sample : blocks[b]) {
        const std::uint32_t s = *slot++;
        if (s >= slot_count) continue;
        const std::uint32_t to = next[s]++;
        sorted_packed_[to] = shared::float4(sample.a, sample.ux, sample.uy, sample.bsdf_pdf);
        sorted_density_[to] = sample.density;
      }
    }
  });
  const pg_kernel_settings& p = settings_.em;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, slot_count, 1024), [&](const auto& range) {
    for (std::size_t s = range.begin(); s != range.end(); ++s) {
      const std::size_t begin = slot_begin_[s], n = slot_begin_[s + 1] - begin;
      if (n == 0) continue;
      int updated = 0;
      states_[s] = shared::pg_pmm_train(states_[s], &sorted_packed_[begin], &sorted_density_[begin],
                                        static_cast<int>(n), p, static_cast<float>(n), 1, &updated);
      slots_[s].model = shared::pg_pmm_model_from_state(states_[s], p);
    }
  });
  double pi_sum = 0.0;
  std::size_t with_model = 0, at_min = 0;
  for (const Slot& slot : slots_) {
    if (slot.cell == kNoCell || !slot.model.valid) continue;
    ++with_model;
    pi_sum += slot.model.pi;
    at_min += slot.model.pi <= p.pi_min;
  }
  mean_pi_ = with_model ? pi_sum / static_cast<double>(with_model) : 0.0;
  at_pi_min_ = with_model ? static_cast<double>(at_min) / static_cast<double>(with_model) : 0.0;
}

}  // namespace rtpg
