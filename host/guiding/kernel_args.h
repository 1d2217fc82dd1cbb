// Sets a guiding kernel's arguments in the order of its signature, which
// kernels/shared/kernel_args.h generates from the channel lists of
// include/rtpg/guiding_layout.h: a buffer struct expands to all its channels, in list order.
#pragma once

#include "rtpg/cl_error.h"
#include "rtpg/guider.h"

namespace rtpg {

class KernelArgs {
 public:
  explicit KernelArgs(cl::Kernel& kernel) : kernel_(kernel) {}

  template <class T>
  KernelArgs& operator<<(const T& value) {
    kernel_.setArg(index_++, value);
    return *this;
  }
  KernelArgs& operator<<(const GuiderGBuffer& b) {
#define RTPG_ARG(name, type, bytes) *this << b.name;
    PG_GBUFFER_CHANNELS(RTPG_ARG)
    return *this;
  }
  KernelArgs& operator<<(const GuiderVpls& b) {
    PG_VPL_CHANNELS(RTPG_ARG)
    return *this;
  }
  KernelArgs& operator<<(const GuiderSamples& b) {
    PG_SAMPLE_CHANNELS(RTPG_ARG)
    return *this;
  }
#undef RTPG_ARG

 private:
  cl::Kernel& kernel_;
  cl_uint index_ = 0;
};

}  // namespace rtpg
