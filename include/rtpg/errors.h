// Errors that reach the user. InputError is bad input (a file, a setting, a size); GuiderError
// is misuse of the guiding library (include/rtpg/guider.h); OpenCL failures are ClError
// (include/rtpg/cl_error.h). The command line prints the one-line message of the first two
// and exits with code 2, of ClError with code 3.
#pragma once

#include <stdexcept>
#include <string>

namespace rtpg {

// what() reads "<subject>: <problem>", subject being a file path, a setting or a flag name.
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& subject, const std::string& problem)
      : std::runtime_error(subject + ": " + problem) {}
};

// Misuse of the guider: settings out of range, buffers of the wrong size, a tile that does
// not fit in the device's local memory, a local size the device refuses.
class GuiderError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

}  // namespace rtpg
