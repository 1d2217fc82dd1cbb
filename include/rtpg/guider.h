// rtpg's guiding library: screen-space path guiding with a per-pixel parametric mixture
// (one 2D Gaussian in Shirley-Chiu square space plus the BSDF lobe), trained online by EM
// from the VPLs of neighbouring pixels and carried across frames by reprojection (paper
// "Real-Time Path-Guiding Based on Parametric Mixture Models").
//
// A renderer that uses it keeps its own G-buffer and VPL buffers on the device, in the
// layouts of kernels/shared/gbuffer.h and vpl.h (one entry per pixel, row-major):
//   per frame:  guider.reproject(current, previous)   state of last frame -> this frame
//               guider.sample(current, ..., out)        first-bounce directions + pdf
//               ... the renderer traces its paths and writes one VPL per pixel ...
//               guider.train(current, vpls, ...)        one EM step per pixel
// Only the guider knows its state; it knows nothing of scenes, files or ray tracing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "cl/cl_include.h"

namespace rtpg {

class ClRuntime;

// Misuse of the guider: buffers of the wrong size, a tile that does not fit in the device's
// local memory, a local size the device refuses.
class GuiderError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// Every parameter of guiding, with the defaults we measured or took from the paper.
struct GuidingConfig {
  float pi_min = 0.05f;  // clamp of the Gaussian's mixing weight (paper 3.2)
  float pi_max = 0.95f;
  float pi_init = 0.05f;       // weight of a new model (paper 3.1)
  int k_max = 32;              // epochs; the step size stops shrinking after k_max updates
  float step_alpha = 1.0f;     // eta_k = max((k+1)^-alpha, 1/(k_max+1)): 1 = plain mean until k_max
  float sigma_eps = 1e-4f;     // regularisation of Sigma's diagonal (square units^2)
  float sigma_prior = 5e-2f;   // prior variance, added as sigma_prior / (k + 1)
  float reseed_ratio = 10.0f;  // a sample with weight > ratio * W outside the lobe re-seeds it
  float weight_clamp = 0.0f;   // training weights clamped to weight_clamp * W (0 = no clamp)
  int em_passes = 3;           // E-step passes over each frame's samples
  float max_correlation = 0.95f;
  float roughness_skip = 0.05f;      // roughness at or below: BSDF only, no training
  int n_min = 5, n_max = 20;         // N = (1 - k/k_max) * (n_max - n_min) + n_min (paper 4.2);
                                     // n_min == n_max gives a fixed N
  int apron = 2;                     // neighbourhood radius: a (2*apron+1)^2 window of VPLs
  float max_weight = 1e8f;           // training weights above this are dropped as absurd
  float reproject_position = 0.05f;  // relative distance (to the depth) that rejects history
  float reproject_normal = 0.9f;     // normal cosine below which history is rejected
  int local_x = 16, local_y = 16;    // work-group size of the kernels (the VPL tile)
  enum class TrainMemory { Auto, Local, Global };
  // Local: VPL tile in local memory (GPUs); Global: direct reads (faster on PoCL). Auto
  // picks Global on CPU devices and Local elsewhere.
  TrainMemory train_memory = TrainMemory::Auto;
};

// One frame's G-buffer on the device (float4 / uint / float2 per pixel).
struct GuiderGBuffer {
  cl::Buffer position_depth;        // float4: xyz position, w linear depth
  cl::Buffer shading_normal;        // float4: xyz
  cl::Buffer view_dir;              // float4: xyz, unit, towards the camera
  cl::Buffer base_color_roughness;  // float4
  cl::Buffer metallic_specular;     // float4: x metallic, y dielectric F0
  cl::Buffer flags;                 // uint: PG_GBUF_* bits
  cl::Buffer material;              // uint: material id (reprojection test)
  cl::Buffer motion;                // float2: offset to the pixel's position last frame
};

// One VPL per pixel (kernels/shared/vpl.h), radiance_info.w holding the info bits.
struct GuiderVpls {
  cl::Buffer position, normal, radiance_info;  // float4 each
};

// What sample() writes: float4 (world direction, mixture pdf) and uint strategy per pixel.
struct GuiderSamples {
  cl::Buffer direction_pdf, strategy;
};

struct GuiderTimes {
  double reproject_ms = 0.0, sample_ms = 0.0, train_ms = 0.0;  // from profiling events
};

class Guider {
 public:
  // Throws GuiderError when the configuration cannot run on the runtime's device.
  Guider(ClRuntime& runtime, int width, int height, const GuidingConfig& config = {});
  ~Guider();
  Guider(const Guider&) = delete;
  Guider& operator=(const Guider&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  const GuidingConfig& config() const { return config_; }
  bool train_uses_local_memory() const { return local_tile_; }

  void reset();  // every pixel back to the initial state (k = 0: BSDF sampling)
  // Carries last frame's state into this frame (previous: last frame's G-buffer).
  void reproject(const GuiderGBuffer& current, const GuiderGBuffer& previous);
  void sample(const GuiderGBuffer& current, std::uint32_t seed, std::uint32_t frame,
              std::uint32_t sample_index, const GuiderSamples& out);
  void train(const GuiderGBuffer& current, const GuiderVpls& vpls, std::uint32_t seed,
             std::uint32_t frame);

  // The state, 8 floats per pixel (s0.xyzw then s1.xyzw; kernels/shared/pmm.h).
  void read_state(std::vector<float>& state);
  void write_state(const std::vector<float>& state);
  // Pixels whose state the last train() changed (reads a byte per pixel back).
  std::size_t count_trained();

  const GuiderTimes& last_times() const { return times_; }

 private:
  void check_gbuffer(const GuiderGBuffer& g, const char* which) const;
  void check_buffer(const cl::Buffer& b, std::size_t element_size, const std::string& name) const;
  cl::NDRange global_range() const;
  double run(cl::Kernel& kernel);  // launches over the image, waits, returns profiled ms

  ClRuntime& runtime_;
  int width_, height_;
  GuidingConfig config_;
  bool local_tile_ = false;
  cl::Buffer state0_[2], state1_[2];
  cl::Buffer trained_;
  int current_ = 0;  // index of the buffers holding this frame's state
  cl::Kernel reproject_, sample_, train_;
  GuiderTimes times_;
};

}  // namespace rtpg
