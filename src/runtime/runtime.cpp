#include "fogcl/runtime.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <vector>

namespace fogcl {

namespace {
std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

struct Candidate {
  cl::Platform platform;
  cl::Device device;
  std::string label;  // "device name (platform name)"
};

std::vector<Candidate> all_devices() {
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error& e) {
    // The ICD loader reports "no platform" as an error; say what to do about it.
    throw Error(std::string("no OpenCL platform found (") + cl_error_name(e.err()) +
                "): install pocl-opencl-icd (scripts/setup.sh does) or point OCL_ICD_VENDORS at a driver");
  }
  std::vector<Candidate> out;
  for (const auto& p : platforms) {
    std::vector<cl::Device> devices;
    try {
      p.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;  // a platform without devices (CL_DEVICE_NOT_FOUND) is not an error here
    }
    for (const auto& d : devices)
      out.push_back({p, d, d.getInfo<CL_DEVICE_NAME>() + " (" + p.getInfo<CL_PLATFORM_NAME>() + ")"});
  }
  return out;
}
}  // namespace

std::string resolve_device_choice(const std::string& explicit_choice) {
  if (!explicit_choice.empty()) return explicit_choice;
  if (const char* env = std::getenv("FOGCL_DEVICE"); env != nullptr && *env != '\0') return env;
  return "cpu";
}

bool device_is_cpu(const cl::Device& device) {
  return (device.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) != 0;
}

std::string device_opencl_c_version(const cl::Device& device) {
  return device.getInfo<CL_DEVICE_OPENCL_C_VERSION>();
}

cl::Device find_device(const std::string& choice) {
  return with_cl_errors([&] {
    const std::vector<Candidate> all = all_devices();
    const std::string want = lower(choice);
    const Candidate* found = nullptr;
    for (const auto& c : all) {
      const cl_device_type type = c.device.getInfo<CL_DEVICE_TYPE>();
      bool match;
      if (want == "cpu")
        match = (type & CL_DEVICE_TYPE_CPU) != 0;
      else if (want == "gpu")
        match = (type & CL_DEVICE_TYPE_GPU) != 0;
      else
        match = lower(c.label + " " + c.device.getInfo<CL_DEVICE_VENDOR>()).find(want) != std::string::npos;
      if (!match) continue;
      // For "cpu", PoCL wins over other CPU drivers: it is what the project installs and tests.
      const bool pocl = c.platform.getInfo<CL_PLATFORM_NAME>().find("Portable Computing") != std::string::npos;
      if (found == nullptr || (want == "cpu" && pocl)) found = &c;
      if (pocl || want != "cpu") break;
    }
    if (found == nullptr) {
      std::string list;
      for (const auto& c : all) list += (list.empty() ? "" : "; ") + c.label;
      throw Error("no OpenCL device matches '" + choice + "' (use cpu, gpu, scalar or part of a device name; available: " +
                  (list.empty() ? std::string("none") : list) + ")");
    }
    return found->device;
  });
}

Runtime::Runtime(const std::string& choice) {
  with_cl_errors([&] {
    device_ = find_device(resolve_device_choice(choice));
    context_ = cl::Context(device_);
    queue_ = cl::CommandQueue(context_, device_, CL_QUEUE_PROFILING_ENABLE);
  });
}

Runtime::Runtime(cl::Context context, cl::Device device, cl::CommandQueue queue)
    : context_(std::move(context)), device_(std::move(device)), queue_(std::move(queue)) {}

std::string Runtime::description() const {
  return with_cl_errors([&] {
    const cl::Platform platform(device_.getInfo<CL_DEVICE_PLATFORM>());
    return device_.getInfo<CL_DEVICE_NAME>() + " (" + platform.getInfo<CL_PLATFORM_NAME>() + ", " +
           device_.getInfo<CL_DEVICE_VERSION>() + ")";
  });
}

bool Runtime::is_cpu() const {
  return with_cl_errors([&] { return device_is_cpu(device_); });
}

}  // namespace fogcl
