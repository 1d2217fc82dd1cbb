#include "render/vpl_packer.h"

#include "shared/vpl_packing.h"

namespace rtpg {

void pack_vpls(const VplBuffer& vpls, const GBuffer& g, std::size_t first, std::size_t last,
               const PackedVplView& out) {
  for (std::size_t i = first; i < last; ++i) {
    out.distance[i] = shared::pg_pack_vpl_distance(vpls.position[i], vpls.normal_radiance[i],
                                                   shared::float3(g.position_depth[i]));
    out.radiance[i] = shared::pg_pack_vpl_bus_radiance(vpls.normal_radiance[i]);
    out.normal[i] =
        static_cast<std::uint16_t>(shared::pg_pack_vpl_bus_normal(vpls.normal_radiance[i]));
  }
}

}  // namespace rtpg
