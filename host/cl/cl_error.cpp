#include "rtpg/cl_error.h"

#include <sstream>

namespace rtpg {
namespace {

// Build logs can run to thousands of lines (one warning per inlined call site); the message
// keeps the first errors, which are the ones that matter, and log() keeps the rest.
constexpr int kLogExcerptLines = 40;

std::string log_excerpt(const std::string& log) {
  std::istringstream in(log);
  std::string line, out;
  int kept = 0, dropped = 0;
  while (std::getline(in, line)) {
    if (kept < kLogExcerptLines) {
      out += line;
      out += '\n';
      ++kept;
    } else {
      ++dropped;
    }
  }
  if (dropped > 0) out += "... (" + std::to_string(dropped) + " more lines in the build log)";
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  if (out.empty()) out = "(empty build log)";
  return out;
}

}  // namespace

std::string cl_error_name(cl_int code) {
  switch (code) {
#define RTPG_CL_CODE(name) \
  case name:               \
    return #name;
    RTPG_CL_CODE(CL_SUCCESS)
    RTPG_CL_CODE(CL_DEVICE_NOT_FOUND)
    RTPG_CL_CODE(CL_DEVICE_NOT_AVAILABLE)
    RTPG_CL_CODE(CL_COMPILER_NOT_AVAILABLE)
    RTPG_CL_CODE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    RTPG_CL_CODE(CL_OUT_OF_RESOURCES)
    RTPG_CL_CODE(CL_OUT_OF_HOST_MEMORY)
    RTPG_CL_CODE(CL_PROFILING_INFO_NOT_AVAILABLE)
    RTPG_CL_CODE(CL_MEM_COPY_OVERLAP)
    RTPG_CL_CODE(CL_IMAGE_FORMAT_MISMATCH)
    RTPG_CL_CODE(CL_IMAGE_FORMAT_NOT_SUPPORTED)
    RTPG_CL_CODE(CL_BUILD_PROGRAM_FAILURE)
    RTPG_CL_CODE(CL_MAP_FAILURE)
    RTPG_CL_CODE(CL_MISALIGNED_SUB_BUFFER_OFFSET)
    RTPG_CL_CODE(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
    RTPG_CL_CODE(CL_COMPILE_PROGRAM_FAILURE)
    RTPG_CL_CODE(CL_LINKER_NOT_AVAILABLE)
    RTPG_CL_CODE(CL_LINK_PROGRAM_FAILURE)
    RTPG_CL_CODE(CL_DEVICE_PARTITION_FAILED)
    RTPG_CL_CODE(CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
    RTPG_CL_CODE(CL_INVALID_VALUE)
    RTPG_CL_CODE(CL_INVALID_DEVICE_TYPE)
    RTPG_CL_CODE(CL_INVALID_PLATFORM)
    RTPG_CL_CODE(CL_INVALID_DEVICE)
    RTPG_CL_CODE(CL_INVALID_CONTEXT)
    RTPG_CL_CODE(CL_INVALID_QUEUE_PROPERTIES)
    RTPG_CL_CODE(CL_INVALID_COMMAND_QUEUE)
    RTPG_CL_CODE(CL_INVALID_HOST_PTR)
    RTPG_CL_CODE(CL_INVALID_MEM_OBJECT)
    RTPG_CL_CODE(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR)
    RTPG_CL_CODE(CL_INVALID_IMAGE_SIZE)
    RTPG_CL_CODE(CL_INVALID_SAMPLER)
    RTPG_CL_CODE(CL_INVALID_BINARY)
    RTPG_CL_CODE(CL_INVALID_BUILD_OPTIONS)
    RTPG_CL_CODE(CL_INVALID_PROGRAM)
    RTPG_CL_CODE(CL_INVALID_PROGRAM_EXECUTABLE)
    RTPG_CL_CODE(CL_INVALID_KERNEL_NAME)
    RTPG_CL_CODE(CL_INVALID_KERNEL_DEFINITION)
    RTPG_CL_CODE(CL_INVALID_KERNEL)
    RTPG_CL_CODE(CL_INVALID_ARG_INDEX)
    RTPG_CL_CODE(CL_INVALID_ARG_VALUE)
    RTPG_CL_CODE(CL_INVALID_ARG_SIZE)
    RTPG_CL_CODE(CL_INVALID_KERNEL_ARGS)
    RTPG_CL_CODE(CL_INVALID_WORK_DIMENSION)
    RTPG_CL_CODE(CL_INVALID_WORK_GROUP_SIZE)
    RTPG_CL_CODE(CL_INVALID_WORK_ITEM_SIZE)
    RTPG_CL_CODE(CL_INVALID_GLOBAL_OFFSET)
    RTPG_CL_CODE(CL_INVALID_EVENT_WAIT_LIST)
    RTPG_CL_CODE(CL_INVALID_EVENT)
    RTPG_CL_CODE(CL_INVALID_OPERATION)
    RTPG_CL_CODE(CL_INVALID_GL_OBJECT)
    RTPG_CL_CODE(CL_INVALID_BUFFER_SIZE)
    RTPG_CL_CODE(CL_INVALID_MIP_LEVEL)
    RTPG_CL_CODE(CL_INVALID_GLOBAL_WORK_SIZE)
    RTPG_CL_CODE(CL_INVALID_PROPERTY)
    RTPG_CL_CODE(CL_INVALID_IMAGE_DESCRIPTOR)
    RTPG_CL_CODE(CL_INVALID_COMPILER_OPTIONS)
    RTPG_CL_CODE(CL_INVALID_LINKER_OPTIONS)
    RTPG_CL_CODE(CL_INVALID_DEVICE_PARTITION_COUNT)
#undef RTPG_CL_CODE
    // cl_khr_icd: what the ICD loader returns when no vendor file names a usable platform.
    case -1001:
      return "CL_PLATFORM_NOT_FOUND_KHR";
    default:
      return "CL_UNKNOWN_ERROR";
  }
}

ClError::ClError(const std::string& call, cl_int code)
    : ClError(call, code, call + ": " + cl_error_name(code) + " (" + std::to_string(code) + ")") {}

ClError::ClError(const std::string& call, cl_int code, const std::string& message)
    : std::runtime_error(message), call_(call), code_(code) {}

ClBuildError::ClBuildError(const std::string& kernel_file, const std::string& device_name,
                           const std::string& log, cl_int code)
    : ClError("clBuildProgram", code,
              "building " + kernel_file + " for " + device_name + ": " + log_excerpt(log)),
      kernel_file_(kernel_file),
      log_(log) {}

void rethrow_cl_error(const cl::Error& error) {
  throw ClError(error.what() != nullptr ? error.what() : "OpenCL call", error.err());
}

void check_cl(cl_int status, const char* call) {
  if (status != CL_SUCCESS) throw ClError(call, status);
}

}  // namespace rtpg
