// Finding OpenCL devices and choosing one from a user's --device string.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "rtpg/cl_runtime.h"
#include "rtpg/opencl.h"

namespace rtpg {

// Every device of every platform, in platform then device order. Throws std::runtime_error
// naming the ICD and PoCL packages when no OpenCL platform is installed.
std::vector<DeviceInfo> list_devices();

struct SelectedDevice {
  DeviceInfo info;
  cl::Device device;
};

// Chooses a device by spec:
//   ""           $RTPG_DEVICE if set, else the first GPU, else the first CPU device, else
//                the first device of any kind (Oclgrind's simulator, when it is alone);
//   "gpu", "cpu", "accelerator"  the first device of that type;
//   "P:D"        platform P, device D (indices as list_devices reports them);
//   other text   the first device whose name, else whose platform name, contains it
//                (case-insensitive).
// No match throws InputError("--device" or "RTPG_DEVICE", "no OpenCL device matches ...")
// listing the devices there are.
SelectedDevice select_device(const std::string& spec);

}  // namespace rtpg
