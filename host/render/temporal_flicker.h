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

// Temporal flicker (docs/design.md, "Metrics"): MSE between consecutive frames over pixels and
// channels; -1 for the first frame (previous empty or of another size). Summed in parallel over
// fixed blocks of pixels, so the figure does not depend on the thread count.
double flicker_mse(const std::vector<glm::vec3>& image, const std::vector<glm::vec3>& previous);

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
  // A frame's history: displayed values and what the history test reads of its G-buffer
  // (everything but the flags only where a pixel has a surface).
  struct History {
    std::vector<glm::vec3> shown;
    std::vector<glm::vec4> position_depth, normal;
    std::vector<std::uint32_t> material, flags;
  };
  int width_ = 0, height_ = 0;
  History previous_, next_;
};

}  // namespace rtpg
