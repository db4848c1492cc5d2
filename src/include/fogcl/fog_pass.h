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

// How the convenience calls (apply, apply_async) move host images to the device and back.
enum class HostTransfer {
  automatic,  // direct on CPU devices, staged on the others (GPUs)
  // Buffers made from the host images each call: on a CPU device the kernel reads and writes the
  // images' own memory (CL_MEM_USE_HOST_PTR, nothing copied); elsewhere the driver copies them
  // from pageable memory (~4x slower than staged on an H100: docs/gpu.md).
  direct,
  // Device buffers and pinned host staging kept per frame size and reused; the images are
  // copied to and from the staging memory in bands that overlap the bus transfers. The GPU
  // default; on a CPU device it runs the same code (tests check it gives the same bytes).
  staged,
};
const char* to_string(HostTransfer transfer);

// Host images in page-locked memory of `context` (CL_MEM_ALLOC_HOST_PTR, mapped for the image's
// life), pixels zeroed: the staged convenience calls of passes in that context move them over
// the bus from where they are, without a staging copy (docs/gpu.md: the round trip at the bus's
// speed). Ordinary images otherwise; a copy of one is ordinary memory. Throws fogcl::ClError
// when the context cannot allocate it.
ColorImage pinned_color_image(cl_context context, cl_device_id device, int width, int height,
                              ColorFormat format = ColorFormat::rgba32f);
DepthImage pinned_depth_image(cl_context context, cl_device_id device, int width, int height);

// A convenience call in flight (FogPass::apply_async): wait() blocks until its `out` holds the
// result. It may outlive its pass (it holds the staging it uses); its `out` must stay alive until
// wait(). The destructor waits too (and swallows errors: call wait()).
class PendingFrame {
 public:
  PendingFrame();
  ~PendingFrame();
  PendingFrame(PendingFrame&&) noexcept;
  PendingFrame& operator=(PendingFrame&&) noexcept;
  // Blocks until `out` holds the result; a second call returns at once. Throws fogcl::ClError
  // when a command failed.
  void wait();
  // Whether wait() would return at once.
  bool done() const;

 private:
  friend class FogPass;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A pass that was moved from throws fogcl::Error ("FogPass used after move") from every call.
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
  // Throws fogcl::Error for invalid input (camera, settings, a camera whose aspect is not the
  // frame's: validate(camera, width, height), buffers of the wrong size or context, a null event
  // in wait_list), fogcl::ClError for OpenCL failures; nothing is enqueued then.
  cl_event enqueue(cl_command_queue queue, const FrameBuffers& frame, const CameraParams& camera,
                   const FogSettings& settings, const std::vector<cl_event>& wait_list = {});

  // Convenience: host images in and out; prepares the variant if needed and blocks until `out`
  // holds the result (it is the one call that may build). out is reallocated unless it already
  // has in's size and format; out may be in. On CPU devices the images' own memory is used by
  // the kernel (CL_MEM_USE_HOST_PTR), nothing is copied.
  void apply(const ColorImage& in, const DepthImage& depth, ColorImage& out,
             const CameraParams& camera, const FogSettings& settings);
  // The same over the caller's memory (views, image.h): out must have in's size and format (a
  // view is not resized) and is either in itself (in place) or memory apart from in and depth.
  // On CPU devices the kernel works in that memory when its rows are packed and it starts at the
  // device's CL_DEVICE_MEM_BASE_ADDR_ALIGN; otherwise each image is copied once (stats():
  // zero_copy_frames or copied_frames). docs/library.md#images-and-views.
  void apply(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
             const CameraParams& camera, const FogSettings& settings);
  // apply() that returns once `in` and `depth` are no longer needed, before `out` holds the
  // result (staged transfers: the upload, kernel and download are queued; the next call's upload
  // overlaps this one's download). `out` is sized here and must stay alive and untouched until
  // the returned frame's wait(), which may run on another thread. The staging of three frames in
  // flight is kept; more get staging of their own, up to 16 in flight, then this throws
  // fogcl::Error. With direct transfers it is apply() and returns a finished frame.
  PendingFrame apply_async(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                           const CameraParams& camera, const FogSettings& settings);
  // The same over views (as apply); `out`'s memory must stay alive until wait().
  PendingFrame apply_async(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                           const CameraParams& camera, const FogSettings& settings);

  // The convenience calls' transfers (default automatic); the choice in effect for this device.
  void set_host_transfer(HostTransfer transfer);
  HostTransfer host_transfer() const;

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
  Impl& impl() const;  // throws when moved from
  std::unique_ptr<Impl> impl_;
};

}  // namespace fogcl
