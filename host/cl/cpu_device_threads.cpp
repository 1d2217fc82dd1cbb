// request_pinned_cpu_device_threads (include/rtpg/cl_runtime.h): one environment variable, set
// only where the user has not set it (docs/design.md, "CPU devices' worker threads pinned").
#include <cstdlib>

#include "rtpg/cl_runtime.h"

namespace rtpg {

bool request_pinned_cpu_device_threads() {
  if (std::getenv("POCL_AFFINITY") != nullptr) return false;
  return setenv("POCL_AFFINITY", "1", /*overwrite=*/0) == 0;
}

}  // namespace rtpg
