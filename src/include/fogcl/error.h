// Error types. Every failure the library reports is one of these; messages name the value
// that was wrong and the rule it broke, or the OpenCL call and its error name.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace fogcl {

// Invalid input or usage: a parameter out of range, mismatched images, an unusable device choice.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Host memory for a frame could not be allocated; what() names what was being allocated and its
// size, e.g. "color image 8192x8192 rgba32f: cannot allocate 1073741824 bytes (out of host memory)".
class OutOfMemory : public Error {
 public:
  using Error::Error;
};

// An OpenCL call failed. what() reads e.g. "clBuildProgram failed: CL_BUILD_PROGRAM_FAILURE (-11)"
// followed by the device's build log when there is one.
class ClError : public Error {
 public:
  ClError(std::string call, std::int32_t code, std::string build_log = {});
  const std::string& call() const { return call_; }
  std::int32_t code() const { return code_; }
  const char* code_name() const;
  const std::string& build_log() const { return build_log_; }

 private:
  std::string call_;
  std::int32_t code_;
  std::string build_log_;
};

// "CL_INVALID_VALUE" for -30, "CL_UNKNOWN_ERROR" for codes the spec does not name.
const char* cl_error_name(std::int32_t code);

}  // namespace fogcl
