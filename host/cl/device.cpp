#include "cl/device.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <stdexcept>
#include <utility>

#include "cl/cache_dir.h"
#include "rtpg/cl_error.h"
#include "rtpg/errors.h"

namespace rtpg {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// Some drivers pad names with spaces or a trailing NUL.
std::string trimmed(const std::string& s) {
  const auto is_space = [](unsigned char c) { return std::isspace(c) != 0 || c == '\0'; };
  auto begin = std::find_if_not(s.begin(), s.end(), is_space);
  auto end = std::find_if_not(s.rbegin(), std::string::const_reverse_iterator(begin), is_space);
  return std::string(begin, end.base());
}

std::string type_name(cl_device_type type) {
  if (type & CL_DEVICE_TYPE_GPU) return "gpu";
  if (type & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  if (type & CL_DEVICE_TYPE_CPU) return "cpu";
  return "other";
}

// No platform is an OpenCL failure like any other (the CLI's exit code 3), with the advice a
// user needs in place of the bare code.
class NoPlatformError final : public ClError {
 public:
  NoPlatformError(cl_int code, const std::string& message)
      : ClError("clGetPlatformIDs", code, message) {}
};

std::vector<cl::Platform> platforms_or_throw() {
  prepare_opencl_environment();
  std::vector<cl::Platform> platforms;
  cl_int status = CL_SUCCESS;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error& e) {
    status = e.err();
  }
  if (platforms.empty()) {
    if (status == CL_SUCCESS) status = -1001;  // CL_PLATFORM_NOT_FOUND_KHR
    throw NoPlatformError(
        status,
        "no OpenCL platform found (clGetPlatformIDs: " + cl_error_name(status) +
            "): install an OpenCL driver and its ICD file in /etc/OpenCL/vendors, e.g. PoCL's CPU "
            "device (Debian: apt-get install ocl-icd-libopencl1 pocl-opencl-icd); `clinfo -l` "
            "lists what the ICD loader finds");
  }
  return platforms;
}

std::vector<SelectedDevice> enumerate() {
  const std::vector<cl::Platform> platforms = platforms_or_throw();
  return translate_cl_errors([&] {
    std::vector<SelectedDevice> out;
    for (std::size_t p = 0; p < platforms.size(); ++p) {
      std::vector<cl::Device> devices;
      try {
        platforms[p].getDevices(CL_DEVICE_TYPE_ALL, &devices);
      } catch (const cl::Error&) {
        continue;  // CL_DEVICE_NOT_FOUND: a platform with no device is not an error
      }
      for (std::size_t d = 0; d < devices.size(); ++d) {
        const cl::Device& dev = devices[d];
        DeviceInfo info;
        info.platform_index = static_cast<int>(p);
        info.device_index = static_cast<int>(d);
        info.platform_name = trimmed(platforms[p].getInfo<CL_PLATFORM_NAME>());
        info.device_name = trimmed(dev.getInfo<CL_DEVICE_NAME>());
        info.type = type_name(dev.getInfo<CL_DEVICE_TYPE>());
        info.opencl_c_version = trimmed(dev.getInfo<CL_DEVICE_OPENCL_C_VERSION>());
        info.driver_version = trimmed(dev.getInfo<CL_DRIVER_VERSION>());
        info.device_version = trimmed(dev.getInfo<CL_DEVICE_VERSION>());
        info.compute_units = dev.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
        info.local_mem_size = dev.getInfo<CL_DEVICE_LOCAL_MEM_SIZE>();
        info.max_work_group_size = dev.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>();
        info.global_mem_size = dev.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
        info.native_float_width = dev.getInfo<CL_DEVICE_NATIVE_VECTOR_WIDTH_FLOAT>();
        info.host_unified_memory = dev.getInfo<CL_DEVICE_HOST_UNIFIED_MEMORY>() == CL_TRUE;
        out.push_back({std::move(info), dev});
      }
    }
    return out;
  });
}

// "P:D" with both parts decimal; false for anything else.
bool parse_indices(const std::string& spec, int& p, int& d) {
  const auto colon = spec.find(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == spec.size()) return false;
  const auto digits = [](const std::string& s) {
    return s.size() <= 6 &&
           std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
  };
  const std::string a = spec.substr(0, colon), b = spec.substr(colon + 1);
  if (!digits(a) || !digits(b)) return false;
  p = std::stoi(a);
  d = std::stoi(b);
  return true;
}

const SelectedDevice* find_by_type(const std::vector<SelectedDevice>& all, const char* type) {
  for (const auto& s : all)
    if (s.info.type == type) return &s;
  return nullptr;
}

const SelectedDevice* find(const std::vector<SelectedDevice>& all, const std::string& spec) {
  const std::string key = lower(trimmed(spec));
  if (key.empty()) {
    if (const auto* gpu = find_by_type(all, "gpu")) return gpu;
    if (const auto* cpu = find_by_type(all, "cpu")) return cpu;
    return all.empty() ? nullptr : &all.front();
  }
  if (key == "gpu" || key == "cpu" || key == "accelerator") return find_by_type(all, key.c_str());
  int p = 0, d = 0;
  if (parse_indices(key, p, d)) {
    for (const auto& s : all)
      if (s.info.platform_index == p && s.info.device_index == d) return &s;
    return nullptr;
  }
  for (const auto& s : all)
    if (lower(s.info.device_name).find(key) != std::string::npos) return &s;
  for (const auto& s : all)
    if (lower(s.info.platform_name).find(key) != std::string::npos) return &s;
  return nullptr;
}

}  // namespace

int DeviceInfo::simd_lanes() const {
  int lanes = 1;
  if (type == "cpu")
    while (lanes < 16 && 2 * lanes <= static_cast<int>(native_float_width)) lanes *= 2;
  return lanes;
}

std::string DeviceInfo::spec() const {
  return std::to_string(platform_index) + ":" + std::to_string(device_index);
}

std::string DeviceInfo::summary() const {
  return spec() + " " + device_name + " (" + type + ", " + platform_name + ", " + opencl_c_version +
         ")";
}

std::vector<DeviceInfo> list_devices() {
  std::vector<DeviceInfo> out;
  for (auto& s : enumerate()) out.push_back(std::move(s.info));
  return out;
}

SelectedDevice select_device(const std::string& spec) {
  std::string subject = "--device";
  std::string wanted = spec;
  if (trimmed(wanted).empty()) {
    const char* env = std::getenv("RTPG_DEVICE");
    if (env != nullptr && trimmed(env) != "") {
      wanted = env;
      subject = "RTPG_DEVICE";
    }
  }
  const std::vector<SelectedDevice> all = enumerate();
  if (const SelectedDevice* found = find(all, wanted)) return *found;
  std::string available;
  for (const auto& s : all) available += (available.empty() ? "" : "; ") + s.info.summary();
  if (available.empty()) available = "none (the OpenCL platforms report no devices)";
  throw InputError(subject, "no OpenCL device matches '" + wanted + "'; available: " + available);
}

}  // namespace rtpg
