#include "cli/version_info.h"

#include <cstdio>
#include <string>
#include <vector>

#include "fogcl/error.h"
#include "fogcl/version.h"
#include "runtime/clhpp.h"

#ifndef FOGCL_GIT_COMMIT
#define FOGCL_GIT_COMMIT "unknown"
#endif

namespace fogcl::cli {

int print_version() {
  std::printf("fogcl %s (library %s)\ncommit: %s\n", FOGCL_VERSION_STRING, library_version(), FOGCL_GIT_COMMIT);
  std::vector<cl::Platform> platforms;
  std::string why;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error& e) {  // the ICD loader's "no platform"
    why = " (" + std::string(cl_error_name(e.err())) + ": no OpenCL driver registered)";
  }
  if (platforms.empty()) {
    std::printf("OpenCL platforms: none%s\n", why.c_str());
    return 0;
  }
  std::printf("OpenCL platforms: %zu\n", platforms.size());
  for (const cl::Platform& p : platforms) {
    std::printf("  %s (%s)\n", p.getInfo<CL_PLATFORM_NAME>().c_str(), p.getInfo<CL_PLATFORM_VERSION>().c_str());
    std::vector<cl::Device> devices;
    try {
      p.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error& e) {
      std::printf("    devices: none (%s)\n", cl_error_name(e.err()));
      continue;
    }
    for (const cl::Device& d : devices) {
      const cl_device_type type = d.getInfo<CL_DEVICE_TYPE>();
      std::printf("    %s: %s (%s, driver %s)\n",
                  (type & CL_DEVICE_TYPE_GPU) != 0   ? "gpu"
                  : (type & CL_DEVICE_TYPE_CPU) != 0 ? "cpu"
                                                     : "other",
                  d.getInfo<CL_DEVICE_NAME>().c_str(), d.getInfo<CL_DEVICE_VERSION>().c_str(),
                  d.getInfo<CL_DRIVER_VERSION>().c_str());
    }
  }
  return 0;
}

}  // namespace fogcl::cli
