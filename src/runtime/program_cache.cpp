#include <cstdio>
#include <cstdlib>
#include <functional>
#include <future>
#include <map>
#include <mutex>
#include <tuple>

#include "fogcl/runtime.h"
#include "runtime/clhpp.h"

namespace fogcl {

namespace {
using Key = std::tuple<cl_device_id, std::string, std::string>;  // device, source name, options

// FOGCL_PROGRAM_BINARIES=DIR: each program built is written to DIR as what the driver returns for
// CL_PROGRAM_BINARIES (PTX on NVIDIA's OpenCL), with its source name and options beside it, to read
// what a device's compiler made of a variant (docs/gpu.md). A failure to write is ignored: it is a
// diagnostic, and the program is built either way.
void write_binary(const cl::Program& program, const std::string& source_name, const std::string& options) {
  const char* dir = std::getenv("FOGCL_PROGRAM_BINARIES");
  if (dir == nullptr || *dir == '\0') return;
  try {
    const std::vector<std::vector<unsigned char>> binaries = program.getInfo<CL_PROGRAM_BINARIES>();
    if (binaries.empty()) return;
    char name[64];
    std::snprintf(name, sizeof name, "%s-%016zx", source_name.c_str(),
                  std::hash<std::string>{}(source_name + '\n' + options));
    const std::string base = std::string(dir) + "/" + name;
    if (std::FILE* f = std::fopen((base + ".bin").c_str(), "wb")) {
      std::fwrite(binaries[0].data(), 1, binaries[0].size(), f);
      std::fclose(f);
    }
    if (std::FILE* f = std::fopen((base + ".options").c_str(), "w")) {
      std::fprintf(f, "%s\n", options.c_str());
      std::fclose(f);
    }
  } catch (const cl::Error&) {
  }
}

struct Entry {
  std::shared_future<cl::Program> program;  // ready once built; carries a build failure to waiters
  bool ready = false;
};
}  // namespace

struct ProgramCache::Impl {
  cl::Context context;
  mutable std::mutex mutex;  // guards entries and builds, never held during a build
  std::map<Key, Entry> entries;
  std::size_t builds = 0;
};

ProgramCache::ProgramCache(cl_context context) : impl_(std::make_unique<Impl>()) {
  if (context == nullptr) throw Error("ProgramCache needs a context (got a null cl_context)");
  impl_->context = wrap(context);
}

ProgramCache::~ProgramCache() = default;

cl_program ProgramCache::get(cl_device_id device, const std::string& source_name, const char* source,
                             const std::string& options) {
  const Key key{device, source_name, options};
  std::promise<cl::Program> promise;
  {
    std::unique_lock<std::mutex> lock(impl_->mutex);
    if (auto it = impl_->entries.find(key); it != impl_->entries.end()) {
      const std::shared_future<cl::Program> built = it->second.program;
      lock.unlock();
      return built.get()();  // waits only when another thread is building this very program
    }
    impl_->entries.emplace(key, Entry{promise.get_future().share(), false});
  }
  // This thread builds; others asking for the same key wait on the future, others do not wait.
  const auto fail = [&](const std::exception_ptr& error) {
    {
      const std::lock_guard<std::mutex> lock(impl_->mutex);
      impl_->entries.erase(key);  // not cached: the next get() tries again
    }
    promise.set_exception(error);
    std::rethrow_exception(error);
  };
  cl::Program program;
  try {
    program = with_cl_errors([&] { return cl::Program(impl_->context, std::string(source)); });
    try {
      program.build(std::vector<cl::Device>{wrap(device)}, options.c_str());
      write_binary(program, source_name, options);
    } catch (const cl::Error& e) {
      std::string log;
      try {
        log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(wrap(device));
      } catch (const cl::Error&) {
        log = "(build log unavailable)";
      }
      throw ClError("clBuildProgram(" + source_name + ", \"" + options + "\")", e.err(), log);
    }
  } catch (...) {
    fail(std::current_exception());
  }
  cl_program handle;
  {
    const std::lock_guard<std::mutex> lock(impl_->mutex);
    Entry& entry = impl_->entries.at(key);
    entry.ready = true;
    ++impl_->builds;
    promise.set_value(program);
    handle = entry.program.get()();  // the future's copy: lives as long as the entry
  }
  return handle;
}

cl_program ProgramCache::find(cl_device_id device, const std::string& source_name,
                              const std::string& options) const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  const auto it = impl_->entries.find(Key{device, source_name, options});
  return it != impl_->entries.end() && it->second.ready ? it->second.program.get()() : nullptr;
}

std::size_t ProgramCache::builds() const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->builds;
}

cl_context ProgramCache::context() const { return impl_->context(); }

}  // namespace fogcl
