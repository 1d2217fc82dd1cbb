// OpenCL failures as exceptions that say which call failed and why, by name. The C++
// bindings throw cl::Error whose what() is only the call name; everything in rtpg that
// launches kernels converts those into ClError (rethrow_cl_error, translate_cl_errors), so
// a user sees "clEnqueueNDRangeKernel: CL_INVALID_WORK_GROUP_SIZE (-54)".
#pragma once

#include <stdexcept>
#include <string>

#include "rtpg/opencl.h"

namespace rtpg {

// "CL_INVALID_WORK_GROUP_SIZE" for -54; every OpenCL 1.2 code plus the ICD loader's
// CL_PLATFORM_NOT_FOUND_KHR; "CL_UNKNOWN_ERROR" otherwise.
std::string cl_error_name(cl_int code);

class ClError : public std::runtime_error {
 public:
  // what() reads "<call>: <NAME> (<code>)".
  ClError(const std::string& call, cl_int code);

  cl_int code() const noexcept { return code_; }
  const std::string& call() const noexcept { return call_; }

 protected:
  // For subclasses that word what() themselves.
  ClError(const std::string& call, cl_int code, const std::string& message);

 private:
  std::string call_;
  cl_int code_;
};

// A program that failed to compile: the full log is kept, what() shows its start.
class ClBuildError : public ClError {
 public:
  // what() reads "building <kernel file> for <device>: <first 40 lines of the log>".
  ClBuildError(const std::string& kernel_file, const std::string& device_name,
               const std::string& log, cl_int code = CL_BUILD_PROGRAM_FAILURE);

  const std::string& kernel_file() const noexcept { return kernel_file_; }
  const std::string& log() const noexcept { return log_; }

 private:
  std::string kernel_file_;
  std::string log_;
};

// Throws ClError for the call and code carried by a cl::Error from the C++ bindings.
[[noreturn]] void rethrow_cl_error(const cl::Error& error);

// For raw C API calls: throws ClError(call, status) unless status is CL_SUCCESS.
void check_cl(cl_int status, const char* call);

// Runs f() and turns any cl::Error it throws into ClError; returns what f returns.
template <class F>
decltype(auto) translate_cl_errors(F&& f) {
  try {
    return f();
  } catch (const cl::Error& e) {
    rethrow_cl_error(e);
  }
}

}  // namespace rtpg
