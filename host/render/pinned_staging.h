// Host memory a discrete GPU copies from at the bus's full rate: one buffer the OpenCL runtime
// allocates (CL_MEM_ALLOC_HOST_PTR), mapped for the object's whole life. On an NVIDIA H100 a
// frame's guiding copies ran at 45 GB/s from such memory and at 6-8 GB/s from std::vectors
// (docs/guiding.md, "On a GPU" and "The renderer on a GPU"). Where the device shares host memory
// the buffer is plain host memory and the copy through it only costs time: users read in place
// there instead (include/rtpg/guider.h, wrap_host_gbuffer).
//
// Per frame: begin(), then stage() each channel (copied into the staging in parallel, since one
// core's memcpy reaches a fraction of the memory's bandwidth, and its write to the device
// enqueued without blocking), then the caller finishes the queue before the next begin().
// (Copying and enqueueing in 4 MiB chunks, each flushed, to overlap the host's copy with the
// bus's, was tried on an H200 and measured no faster: docs/guiding.md, "The G-buffer packed for
// the bus".)
#pragma once

#include <cstddef>
#include <string>

#include "rtpg/opencl.h"

namespace rtpg {

class PinnedStaging {
 public:
  // Maps staging for up to `channels` channels of `bytes` together per begin() (each channel
  // starts on a cache line of its own); throws ClError when OpenCL refuses.
  PinnedStaging(const cl::Context& context, const cl::CommandQueue& queue, std::size_t bytes,
                std::size_t channels);
  ~PinnedStaging();
  PinnedStaging(const PinnedStaging&) = delete;
  PinnedStaging& operator=(const PinnedStaging&) = delete;

  void begin() { used_ = 0; }
  // Copies `bytes` of host memory into the staging and enqueues their copy into `device` at
  // offset 0. Throws GuiderError naming `what` when they do not fit in the staging or in
  // `device`.
  void stage(const void* host, std::size_t bytes, const cl::Buffer& device,
             const std::string& what);
  template <class Container>
  void stage(const Container& host, const cl::Buffer& device, const std::string& what) {
    stage(host.data(), host.size() * sizeof(*host.data()), device, what);
  }
  // For data the caller writes into the staging itself (packs, say): reserve() checks and
  // returns `bytes` of staging, commit() enqueues their copy into `device` at offset 0.
  void* reserve(std::size_t bytes, const cl::Buffer& device, const std::string& what);
  void commit(const void* reserved, std::size_t bytes, const cl::Buffer& device);
  std::size_t size() const { return size_; }

 private:
  cl::CommandQueue queue_;
  cl::Buffer buffer_;
  unsigned char* mapped_ = nullptr;
  std::size_t size_ = 0, used_ = 0;
};

}  // namespace rtpg
