#include "render/distribution.h"

#include <algorithm>
#include <cmath>

namespace rtpg {

Distribution1D::Distribution1D(std::vector<float> weights) : weights_(std::move(weights)) {
  cdf_.assign(weights_.size() + 1, 0.0);
  for (std::size_t i = 0; i < weights_.size(); ++i) {
    if (!(weights_[i] > 0.0f) || !std::isfinite(weights_[i])) weights_[i] = 0.0f;
    cdf_[i + 1] = cdf_[i] + weights_[i];
  }
  total_ = static_cast<float>(cdf_.back());
  probabilities_.resize(weights_.size());
  std::size_t cells_with_weight = 0;
  only_cell_ = weights_.size();
  for (std::size_t i = 0; i < weights_.size(); ++i) {
    probabilities_[i] = total_ > 0.0f ? weights_[i] / total_ : 0.0f;
    if (weights_[i] > 0.0f) {
      ++cells_with_weight;
      only_cell_ = i;
    }
  }
  if (cells_with_weight != 1) only_cell_ = weights_.size();
}

std::size_t Distribution1D::sample_discrete(float u, float* probability, float* remapped) const {
  if (only_cell_ < weights_.size()) {
    // What the search below gives for one cell with weight w: cdf = w exactly (a float in a
    // double), so target = u * w is exact and (target - 0) / w = u, before the same clamp.
    if (probability) *probability = probabilities_[only_cell_];
    if (remapped) *remapped = remap(u, only_cell_);
    return only_cell_;
  }
  const double target = static_cast<double>(u) * cdf_.back();
  std::size_t i = 0;
  if (weights_.size() <= kCountedCells) {
    // The index upper_bound finds, counted without a branch: the cells whose upper end is at or
    // below the target. A search's branch goes either way at random (u is uniform), and a
    // scene's few emissive triangles (two for a quad light) made it a fifth of next-event
    // estimation's light sampling (docs/host-path-tracer.md, "Light selection by counting").
    for (std::size_t k = 1; k <= weights_.size(); ++k) i += cdf_[k] <= target;
  } else {
    i = static_cast<std::size_t>(std::upper_bound(cdf_.begin() + 1, cdf_.end(), target) -
                                 cdf_.begin()) -
        1;
  }
  i = std::min(i, weights_.size() - 1);
  // u at the very top of a run of empty cells; the weight tested first, as i > 0 alone is as
  // random as u
  while (weights_[i] == 0.0f && i > 0) --i;
  if (probability) *probability = this->probability(i);
  if (remapped) *remapped = remap(u, i);
  return i;
}

float Distribution1D::remap(float u, std::size_t i) const {
  if (only_cell_ < weights_.size()) return remap_in_only_cell(u);
  const double target = static_cast<double>(u) * cdf_.back();
  const double width = cdf_[i + 1] - cdf_[i];
  const double r = width > 0.0 ? (target - cdf_[i]) / width : 0.5;
  return static_cast<float>(std::clamp(r, 0.0, 1.0 - 1e-7));
}

float Distribution1D::sample_continuous(float u, float* pdf, std::size_t* cell) const {
  const std::size_t i = sample_discrete(u, nullptr);
  const double lo = cdf_[i], width = cdf_[i + 1] - cdf_[i];
  double offset = width > 0.0 ? (static_cast<double>(u) * cdf_.back() - lo) / width : 0.5;
  offset = std::clamp(offset, 0.0, 1.0 - 1e-7);
  const float n = static_cast<float>(weights_.size());
  if (pdf) *pdf = total_ > 0.0f ? weights_[i] * n / total_ : 0.0f;
  if (cell) *cell = i;
  return std::min((static_cast<float>(i) + static_cast<float>(offset)) / n, 0.99999994f);
}

float Distribution1D::pdf_continuous(float x) const {
  if (total_ <= 0.0f) return 0.0f;
  const float n = static_cast<float>(weights_.size());
  const std::size_t i =
      std::min(static_cast<std::size_t>(std::max(x, 0.0f) * n), weights_.size() - 1);
  return weights_[i] * n / total_;
}

Distribution2D::Distribution2D(const std::vector<float>& weights, int width, int height) {
  std::vector<float> row_totals(height);
  rows_.reserve(height);
  for (int y = 0; y < height; ++y) {
    rows_.emplace_back(
        std::vector<float>(weights.begin() + static_cast<std::ptrdiff_t>(y) * width,
                           weights.begin() + static_cast<std::ptrdiff_t>(y + 1) * width));
    row_totals[y] = rows_.back().total();
  }
  marginal_ = Distribution1D(std::move(row_totals));
}

void Distribution2D::sample(float u0, float u1, float& u, float& v, float& pdf) const {
  float pdf_v = 0.0f, pdf_u = 0.0f;
  std::size_t row = 0;
  v = marginal_.sample_continuous(u1, &pdf_v, &row);
  u = rows_[row].sample_continuous(u0, &pdf_u, nullptr);
  pdf = pdf_v * pdf_u;
}

float Distribution2D::pdf(float u, float v) const {
  const std::size_t h = rows_.size();
  const std::size_t row =
      std::min(static_cast<std::size_t>(std::max(v, 0.0f) * static_cast<float>(h)), h - 1);
  return marginal_.pdf_continuous(v) * rows_[row].pdf_continuous(u);
}

}  // namespace rtpg
