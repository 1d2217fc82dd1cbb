// A frame's camera rays: one per pixel, through the pixel's film point jittered by its own
// random stream (PG_RNG_STREAM_CAMERA, include/rtpg/guiding_layout.h) or through its centre.
// Computed a row at a time in vector lanes; on an x86-64 CPU with AVX2 by code built for it
// (chosen at run time, so the binary stays baseline x86-64), with the same operations in the
// same order, so every variant gives the same rays to the bit (docs/host-path-tracer.md,
// "Camera rays in vector lanes").
#pragma once

#include <cstdint>

#include "scene/camera.h"
#include "trace/ray.h"

namespace rtpg {

struct CameraJitter {
  bool enabled = true;  // false: every ray through its pixel's centre
  std::uint32_t seed = 0;
  std::uint32_t frame = 0;
};

// Which code computes the rays: the best the CPU runs (automatic), or one named variant (tests
// compare them).
enum class CameraRayCode { automatic, baseline, avx2 };

// Whether this CPU runs the avx2 variant.
bool camera_rays_avx2_available();

// rays[y * width + x] for every pixel of a width x height frame (rows in parallel). Throws
// std::invalid_argument where `code` names a variant this CPU does not run.
void make_camera_rays(const CameraFrame& camera, int width, int height, const CameraJitter& jitter,
                      Ray* rays, CameraRayCode code = CameraRayCode::automatic);

}  // namespace rtpg
