// fogcl's public headers under an integrator's own CLHPP settings: OpenCL 1.2 target and minimum,
// CLHPP exceptions on (CMakeLists.txt), CLHPP included first. Compiled with -Werror (deprecation
// warnings included): fogcl must not raise the target version under the integrator's feet.
#include <CL/opencl.hpp>

#include <fogcl/external_memory.h>
#include <fogcl/fogcl.h>

#ifndef CL_HPP_ENABLE_EXCEPTIONS
#error "CL_HPP_ENABLE_EXCEPTIONS was lost"
#endif
#if CL_TARGET_OPENCL_VERSION != 120
#error "fogcl's headers changed the integrator's OpenCL target version"
#endif
#ifdef CL_VERSION_2_0
#error "the OpenCL 2.0 API is declared under a 1.2 target"
#endif

cl::Event fogcl_check_cl120(const cl::Context& context, const cl::Device& device, const cl::CommandQueue& queue,
                            const fogcl::FrameBuffers& frame, const fogcl::CameraParams& camera) {
  try {
    fogcl::FogPass pass(context(), device());
    return cl::Event(pass.enqueue(queue(), frame, camera, fogcl::FogSettings{}));  // takes over the reference
  } catch (const cl::Error& e) {  // CLHPP's exceptions and fogcl's coexist
    throw fogcl::ClError(e.what(), e.err());
  }
}
