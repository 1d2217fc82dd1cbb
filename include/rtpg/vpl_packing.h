// A VPL's normal_radiance channel packed on the host (include/rtpg/guiding_layout.h, "VPLs"):
// what a renderer that fills the VPL channels itself writes per pixel next to its position.
// The train kernels unpack it with the inverse operations of kernels/shared/vpl_packing.h.
#pragma once

#include <array>
#include <cstdint>

namespace rtpg {

// The four words of one pixel's normal_radiance: normal (unit, facing the pixel's point; any
// value for a distant VPL), the mixture density D in area measure at the VPL (solid angle for a
// distant one), the radiance leaving it towards the pixel's point (finite, not negative), and
// the info word (PG_VPL_* bits, the strategy at PG_VPL_STRATEGY_SHIFT; a wider word throws
// GuiderError).
std::array<std::uint32_t, 4> pack_vpl_normal_radiance(const std::array<float, 3>& normal,
                                                      float mixture_density,
                                                      const std::array<float, 3>& radiance,
                                                      std::uint32_t info);

}  // namespace rtpg
