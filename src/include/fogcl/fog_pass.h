// The OpenCL fog pass, in the two API levels of DESIGN.md §1.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "fogcl/cl.h"

#include "fogcl/camera.h"
#include "fogcl/fog_settings.h"
#include "fogcl/image.h"
#include "fogcl/runtime.h"
#include "fogcl/variant.h"

namespace fogcl {

// The caller's device buffers for one frame. color_out may be the same buffer as color_in
// (in place). Sizes are checked against width x height.
struct FrameBuffers {
  cl::Buffer color_in;   // width * height RGBA pixels in `format`, row 0 = top
  cl::Buffer depth;      // width * height float32 raw device depth
  cl::Buffer color_out;  // width * height RGBA pixels in `format`
  int width = 0;         // >= 1
  int height = 0;        // >= 1
  ColorFormat format = ColorFormat::rgba32f;
};

struct PassStats {
  std::size_t kernel_dispatches = 0;  // fog kernels enqueued
  std::size_t buffer_copies = 0;      // fog-off copies (integration API, out != in)
  std::size_t zero_copy_frames = 0;   // convenience frames run on host memory in place
  std::size_t copied_frames = 0;      // convenience frames copied to and from the device
};

// Not thread-safe: use one FogPass per thread (they may share nothing but the device).
class FogPass {
 public:
  // Integration: programs are built for `device` in the caller's `context`.
  FogPass(cl::Context context, cl::Device device);
  // Convenience: the runtime's context, device and queue. codegen: see CpuCodegen.
  explicit FogPass(const Runtime& runtime, const CpuCodegen& codegen = {});

  // Enqueues the pass on `queue` (of this pass's context and device) after `wait_list` and
  // returns the event of its last command. Never blocks the host. Fog off (or density 0)
  // enqueues no kernel: a marker when color_out is color_in, else one buffer copy.
  // Throws fogcl::Error for invalid input, fogcl::ClError for OpenCL failures.
  cl::Event enqueue(const cl::CommandQueue& queue, const FrameBuffers& frame,
                    const CameraParams& camera, const FogSettings& settings,
                    const std::vector<cl::Event>& wait_list = {});

  // Convenience: host images in and out; blocks until `out` holds the result. out is
  // reallocated unless it already has in's size and format; out may be in. On CPU devices the
  // images' own memory is used by the kernel (CL_MEM_USE_HOST_PTR), nothing is copied.
  void apply(const ColorImage& in, const DepthImage& depth, ColorImage& out,
             const CameraParams& camera, const FogSettings& settings);

  // Builds (or finds in the cache) the program of `variant`, e.g. before the first frame.
  void prepare(const Variant& variant);

  // The build options this pass uses for `variant` on its device.
  std::string build_options_for(const Variant& variant) const { return build_options(variant, traits_); }

  const PassStats& stats() const { return stats_; }
  const ProgramCache& programs() const { return programs_; }
  const cl::Device& device() const { return device_; }
  // The variant of the most recent enqueue/apply (mode none when no pass ran).
  const Variant& last_variant() const { return last_variant_; }

 private:
  cl::Kernel& kernel_for(const Variant& variant);

  cl::Device device_;
  ProgramCache programs_;
  cl::CommandQueue queue_;  // convenience queue; created on first apply() if not given
  DeviceTraits traits_;
  std::map<std::string, cl::Kernel> kernels_;  // by build options
  // The kernel of the most recent variant: a steady stream of frames skips the option string.
  Variant last_kernel_variant_;
  cl::Kernel* last_kernel_ = nullptr;
  PassStats stats_;
  Variant last_variant_;
};

}  // namespace fogcl
