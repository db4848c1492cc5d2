#include "cli/cli.h"

namespace fogcl::cli {

Backend::Backend(const std::string& choice) {
  const std::string resolved = resolve_device_choice(choice);
  if (resolved == "scalar") return;
  runtime_ = std::make_unique<Runtime>(resolved);
  pass_ = std::make_unique<FogPass>(*runtime_);
}

std::string Backend::name() const {
  return runtime_ ? runtime_->description() : std::string("scalar C++ (1 thread)");
}

void Backend::apply(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                    const CameraParams& camera, const FogSettings& settings) {
  if (pass_)
    pass_->apply(in, depth, out, camera, settings);
  else
    apply_fog_scalar(in, depth, out, camera, settings);
}

}  // namespace fogcl::cli
