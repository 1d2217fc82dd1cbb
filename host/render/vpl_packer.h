// The host's VPLs packed for the bus (include/rtpg/guiding_layout.h, "Packed VPLs";
// kernels/shared/vpl_packing.h defines every bit): what HostTransfer::packed sends a device with
// memory of its own, 10 bytes a pixel instead of the layout's 32, which the device's
// unpack_vpls kernel turns back into the layout from its G-buffer and the frame's first samples.
#pragma once

#include <cstddef>

#include "render/gbuffer.h"
#include "render/vpl_buffer.h"

namespace rtpg {

// Where the packed channels go (PG_PACKED_VPL_CHANNELS), pixel i at index i.
struct PackedVplView {
  std::uint32_t* distance = nullptr;
  std::uint32_t* radiance = nullptr;
  std::uint16_t* normal = nullptr;
};

// Packs pixels [first, last) of vpls, found from the points of g, into out.
void pack_vpls(const VplBuffer& vpls, const GBuffer& g, std::size_t first, std::size_t last,
               const PackedVplView& out);

}  // namespace rtpg
