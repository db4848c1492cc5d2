#include <algorithm>
#include <exception>
#include <functional>
#include <string>
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

}  // namespace

Backend::Backend(const std::string& choice) {
  const std::string resolved = resolve_device_choice(choice);
  if (resolved == "scalar") return;
  runtime_ = std::make_unique<Runtime>(resolved);
  pass_ = std::make_unique<FogPass>(*runtime_);
}

std::string Backend::name() const {
  if (runtime_) return runtime_->description();
  const int threads = pool_threads();
  return threads <= 1 ? std::string("scalar C++ (1 thread)")
                      : "scalar C++ (row bands on OpenEXR's pool of " + std::to_string(threads) + " threads)";
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

}  // namespace fogcl::cli
