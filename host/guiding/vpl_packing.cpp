#include "rtpg/vpl_packing.h"

#include <string>

#include "rtpg/errors.h"
#include "shared/vpl_packing.h"

namespace rtpg {

std::array<std::uint32_t, 4> pack_vpl_normal_radiance(const std::array<float, 3>& normal,
                                                      float mixture_density,
                                                      const std::array<float, 3>& radiance,
                                                      std::uint32_t info) {
  if (info > 0xffffu)
    throw GuiderError("VPL info word " + std::to_string(info) +
                      " does not fit in the 16 bits of normal_radiance.w");
  const shared::uint4 p = shared::pg_pack_vpl_normal_radiance(
      shared::float3(normal[0], normal[1], normal[2]), mixture_density,
      shared::float3(radiance[0], radiance[1], radiance[2]), info);
  return {p.x, p.y, p.z, p.w};
}

}  // namespace rtpg
