// Kernel sources as the OpenCL compiler sees them: one string per .cl file with its
// `#include "..."` lines replaced by the included text, since clBuildProgram cannot read our
// embedded files. #line directives keep every line attributed to kernels/<path>, so build
// logs and Oclgrind reports name the real file and line.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>

namespace rtpg {

// The kernels/ tree compiled into the program: {path relative to kernels/, text}. Defined
// in the generated embedded_kernels.cpp (cmake/EmbedKernelsScript.cmake).
const std::map<std::string, std::string>& embedded_kernel_files();

// The text of kernels/<path> (include/<path> for "rtpg/..."), or nullopt. When
// $RTPG_KERNEL_DIR is set the file is read
// from that folder instead of the embedded copy (a developer switch: edit kernels and rerun
// without rebuilding; point it at the source tree's kernels/ or the installed share/rtpg/kernels;
// "rtpg/..." is then read from $RTPG_KERNEL_DIR/../include).
// The switch replaces the embedded set as a whole, so a half-copied folder fails loudly.
std::optional<std::string> load_kernel_file(const std::string& path);

// Where load_kernel_file reads from, for messages: "RTPG_KERNEL_DIR=<dir>" or "embedded".
std::string kernel_file_origin();

using KernelFileLoader = std::function<std::optional<std::string>(const std::string& path)>;

// kernel_file (relative to kernels/) with `#include "p"` (p relative to kernels/) resolved
// recursively; each file is inserted once, at its first inclusion (headers carry include
// guards anyway; skipping repeats keeps sources small). `#include <...>` lines are left to
// the compiler. An #include inside a preprocessor conditional is still inlined, so shared
// headers must not quote-include files in branches that the device does not take.
// A missing file throws InputError("kernels/<p>", "... included from kernels/<f>:<line>").
std::string resolve_kernel_source(const std::string& kernel_file,
                                  const KernelFileLoader& load = load_kernel_file);

// A build log with each position in the submitted text, as compilers that ignore #line print
// them (NVIDIA's OpenCL: "<kernel>:6:14: error"; Oclgrind: "input.cl:12:3"), followed by the
// file and line that resolved_source's #line directives give it:
// "<kernel>:6:14 (kernels/shared/bad_helper.h:3): error". Positions the compiler already
// attributed (PoCL: "kernels/bad.cl:6:14") are left as they are.
std::string attribute_build_log(const std::string& log, const std::string& resolved_source);

}  // namespace rtpg
