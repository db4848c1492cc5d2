#include "fogcl/runtime.h"

namespace fogcl {

ProgramCache::ProgramCache(cl::Context context) : context_(std::move(context)) {}

cl::Program ProgramCache::get(const cl::Device& device, const std::string& source_name,
                              const char* source, const std::string& options) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto key = std::make_tuple(device(), source_name, options);
  if (auto it = programs_.find(key); it != programs_.end()) return it->second;
  cl::Program program = with_cl_errors([&] { return cl::Program(context_, std::string(source)); });
  try {
    program.build(std::vector<cl::Device>{device}, options.c_str());
  } catch (const cl::Error& e) {
    std::string log;
    try {
      log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device);
    } catch (const cl::Error&) {
      log = "(build log unavailable)";
    }
    throw ClError("clBuildProgram(" + source_name + ", \"" + options + "\")", e.err(), log);
  }
  ++builds_;
  programs_.emplace(key, program);
  return program;
}

std::size_t ProgramCache::builds() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return builds_;
}

}  // namespace fogcl
