// The volumetric fog volumes pass (docs/volumetric.md), in the two API levels of the deferred
// pass: integration (the caller's queue and buffers, wait list in, event out) and convenience
// (host images). The scalar C++ path of the same maths is in fogcl/volume_scalar.h.
#pragma once

#include <cmath>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "fogcl/camera.h"
#include "fogcl/fog_pass.h"
#include "fogcl/image.h"
#include "fogcl/opencl_types.h"
#include "fogcl/runtime.h"
#include "fogcl/volumes.h"

namespace fogcl {

// The main light's shadow map on the device (integration API; the buffer is borrowed).
struct ShadowMapBuffer {
  cl_mem depth = nullptr;  // exactly width * height float32: the light's raw depth, row 0 = top
  int width = 0;           // >= 1
  int height = 0;          // >= 1
  ShadowMapParams params;
};

struct VolumePassStats {
  std::size_t march_dispatches = 0;        // march kernels enqueued
  std::size_t composite_dispatches = 0;    // upsample + composite kernels enqueued
  std::size_t frames_without_volumes = 0;  // frames where nothing was visible: no dispatch
  std::size_t noise_uploads = 0;           // noise textures uploaded to the device
  std::size_t volumes_culled = 0;          // volumes left out by the host-side culling, all frames
  std::size_t zero_copy_frames = 0;        // convenience frames run on host memory in place
  std::size_t copied_frames = 0;           // convenience frames copied to and from the device
};

// The volumes of `scene` a frame can see, in the order given: each sphere is tested against the
// camera's near and side planes and against the depth buffer's range (a volume wholly behind the
// farthest surface is hidden; max_eye_depth = +inf keeps every volume the frustum keeps; there is
// no far-plane test, sky pixels see infinitely far). Throws fogcl::Error for an invalid scene or
// camera.
std::vector<std::size_t> visible_volumes(const VolumeScene& scene, const CameraParams& camera,
                                         float max_eye_depth = INFINITY);

// The farthest eye depth of a depth buffer, +inf when any pixel is sky (docs/DESIGN.md §2's test).
float max_eye_depth(const ConstDepthView& depth, const CameraParams& camera);

// A pass that was moved from throws fogcl::Error ("VolumePass used after move") from every call.
// Threads: a VolumePass is not thread-safe (kernel arguments, noise uploads): one per thread, or
// lock around it. Passes may share one ProgramCache (thread-safe) with each other and with
// FogPasses. It keeps its noise textures on the device across frames, and up to four frames'
// scratch (the march's low-resolution output, 20 bytes a low-resolution pixel, and the frame's
// constants), reused once the frame that last used it is complete. Handles passed in are
// borrowed for the call, except the context and device of the constructor, which it retains.
class VolumePass {
 public:
  // Integration: programs are built for `device` in the caller's `context`, in `programs` when
  // given (a cache of the same context), else in a cache of its own.
  // codegen: how CPU devices' kernels are built (CpuCodegen, variant.h; the tests' knob).
  VolumePass(cl_context context, cl_device_id device, std::shared_ptr<ProgramCache> programs = nullptr,
             const CpuCodegen& codegen = {});
  // Convenience: the runtime's context, device and queue.
  explicit VolumePass(const Runtime& runtime, std::shared_ptr<ProgramCache> programs = nullptr,
                      const CpuCodegen& codegen = {});
  ~VolumePass();
  VolumePass(VolumePass&&) noexcept;
  VolumePass& operator=(VolumePass&&) noexcept;

  // Builds (or finds) the march and composite programs a frame of `scene` with `settings` needs:
  // blocks for the builds (0.1-1 s each on PoCL). Call it at load time and when the variant
  // changes (integrator, steps, features the visible volumes use, shadow map on/off, resolution,
  // upsampling, storage, camera projection or Z direction). shadow: the shadow map's parameters
  // when frames will have one (its Z direction is part of the variant), else null.
  void prepare(const CameraParams& camera, const VolumeScene& scene, const VolumeSettings& settings,
               ColorFormat storage, const ShadowMapParams* shadow = nullptr);

  // Enqueues the march and the upsample + composite of `frame` on `queue` after `wait_list` and
  // returns the event of the last command: a new reference the caller owns (clReleaseEvent).
  // Never blocks and never builds (an unprepared variant throws fogcl::Error saying so). color_out
  // may be color_in (in place). Nothing visible (culling with max_eye_depth, see visible_volumes):
  // no kernel, a marker when in place, else one buffer copy — the output is the input bit for
  // bit. A noise texture's first frame enqueues its upload. shadow may be null. The camera's
  // aspect must be the frame's (validate(camera, width, height)); a null event in wait_list throws.
  cl_event enqueue(cl_command_queue queue, const FrameBuffers& frame, const CameraParams& camera,
                   const VolumeScene& scene, const VolumeSettings& settings,
                   const ShadowMapBuffer* shadow = nullptr, const std::vector<cl_event>& wait_list = {},
                   float max_eye_depth = INFINITY);

  // Convenience: host images in and out; prepares what it needs and blocks until `out` holds the
  // result. out is reallocated unless it has in's size and format; out may be in. Culls with the
  // depth image's range: nothing visible touches no device.
  void apply(const ColorImage& in, const DepthImage& depth, ColorImage& out, const CameraParams& camera,
             const VolumeScene& scene, const VolumeSettings& settings, const ShadowMap* shadow = nullptr);
  // The same over the caller's memory (views, image.h), as FogPass::apply's views: out has in's
  // size and format and is in itself or apart from in and depth; on CPU devices memory with packed
  // rows at the device's alignment is used in place, other memory is copied once.
  void apply(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out, const CameraParams& camera,
             const VolumeScene& scene, const VolumeSettings& settings, const ShadowMap* shadow = nullptr);
  // The convenience call's transfers (FogPass's HostTransfer; default automatic: direct on CPU
  // devices, pinned staging elsewhere); the choice in effect for this device.
  void set_host_transfer(HostTransfer transfer);
  HostTransfer host_transfer() const;

  const VolumePassStats& stats() const;
  const ProgramCache& programs() const;
  const std::shared_ptr<ProgramCache>& program_cache() const;
  // The march and composite build options of the most recent frame ("" when nothing ran).
  const std::string& last_march_options() const;
  const std::string& last_composite_options() const;
  // The noise sampling this pass uses for `requested`: buffer and image as given, automatic (the
  // VolumeSettings default) resolved for its device (resolve_noise_sampling).
  NoiseSampling noise_sampling(NoiseSampling requested = NoiseSampling::automatic) const;

 private:
  struct Impl;
  Impl& impl() const;  // throws when moved from
  std::unique_ptr<Impl> impl_;
};

}  // namespace fogcl
