// One OpenCL device with its context, an in-order profiling queue and a cache of built
// programs. Everything that launches kernels goes through a ClRuntime, so device choice,
// build options, caching and error reporting are decided here once.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "rtpg/cl_error.h"
#include "rtpg/opencl.h"

namespace rtpg {

// What rtpg knows of an OpenCL device (list_devices() in host/cl/device.h fills it).
struct DeviceInfo {
  int platform_index = 0;  // position in clGetPlatformIDs order
  int device_index = 0;    // position among that platform's devices
  std::string platform_name;
  std::string device_name;
  std::string type;              // "gpu", "cpu", "accelerator" or "other"
  std::string opencl_c_version;  // CL_DEVICE_OPENCL_C_VERSION, e.g. "OpenCL C 1.2 pocl"
  std::string driver_version;    // CL_DRIVER_VERSION: part of the program cache key
  std::string device_version;    // CL_DEVICE_VERSION
  std::uint32_t compute_units = 0;
  std::uint64_t local_mem_size = 0;  // bytes
  std::size_t max_work_group_size = 0;
  std::uint64_t global_mem_size = 0;     // bytes
  std::uint32_t native_float_width = 1;  // CL_DEVICE_NATIVE_VECTOR_WIDTH_FLOAT: SIMD lanes
  bool host_unified_memory = false;      // CL_DEVICE_HOST_UNIFIED_MEMORY: the device works in
                                         // host memory (CPUs, integrated GPUs)

  // "P:D", the index form of a device spec.
  std::string spec() const;
  // One line for listings and error messages: "0:0 <name> (cpu, <platform>, <OpenCL C>)".
  std::string summary() const;
  // Pixels per work-item for the kernels that run several in vector lanes (kernels/wide/): on a
  // CPU device as many as its SIMD registers hold floats (a power of two, at most 16), since its
  // compiler turns the lanes into SIMD code; 1 on GPUs, whose work-items are SIMD lanes already
  // (docs/guiding.md, "Several pixels per work-item").
  int simd_lanes() const;
};

struct SelectedDevice;

// How program() requests were served since construction (tests and logs read these).
struct ProgramCacheStats {
  int memory_hits = 0;    // the same key was built before by this runtime
  int disk_hits = 0;      // loaded from a binary in the disk cache
  int source_builds = 0;  // compiled from source (and then stored to disk)
};

class ClRuntime {
 public:
  // device_spec as select_device() reads it ("" = $RTPG_DEVICE or the default device).
  // Throws InputError for a spec matching no device, ClError when OpenCL fails.
  //   spec: "" ($RTPG_DEVICE, else the first GPU, else the CPU), "gpu", "cpu", "P:D" (platform
  //   and device index) or part of a device's name.
  explicit ClRuntime(const std::string& device_spec = "");
  ~ClRuntime();

  // Programs and kernels point into this context: neither copied nor moved.
  ClRuntime(const ClRuntime&) = delete;
  ClRuntime& operator=(const ClRuntime&) = delete;

  const DeviceInfo& info() const { return info_; }
  cl::Context& context() { return context_; }
  cl::Device& device() { return device_; }
  // In-order, with CL_QUEUE_PROFILING_ENABLE so that every event can be timed (event_ms).
  cl::CommandQueue& queue() { return queue_; }

  // The program of kernels/<kernel_file> (e.g. "tonemap.cl") built with
  // "-cl-std=CL1.2 <build_options>" (feature switches such as -DPG_...). Built once per
  // (resolved source, options, device): from memory, else the disk binary cache, else from
  // source. A failed compile throws ClBuildError with the log; a corrupt or unloadable
  // cache entry is rebuilt from source silently. The reference lives as long as *this.
  cl::Program& program(const std::string& kernel_file, const std::string& build_options = "");

  // A new kernel object (kernels carry their arguments: one per user) from program().
  cl::Kernel kernel(const std::string& kernel_file, const std::string& kernel_name,
                    const std::string& build_options = "");

  // END - START of a finished command in milliseconds, from its profiling info.
  static double event_ms(const cl::Event& event);

  // Held by every object that keeps a reference to a runtime (Guider, and the renderer's guided
  // first bounce, denoiser and image kernels). A runtime destroyed while one is alive would leave
  // it a released queue, which some drivers survive and others do not (NVIDIA's crashed where
  // PoCL's did not; docs/guiding.md, "The renderer on a GPU"): the runtime's destructor then
  // stops the program with a message instead, on every device.
  class Use {
   public:
    explicit Use(ClRuntime& runtime) : runtime_(runtime) { ++runtime_.users_; }
    ~Use() { --runtime_.users_; }
    Use(const Use&) = delete;
    Use& operator=(const Use&) = delete;

   private:
    ClRuntime& runtime_;
  };
  int users() const { return users_.load(); }

  ProgramCacheStats cache_stats() const;
  // The rtpg cache folder this runtime uses (rtpg_cache_dir() at construction; "" = off).
  const std::string& cache_dir() const { return cache_dir_; }

 private:
  struct Programs;  // the program cache in memory and on disk (host/cl/cl_runtime.cpp)
  explicit ClRuntime(SelectedDevice selected);
  const std::string& resolved_source(const std::string& kernel_file);
  cl::Program build(const std::string& kernel_file, const std::string& source,
                    const std::string& options, const std::string& key);

  DeviceInfo info_;
  cl::Device device_;
  cl::Context context_;
  cl::CommandQueue queue_;
  std::string cache_dir_;
  std::unique_ptr<Programs> programs_;
  std::atomic<int> users_{0};
};

// A read-only device buffer over a host container's memory (CL_MEM_USE_HOST_PTR, any container
// with data(), size() and value_type): no copy where the device shares host memory
// (DeviceInfo::host_unified_memory). The kernels only read it, so the const_cast writes nothing.
// The device may cache the data when the buffer is made (OpenCL 1.2, clCreateBuffer): make it
// after the host has written the data, and release it before the host writes again. Throws
// cl::Error.
template <class Container>
cl::Buffer read_in_place(const cl::Context& context, const Container& host) {
  using T = typename Container::value_type;
  return cl::Buffer(context, CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, host.size() * sizeof(T),
                    const_cast<T*>(host.data()));
}

// Asks a CPU OpenCL device to keep one worker thread per core: sets POCL_AFFINITY=1 (read by
// PoCL's CPU device when it first loads; ignored by every other implementation) unless the
// environment already sets it, 0 included. Without it, on the 2-core test machine PoCL's two
// workers shared one core for a whole kernel in up to half the frames, and those kernels took
// twice their time (docs/design.md, "CPU devices' worker threads pinned"). Call before the
// process's first OpenCL call; returns whether it set the variable.
bool request_pinned_cpu_device_threads();

}  // namespace rtpg
