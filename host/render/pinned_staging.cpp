#include "render/pinned_staging.h"

#include <algorithm>
#include <cstring>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "rtpg/cl_error.h"
#include "rtpg/errors.h"

namespace rtpg {
namespace {
// Each channel starts on a cache line of its own.
constexpr std::size_t kAlignment = 64;
}  // namespace

PinnedStaging::PinnedStaging(const cl::Context& context, const cl::CommandQueue& queue,
                             std::size_t bytes, std::size_t channels)
    : queue_(queue), size_(std::max<std::size_t>(bytes + channels * kAlignment, 1)) {
  translate_cl_errors([&] {
    buffer_ = cl::Buffer(context, CL_MEM_ALLOC_HOST_PTR | CL_MEM_READ_ONLY, size_);
    mapped_ = static_cast<unsigned char*>(
        queue_.enqueueMapBuffer(buffer_, CL_TRUE, CL_MAP_WRITE, 0, size_));
  });
}

PinnedStaging::~PinnedStaging() {
  try {
    queue_.enqueueUnmapMemObject(buffer_, mapped_);
  } catch (...) {  // a failing unmap at teardown leaves the finish below to do
  }
  try {
    queue_.finish();  // copies still reading the staging finish before it is freed
  } catch (...) {     // a failing queue at teardown has nothing left to corrupt
  }
}

void* PinnedStaging::reserve(std::size_t bytes, const cl::Buffer& device, const std::string& what) {
  const std::size_t start = (used_ + kAlignment - 1) / kAlignment * kAlignment;
  if (start + bytes > size_)
    throw GuiderError("upload of " + what + ": " + std::to_string(bytes) +
                      " bytes do not fit in the pinned staging");
  translate_cl_errors([&] {
    if (bytes > device.getInfo<CL_MEM_SIZE>())
      throw GuiderError("upload of " + what + ": " + std::to_string(bytes) +
                        " bytes do not fit in its device buffer");
  });
  used_ = start + bytes;
  return mapped_ + start;
}

void PinnedStaging::commit(const void* reserved, std::size_t bytes, const cl::Buffer& device) {
  translate_cl_errors([&] { queue_.enqueueWriteBuffer(device, CL_FALSE, 0, bytes, reserved); });
}

void PinnedStaging::stage(const void* host, std::size_t bytes, const cl::Buffer& device,
                          const std::string& what) {
  auto* to = static_cast<unsigned char*>(reserve(bytes, device, what));
  const auto* from = static_cast<const unsigned char*>(host);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, bytes, std::size_t{1} << 18),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      std::memcpy(to + r.begin(), from + r.begin(), r.size());
                    });
  commit(to, bytes, device);
}

}  // namespace rtpg
