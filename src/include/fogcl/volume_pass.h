// The volumetric fog volumes pass (docs/volumetric.md), in the two API levels of the deferred
// pass: integration (the caller's queue and buffers, wait list in, event out) and convenience
// (host images). The scalar C++ path of the same maths is in fogcl/volume_scalar.h.
#pragma once

#include <cmath>
#include <cstddef>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "fogcl/camera.h"
#include "fogcl/cl.h"
#include "fogcl/fog_pass.h"
#include "fogcl/image.h"
#include "fogcl/runtime.h"
#include "fogcl/volumes.h"

namespace fogcl {

// The main light's shadow map on the device (integration API).
struct ShadowMapBuffer {
  cl::Buffer depth;  // width * height float32 raw depth of the light, row 0 = top
  int width = 0;     // >= 1
  int height = 0;    // >= 1
  ShadowMapParams params;
};

struct VolumePassStats {
  std::size_t march_dispatches = 0;      // march kernels enqueued
  std::size_t composite_dispatches = 0;  // upsample + composite kernels enqueued
  std::size_t frames_without_volumes = 0;  // frames where nothing was visible: no dispatch
  std::size_t noise_uploads = 0;         // noise textures uploaded to the device
  std::size_t volumes_culled = 0;        // volumes left out by the host-side culling, all frames
};

// The volumes of `scene` a frame can see, in the order given: each sphere is tested against the
// camera's frustum (side planes, near and far) and against the depth buffer's range (a volume
// wholly behind the farthest surface is hidden; max_eye_depth = +inf keeps every volume the
// frustum keeps). Throws fogcl::Error for an invalid scene or camera.
std::vector<std::size_t> visible_volumes(const VolumeScene& scene, const CameraParams& camera,
                                         float max_eye_depth = INFINITY);

// The farthest eye depth of a depth buffer, +inf when any pixel is sky (DESIGN §2's test).
float max_eye_depth(const DepthImage& depth, const CameraParams& camera);

// Not thread-safe: one VolumePass per thread. Keeps its noise textures on the device across frames.
class VolumePass {
 public:
  // Integration: programs are built for `device` in the caller's `context`.
  VolumePass(cl::Context context, cl::Device device);
  // Convenience: the runtime's context, device and queue.
  explicit VolumePass(const Runtime& runtime);

  // Enqueues the march and the upsample + composite of `frame` on `queue` after `wait_list`
  // and returns the event of the last command; never waits on the host. color_out may be
  // color_in (in place). Nothing visible (culling with max_eye_depth, see visible_volumes): no
  // kernel, a marker when in place, else one buffer copy — the output is the input bit for bit.
  // The first frame of a noise texture uploads it (enqueued, not blocking). shadow may be null.
  cl::Event enqueue(const cl::CommandQueue& queue, const FrameBuffers& frame, const CameraParams& camera,
                    const VolumeScene& scene, const VolumeSettings& settings,
                    const ShadowMapBuffer* shadow = nullptr, const std::vector<cl::Event>& wait_list = {},
                    float max_eye_depth = INFINITY);

  // Convenience: host images in and out, blocks until `out` holds the result. out is reallocated
  // unless it has in's size and format; out may be in. Culls with the depth image's range.
  void apply(const ColorImage& in, const DepthImage& depth, ColorImage& out, const CameraParams& camera,
             const VolumeScene& scene, const VolumeSettings& settings, const ShadowMap* shadow = nullptr);

  // Builds (or finds) the programs `scene` and `settings` need on this pass's device, e.g. before
  // the first frame (a first build takes 0.1-1 s on PoCL).
  void prepare(const CameraParams& camera, const VolumeScene& scene, const VolumeSettings& settings,
               ColorFormat storage, bool with_shadow_map = false);

  const VolumePassStats& stats() const { return stats_; }
  const ProgramCache& programs() const { return programs_; }
  // The march and composite build options of the most recent frame ("" when nothing ran).
  const std::string& last_march_options() const { return last_march_options_; }
  const std::string& last_composite_options() const { return last_composite_options_; }

 private:
  cl::Kernel& kernel(const std::string& source_name, const char* source, const char* kernel_name,
                     const std::string& options);
  const cl::Memory& noise_on_device(const cl::CommandQueue& queue, const VolumeSettings& settings,
                                    std::vector<cl::Event>& waits);

  cl::Device device_;
  ProgramCache programs_;
  cl::CommandQueue queue_;  // convenience queue
  DeviceTraits traits_;
  bool images_ = false;     // the device supports images
  std::map<std::string, cl::Kernel> kernels_;
  std::map<std::tuple<int, unsigned, int>, std::pair<cl::Memory, cl::Event>> noise_;  // (size, seed, image)
  VolumePassStats stats_;
  std::string last_march_options_, last_composite_options_;
};

}  // namespace fogcl
