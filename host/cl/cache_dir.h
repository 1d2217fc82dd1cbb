// Where compiled programs are kept between runs, and the process environment that the
// OpenCL drivers read once, at their first call.
#pragma once

#include <string>

namespace rtpg {

// The folder for rtpg's program cache: $RTPG_CACHE_DIR, else $XDG_CACHE_HOME/rtpg, else
// $HOME/.cache/rtpg; empty when none of these is set (the disk cache is then off). Read on
// every call, so a test can point one ClRuntime at a folder of its own.
std::string rtpg_cache_dir();

// Call before the first OpenCL call of the process (list_devices and ClRuntime do; later
// calls do nothing). PoCL caches compiled kernels in $POCL_CACHE_DIR, which it reads once;
// when unset it falls back to a folder of its own choosing, so rtpg sets it to
// <rtpg_cache_dir()>/pocl to keep everything it caches in one place the user can delete.
void prepare_opencl_environment();

}  // namespace rtpg
