#include "rtpg/guiding_settings.h"

#include <cmath>
#include <limits>
#include <numeric>

#include "rtpg/errors.h"

namespace rtpg {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
using S = GuidingSettings;

constexpr auto real = &GuidingSettingInfo::real;
constexpr auto integer = &GuidingSettingInfo::integer;

// A step through the neighbourhood window that visits every cell once: coprime with its size.
int window_stride(int apron) {
  const int size = (2 * apron + 1) * (2 * apron + 1);
  for (int s = std::max(1, size / 3); s < size; ++s)
    if (std::gcd(s, size) == 1) return s;
  return 1;
}

}  // namespace

const std::vector<GuidingSettingInfo>& guiding_settings_table() {
  // The bounds are what the kernels' arithmetic needs (docs/guiding.md explains the values).
  static const std::vector<GuidingSettingInfo> table = {
      real("pi_min", &S::pi_min, 0, 1, false, true, "Lower clamp of the mixing weight"),
      real("pi_max", &S::pi_max, 0, 1, false, true, "Upper clamp of the mixing weight"),
      real("pi_init", &S::pi_init, 0, 1, true, true, "Mixing weight of a new model"),
      integer("k_max", &S::k_max, 1, 1e6, "Epochs after which the EM step size stops shrinking"),
      real("step_alpha", &S::step_alpha, 0, 1, true, false,
           "Step size exponent: eta_k = max((k+1)^-alpha, 1/(k_max+1))"),
      real("sigma_eps", &S::sigma_eps, 0, kInf, true, false,
           "Regularisation of the covariance diagonal"),
      real("sigma_prior", &S::sigma_prior, 0, kInf, false, false,
           "Prior variance, added as sigma_prior / (k + 1)"),
      real("reseed_ratio", &S::reseed_ratio, 0, kInf, true, false,
           "Re-seed a lobe on a sample this many times brighter than its history"),
      integer("reseed_samples", &S::reseed_samples, 1, PG_MAX_TRAIN_SAMPLES,
              "Samples of one batch that must call for a re-seed before it happens"),
      real("weight_clamp", &S::weight_clamp, 0, kInf, false, false,
           "Clamp training weights to this multiple of the running mean (0 = off)"),
      integer("em_passes", &S::em_passes, 1, 8, "E-step passes over each frame's training samples"),
      real("max_correlation", &S::max_correlation, 0, 1, true, true,
           "Bound of the Gaussian's correlation coefficient"),
      real("roughness_skip", &S::roughness_skip, 0, 1, false, false,
           "No guiding at or below this roughness"),
      integer("n_min", &S::n_min, 1, PG_MAX_TRAIN_SAMPLES, "Neighbour VPLs per pixel at k = k_max"),
      integer("n_max", &S::n_max, 1, PG_MAX_TRAIN_SAMPLES,
              "Neighbour VPLs per pixel at k = 0 (n_min = n_max: a fixed N)"),
      integer("apron", &S::apron, 0, 8, "Neighbourhood radius in pixels"),
      real("max_weight", &S::max_weight, 0, kInf, true, false,
           "Training weights above this are dropped as absurd"),
      real("reproject_position", &S::reproject_position, 0, kInf, false, false,
           "Position change, relative to the depth, that rejects history"),
      real("reproject_normal", &S::reproject_normal, -1, 1, false, false,
           "Normal cosine below which history is rejected"),
      real("reproject_view_memory", &S::reproject_view_memory, 0, kInf, false, false,
           "Glossy pixels: the carried model's age falls by 1/e per this many GGX alphas of view "
           "turn (0 = off)"),
      integer("train_interval", &S::train_interval, 1, 64,
              "A mature pixel (k >= k_max/4) trains every this many frames"),
      integer("rows_per_model", &S::rows_per_model, 0, 8,
              "1, 2, 4 or 8: pixels of a column's group of this many rows showing the first "
              "one's surface sample with its model and train none of their own (0: 8 from 1080 "
              "rows of image, 4 from 540, 2 from 270, else 1)"),
      integer("train_all_samples", &S::train_all_samples, 0, 1,
              "1: train on every VPL at its mixture density; 0: BSDF samples only"),
      integer("pi_learning", &S::pi_learning, 0, 1,
              "1: the mixing weight minimises the first bounce's second moment; 0: EM's"),
      integer("local_x", &S::local_x, 0, 65536,
              "Work-group (VPL tile) width (0 with local_y 0: per device)"),
      integer("local_y", &S::local_y, 0, 65536,
              "Work-group (VPL tile) height (0 with local_x 0: per device)"),
      integer("train_lanes", &S::train_lanes, 0, 16,
              "Pixels per work-item of the train kernel: 1, 2, 4, 8 or 16 (0: the SIMD width on "
              "CPUs, else 1)"),
      integer("sample_lanes", &S::sample_lanes, 0, 16,
              "Pixels per work-item of the sample kernel: 1, 2, 4, 8 or 16 (0: the SIMD width "
              "on CPUs, else 1)"),
  };
  return table;
}

const char* train_memory_name(GuidingSettings::TrainMemory memory) {
  switch (memory) {
    case GuidingSettings::TrainMemory::Local:
      return "local";
    case GuidingSettings::TrainMemory::Global:
      return "global";
    case GuidingSettings::TrainMemory::Auto:
      break;
  }
  return "auto";
}

bool parse_train_memory(const std::string& word, GuidingSettings::TrainMemory& memory) {
  for (auto m : {GuidingSettings::TrainMemory::Auto, GuidingSettings::TrainMemory::Local,
                 GuidingSettings::TrainMemory::Global})
    if (word == train_memory_name(m)) {
      memory = m;
      return true;
    }
  return false;
}

void validate(const GuidingSettings& s) {
  auto fail = [](const std::string& what) { throw GuiderError("guiding settings: " + what); };
  for (const GuidingSettingInfo& row : guiding_settings_table()) {
    const double v = row.get(s);
    if (!row.in_range(v))
      fail(std::string(row.name) + " = " + setting_number(v) + " is outside " + row.range_text());
  }
  if (s.pi_min > s.pi_max)
    fail("pi_min (" + setting_number(s.pi_min) + ") must not exceed pi_max (" +
         setting_number(s.pi_max) + ")");
  const std::pair<const char*, int> lanes[] = {{"train_lanes", s.train_lanes},
                                               {"sample_lanes", s.sample_lanes}};
  if (s.rows_per_model & (s.rows_per_model - 1))
    fail("rows_per_model = " + setting_number(s.rows_per_model) +
         " must be 0 (by the image's height) or a power of two: 1, 2, 4 or 8");
  for (const auto& [name, value] : lanes)
    if (value & (value - 1))
      fail(std::string(name) + " = " + setting_number(value) +
           " must be 0 (auto) or a power of two: 1, 2, 4, 8 or 16");
  if ((s.local_x == 0) != (s.local_y == 0))
    fail("local_x = " + setting_number(s.local_x) + " and local_y = " + setting_number(s.local_y) +
         ": both 0 (per device) or neither");
  if (s.n_min > s.n_max)
    fail("n_min (" + setting_number(s.n_min) + ") must not exceed n_max (" +
         setting_number(s.n_max) + ")");
  const int memory = static_cast<int>(s.train_memory);
  if (memory != static_cast<int>(GuidingSettings::TrainMemory::Auto) &&
      memory != static_cast<int>(GuidingSettings::TrainMemory::Local) &&
      memory != static_cast<int>(GuidingSettings::TrainMemory::Global))
    fail("train_memory = " + std::to_string(memory) + " is none of Auto, Local and Global");
}

int rows_per_model_for_height(int height) {
  int rows = 1;
  while (rows < 8 && 2 * rows * 135 <= height) rows *= 2;
  return rows;
}

pg_kernel_settings to_kernel_settings(const GuidingSettings& c, int image_height) {
  // Settings out of range are refused before any arithmetic on them (the window's stride of an
  // absurd apron overflowed an int).
  validate(c);
  pg_kernel_settings p{};
  p.pi_min = c.pi_min;
  p.pi_max = c.pi_max;
  p.pi_init = c.pi_init;
  p.k_max = static_cast<float>(c.k_max);
  p.step_alpha = c.step_alpha;
  p.sigma_eps = c.sigma_eps;
  p.max_correlation = c.max_correlation;
  p.roughness_skip = c.roughness_skip;
  p.n_min = static_cast<float>(c.n_min);
  p.n_max = static_cast<float>(c.n_max);
  p.max_weight = c.max_weight;
  p.reproject_position = c.reproject_position;
  p.reproject_normal = c.reproject_normal;
  p.reproject_view_memory = c.reproject_view_memory;
  p.sigma_prior = c.sigma_prior;
  p.reseed_ratio = c.reseed_ratio;
  p.weight_clamp = c.weight_clamp;
  p.em_passes = c.em_passes;
  p.apron = c.apron;
  p.stride = window_stride(c.apron);
  p.train_interval = c.train_interval;
  p.train_all_samples = c.train_all_samples;
  p.reseed_samples = c.reseed_samples;
  p.pi_learning = c.pi_learning;
  p.rows_per_model =
      c.rows_per_model > 0 ? c.rows_per_model : rows_per_model_for_height(image_height);
  return p;
}

}  // namespace rtpg
