// A frame's camera rays: one per pixel, through the pixel's film point jittered by its own
// random stream (PG_RNG_STREAM_CAMERA, include/rtpg/guiding_layout.h) or through its centre.
// Computed a row at a time in vector lanes, by the variant `code` names (render/cpu_code.h);
// every variant gives the same rays to the bit (docs/host-path-tracer.md, "Camera rays in
// vector lanes").
#pragma once

#include <cstdint>

#include "render/cpu_code.h"
#include "scene/camera.h"
#include "trace/ray.h"

namespace rtpg {

struct CameraJitter {
  bool enabled = true;  // false: every ray through its pixel's centre
  std::uint32_t seed = 0;
  std::uint32_t frame = 0;
};

// rays[y * width + x] for every pixel of a width x height frame (rows in parallel). Throws
// std::invalid_argument where `code` names a variant this CPU does not run.
void make_camera_rays(const CameraFrame& camera, int width, int height, const CameraJitter& jitter,
                      Ray* rays, CpuCode code = CpuCode::automatic);

}  // namespace rtpg
