// Piecewise-constant densities for light selection and environment map sampling
// (pbrt's Distribution1D/2D): sample in proportion to non-negative weights, return the density.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace rtpg {

class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(std::vector<float> weights);
  std::size_t size() const { return weights_.size(); }
  float total() const { return total_; }
  // Discrete: index with probability weight / total (u in [0,1)).
  // remapped (optional) receives u's relative position inside the chosen cell, a fresh
  // uniform number for the next decision.
  std::size_t sample_discrete(float u, float* probability = nullptr,
                              float* remapped = nullptr) const;
  // The remapped number sample_discrete gives for u, which picked cell i: for a caller that
  // needs it for some cells only (its double division is a fifth of a light sample).
  float remap(float u, std::size_t i) const;
  // What remap gives in a distribution whose weight is all in one cell: u, kept below 1.
  static float remap_in_only_cell(float u) {
    return static_cast<float>(std::clamp(static_cast<double>(u), 0.0, 1.0 - 1e-7));
  }
  // 0 for an index outside the distribution (an empty one has no cells).
  float probability(std::size_t i) const {
    return i < probabilities_.size() ? probabilities_[i] : 0.0f;
  }
  // Continuous on [0,1): returns x, writes the density over [0,1) and the cell index.
  float sample_continuous(float u, float* pdf, std::size_t* cell) const;
  float pdf_continuous(float x) const;

 private:
  std::vector<float> weights_;
  std::vector<double> cdf_;  // size()+1 entries; double: sums over millions of texels
  std::vector<float>
      probabilities_;  // weight / total, once (next-event estimation asks per vertex)
  float total_ = 0.0f;
  // Up to this many cells sample_discrete counts instead of searching.
  static constexpr std::size_t kCountedCells = 16;
  // The only cell with weight (a scene with one kind of light), else size(): sampling it needs
  // no search and no division.
  std::size_t only_cell_ = 0;
};

// Over [0,1)^2, rows along v: a marginal over v, a conditional over u per row.
class Distribution2D {
 public:
  Distribution2D() = default;
  Distribution2D(const std::vector<float>& weights, int width, int height);
  // Returns (u, v) and the density over [0,1)^2.
  void sample(float u0, float u1, float& u, float& v, float& pdf) const;
  float pdf(float u, float v) const;
  bool empty() const { return rows_.empty(); }

 private:
  std::vector<Distribution1D> rows_;
  Distribution1D marginal_;
};

}  // namespace rtpg
