// Errors that reach the user. InputError is bad input (a file, a flag, a size): the command
// line prints its one-line message and exits with code 2.
#pragma once

#include <stdexcept>
#include <string>

namespace rtpg {

class InputError : public std::runtime_error {
 public:
  // what() reads "<subject>: <problem>", subject being a file path or a flag name.
  InputError(const std::string& subject, const std::string& problem)
      : std::runtime_error(subject + ": " + problem) {}
};

}  // namespace rtpg
