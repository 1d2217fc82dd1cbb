// Finding OpenCL devices and choosing one from a user's --device string.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cl/cl_include.h"

namespace rtpg {

struct DeviceInfo {
  int platform_index = 0;  // position in clGetPlatformIDs order
  int device_index = 0;    // position among that platform's devices
  std::string platform_name;
  std::string device_name;
  std::string type;              // "gpu", "cpu", "accelerator" or "other"
  std::string opencl_c_version;  // CL_DEVICE_OPENCL_C_VERSION, e.g. "OpenCL C 1.2 pocl"
  std::string driver_version;    // CL_DRIVER_VERSION: part of the program cache key
  std::string device_version;    // CL_DEVICE_VERSION
  std::uint32_t compute_units = 0;
  std::uint64_t local_mem_size = 0;  // bytes
  std::size_t max_work_group_size = 0;
  std::uint64_t global_mem_size = 0;  // bytes

  // "P:D", the index form of a device spec.
  std::string spec() const;
  // One line for listings and error messages: "0:0 <name> (cpu, <platform>, <OpenCL C>)".
  std::string summary() const;
};

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
