#include "fogcl/fog_pass.h"

#include <cstring>
#include <map>
#include <optional>

#include "deferred_fog_cl.h"
#include "fogcl/error.h"
#include "pass/formulas.h"
#include "image/packed_frame.h"
#include "runtime/clhpp.h"
#include "runtime/host_call.h"
#include "runtime/frame_buffers.h"
#include "runtime/host_staging.h"
#include "runtime/pinned_memory.h"
#include "settings/fog_coefficients.h"

namespace fogcl {

namespace {
cl_float4 f4(float x, float y, float z, float w) { return cl_float4{{x, y, z, w}}; }
cl_float4 f4(const glm::vec4& v) { return f4(v.x, v.y, v.z, v.w); }
cl_float4 f4(const glm::vec3& v) { return f4(v.x, v.y, v.z, 0.0f); }
}  // namespace

std::size_t color_buffer_bytes(int width, int height, ColorFormat format) {
  return std::size_t(width) * std::size_t(height) * bytes_per_pixel(format);
}

std::size_t depth_buffer_bytes(int width, int height) {
  return std::size_t(width) * std::size_t(height) * sizeof(float);
}

struct FogPass::Impl {
  cl::Context context;
  cl::Device device;
  std::shared_ptr<ProgramCache> programs;
  cl::CommandQueue queue;  // convenience queue; created on first apply() if not given
  DeviceTraits traits;
  std::size_t host_align = 1;  // host memory a CPU device uses in place (frame_buffers.h)
  std::map<std::string, cl::Kernel> kernels;  // by build options
  // The kernel of the most recent variant: a steady stream of frames skips the option string.
  Variant last_kernel_variant;
  cl::Kernel* last_kernel = nullptr;
  PassStats stats;
  Variant last_variant;
  detail::ConvenienceTransfers transfers;

  bool staged() const { return transfers.staged(traits.cpu); }
  // apply()'s checks and sizing of `out`; the variant, or nullopt when no device work is needed
  // (then `out` already holds the result).
  std::optional<Variant> begin_apply(FogPass& pass, const ConstColorView& in, const ConstDepthView& depth,
                                     const ColorView& out, const CameraParams& camera, const FogSettings& settings);
  // The staged convenience call up to the download's enqueue; `done` is the kernel's event.
  PendingFrame start_staged(detail::PackedFrame views, const Variant& v, const CameraParams& camera,
                            const FogSettings& settings, cl::Event& done);
  void record_kernel_time(const cl::Event& done);

  cl::Kernel* find_kernel(const Variant& variant);
  // enqueue() after its checks: the variant `v` of (settings, camera, fb.format), a queue of the
  // pass's context and device, buffers of the frame's sizes. apply() comes here directly: its
  // buffers are made for the frame (frame_buffers.h) and its queue is the pass's own.
  cl_event dispatch(const cl::CommandQueue& queue, const FrameBuffers& fb, const Variant& v,
                    const CameraParams& camera, const FogSettings& settings, const std::vector<cl_event>& wait_list);
};

FogPass::FogPass(cl_context context, cl_device_id device, std::shared_ptr<ProgramCache> programs,
                 const CpuCodegen& codegen)
    : impl_(std::make_unique<Impl>()) {
  if (context == nullptr || device == nullptr)
    throw Error("FogPass needs a context and a device (got a null handle)");
  Impl& m = *impl_;
  m.context = wrap(context);
  m.device = wrap(device);
  if (programs == nullptr) programs = std::make_shared<ProgramCache>(context);
  if (programs->context() != context)
    throw Error("FogPass: the shared ProgramCache belongs to another OpenCL context than the pass");
  m.programs = std::move(programs);
  m.traits = device_traits(device, codegen);
  m.host_align = with_cl_errors([&] { return detail::host_ptr_alignment(m.device); });
}

FogPass::FogPass(const Runtime& runtime, const CpuCodegen& codegen, std::shared_ptr<ProgramCache> programs)
    : FogPass(runtime.context(), runtime.device(), std::move(programs), codegen) {
  impl_->queue = wrap(runtime.queue());
}

FogPass::Impl& FogPass::impl() const {
  if (impl_ == nullptr) throw Error("FogPass used after move: assign a pass to it before calling it again");
  return *impl_;
}

FogPass::~FogPass() = default;
FogPass::FogPass(FogPass&&) noexcept = default;
FogPass& FogPass::operator=(FogPass&&) noexcept = default;

std::string FogPass::build_options_for(const Variant& variant) const {
  return build_options(variant, impl().traits);
}
const PassStats& FogPass::stats() const { return impl().stats; }
const ProgramCache& FogPass::programs() const { return *impl().programs; }
const std::shared_ptr<ProgramCache>& FogPass::program_cache() const { return impl().programs; }
cl_context FogPass::context() const { return impl().context(); }
cl_device_id FogPass::device() const { return impl().device(); }
const Variant& FogPass::last_variant() const { return impl().last_variant; }

// The kernel of a built variant, or nullptr; creates the kernel object (no build) when another
// pass sharing the cache built the program.
cl::Kernel* FogPass::Impl::find_kernel(const Variant& variant) {
  if (last_kernel != nullptr && variant == last_kernel_variant) return last_kernel;
  const std::string options = build_options(variant, traits);
  auto it = kernels.find(options);
  if (it == kernels.end()) {
    const cl_program program = programs->find(device(), "deferred_fog.cl", options);
    if (program == nullptr) return nullptr;
    it = kernels.emplace(options, with_cl_errors([&] { return cl::Kernel(wrap(program), "deferred_fog"); })).first;
  }
  last_kernel_variant = variant;
  last_kernel = &it->second;  // std::map nodes do not move
  return last_kernel;
}

void FogPass::prepare(const Variant& variant) {
  Impl& m = impl();
  if (!variant.needs_pass() || m.find_kernel(variant) != nullptr) return;
  m.programs->get(m.device(), "deferred_fog.cl", deferred_fog_cl, build_options_for(variant));
  m.find_kernel(variant);
}

void FogPass::prepare(const FogSettings& settings, const CameraParams& camera, ColorFormat storage) {
  impl();
  validate(camera);
  prepare(select_variant(settings, camera, storage));
}

bool FogPass::is_prepared(const Variant& variant) const {
  const Impl& m = impl();
  if (!variant.needs_pass()) return true;
  const std::string options = build_options_for(variant);
  return m.kernels.count(options) != 0 || m.programs->find(m.device(), "deferred_fog.cl", options) != nullptr;
}

cl_event FogPass::enqueue(cl_command_queue queue_handle, const FrameBuffers& fb, const CameraParams& camera,
                          const FogSettings& settings, const std::vector<cl_event>& wait_list) {
  Impl& m = impl();
  if (fb.width < 1 || fb.height < 1)
    throw Error("frame size must be at least 1x1 (got " + std::to_string(fb.width) + "x" +
                std::to_string(fb.height) + ")");
  validate(camera, fb.width, fb.height);
  detail::check_wait_list(wait_list, "FogPass::enqueue");
  const Variant v = select_variant(settings, camera, fb.format);
  return detail::host_call("FogPass::enqueue", [&] {
    return with_cl_errors([&] {
      const cl::CommandQueue queue = detail::checked_queue(queue_handle, m.context, m.device, "FogPass::enqueue");
      detail::check_frame_buffers(fb, m.context);
      return m.dispatch(queue, fb, v, camera, settings, wait_list);
    });
  });
}

cl_event FogPass::Impl::dispatch(const cl::CommandQueue& queue, const FrameBuffers& fb, const Variant& v,
                                 const CameraParams& camera, const FogSettings& settings,
                                 const std::vector<cl_event>& wait_list) {
  cl::Kernel* kernel = v.needs_pass() ? find_kernel(v) : nullptr;
  if (v.needs_pass() && kernel == nullptr)
    throw Error("fog variant '" + describe(v) + "' is not prepared: call FogPass::prepare(settings, camera, " +
                to_string(fb.format) + ") (or prepare(variant)) before enqueue, which never builds a program");
  std::vector<cl::Event> waits_storage;
  for (cl_event e : wait_list) waits_storage.push_back(wrap(e));  // enqueue checked them (null)
  const std::vector<cl::Event>* waits = waits_storage.empty() ? nullptr : &waits_storage;
  cl::Event done;
  last_variant = v;
  if (!v.needs_pass()) {
    if (fb.color_out == fb.color_in) {
      queue.enqueueMarkerWithWaitList(waits, &done);
    } else {
      queue.enqueueCopyBuffer(wrap(fb.color_in), wrap(fb.color_out), 0, 0,
                              color_buffer_bytes(fb.width, fb.height, fb.format), waits, &done);
      ++stats.buffer_copies;
    }
    return share(done);
  }
  const detail::FogCoefficients<float> k = detail::fog_coefficients<float>(settings, v.mode);
  const auto c = formulas::fog_ray_corners(camera);
  kernel->setArg(0, wrap(fb.color_in));
  kernel->setArg(1, wrap(fb.depth));
  kernel->setArg(2, wrap(fb.color_out));
  kernel->setArg(3, cl_int(fb.width));
  kernel->setArg(4, cl_int(fb.height));
  kernel->setArg(5, f4(camera.zbuffer_params));
  kernel->setArg(6, f4(camera.projection_params));
  kernel->setArg(7, f4(c[kBottomLeft]));
  kernel->setArg(8, f4(c[kBottomRight]));
  kernel->setArg(9, f4(c[kTopLeft]));
  kernel->setArg(10, f4(c[kTopRight]));
  kernel->setArg(11, f4(k.a, k.b, 0.0f, 0.0f));
  kernel->setArg(12, f4(settings.color.r, settings.color.g, settings.color.b, 0.0f));
  if (v.mode == KernelMode::height) {  // docs/DESIGN.md §6: the constants of fog_math.h's FOG_HP_* block
    const detail::HeightCoefficients<float> h = detail::height_coefficients<float>(settings, camera);
    const float* p = h.p;
    kernel->setArg(13, f4(p[FOG_HP_K], p[FOG_HP_START], p[FOG_HP_CUTOFF], p[FOG_HP_MAX]));
    kernel->setArg(14, f4(p[FOG_HP_MIN_T], p[FOG_HP_SUN_EXP], p[FOG_HP_SUN_START], h.d0));
    kernel->setArg(15, f4(p[FOG_HP_EXT], p[FOG_HP_EXT + 1], p[FOG_HP_EXT + 2], 0.0f));
    kernel->setArg(16, f4(p[FOG_HP_IN], p[FOG_HP_IN + 1], p[FOG_HP_IN + 2], 0.0f));
    kernel->setArg(17, f4(p[FOG_HP_SUN], p[FOG_HP_SUN + 1], p[FOG_HP_SUN + 2], 0.0f));
    kernel->setArg(18, f4(h.up[0], h.up[1], h.up[2], 0.0f));
    kernel->setArg(19, f4(h.light[0], h.light[1], h.light[2], 0.0f));
  }
  const int per_item = pixels_per_work_item(traits);
  queue.enqueueNDRangeKernel(*kernel, cl::NullRange, cl::NDRange((fb.width + per_item - 1) / per_item, fb.height),
                             cl::NullRange, waits, &done);
  ++stats.kernel_dispatches;
  return share(done);
}

ColorImage pinned_color_image(cl_context context, cl_device_id device, int width, int height, ColorFormat format) {
  if (width < 1 || height < 1) return ColorImage(width, height, format);  // throws, naming the size
  return ColorImage(width, height, format,
                    detail::pinned_bytes(wrap(context), wrap(device), color_buffer_bytes(width, height, format)));
}

DepthImage pinned_depth_image(cl_context context, cl_device_id device, int width, int height) {
  if (width < 1 || height < 1) return DepthImage(width, height);  // throws, naming the size
  return DepthImage(width, height, detail::pinned_bytes(wrap(context), wrap(device), depth_buffer_bytes(width, height)));
}

const char* to_string(HostTransfer transfer) {
  switch (transfer) {
    case HostTransfer::automatic: return "automatic";
    case HostTransfer::direct: return "direct";
    case HostTransfer::staged: return "staged";
  }
  return "?";
}

struct PendingFrame::Impl {
  std::shared_ptr<detail::HostStaging> staging;
  detail::StagedFrame frame;
  detail::PackedFrame views;  // out: where the download goes, copied to the caller's view after
};

namespace {
// A frame given up (destroyed or overwritten) still completes; its error has no one to go to.
void wait_quietly(PendingFrame& frame) noexcept {
  try {
    frame.wait();
  } catch (...) {
  }
}
}  // namespace

PendingFrame::PendingFrame() = default;
PendingFrame::~PendingFrame() { wait_quietly(*this); }
PendingFrame::PendingFrame(PendingFrame&&) noexcept = default;
PendingFrame& PendingFrame::operator=(PendingFrame&& other) noexcept {
  if (this != &other) {
    wait_quietly(*this);
    impl_ = std::move(other.impl_);
  }
  return *this;
}

void PendingFrame::wait() {
  if (impl_ == nullptr) return;
  const std::unique_ptr<Impl> m = std::move(impl_);  // once, also when it throws
  with_cl_errors([&] { m->staging->finish(m->frame, m->views.out); });
  m->views.write_back();
}

bool PendingFrame::done() const { return impl_ == nullptr; }

void FogPass::set_host_transfer(HostTransfer transfer) { impl().transfers.choice = transfer; }
HostTransfer FogPass::host_transfer() const {
  return impl().staged() ? HostTransfer::staged : HostTransfer::direct;
}

std::optional<Variant> FogPass::Impl::begin_apply(FogPass& pass, const ConstColorView& in, const ConstDepthView& depth,
                                                  const ColorView& out, const CameraParams& camera,
                                                  const FogSettings& settings) {
  validate_frame(in, depth, out);
  validate(camera, in.width(), in.height());
  const Variant v = select_variant(settings, camera, in.format());
  stats.last_kernel_ms = 0;
  if (!v.needs_pass()) {  // no device work at all
    last_variant = v;
    if (out.data() != in.data()) detail::copy_pixels(in, out);
    return std::nullopt;
  }
  pass.prepare(v);  // the convenience calls block anyway: the one place that builds on demand
  if (queue() == nullptr) queue = cl::CommandQueue(context, device, CL_QUEUE_PROFILING_ENABLE);
  return v;
}

PendingFrame FogPass::Impl::start_staged(detail::PackedFrame views, const Variant& v, const CameraParams& camera,
                                         const FogSettings& settings, cl::Event& done) {
  detail::HostStaging& staging = transfers.staging_of(context, device);
  detail::StagedFrame frame = staging.start(views.in, views.depth, views.out,
                                            [&](const FrameBuffers& fb, const detail::HostStaging::UploadDepth&,
                                                const detail::HostStaging::UploadColor& upload_color) {
    done = adopt(dispatch(queue, fb, v, camera, settings, {upload_color()()}));
    queue.flush();
    return std::vector<detail::HostStaging::RowsReady>{{fb.height, done}};
  });
  ++stats.copied_frames;
  PendingFrame pending;
  pending.impl_ = std::make_unique<PendingFrame::Impl>(
      PendingFrame::Impl{transfers.staging, std::move(frame), std::move(views)});
  return pending;
}

// `done` has completed: its timestamps are final. A caller's queue (Runtime from handles) may
// have no profiling: then there are none, and the figure stays 0.
void FogPass::Impl::record_kernel_time(const cl::Event& done) {
  cl_ulong start = 0, end = 0;
  if (clGetEventProfilingInfo(done(), CL_PROFILING_COMMAND_START, sizeof start, &start, nullptr) == CL_SUCCESS &&
      clGetEventProfilingInfo(done(), CL_PROFILING_COMMAND_END, sizeof end, &end, nullptr) == CL_SUCCESS)
    stats.last_kernel_ms = double(end - start) * 1e-6;
}

void FogPass::apply(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                    const CameraParams& camera, const FogSettings& settings) {
  impl();
  detail::host_call("FogPass::apply", [&] {
    detail::size_output(in, depth, out, camera);
    apply(in.view(), depth.view(), out.view(), camera, settings);
  });
}

void FogPass::apply(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                    const CameraParams& camera, const FogSettings& settings) {
  Impl& m = impl();
  detail::host_call("FogPass::apply", [&] {
    const std::optional<Variant> v = m.begin_apply(*this, in, depth, out, camera, settings);
    if (!v) return;
    with_cl_errors([&] {
      cl::Event done;
      if (m.staged()) {
        m.start_staged(detail::PackedFrame(in, depth, out, 1), *v, camera, settings, done).wait();
        m.record_kernel_time(done);
        return;
      }
      // CPU devices read and write the caller's memory where it is (packed rows at the device's
      // alignment; other memory is copied once); other devices get copies.
      const detail::PackedFrame views(in, depth, out, m.traits.cpu ? m.host_align : 1);
      const detail::HostFrame frame =
          detail::host_frame(m.context, m.traits.cpu, views.in, views.depth, views.out, views.in_place);
      // Input, camera and settings were checked above, the buffers are the frame's and the queue
      // the pass's: no integration-API checks (their getInfo calls were 5-14 us a call).
      done = adopt(m.dispatch(m.queue, frame.raw, *v, camera, settings, {}));
      if (detail::read_back(m.queue, m.traits.cpu, frame, done, views.out) && !views.copied())
        ++m.stats.zero_copy_frames;
      else
        ++m.stats.copied_frames;
      views.write_back();
      m.record_kernel_time(done);  // read_back waited for it
    });
  });
}

PendingFrame FogPass::apply_async(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                                  const CameraParams& camera, const FogSettings& settings) {
  impl();
  return detail::host_call("FogPass::apply_async", [&] {
    detail::size_output(in, depth, out, camera);
    return apply_async(in.view(), depth.view(), out.view(), camera, settings);
  });
}

PendingFrame FogPass::apply_async(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                                  const CameraParams& camera, const FogSettings& settings) {
  Impl& m = impl();
  if (!m.staged()) {
    apply(in, depth, out, camera, settings);
    return PendingFrame();
  }
  return detail::host_call("FogPass::apply_async", [&] {
    const std::optional<Variant> v = m.begin_apply(*this, in, depth, out, camera, settings);
    if (!v) return PendingFrame();
    return with_cl_errors([&] {
      cl::Event done;
      return m.start_staged(detail::PackedFrame(in, depth, out, 1), *v, camera, settings, done);
    });
  });
}

}  // namespace fogcl
