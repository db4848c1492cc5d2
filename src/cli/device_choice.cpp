#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <exception>
#include <filesystem>
#include <functional>
#include <string>
#include <system_error>
#include <vector>

#include <OpenEXR/IlmThreadPool.h>

#include "cli/cli.h"

namespace fogcl::cli {

namespace {

// A band of rows of a frame, fogged on OpenEXR's global thread pool: the scalar path shares the
// --threads workers with the (de)compression of the frames before and after it.
class RowsTask : public IlmThread::Task {
 public:
  RowsTask(IlmThread::TaskGroup* group, std::function<void()> work) : Task(group), work_(std::move(work)) {}
  void execute() override { work_(); }

 private:
  std::function<void()> work_;
};

int pool_threads() { return IlmThread::ThreadPool::globalThreadPool().numThreads(); }

// PoCL keeps its compiled kernels in a cache folder: POCL_CACHE_DIR, else
// $XDG_CACHE_HOME/pocl/kcache, else $HOME/.cache/pocl/kcache (PoCL's lib/CL/pocl_cache.c). If it
// cannot create that folder its platform offers no device ("no OpenCL device matches 'cpu' ...
// available: none"); if it cannot write in it, every program build fails with a bare
// CL_BUILD_PROGRAM_FAILURE. Returns the one line that says which, "" when the folder is usable
// (or no variable names one).
std::string pocl_cache_problem() {
  std::string dir, from;
  const auto env = [](const char* name) -> const char* {
    const char* v = std::getenv(name);
    return v != nullptr && *v != '\0' ? v : nullptr;
  };
  if (const char* d = env("POCL_CACHE_DIR")) {
    dir = d, from = "POCL_CACHE_DIR";
  } else if (const char* x = env("XDG_CACHE_HOME")) {
    dir = std::string(x) + "/pocl/kcache", from = "XDG_CACHE_HOME";
  } else if (const char* h = env("HOME")) {
    dir = std::string(h) + "/.cache/pocl/kcache", from = "HOME";
  } else {
    return "";
  }
  std::string why;
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec)) {
    why = "is not a folder";
  } else if (std::filesystem::create_directories(dir, ec); ec) {
    why = "cannot be created (" + ec.message() + ")";
  } else {
    std::string probe = dir + "/.fogcl-write-test-XXXXXX";
    const int fd = ::mkstemp(probe.data());
    if (fd < 0) {
      why = std::string("cannot be written (") + std::strerror(errno) + ")";
    } else {
      ::close(fd);
      ::unlink(probe.c_str());
    }
  }
  if (why.empty()) return "";
  return "PoCL (the OpenCL CPU driver) cannot use its kernel cache folder '" + dir + "' (from " + from + "): it " + why +
         "; set POCL_CACHE_DIR to a writable folder, or use --device scalar";
}

// The scalar path in row bands on OpenEXR's pool of `threads`.
void apply_in_bands(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                    const CameraParams& camera, const FogSettings& settings, int threads) {
  // A few bands per thread so that uneven bands (sky rows are cheap) still keep every worker busy;
  // each pixel gets the bits that one apply_fog_scalar call would give it.
  const int bands = std::min(in.height(), 4 * threads);
  std::vector<std::string> errors(static_cast<std::size_t>(bands));
  {
    IlmThread::TaskGroup group;  // its destructor waits for every band
    for (int b = 0; b < bands; ++b) {
      const int first = int(std::int64_t(in.height()) * b / bands), end = int(std::int64_t(in.height()) * (b + 1) / bands);
      IlmThread::ThreadPool::addGlobalTask(new RowsTask(&group, [&, b, first, end] {
        try {
          apply_fog_scalar_rows(in, depth, out, camera, settings, first, end);
        } catch (const std::exception& e) {
          errors[std::size_t(b)] = e.what();
        }
      }));
    }
  }
  for (const std::string& e : errors)
    if (!e.empty()) throw Error(e);
}

}  // namespace

std::string device_choice_source(const std::string& choice) {
  if (!choice.empty()) return "--device: ";
  const char* env = std::getenv("FOGCL_DEVICE");
  return env != nullptr && *env != '\0' ? "FOGCL_DEVICE: " : "";
}

Backend::Backend(const std::string& choice) {
  const std::string resolved = resolve_device_choice(choice);
  if (resolved == "scalar") return;
  try {
    runtime_ = std::make_unique<Runtime>(resolved);
  } catch (const Error& e) {
    // A PoCL that could not start offers no device: say why instead of "available: none".
    if (const std::string problem = pocl_cache_problem(); !problem.empty()) throw Error(problem);
    throw Error(device_choice_source(choice) + e.what());
  }
  // Its builds would fail one by one, each with a build log that does not say why.
  if (device_is_pocl_cpu(runtime_->device()))
    if (const std::string problem = pocl_cache_problem(); !problem.empty()) throw Error(problem);
  pass_ = std::make_unique<FogPass>(*runtime_);
}

std::string Backend::name() const {
  if (runtime_) return runtime_->description();
  const int threads = pool_threads();
  return threads <= 1 ? std::string("scalar C++ (1 thread)")
                      : "scalar C++ (row bands on OpenEXR's pool of " + std::to_string(threads) + " threads)";
}

PendingFrame Backend::apply_async(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                                  const CameraParams& camera, const FogSettings& settings) {
  if (pass_) return pass_->apply_async(in, depth, out, camera, settings);
  apply(in, depth, out, camera, settings);
  return PendingFrame();
}

void Backend::apply(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                    const CameraParams& camera, const FogSettings& settings) {
  if (pass_) {
    pass_->apply(in, depth, out, camera, settings);
    return;
  }
  const int threads = pool_threads();
  if (threads <= 1 || in.empty() || &out == &in) {
    apply_fog_scalar(in, depth, out, camera, settings);
    return;
  }
  if (out.width() != in.width() || out.height() != in.height() || out.format() != in.format())
    out = ColorImage(in.width(), in.height(), in.format());
  apply_in_bands(in, depth, out, camera, settings, threads);
}

void Backend::apply(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                    const CameraParams& camera, const FogSettings& settings) {
  if (pass_) {
    pass_->apply(in, depth, out, camera, settings);
    return;
  }
  const int threads = pool_threads();
  if (threads <= 1 || in.empty() || out.data() == in.data()) {
    apply_fog_scalar(in, depth, out, camera, settings);
    return;
  }
  apply_in_bands(in, depth, out, camera, settings, threads);
}

}  // namespace fogcl::cli
