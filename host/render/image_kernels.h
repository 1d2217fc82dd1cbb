// Host side of kernels/tonemap.cl and kernels/accumulate.cl: whole-image kernels launched in
// 1D over width * height pixels (float4 radiance, RGBA8 output), the per-pixel math being
// kernels/shared/tonemap.h so that host code can compute the same pixels.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "rtpg/cl_runtime.h"

namespace rtpg {

// Work-group size of the launches; the global size is rounded up to a multiple of it and
// the kernels skip the extra work-items. 0 lets the driver choose (global = pixel count).
constexpr std::size_t kImageLocalSize = 64;

// Enqueues the tonemap of w * h float4 pixels in radiance into w * h RGBA8 pixels in rgba8
// (see shared/tonemap.h for the transform). Returns the kernel's event.
cl::Event enqueue_tonemap(ClRuntime& runtime, const cl::Buffer& radiance, const cl::Buffer& rgba8,
                          int width, int height, float exposure,
                          std::size_t local_size = kImageLocalSize);

// The same from and to host memory, blocking: rgba8 is resized to 4 * w * h bytes (R, G, B,
// A per pixel, row-major). Throws std::invalid_argument when radiance.size() != w * h.
void tonemap_on_device(ClRuntime& runtime, const std::vector<glm::vec4>& radiance, int width,
                       int height, float exposure, std::vector<std::uint8_t>& rgba8);

// The running mean of a sequence of frames, kept on the device: frame n (from 0) is added
// with weight 1 / (n + 1), so after n frames mean() is their average.
class Accumulator {
 public:
  Accumulator(ClRuntime& runtime, int width, int height, std::size_t local_size = kImageLocalSize);

  Accumulator(const Accumulator&) = delete;
  Accumulator& operator=(const Accumulator&) = delete;

  // Starts a new mean (the camera moved): the next add() replaces the sum.
  void reset();
  // Adds a device buffer of width * height float4 (enqueued, not waited for).
  cl::Event add(const cl::Buffer& frame);
  // Uploads and adds a host frame; throws std::invalid_argument for a wrong size.
  cl::Event add(const std::vector<glm::vec4>& frame);

  int frames() const { return frames_; }
  int width() const { return width_; }
  int height() const { return height_; }
  // The mean so far, width * height float4 on the device; undefined while frames() == 0.
  const cl::Buffer& mean() const { return sum_; }
  // Downloads the mean (blocking); all zero while frames() == 0.
  std::vector<glm::vec4> read();

 private:
  ClRuntime& runtime_;
  ClRuntime::Use runtime_use_{runtime_};  // the runtime must outlive this
  int width_;
  int height_;
  std::size_t local_size_;
  cl::Kernel kernel_;
  cl::Buffer sum_;
  cl::Buffer upload_;  // staging for add(std::vector): created on first use
  int frames_ = 0;
};

}  // namespace rtpg
