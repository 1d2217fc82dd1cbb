// The host G-buffer packed for the bus (include/rtpg/guiding_layout.h, "Packed G-buffer";
// kernels/shared/gbuffer_packing.h defines every bit): what HostTransfer::packed sends a device
// with memory of its own. Two variants give the same bits: the shared functions pixel by pixel
// (baseline x86-64, and the reference), and eight pixels at a time in AVX2 lanes with F16C's half
// floats, chosen at run time where the CPU has both (render/cpu_code.h). Packing costs the host
// what the bus saves, so its speed decides whether packing pays (docs/guiding.md, "The G-buffer
// packed for the bus").
#pragma once

#include <cstddef>

#include "render/cpu_code.h"
#include "render/gbuffer.h"

namespace rtpg {

// Where the packed channels go (PG_PACKED_GBUFFER_CHANNELS), pixel i at index i.
struct PackedGBufferView {
  shared::uint4* surface = nullptr;
  shared::uint2* shading = nullptr;
};

// Whether this CPU runs the lane variant (AVX2 and F16C).
bool cpu_runs_gbuffer_packer_lanes();

// Packs pixels [first, last) of g into out (the G-buffer's values finite). Returns false where
// a pixel's material id or flags do not fit in the packed word (PG_PACKED_MATERIAL_MAX, 8 bits
// of flags); the other pixels are packed all the same. code: CpuCode::avx2 is the lane
// variant; throws std::invalid_argument where the CPU does not run it.
bool pack_gbuffer(const GBuffer& g, std::size_t first, std::size_t last,
                  const PackedGBufferView& out, CpuCode code = CpuCode::automatic);

}  // namespace rtpg
