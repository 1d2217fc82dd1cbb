// The denoiser's intermediate images (layouts: kernels/shared/svgf.h), by name, so that the
// device denoiser and its host reference can be compared stage by stage.
#pragma once

namespace rtpg {

enum class SvgfStage {
  Surface,       // shading normal and depth
  Integrated,    // demodulated illumination after temporal accumulation
  Moments,       // luminance moments and history length
  Illumination,  // after the variance estimate: the first a-trous iteration's input
  Filtered,      // after the last a-trous iteration
  History,       // the output of a-trous iteration history_iteration, kept for the next frame
  Output,        // the denoised colour
};

}  // namespace rtpg
