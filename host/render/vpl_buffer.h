// The VPLs of one frame on the host: the first-bounce hit of every pixel's path, written by
// the path tracer, read by the guiding trainer. Its channels come from PG_VPL_CHANNELS (layout
// and meaning: include/rtpg/guiding_layout.h); info is the host's copy of the info word that
// normal_radiance.w carries packed for the kernels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "rtpg/guiding_layout.h"
#include "shared/compat.h"
#include "util/huge_pages.h"

namespace rtpg {

struct VplBuffer {
#define RTPG_HOST_CHANNEL(name, type, bytes) LargeVector<shared::type> name;
  PG_VPL_CHANNELS(RTPG_HOST_CHANNEL)
  LargeVector<std::uint32_t> info;  // PG_VPL_* bits, the strategy in bits 8..15
  // Host only, from the first bounce to its hit: the density (solid angle at x0) of the
  // strategy that drew the direction, which becomes position.w in area measure at the hit.
  // Kept apart so that the path tracer writes position, normal and mixture density once, at
  // the hit, instead of some at x0 and the rest at y (docs/guiding.md, "The VPLs written once").
  LargeVector<float> strategy_pdf;

  // The VPLs as they cross the bus (PG_PACKED_VPL_CHANNELS: distance, radiance, normal), which
  // the path tracer writes beside the layout where for_bus is set (the guided first bounce with
  // HostTransfer::packed): at the hit and in the final gather it has the distance, the normal
  // and the radiance at hand, where packing them costs a fraction of packing the layout
  // afterwards (docs/guiding.md, "The bus at 46 bytes a pixel"). Invalid VPLs have distance 0.
  bool for_bus = false;
  struct Packed {
    PG_PACKED_VPL_CHANNELS(RTPG_HOST_CHANNEL)
  } packed;

  // Every VPL invalid: info 0. Each frame's path tracer calls it, so only a new size zeroes
  // every channel; otherwise the channels keep last frame's values, read by nobody before the
  // path tracer writes them (strategy_pdf, a VPL's position, normal and mixture density only
  // where its path reaches the first bounce's hit; the radiance and the kernels' copy of info
  // in normal_radiance for every pixel, PathTracer::gather). Zeroing every channel each frame
  // (52 bytes a pixel when a VPL took 48) was a serial pass of 27 MB at 960x540
  // (docs/host-path-tracer.md, "Empty shadow rays skipped; per-frame fills").
  void resize(std::size_t n);
};
#undef RTPG_HOST_CHANNEL

}  // namespace rtpg
