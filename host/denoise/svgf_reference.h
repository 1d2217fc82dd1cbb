// The SVGF denoiser on the host, pixel for pixel what kernels/svgf_*.cl do with the same
// functions (kernels/shared/svgf.h): the reference the kernel tests compare the device denoiser
// (host/denoise/svgf_denoiser.h) against. Single-threaded; not for rendering.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "denoise/svgf_settings.h"
#include "denoise/svgf_stage.h"
#include "render/gbuffer.h"

namespace rtpg {

class SvgfReference {
 public:
  // Throws InputError for settings out of range or a size below 1x1.
  SvgfReference(int width, int height, const SvgfSettings& settings = {});

  // Filters one frame of noisy colour seen through the G-buffer g; returns the denoised colour
  // (stage(SvgfStage::Output) holds it with w = 1). Throws InputError when the sizes do not
  // match.
  const std::vector<glm::vec3>& denoise(const std::vector<glm::vec3>& colour, const GBuffer& g);
  // Forgets the history: the next frame starts anew.
  void reset() { has_history_ = false; }

  const std::vector<glm::vec4>& stage(SvgfStage stage) const;
  const std::vector<float>& depth_slope() const { return depth_slope_; }

 private:
  void temporal(const std::vector<glm::vec3>& colour, const GBuffer& g);
  void variance();
  void atrous(const std::vector<glm::vec4>& in, std::vector<glm::vec4>& out, int step,
              int radius) const;
  void remodulate(const std::vector<glm::vec3>& colour, const GBuffer& g);

  int width_, height_;
  SvgfSettings settings_;
  shared::pg_svgf_settings kernel_settings_;
  bool has_history_ = false;
  std::vector<glm::vec4> surface_, integrated_, moments_, illumination_, filtered_, history_,
      output_, scratch_;
  std::vector<glm::vec3> denoised_;  // output_'s rgb
  std::vector<float> depth_slope_;
  // Last frame's G-buffer channels that the history test reads.
  std::vector<glm::vec4> prev_position_depth_, prev_normal_;
  std::vector<std::uint32_t> prev_material_;
  std::vector<glm::vec4> prev_moments_;
};

// InputError unless colour and g hold width x height pixels.
void check_svgf_input(int width, int height, const std::vector<glm::vec3>& colour,
                      const GBuffer& g);

}  // namespace rtpg
