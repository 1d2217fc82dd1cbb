// Every setting of guiding, its default, bounds and meaning, in one table. The command line
// builds its --pg-* flags from the table, the guider validates against it, and the stats JSON
// records every row (host/app); the kernels receive the settings as one pg_kernel_settings
// block (include/rtpg/guiding_layout.h), built once per Guider.
#pragma once

#include <string>
#include <vector>

#include "rtpg/guiding_layout.h"
#include "rtpg/setting_info.h"

namespace rtpg {

struct GuidingSettings {
  float pi_min = 0.05f;     // clamp of the Gaussian's mixing weight (paper 3.2)
  float pi_max = 0.5f;      // the paper's 0.95 lets a lobe narrower than its target cost up to
                            // 20x BSDF sampling's second moment (docs/guiding.md, "Mixing weight")
  float pi_init = 0.05f;    // weight of a new model (paper 3.1)
  int k_max = 32;           // epochs; the step size stops shrinking after k_max updates
  float step_alpha = 1.0f;  // eta_k = max((k+1)^-alpha, 1/(k_max+1)): 1 = plain mean until k_max
  float sigma_eps = 1e-4f;  // regularisation of Sigma's diagonal (square units^2)
  float sigma_prior = 5e-2f;   // prior variance, added as sigma_prior / (k + 1)
  float reseed_ratio = 10.0f;  // a sample with weight > ratio * W outside the lobe re-seeds it,
  int reseed_samples = 2;      // when this many samples of one frame's batch say so (one may be
                               // a firefly; docs/guiding.md, "Re-seeds that take two samples")
  float weight_clamp = 0.0f;   // training weights clamped to weight_clamp * W (0 = no clamp)
  int em_passes = 3;           // E-step passes over each frame's samples
  float max_correlation = 0.95f;
  float roughness_skip = 0.05f;        // roughness at or below: BSDF only, no training
  int n_min = 5, n_max = 20;           // N = (1 - k/k_max) * (n_max - n_min) + n_min (paper 4.2);
                                       // n_min == n_max gives a fixed N
  int apron = 2;                       // neighbourhood radius: a (2*apron+1)^2 window of VPLs
  float max_weight = 1e30f;            // training weights above this are dropped as absurd:
                                       // beyond any radiance unit, below what a batch's sums
                                       // can hold (docs/robustness.md, "Radiance scale")
  float reproject_position = 0.05f;    // relative distance (to the depth) that rejects history
  float reproject_normal = 0.9f;       // normal cosine below which history is rejected
  float reproject_view_memory = 0.0f;  // where a pixel's BSDF has a glossy lobe, its carried
                                       // model's age k falls by 1/e for every this many GGX
                                       // alphas (radians) its view turns, so a stale lobe is
                                       // relearnt; 0: k survives reprojection (paper 3.1)
                                       // (docs/guiding.md, "Glossy history under a moving camera")
  int train_interval = 2;     // a mature pixel (k >= k_max / 4) trains every this many frames,
                              // in a rotating pattern (the rest keep their state); 2: the
                              // same error as 1 for 14-24% less train time
                              // (docs/guiding.md, "What amortised training saves")
  int train_all_samples = 1;  // 1: every VPL trains, weighted by its full mixture density;
                              // 0: BSDF-strategy VPLs only (paper 3.2); 1 since it costs nothing
                              // in train_wide (docs/guiding.md, "Every VPL trains, revisited")
  int rows_per_model = 0;     // 1, 2, 4 or 8: the pixels of a column's group of this many rows
                              // that show the first one's surface, normals within 1.1 degrees,
                              // both diffuse or rough (kernels/shared/guiding_pixel.h,
                              // pg_shares_model), sample with its model, carry it as their own
                              // state and train none, so train runs on fewer pixels; 1 is the
                              // paper's model per pixel; 0: by the image's height
                              // (rows_per_model_for_height; docs/guiding.md, "Models shared by
                              // rows")
  int pi_learning = 0;        // 1: the mixing weight is the one that minimises the first
                              // bounce's second moment (a Newton step per frame on the
                              // training samples); 0: EM's weight (paper 3.2)
                              // (docs/guiding.md, "A mixing weight that minimises the variance")
  // Work-group size of the kernels (the VPL tile of train.cl's local-memory variant); 0 and 0 =
  // per device: on CPU devices reproject and sample in rows of up to 128 work-items and train in
  // 16x16, 16x16 elsewhere (host/cl/work_groups.h; docs/guiding.md, "Work-groups along rows").
  int local_x = 0, local_y = 0;
  int train_lanes = 0;   // pixels per work-item of the train kernel: 1 (train.cl), or 2, 4, 8, 16
                         // in vector lanes (train_wide.cl); 0 = auto: on CPU devices the SIMD
                         // width in floats (CL_DEVICE_NATIVE_VECTOR_WIDTH_FLOAT), else 1
                         // (docs/guiding.md, "Several pixels per work-item")
  int sample_lanes = 0;  // the same for the sample kernel: 1 (sample.cl), or 2, 4, 8, 16
                         // (sample_wide.cl); 0 = auto as for train_lanes
  enum class TrainMemory { Auto, Local, Global };
  // Local: VPL tile in local memory (GPUs); Global: direct reads (faster on PoCL). Auto
  // picks Global on CPU devices and where train_lanes asks for more than one pixel per
  // work-item (train_wide.cl reads global memory), Local elsewhere.
  TrainMemory train_memory = TrainMemory::Auto;
};

using GuidingSettingInfo = SettingInfo<GuidingSettings>;

// Every numeric field of GuidingSettings, in declaration order.
const std::vector<GuidingSettingInfo>& guiding_settings_table();

// "auto", "local", "global" and back; parse returns false for another word.
const char* train_memory_name(GuidingSettings::TrainMemory memory);
bool parse_train_memory(const std::string& word, GuidingSettings::TrainMemory& memory);

// Throws GuiderError ("guiding settings: <name> ...") for a value outside its row's range or
// a broken relation between two rows (pi_min <= pi_max, n_min <= n_max).
void validate(const GuidingSettings& settings);

// rows_per_model 0's choice for an image `height` pixels high: the largest of 1, 2, 4 and 8
// whose group of rows spans at most 1/135 of the height (1080 and more rows: 8; 540-1079: 4;
// 270-539: 2; fewer: 1). A model serves pixels up to that far from its own: at 960x540 groups of
// 4 and at 1920x1080 groups of 8 cost no measured error, at 240x135 groups of 2 and 4 cost the
// untextured rooms 1-3% (docs/guiding.md, "Models shared by rows, by the image's height", "Eight
// rows per model from 1080 rows").
int rows_per_model_for_height(int height);

// The block the kernels read. Host code that evaluates the mixture itself (the
// GuidingDistribution) uses the same block. image_height resolves rows_per_model 0
// (rows_per_model_for_height); 0, for a block that serves no image (the world guide's EM), gives 1.
// Throws GuiderError where validate() does.
pg_kernel_settings to_kernel_settings(const GuidingSettings& settings, int image_height = 0);

}  // namespace rtpg
