// Holds back what libraries print on the process's stderr (file descriptor 2) for a while.
// Some report an error twice: libpng, under OpenImageIO 2.4, prints "libpng error: ..." to
// stderr and then returns the same text as the error that rtpg reports in its one-line
// message. Loading input under a capture keeps that message the only line.
#pragma once

#include <cstdio>
#include <string>

namespace rtpg {

class StderrCapture {
 public:
  // Starts capturing into an anonymous temporary file; when that cannot be set up, nothing is
  // captured and finish() returns "".
  StderrCapture();
  // Restores stderr if finish() was not called; the captured text is dropped.
  ~StderrCapture();
  StderrCapture(const StderrCapture&) = delete;
  StderrCapture& operator=(const StderrCapture&) = delete;

  // Restores stderr and returns what was written to it meanwhile.
  std::string finish();

 private:
  std::FILE* file_ = nullptr;
  int saved_fd_ = -1;
};

// Runs load() with stderr captured. On success the captured text is passed on to stderr (a
// library's warnings stay visible); when load() throws it is dropped, as the exception says
// what went wrong.
template <class Load>
auto load_quietly(Load&& load) -> decltype(load()) {
  StderrCapture capture;
  auto result = load();
  const std::string text = capture.finish();
  if (!text.empty()) std::fputs(text.c_str(), stderr);
  return result;
}

}  // namespace rtpg
