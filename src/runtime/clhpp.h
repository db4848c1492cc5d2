// OpenCL C++ bindings as fogcl's own code uses them (library, CLI, tests, bench): exceptions on,
// OpenCL 1.2 API (what PoCL and NVIDIA both offer). PRIVATE to the build: the public headers use
// raw handles (fogcl/opencl_types.h), so an integrator's own CLHPP settings never meet these
// (docs/DESIGN.md §1.1). The targets that include this are compiled with the same macros
// (fogcl_clhpp_settings in src/CMakeLists.txt), so whichever header comes first, they agree.
#pragma once

#ifndef CL_HPP_ENABLE_EXCEPTIONS
#define CL_HPP_ENABLE_EXCEPTIONS
#endif
#ifndef CL_HPP_TARGET_OPENCL_VERSION
#define CL_HPP_TARGET_OPENCL_VERSION 120
#endif
#ifndef CL_HPP_MINIMUM_OPENCL_VERSION
#define CL_HPP_MINIMUM_OPENCL_VERSION 120
#endif
#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#include <CL/opencl.hpp>

#include <string>
#include <vector>

#include "fogcl/error.h"

namespace fogcl {

// Runs fn() and turns cl::Error / cl::BuildError into fogcl::ClError (CL call + error name).
template <class Fn>
auto with_cl_errors(Fn&& fn) -> decltype(fn()) {
  try {
    return fn();
  } catch (const cl::BuildError& e) {
    std::string log;
    for (const auto& [device, text] : e.getBuildLog()) log += text;
    throw ClError(e.what(), e.err(), log);
  } catch (const cl::Error& e) {
    throw ClError(e.what(), e.err());
  }
}

// CLHPP views of the raw handles of the public API. Each takes its own reference (retain), so
// the wrapper's release leaves the caller's reference alone.
inline cl::Context wrap(cl_context h) { return cl::Context(h, true); }
inline cl::Device wrap(cl_device_id h) { return cl::Device(h, true); }
inline cl::CommandQueue wrap(cl_command_queue h) { return cl::CommandQueue(h, true); }
inline cl::Buffer wrap(cl_mem h) { return cl::Buffer(h, true); }
inline cl::Event wrap(cl_event h) { return cl::Event(h, true); }
inline cl::Program wrap(cl_program h) { return cl::Program(h, true); }
// Takes over an event returned by FogPass::enqueue (the caller's reference).
inline cl::Event adopt(cl_event h) { return cl::Event(h, false); }
// A new reference for the caller (what the public API hands out).
inline cl_event share(const cl::Event& e) {
  cl_event h = e();
  if (h != nullptr) clRetainEvent(h);
  return h;
}

}  // namespace fogcl
