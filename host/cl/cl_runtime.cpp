#include "rtpg/cl_runtime.h"

#include <cstdio>
#include <cstdlib>
#include <map>
#include <mutex>
#include <utility>
#include <vector>

#include "cl/cache_dir.h"
#include "cl/device.h"
#include "cl/kernel_source.h"
#include "cl/program_cache.h"

namespace rtpg {
namespace {

// OpenCL C 1.2 on every device, whatever newer version a driver would default to.
// No -Werror: drivers warn about harmless things (PoCL about unused parameters).
constexpr const char* kBaseOptions = "-cl-std=CL1.2";

SelectedDevice select_or_throw(const std::string& spec) {
  prepare_opencl_environment();  // before any OpenCL call: PoCL reads POCL_CACHE_DIR once
  return select_device(spec);
}

}  // namespace

struct ClRuntime::Programs {
  explicit Programs(const std::string& dir) : disk_cache(dir) {}
  DiskProgramCache disk_cache;
  std::mutex mutex;  // guards everything below: program() may be called from any thread
  std::map<std::string, std::string> embedded_sources;  // resolved embedded sources
  std::map<std::string, cl::Program> built;             // by cache key
  ProgramCacheStats stats;
};

ClRuntime::~ClRuntime() {
  if (const int users = users_.load(); users > 0) {
    std::fprintf(stderr,
                 "rtpg: an OpenCL runtime was destroyed while %d object(s) still use it: destroy "
                 "the guider, renderer and denoiser first\n",
                 users);
    std::abort();
  }
}

ProgramCacheStats ClRuntime::cache_stats() const {
  std::lock_guard<std::mutex> lock(programs_->mutex);
  return programs_->stats;
}

ClRuntime::ClRuntime(const std::string& device_spec) : ClRuntime(select_or_throw(device_spec)) {}

ClRuntime::ClRuntime(SelectedDevice selected)
    : info_(std::move(selected.info)),
      device_(std::move(selected.device)),
      cache_dir_(rtpg_cache_dir()),
      programs_(std::make_unique<Programs>(cache_dir_)) {
  translate_cl_errors([&] {
    context_ = cl::Context(device_);
    queue_ = cl::CommandQueue(context_, device_, CL_QUEUE_PROFILING_ENABLE);
  });
}

const std::string& ClRuntime::resolved_source(const std::string& kernel_file) {
  // Embedded sources cannot change while the process runs; RTPG_KERNEL_DIR ones may (that
  // is the point of the switch), so those are read again on every request.
  const std::string origin = kernel_file_origin();
  const std::string memo_key = origin + '\n' + kernel_file;
  auto it = programs_->embedded_sources.find(memo_key);
  if (it == programs_->embedded_sources.end() || origin != "embedded") {
    it = programs_->embedded_sources.insert_or_assign(memo_key, resolve_kernel_source(kernel_file))
             .first;
  }
  return it->second;
}

cl::Program& ClRuntime::program(const std::string& kernel_file, const std::string& build_options) {
  std::lock_guard<std::mutex> lock(programs_->mutex);
  const std::string& source = resolved_source(kernel_file);
  const std::string options =
      build_options.empty() ? kBaseOptions : std::string(kBaseOptions) + " " + build_options;
  // Everything the binary depends on. Options are compared as written: "-DA -DB" and
  // "-DB -DA" are two entries, which costs a compile, never a wrong program.
  const std::string key = "source " + content_hash(source) + "\noptions " + options +
                          "\nplatform " + info_.platform_name + "\ndevice " + info_.device_name +
                          " | " + info_.device_version + " | " + info_.driver_version + "\n";
  if (auto it = programs_->built.find(key); it != programs_->built.end()) {
    ++programs_->stats.memory_hits;
    return it->second;
  }
  return programs_->built.emplace(key, build(kernel_file, source, options, key)).first->second;
}

cl::Program ClRuntime::build(const std::string& kernel_file, const std::string& source,
                             const std::string& options, const std::string& key) {
  const std::vector<cl::Device> devices{device_};
  if (auto binary = programs_->disk_cache.load(key)) {
    try {
      cl::Program program(context_, devices, cl::Program::Binaries{std::move(*binary)});
      program.build(devices, options.c_str());
      ++programs_->stats.disk_hits;
      return program;
    } catch (const cl::Error&) {
      // A binary from another driver build or a damaged file: fall through to the source.
    }
  }

  cl::Program program = translate_cl_errors([&] { return cl::Program(context_, source); });
  try {
    program.build(devices, options.c_str());
  } catch (const cl::Error& e) {
    std::string log;
    try {
      log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_);
    } catch (const cl::Error&) {
      // No log to be had; the message below still names the failure.
    }
    if (log.find_first_not_of(" \t\r\n") == std::string::npos) {
      log = std::string(e.what()) + " failed with " + cl_error_name(e.err()) + " (" +
            std::to_string(e.err()) + "), options '" + options + "', and no build log";
    }
    throw ClBuildError(kernel_file, info_.device_name, attribute_build_log(log, source), e.err());
  }
  ++programs_->stats.source_builds;

  try {
    const auto binaries = program.getInfo<CL_PROGRAM_BINARIES>();
    if (binaries.size() == 1) programs_->disk_cache.store(key, binaries.front());
  } catch (const cl::Error&) {
    // A driver that cannot hand out binaries simply gets no disk cache.
  }
  return program;
}

cl::Kernel ClRuntime::kernel(const std::string& kernel_file, const std::string& kernel_name,
                             const std::string& build_options) {
  cl::Program& built = program(kernel_file, build_options);
  try {
    return cl::Kernel(built, kernel_name.c_str());
  } catch (const cl::Error& e) {
    throw ClError("clCreateKernel(" + kernel_name + " in " + kernel_file + ")", e.err());
  }
}

double ClRuntime::event_ms(const cl::Event& event) {
  return translate_cl_errors([&] {
    const cl_ulong start = event.getProfilingInfo<CL_PROFILING_COMMAND_START>();
    const cl_ulong end = event.getProfilingInfo<CL_PROFILING_COMMAND_END>();
    return end >= start ? static_cast<double>(end - start) * 1e-6 : 0.0;
  });
}

}  // namespace rtpg
