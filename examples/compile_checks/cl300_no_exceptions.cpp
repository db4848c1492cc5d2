// fogcl's public headers under an integrator's own CLHPP settings: OpenCL 3.0 target, CLHPP
// exceptions off (CMakeLists.txt sets the macros as the project's compile definitions), fogcl
// included first. Compiled with -Werror: fogcl must neither define nor change any OpenCL macro.
#include <fogcl/external_memory.h>
#include <fogcl/fogcl.h>
#include <fogcl/version.h>

#include <CL/opencl.hpp>

#ifdef CL_HPP_ENABLE_EXCEPTIONS
#error "fogcl's headers turned CLHPP exceptions on"
#endif
#if CL_TARGET_OPENCL_VERSION != 300 || CL_HPP_TARGET_OPENCL_VERSION != 300
#error "fogcl's headers changed the integrator's OpenCL target version"
#endif
#ifndef CL_VERSION_3_0
#error "the OpenCL 3.0 API is not declared"
#endif

// Uses 3.0-only API next to fogcl's: both must be declared in this translation unit.
cl_event fogcl_check_cl300(const cl::Context& context, const cl::Device& device, const cl::CommandQueue& queue,
                           const fogcl::FrameBuffers& frame, const fogcl::CameraParams& camera) {
  cl_int err = CL_SUCCESS;
  const cl_mem_properties none[] = {0};
  cl_mem scratch = clCreateBufferWithProperties(context(), none, CL_MEM_READ_WRITE, 16, nullptr, &err);
  if (scratch != nullptr) clReleaseMemObject(scratch);
  fogcl::FogPass pass(context(), device());
  return pass.enqueue(queue(), frame, camera, fogcl::FogSettings{});
}
