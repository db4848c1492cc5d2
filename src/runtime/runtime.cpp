#include "fogcl/runtime.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <vector>

#include "runtime/clhpp.h"

namespace fogcl {

namespace {
std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

// PoCL: what the project installs and tests, and the CPU device whose kernel gives the scalar
// path's bits (kernel_factor_bits_test.cpp).
bool is_pocl(const cl::Platform& platform) {
  return platform.getInfo<CL_PLATFORM_NAME>().find("Portable Computing") != std::string::npos;
}

struct Candidate {
  cl::Platform platform;
  cl::Device device;
  std::string label;  // "device name (platform name)"
};

// Platforms that failed to list their devices, with the CL error ("" if none): a driver that is
// registered but does not come up (e.g. a GPU driver in a container without the device) is named
// in find_device's message instead of vanishing from the list.
std::vector<Candidate> all_devices(std::string* failed_platforms = nullptr) {
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
    } catch (const cl::Error& e) {
      // A platform without devices (CL_DEVICE_NOT_FOUND) is not an error here; others are noted.
      if (e.err() != CL_DEVICE_NOT_FOUND && failed_platforms != nullptr)
        *failed_platforms += "; " + p.getInfo<CL_PLATFORM_NAME>() + " platform failed to list its devices: " +
                             cl_error_name(e.err());
      continue;
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

bool device_is_cpu(cl_device_id device) {
  return with_cl_errors([&] { return (wrap(device).getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) != 0; });
}

bool device_is_pocl_cpu(cl_device_id device) {
  return device_is_cpu(device) &&
         with_cl_errors([&] { return is_pocl(cl::Platform(wrap(device).getInfo<CL_DEVICE_PLATFORM>())); });
}

std::string device_opencl_c_version(cl_device_id device) {
  return with_cl_errors([&] { return wrap(device).getInfo<CL_DEVICE_OPENCL_C_VERSION>(); });
}

unsigned long long device_cache_bytes(cl_device_id device) {
  return with_cl_errors([&] { return (unsigned long long)wrap(device).getInfo<CL_DEVICE_GLOBAL_MEM_CACHE_SIZE>(); });
}

std::string device_name(cl_device_id device) {
  return with_cl_errors([&] { return wrap(device).getInfo<CL_DEVICE_NAME>(); });
}

cl_device_id find_device(const std::string& choice) {
  return with_cl_errors([&] {
    std::string failed;
    const std::vector<Candidate> all = all_devices(&failed);
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
      const bool pocl = is_pocl(c.platform);
      if (found == nullptr || (want == "cpu" && pocl)) found = &c;
      if (pocl || want != "cpu") break;
    }
    if (found == nullptr) {
      std::string list;
      for (const auto& c : all) list += (list.empty() ? "" : "; ") + c.label;
      throw Error("no OpenCL device matches '" + choice + "' (use cpu, gpu, scalar or part of a device name; available: " +
                  (list.empty() ? std::string("none") : list) + failed + ")");
    }
    return found->device();  // root devices are not reference counted: the handle outlives `all`
  });
}

struct Runtime::Handles {
  cl::Context context;
  cl::Device device;
  cl::CommandQueue queue;
};

Runtime::Runtime(const std::string& choice) {
  handles_ = with_cl_errors([&] {
    auto h = std::make_shared<Handles>();
    h->device = cl::Device(find_device(resolve_device_choice(choice)));
    h->context = cl::Context(h->device);
    h->queue = cl::CommandQueue(h->context, h->device, CL_QUEUE_PROFILING_ENABLE);
    return h;
  });
}

Runtime::Runtime(cl_context context, cl_device_id device, cl_command_queue queue) {
  if (context == nullptr || device == nullptr || queue == nullptr)
    throw Error("Runtime needs a context, a device and a queue (one of them is null)");
  handles_ = std::make_shared<Handles>(Handles{wrap(context), wrap(device), wrap(queue)});
}

cl_context Runtime::context() const { return handles_->context(); }
cl_device_id Runtime::device() const { return handles_->device(); }
cl_command_queue Runtime::queue() const { return handles_->queue(); }

std::string Runtime::description() const {
  return with_cl_errors([&] {
    const cl::Device& device = handles_->device;
    const cl::Platform platform(device.getInfo<CL_DEVICE_PLATFORM>());
    return device.getInfo<CL_DEVICE_NAME>() + " (" + platform.getInfo<CL_PLATFORM_NAME>() + ", " +
           device.getInfo<CL_DEVICE_VERSION>() + ")";
  });
}

bool Runtime::is_cpu() const { return device_is_cpu(device()); }

}  // namespace fogcl
