// OpenCL runtime: device choice, one context and in-order queue, and the program cache keyed by
// (device, source, build options) (STYLE.md habits 2 and 4). Raw OpenCL handles only
// (docs/DESIGN.md §1.1): no CLHPP type appears in fogcl's public headers.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "fogcl/opencl_types.h"

namespace fogcl {

// The device to run on, resolved from (in order) an explicit choice such as a CLI flag, the
// FOGCL_DEVICE environment variable, or the default "cpu".
//   "cpu"   the first CPU device, PoCL's preferred (PoCL ships with the project's setup)
//   "gpu"   the first GPU device
//   other   the first device whose name, vendor or platform name contains it (case-insensitive)
// ("scalar" is not an OpenCL device; the CLI handles it before asking for one.)
std::string resolve_device_choice(const std::string& explicit_choice = {});

// Finds the device for a resolved choice (a root device: no reference to release); throws
// fogcl::Error listing the available devices when none matches.
cl_device_id find_device(const std::string& choice);

// Device queries the rest of the library needs. Throw fogcl::ClError on failure.
std::string device_opencl_c_version(cl_device_id device);  // CL_DEVICE_OPENCL_C_VERSION
bool device_is_cpu(cl_device_id device);                   // CL_DEVICE_TYPE has CPU
bool device_is_pocl_cpu(cl_device_id device);              // ... and PoCL's platform
std::string device_name(cl_device_id device);              // CL_DEVICE_NAME
unsigned long long device_cache_bytes(cl_device_id device);  // CL_DEVICE_GLOBAL_MEM_CACHE_SIZE

// A compiled program per (device, source name, build options) within one context. The first
// request builds (PoCL additionally keeps its own on-disk cache across processes); later ones
// return the cached program.
//
// Threads: thread-safe. Share one cache between passes (std::shared_ptr, see FogPass) and
// threads as you like. A build runs outside the cache's lock: get() of a program being built by
// another thread waits for that build only; find() and the other members never wait for a build.
// A failed build is not cached (the next get() tries again).
class ProgramCache {
 public:
  explicit ProgramCache(cl_context context);  // retains the context
  ~ProgramCache();
  ProgramCache(const ProgramCache&) = delete;
  ProgramCache& operator=(const ProgramCache&) = delete;

  // The program, built on this thread if no one built it yet: blocks for the build (~100 ms
  // from PoCL's disk cache, over a second cold). Throws fogcl::ClError with the device's build log
  // if the build fails. The handle is the cache's: valid while the cache lives (retain it to
  // keep it longer).
  cl_program get(cl_device_id device, const std::string& source_name, const char* source,
                 const std::string& options);
  // The program if it is built, else nullptr. Never builds and never waits.
  cl_program find(cl_device_id device, const std::string& source_name, const std::string& options) const;
  std::size_t builds() const;  // programs built so far (cache misses)
  cl_context context() const;  // the cache's reference; valid while the cache lives

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Owns (a reference to) a context and an in-order, profiling-enabled queue on one device.
//
// Threads: immutable after construction; copies share the same handles. The handles follow
// OpenCL's rules (a queue may be used from several threads, its commands run in order).
class Runtime {
 public:
  // choice as for resolve_device_choice(); "" = FOGCL_DEVICE or "cpu".
  explicit Runtime(const std::string& choice = {});
  // Wraps the caller's handles: each is retained here and released with the last copy.
  Runtime(cl_context context, cl_device_id device, cl_command_queue queue);

  // Borrowed handles, valid while this Runtime (or a copy) lives.
  cl_context context() const;
  cl_device_id device() const;
  cl_command_queue queue() const;
  // "pthread-skylake-avx512 (Portable Computing Language, OpenCL 3.0 PoCL ...)"
  std::string description() const;
  bool is_cpu() const;

 private:
  struct Handles;
  std::shared_ptr<const Handles> handles_;
};

}  // namespace fogcl
