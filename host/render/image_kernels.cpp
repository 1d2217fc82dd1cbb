#include "render/image_kernels.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace rtpg {
namespace {

// float4 and glm::vec4 cross the boundary as the same 16 bytes.
static_assert(sizeof(glm::vec4) == sizeof(cl_float4), "glm::vec4 must match cl_float4");

std::size_t pixel_count(int width, int height) {
  if (width <= 0 || height <= 0) {
    throw std::invalid_argument("image size must be positive, got " + std::to_string(width) + "x" +
                                std::to_string(height));
  }
  return static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
}

// 1D launch over count items: local size clamped to what the device allows, global rounded
// up to a multiple of it.
// One work-item per pixel; local_size 0 lets the driver choose, else the global size is
// rounded up to a multiple of it (the kernels bounds-check).
cl::Event enqueue_1d(ClRuntime& runtime, cl::Kernel& kernel, std::size_t count,
                     std::size_t local_size) {
  cl::NDRange global(count), local = cl::NullRange;
  if (local_size != 0) {
    const std::size_t l = std::min(local_size, runtime.info().max_work_group_size);
    global = cl::NDRange((count + l - 1) / l * l);
    local = cl::NDRange(l);
  }
  cl::Event event;
  runtime.queue().enqueueNDRangeKernel(kernel, cl::NullRange, global, local, nullptr, &event);
  return event;
}

}  // namespace

cl::Event enqueue_tonemap(ClRuntime& runtime, const cl::Buffer& radiance, const cl::Buffer& rgba8,
                          int width, int height, float exposure, std::size_t local_size) {
  const std::size_t count = pixel_count(width, height);
  cl::Kernel kernel = runtime.kernel("tonemap.cl", "tonemap");
  return translate_cl_errors([&] {
    kernel.setArg(0, radiance);
    kernel.setArg(1, rgba8);
    kernel.setArg(2, static_cast<cl_uint>(width));
    kernel.setArg(3, static_cast<cl_uint>(height));
    kernel.setArg(4, exposure);
    return enqueue_1d(runtime, kernel, count, local_size);
  });
}

void tonemap_on_device(ClRuntime& runtime, const std::vector<glm::vec4>& radiance, int width,
                       int height, float exposure, std::vector<std::uint8_t>& rgba8) {
  const std::size_t count = pixel_count(width, height);
  if (radiance.size() != count) {
    throw std::invalid_argument("tonemap_on_device: " + std::to_string(radiance.size()) +
                                " pixels given for a " + std::to_string(width) + "x" +
                                std::to_string(height) + " image");
  }
  rgba8.resize(4 * count);
  translate_cl_errors([&] {
    // CL_MEM_COPY_HOST_PTR copies at creation: the const vector is never written.
    cl::Buffer in(runtime.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                  count * sizeof(glm::vec4), const_cast<glm::vec4*>(radiance.data()));
    cl::Buffer out(runtime.context(), CL_MEM_WRITE_ONLY, 4 * count);
    enqueue_tonemap(runtime, in, out, width, height, exposure);
    runtime.queue().enqueueReadBuffer(out, CL_TRUE, 0, 4 * count, rgba8.data());
  });
}

Accumulator::Accumulator(ClRuntime& runtime, int width, int height, std::size_t local_size)
    : runtime_(runtime), width_(width), height_(height), local_size_(local_size) {
  const std::size_t count = pixel_count(width, height);
  kernel_ = runtime_.kernel("accumulate.cl", "accumulate");
  translate_cl_errors(
      [&] { sum_ = cl::Buffer(runtime_.context(), CL_MEM_READ_WRITE, count * sizeof(glm::vec4)); });
}

void Accumulator::reset() {
  // Nothing to clear: the next add() has weight 1 and overwrites the sum without reading it
  // (pg_accumulate). No clEnqueueFillBuffer either: Oclgrind 21.10 --uninitialized then
  // reports every later read of the buffer as uninitialised, even after kernels wrote it.
  frames_ = 0;
}

cl::Event Accumulator::add(const cl::Buffer& frame) {
  const std::size_t count = pixel_count(width_, height_);
  const float weight_new = 1.0f / static_cast<float>(frames_ + 1);
  cl::Event event = translate_cl_errors([&] {
    kernel_.setArg(0, frame);
    kernel_.setArg(1, sum_);
    kernel_.setArg(2, static_cast<cl_uint>(width_));
    kernel_.setArg(3, static_cast<cl_uint>(height_));
    kernel_.setArg(4, weight_new);
    return enqueue_1d(runtime_, kernel_, count, local_size_);
  });
  ++frames_;
  return event;
}

cl::Event Accumulator::add(const std::vector<glm::vec4>& frame) {
  const std::size_t count = pixel_count(width_, height_);
  if (frame.size() != count) {
    throw std::invalid_argument("Accumulator::add: " + std::to_string(frame.size()) +
                                " pixels given for a " + std::to_string(width_) + "x" +
                                std::to_string(height_) + " image");
  }
  translate_cl_errors([&] {
    if (upload_() == nullptr) {
      upload_ = cl::Buffer(runtime_.context(), CL_MEM_READ_ONLY, count * sizeof(glm::vec4));
    }
    // Blocking write: the caller may reuse its vector as soon as add() returns.
    runtime_.queue().enqueueWriteBuffer(upload_, CL_TRUE, 0, count * sizeof(glm::vec4),
                                        frame.data());
  });
  return add(upload_);
}

std::vector<glm::vec4> Accumulator::read() {
  std::vector<glm::vec4> mean(pixel_count(width_, height_), glm::vec4(0.0f));
  if (frames_ == 0) return mean;  // the device buffer holds nothing meaningful yet
  translate_cl_errors([&] {
    runtime_.queue().enqueueReadBuffer(sum_, CL_TRUE, 0, mean.size() * sizeof(glm::vec4),
                                       mean.data());
  });
  return mean;
}

}  // namespace rtpg
