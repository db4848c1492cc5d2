// OpenCL runtime: device choice, one context and in-order queue, and the program cache keyed by
// (device, source, build options) (STYLE.md habits 2 and 4).
#pragma once

#include <cstddef>
#include <map>
#include <mutex>
#include <string>
#include <tuple>

#include "fogcl/cl.h"

namespace fogcl {

// The device to run on, resolved from (in order) an explicit choice such as a CLI flag, the
// FOGCL_DEVICE environment variable, or the default "cpu".
//   "cpu"   the first CPU device, PoCL's preferred (PoCL ships with the project's setup)
//   "gpu"   the first GPU device
//   other   the first device whose name, vendor or platform name contains it (case-insensitive)
// ("scalar" is not an OpenCL device; the CLI handles it before asking for one.)
std::string resolve_device_choice(const std::string& explicit_choice = {});

// Finds the device for a resolved choice; throws fogcl::Error listing the available devices
// when none matches.
cl::Device find_device(const std::string& choice);

// A compiled program per (device, source name, build options) within one context. The first
// request builds (PoCL additionally keeps its own on-disk cache across processes); later ones
// return the cached program. Thread-safe.
class ProgramCache {
 public:
  explicit ProgramCache(cl::Context context);
  // Throws fogcl::ClError with the device's build log if the build fails.
  cl::Program get(const cl::Device& device, const std::string& source_name, const char* source,
                  const std::string& options);
  std::size_t builds() const;  // programs built so far (cache misses)
  const cl::Context& context() const { return context_; }

 private:
  cl::Context context_;
  mutable std::mutex mutex_;
  std::map<std::tuple<cl_device_id, std::string, std::string>, cl::Program> programs_;
  std::size_t builds_ = 0;
};

// Owns a context and an in-order, profiling-enabled queue on one device.
class Runtime {
 public:
  // choice as for resolve_device_choice(); "" = FOGCL_DEVICE or "cpu".
  explicit Runtime(const std::string& choice = {});
  Runtime(cl::Context context, cl::Device device, cl::CommandQueue queue);

  const cl::Context& context() const { return context_; }
  const cl::Device& device() const { return device_; }
  const cl::CommandQueue& queue() const { return queue_; }
  // "pthread-skylake-avx512 (Portable Computing Language, OpenCL 3.0 PoCL ...)"
  std::string description() const;
  bool is_cpu() const;

 private:
  cl::Context context_;
  cl::Device device_;
  cl::CommandQueue queue_;
};

// Runs fn() and turns cl::Error / cl::BuildError into fogcl::ClError (CL call + error name).
template <class Fn>
auto with_cl_errors(Fn&& fn) -> decltype(fn());

// Device queries the rest of the library needs.
std::string device_opencl_c_version(const cl::Device& device);
bool device_is_cpu(const cl::Device& device);

}  // namespace fogcl

#include "fogcl/error.h"

namespace fogcl {
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
}  // namespace fogcl
