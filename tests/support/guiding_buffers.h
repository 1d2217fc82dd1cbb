// Host-side guiding buffers for the kernel tests and the kernel benchmarks: structs generated
// from the channel lists of include/rtpg/guiding_layout.h (so they never drift from the
// kernels) and their upload through the library's own enqueue_upload.
#pragma once

#include <cstddef>
#include <vector>

#include "rtpg/cl_runtime.h"
#include "rtpg/guider.h"
#include "rtpg/guiding_layout.h"
#include "shared/compat.h"

namespace rtpg::testing {

#define RTPG_TEST_CHANNEL(name, type, bytes) std::vector<shared::type> name;
#define RTPG_TEST_RESIZE(name, type, bytes) name.assign(n, shared::type(0));

// One frame's G-buffer, every channel zero.
struct HostGBuffer {
  int width = 0, height = 0;
  PG_GBUFFER_CHANNELS(RTPG_TEST_CHANNEL)
  HostGBuffer() = default;
  HostGBuffer(int w, int h) : width(w), height(h) {
    const std::size_t n = this->n();
    PG_GBUFFER_CHANNELS(RTPG_TEST_RESIZE)
  }
  std::size_t n() const { return static_cast<std::size_t>(width) * height; }
};

struct HostVpls {
  PG_VPL_CHANNELS(RTPG_TEST_CHANNEL)
  void resize(std::size_t n) { PG_VPL_CHANNELS(RTPG_TEST_RESIZE) }
};

#undef RTPG_TEST_CHANNEL
#undef RTPG_TEST_RESIZE

// Device copies, uploaded and finished.
inline GuiderGBuffer upload(ClRuntime& rt, const HostGBuffer& g) {
  GuiderGBuffer d = make_guider_gbuffer(rt.context(), g.width, g.height);
  enqueue_upload(rt.queue(), g, d);
  rt.queue().finish();
  return d;
}

inline GuiderVpls upload(ClRuntime& rt, const HostVpls& v, int width, int height) {
  GuiderVpls d = make_guider_vpls(rt.context(), width, height);
  enqueue_upload(rt.queue(), v, d);
  rt.queue().finish();
  return d;
}

}  // namespace rtpg::testing
