// The OpenCL fog pass, in the two API levels of docs/DESIGN.md §1: integration (the caller's
// context, queue and buffers, raw OpenCL handles) and convenience (host images).
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "fogcl/camera.h"
#include "fogcl/fog_settings.h"
#include "fogcl/image.h"
#include "fogcl/opencl_types.h"
#include "fogcl/runtime.h"
#include "fogcl/variant.h"

namespace fogcl {

// The caller's device buffers for one frame (borrowed: fogcl neither retains nor releases them).
// Frames are packed: pixel (x, y) at element y * width + x of each buffer, row 0 = top, no row
// padding, from byte 0 of the buffer. Each buffer must be *exactly* the frame's size (a larger
// buffer is rejected: that is how an RGBA16F frame on a buffer sized for RGBA32F, or a wrong
// width, shows); to use a region of a larger allocation, pass a sub-buffer (clCreateSubBuffer;
// its origin must be a multiple of CL_DEVICE_MEM_BASE_ADDR_ALIGN). docs/DESIGN.md §1.1.
struct FrameBuffers {
  cl_mem color_in = nullptr;   // width * height * bytes_per_pixel(format) bytes: RGBA in `format`
  cl_mem depth = nullptr;      // width * height * 4 bytes: float32 raw device depth
  cl_mem color_out = nullptr;  // like color_in; may be color_in itself (in place)
  int width = 0;               // >= 1
  int height = 0;              // >= 1
  ColorFormat format = ColorFormat::rgba32f;
};

// The bytes FrameBuffers::color_in/color_out and depth must hold for a width x height frame.
std::size_t color_buffer_bytes(int width, int height, ColorFormat format);
std::size_t depth_buffer_bytes(int width, int height);

struct PassStats {
  std::size_t kernel_dispatches = 0;  // fog kernels enqueued
  std::size_t buffer_copies = 0;      // fog-off copies (integration API, out != in)
  std::size_t zero_copy_frames = 0;   // convenience frames run on host memory in place
  std::size_t copied_frames = 0;      // convenience frames copied to and from the device
  // The last convenience apply's fog kernel on the device, profiling START -> END [ms]; 0 when
  // that call ran no kernel or its queue has no profiling (a Runtime made from the caller's
  // queue). Its host call over this is the call's overhead (BM_OpenCLHostCall).
  double last_kernel_ms = 0;
};

// Threads: a FogPass is not thread-safe (its kernels carry arguments between setArg and the
// enqueue): use one per thread, or lock around it. Passes on any threads may share one
// ProgramCache, which is thread-safe. Handles passed in are borrowed for the call, except the
// context and device of the constructor, which the pass retains.
class FogPass {
 public:
  // Integration: programs are built for `device` in the caller's `context`, in `programs` when
  // given (a cache of the same context, shared with other passes), else in a cache of its own.
  FogPass(cl_context context, cl_device_id device, std::shared_ptr<ProgramCache> programs = nullptr,
          const CpuCodegen& codegen = {});
  // Convenience: the runtime's context, device and queue. codegen: see CpuCodegen.
  explicit FogPass(const Runtime& runtime, const CpuCodegen& codegen = {},
                   std::shared_ptr<ProgramCache> programs = nullptr);
  ~FogPass();
  FogPass(FogPass&&) noexcept;
  FogPass& operator=(FogPass&&) noexcept;

  // Builds (or finds in the cache) the program of each variant a scene will use and creates its
  // kernel: blocks for the build (~100 ms per variant from PoCL's disk cache, up to ~1.4 s cold).
  // Call it at load time, and again when the settings or camera change to a new variant (fog
  // mode, depth/distance, skybox, Z direction, projection, color format, precision).
  // A variant that needs no pass (fog off, density 0) builds nothing.
  void prepare(const Variant& variant);
  void prepare(const FogSettings& settings, const CameraParams& camera, ColorFormat storage);
  // Whether enqueue() can run `variant` without a build: prepared by this pass, or built in the
  // shared cache by another pass. Never blocks.
  bool is_prepared(const Variant& variant) const;

  // Enqueues the pass on `queue` (of this pass's context and device) after `wait_list` and
  // returns the event of its last command: a new reference the caller owns and must release
  // (clReleaseEvent). Never blocks the host and never builds: a variant that is not prepared
  // (see is_prepared) throws fogcl::Error naming it; call prepare() first. Fog off (or density
  // 0) enqueues no kernel: a marker when color_out is color_in, else one buffer copy.
  // Throws fogcl::Error for invalid input (camera, settings, buffers of the wrong size or
  // context), fogcl::ClError for OpenCL failures; nothing is enqueued then.
  cl_event enqueue(cl_command_queue queue, const FrameBuffers& frame, const CameraParams& camera,
                   const FogSettings& settings, const std::vector<cl_event>& wait_list = {});

  // Convenience: host images in and out; prepares the variant if needed and blocks until `out`
  // holds the result (it is the one call that may build). out is reallocated unless it already
  // has in's size and format; out may be in. On CPU devices the images' own memory is used by
  // the kernel (CL_MEM_USE_HOST_PTR), nothing is copied.
  void apply(const ColorImage& in, const DepthImage& depth, ColorImage& out,
             const CameraParams& camera, const FogSettings& settings);

  // The build options this pass uses for `variant` on its device.
  std::string build_options_for(const Variant& variant) const;

  const PassStats& stats() const;
  const ProgramCache& programs() const;
  const std::shared_ptr<ProgramCache>& program_cache() const;
  cl_context context() const;  // borrowed, valid while the pass lives
  cl_device_id device() const;
  // The variant of the most recent enqueue/apply (mode none when no pass ran).
  const Variant& last_variant() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fogcl
