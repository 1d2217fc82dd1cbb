// The VPLs of one frame on the host: the first-bounce hit of every pixel's path, written by
// the path tracer, read by the guiding trainer. Its channels come from PG_VPL_CHANNELS (layout
// and meaning: include/rtpg/guiding_layout.h); info is the host's integer copy of the info
// word that radiance_info.w carries as a float for the kernels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "rtpg/guiding_layout.h"
#include "shared/compat.h"

namespace rtpg {

struct VplBuffer {
#define RTPG_HOST_CHANNEL(name, type, bytes) std::vector<shared::type> name;
  PG_VPL_CHANNELS(RTPG_HOST_CHANNEL)
#undef RTPG_HOST_CHANNEL
  std::vector<std::uint32_t> info;  // PG_VPL_* bits, the strategy in bits 8..15

  void resize(std::size_t n);  // every VPL invalid
};

}  // namespace rtpg
