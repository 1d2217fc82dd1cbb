// Temporal flicker of a displayed sequence under a moving camera (docs/design.md, "Metrics"):
// each pixel's change of displayed value (the PNG display transform of kernels/shared/tonemap.h
// at the scene's exposure, before its rounding to 8 bits) from last frame's pixel that shows the
// same surface, found through the motion vector (the nearest pixel) and the history test of
// reprojection (kernels/shared/same_surface.h). Squared, averaged over the pixels that have such
// a pixel and over the channels. Consecutive frames of a moving camera differ mostly because the
// picture moves; compared this way they differ by noise and by what the denoiser's history does.
// Pixels without history (sky, disocclusions, a silhouette that the camera's jitter moved) are
// left out and counted (tracked_fraction).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "render/gbuffer.h"

namespace rtpg {

class ReprojectedFlicker {
 public:
  struct Frame {
    double mse = -1.0;              // -1: the first frame, or no pixel has history
    double tracked_fraction = 0.0;  // share of all pixels that entered mse
  };
  // image and gbuffer are this frame's (width x height, the G-buffer's motion vectors point to
  // last frame's pixel); the sequence's first call returns mse -1. Throws std::invalid_argument
  // when the sizes disagree.
  Frame add(const std::vector<glm::vec3>& image, const GBuffer& gbuffer, float exposure);

 private:
  int width_ = 0, height_ = 0;
  std::vector<glm::vec3> previous_;  // displayed values
  std::vector<glm::vec4> previous_position_depth_, previous_normal_;
  std::vector<std::uint32_t> previous_material_, previous_flags_;
};

}  // namespace rtpg
