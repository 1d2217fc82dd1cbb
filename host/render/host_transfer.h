// How per-pixel buffers cross between the host and an OpenCL device: read in place where the
// device shares host memory, else copied through pinned staging or straight from the host's
// vectors (docs/guiding.md, "The renderer on a GPU"). The guided first bounce takes one of these;
// the SVGF denoiser reads in place or copies through pinned staging.
#pragma once

#include <string>

namespace rtpg {

enum class HostTransfer {
  automatic,  // in_place where the device shares host memory (DeviceInfo::host_unified_memory),
              // else packed (its uploads measured 8-15% shorter than pinned's on an H200:
              // docs/guiding.md, "The G-buffer packed for the bus")
  in_place,   // the device reads the host's G-buffer and VPLs where they are
              // (CL_MEM_USE_HOST_PTR) and the host maps the samples: no copies where memory is
              // shared; elsewhere the OpenCL implementation copies when the kernels need them
  pinned,     // the host copies the G-buffer and VPLs into mapped CL_MEM_ALLOC_HOST_PTR staging
              // (pinned memory on a discrete GPU), which the device copies from; the samples
              // come back into such staging
  pageable,   // the device copies straight from the host's own (pageable) vectors; the samples
              // come back into pinned staging
  packed,     // as pinned, but packed: the G-buffer in 24 bytes a pixel instead of 96 and the
              // VPLs in 10 instead of 32, which the device unpacks (Guider::unpack_gbuffer,
              // unpack_vpls), and the samples back in 12 instead of 20 (Guider::pack_samples;
              // include/rtpg/guiding_layout.h, "Packed ..."); the SVGF denoiser copies as with
              // pinned
};
// "auto", "in-place", "pinned", "packed", "pageable" (the CLI's --host-transfer); throws
// GuiderError else.
HostTransfer parse_host_transfer(const std::string& name);
const char* host_transfer_name(HostTransfer transfer);

// automatic resolved: RTPG_HOST_TRANSFER, where set (auto, in-place, pinned, packed or pageable;
// the tests run the guided and denoised renders once more with it set to packed, so that the copies
// a discrete GPU takes are exercised on PoCL too), else in_place where the device shares host
// memory and packed elsewhere. Any other choice is returned as it is. Throws GuiderError naming
// the variable when its value is none of those.
HostTransfer resolve_host_transfer(HostTransfer transfer, bool host_unified_memory);

}  // namespace rtpg
