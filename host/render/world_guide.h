// A guide for the path vertices after the first bounce that lives in world space, not in the
// image: a hash grid of cells (position and the normal's dominant axis), each with the paper's
// mixture of one Gaussian in the square of the cell's hemisphere and the vertex's BSDF (the model
// of shared/pmm.h, trained by the same stepwise EM from every later vertex's bounce, not only
// from the first bounce's VPLs). Screen-space borrowing (--guide-vertices all) reaches only the
// vertices the camera sees; most of the error of the strongly indirect scenes lies at vertices it
// does not (docs/guiding.md, "Where the variance is", and "A world-space guide for later
// vertices"). An experiment, off by default (--guide-vertices world).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "render/first_bounce.h"
#include "rtpg/guiding_layout.h"
#include "shared/pmm.h"

namespace rtpg {

// The largest WorldGuideSettings::max_cells_log2: the training's slot indices are 32 bits.
constexpr int kMaxCellsLog2 = 30;

struct WorldGuideSettings {
  int resolution = 32;      // cells along the scene's longest extent
  int max_cells_log2 = 20;  // at most 2^n cells, n in [0, kMaxCellsLog2] (the table doubles as
                            // cells are made)
  int max_depth = 2;        // the deepest path vertex guided and trained (y is 1)
  int record_every = 1;     // one path in n records its vertices for training (all sample)
  // A cell guides only where its lobe's mixing weight exceeds this (0: every cell with a model;
  // 0.06 and 0.1, which leave out the cells at the lower clamp, gained neither error nor time:
  // docs/guiding.md, "A world-space guide for later vertices").
  float min_guiding_pi = 0.0f;
  pg_kernel_settings em{};  // the mixture's EM settings (the pixels', to_kernel_settings)
};

// One later vertex's bounce as a training sample of its cell (shared/pmm.h: a = lum(L_i f cos)
// / r, u the direction in the cell's square, the vertex's BSDF density and the density r the
// direction was drawn with).
struct WorldTrainingSample {
  std::uint64_t cell;
  float a, ux, uy, bsdf_pdf, density;
};

class WorldGuide {
 public:
  static constexpr std::uint64_t kNoCell = ~std::uint64_t{0};

  WorldGuide(const glm::vec3& bounds_min, const glm::vec3& bounds_max,
             const WorldGuideSettings& settings);

  // The cell of a surface point (kNoCell outside the grid's bounds).
  std::uint64_t cell_of(const glm::vec3& position, const glm::vec3& normal) const;
  // The hemisphere frame of a cell: its normal axis.
  static shared::pg_frame cell_frame(std::uint64_t cell);
  // The cell's trained mixture, in its frame; false where it has none.
  bool guide(std::uint64_t cell, PixelGuide& out) const;
  // Starts loading the slots of the cells at a position (the shading loop asks a few vertices
  // ahead, before it knows the normal: a position's cells share their first slot).
  void prefetch(const glm::vec3& position) const;

  // After a frame's last sample: each cell with samples takes one step of the pixels' stepwise
  // EM (pg_pmm_train, one E-step pass); cells seen for the first time are made and seeded.
  // `blocks` hold the frame's samples in a fixed order (the path tracer's blocks of paths), and
  // each cell sums its samples in that order, so the guide is the same whatever the thread
  // count. Not concurrent with lookups.
  void train(const std::vector<std::vector<WorldTrainingSample>>& blocks);

  const WorldGuideSettings& settings() const { return settings_; }
  std::size_t cell_count() const { return used_; }
  std::size_t samples_last_frame() const { return samples_last_; }
  // Over the cells with a model after the last train(): their mean mixing weight, and the
  // fraction at the lower clamp (pi_min: the lobe explains little of what the cell saw).
  double mean_pi() const { return mean_pi_; }
  double fraction_at_pi_min() const { return at_pi_min_; }

 private:
  // What a lookup reads, apart from the EM state only training reads: 40 bytes a slot, so that
  // the table of a scene's cells mostly stays in cache.
  struct Slot {
    std::uint64_t cell = kNoCell;
    shared::pg_pmm_model model{};
  };
  std::size_t home(std::uint64_t cell) const;
  std::size_t find(std::uint64_t cell) const;  // its slot, or slots_.size()
  std::size_t find_or_insert(std::uint64_t cell);
  void grow();
  // slot_of_[k]: the slot of the frame's sample k (slots_.size(): the table is full).
  void find_slots(const std::vector<std::vector<WorldTrainingSample>>& blocks);

  WorldGuideSettings settings_;
  glm::vec3 origin_;
  float inverse_cell_ = 1.0f;
  std::vector<Slot> slots_;
  std::vector<shared::pg_pmm_state> states_;  // per slot
  std::size_t mask_ = 0, used_ = 0, samples_last_ = 0;
  double mean_pi_ = 0.0, at_pi_min_ = 0.0;
  // Training's scratch, kept from frame to frame: the samples' slots and block offsets, each
  // slot's first sample in the samples grouped by slot (a counting sort), and those samples as
  // pg_pmm_train reads them (weight, square point, BSDF density; the density drawn with).
  std::vector<std::uint32_t> slot_of_, slot_begin_;
  std::vector<std::uint32_t> group_next_;  // per group of blocks and slot: count, then next place
  std::vector<std::size_t> block_offset_, misses_;  // misses_: per block, samples without a slot
  std::vector<shared::float4> sorted_packed_;
  std::vector<float> sorted_density_;
};

}  // namespace rtpg
