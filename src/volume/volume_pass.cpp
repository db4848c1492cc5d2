#include "fogcl/volume_pass.h"

#include <cstring>
#include <map>
#include <tuple>

#include "fogcl/error.h"
#include "image/packed_frame.h"
#include "runtime/clhpp.h"
#include "runtime/host_call.h"
#include "runtime/frame_buffers.h"
#include "runtime/host_staging.h"
#include "runtime/work_groups.h"
#include "volume/volume_params.h"
#include "volume_composite_cl.h"
#include "volume_march_cl.h"

namespace fogcl {

namespace {
cl::Buffer constant_buffer(const cl::Context& ctx, const float* data, std::size_t count) {
  // Copied at creation, so the host arrays may go before the kernel runs.
  return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, count * sizeof(float), const_cast<float*>(data));
}

struct Source {
  const char* name;
  const char* text;
  const char* kernel;
};
const Source kMarch{"volume_march.cl", volume_march_cl, "volume_march"};
const Source kComposite{"volume_composite.cl", volume_composite_cl, "volume_composite"};
// `b` holding at least `bytes`: allocated anew where missing or too small.
void fit_buffer(const cl::Context& ctx, cl::Buffer& b, std::size_t bytes, cl_mem_flags flags) {
  if (b() == nullptr || b.getInfo<CL_MEM_SIZE>() < bytes) b = cl::Buffer(ctx, flags, bytes);
}
// The march's low-resolution output for `f`: (P, A) and any coverage per channel in `low`, its
// depth key in `low_key`.
void fit_march_output(const cl::Context& ctx, const detail::PackedVolumeFrame& f, cl::Buffer& low,
                      cl::Buffer& low_key) {
  const std::size_t low_pixels = std::size_t(f.low_width) * std::size_t(f.low_height);
  fit_buffer(ctx, low, low_pixels * std::size_t(detail::target_floats(f.variant)) * sizeof(float), CL_MEM_READ_WRITE);
  fit_buffer(ctx, low_key, low_pixels * sizeof(float), CL_MEM_READ_WRITE);
}
}  // namespace

struct VolumePass::Impl {
  cl::Context context;
  cl::Device device;
  std::shared_ptr<ProgramCache> programs;
  cl::CommandQueue queue;  // convenience queue
  DeviceTraits traits;
  std::size_t host_align = 1;  // host memory a CPU device uses in place (frame_buffers.h)
  bool images = false;     // the device supports images
  NoiseSamplingDevice noise_device;  // what NoiseSampling::automatic resolves from
  struct KernelEntry {
    cl::Kernel kernel;
    detail::WorkGroupShape shape;  // its launches' local size (runtime/work_groups.h)
  };
  std::map<std::string, KernelEntry> kernels;  // by source name + options
  // (size, seed, as image) -> the texture on the device and its upload's event
  std::map<std::tuple<int, unsigned, int>, std::pair<cl::Memory, cl::Event>> noise;
  VolumePassStats stats;
  std::string last_march_options, last_composite_options;
  // A frame's device scratch: the packed constants and the low-resolution march output, kept and
  // reused across frames (on NVIDIA their allocation, release and the first touch of fresh pages
  // cost 0.3-0.4 ms a frame: docs/gpu.md). A set is taken again once the composite that last read
  // it is complete; while all kScratchSets are in flight a frame gets buffers of its own, as it
  // would without the pool (enqueue never blocks).
  struct Scratch {
    cl::Buffer frame, volumes, low, low_key;
    std::vector<float> frame_host, volumes_host;  // the writes' sources, kept until `done`
    cl::Event done;                               // the last composite that read the set
  };
  static constexpr std::size_t kScratchSets = 4;
  // Bands of rows of a staged call's march and composite on GPUs (enqueue_frame's rows), in
  // shares of the target's rows: the last band's download is all that follows the last march, so
  // it is the smallest (H100, docs/gpu.md: 0.16 ms of bus after the last composite with quarters).
  static constexpr std::size_t kBandShares[] = {6, 6, 5, 3};
  std::vector<Scratch> scratch;
  // A free set sized for `f`, its constants' writes enqueued on `queue` (their events appended to
  // `writes`), or nullptr when every set is in flight.
  Scratch* take_scratch(const cl::CommandQueue& queue, const detail::PackedVolumeFrame& f,
                        std::vector<cl::Event>& writes);
  detail::ConvenienceTransfers transfers;
  bool staged() const { return transfers.staged(traits.cpu); }
  // The convenience call over views (VolumePass::apply).
  void apply(VolumePass& pass, const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
             const CameraParams& camera, const VolumeScene& scene, const VolumeSettings& settings,
             const ShadowMap* shadow);

  // The kernel of a built program, or nullptr (never builds; creates the kernel object when
  // another pass sharing the cache built the program). private_bytes: the host's bound of a work-item's
  // private memory (volume_params.h), for its work-group shape.
  KernelEntry* find_kernel(const Source& source, const std::string& options, std::size_t private_bytes) {
    const std::string key = std::string(source.name) + '\n' + options;
    auto it = kernels.find(key);
    if (it == kernels.end()) {
      const cl_program program = programs->find(device(), source.name, options);
      if (program == nullptr) return nullptr;
      it = kernels.emplace(key, with_cl_errors([&] {
        KernelEntry e{cl::Kernel(wrap(program), source.kernel), {}};
        e.shape = detail::work_group_shape(e.kernel, device, private_bytes);
        return e;
      })).first;
    }
    return &it->second;
  }
  KernelEntry& prepared_kernel(const Source& source, const std::string& options, std::size_t private_bytes) {
    KernelEntry* k = find_kernel(source, options, private_bytes);
    if (k == nullptr)
      throw Error(std::string("volumetric variant '") + options + "' of " + source.name +
                  " is not prepared: call VolumePass::prepare(camera, scene, settings, storage, shadow) "
                  "before enqueue, which never builds a program");
    return *k;
  }
  void build(const Source& source, const std::string& options, std::size_t private_bytes) {
    if (find_kernel(source, options, private_bytes) != nullptr) return;
    programs->get(device(), source.name, source.text, options);
    find_kernel(source, options, private_bytes);
  }
  const cl::Memory& noise_on_device(const cl::CommandQueue& queue, const VolumeSettings& settings,
                                    std::vector<cl::Event>& waits);
  // VolumePass::enqueue's work after `waits`. The staged call passes upload_depth, called once
  // the frame's constants and kernels are ready (the depth's copies run meanwhile), per band of
  // the march with the rows it reads, which returns when which rows of the depth are there (each
  // band of the march waits for its own, the first one not for the copies of the others), and
  // after_march, which runs once the first marches are enqueued and flushed (the march reads the
  // depth, not the color) and returns the event the composite waits for besides the march: the
  // color sent up. rows (the staged call; `queue` in order): on devices of one pixel per
  // work-item the march and the composite go in bands of rows, interleaved, and rows gets when
  // each band of the output is final, so that its download follows while the march goes on;
  // else one entry.
  using RowsReady = detail::HostStaging::RowsReady;
  using AfterMarch = detail::HostStaging::UploadColor;
  cl::Event enqueue_frame(const cl::CommandQueue& queue, const FrameBuffers& fb, const CameraParams& camera,
                          const VolumeScene& scene, const VolumeSettings& requested, const ShadowMapBuffer* shadow,
                          std::vector<cl::Event> waits, const detail::HostStaging::UploadDepth& upload_depth,
                          const AfterMarch& after_march, float max_eye, std::vector<RowsReady>* rows = nullptr);
  // `settings` with its noise sampling resolved for this device: what the variant, its build
  // options and the noise upload are chosen from.
  VolumeSettings resolved(const VolumeSettings& settings) const {
    VolumeSettings r = settings;
    r.noise_sampling = resolve_noise_sampling(settings.noise_sampling, noise_device);
    return r;
  }
};

VolumePass::VolumePass(cl_context context, cl_device_id device, std::shared_ptr<ProgramCache> programs,
                       const CpuCodegen& codegen)
    : impl_(std::make_unique<Impl>()) {
  if (context == nullptr || device == nullptr)
    throw Error("VolumePass needs a context and a device (got a null handle)");
  Impl& m = *impl_;
  m.context = wrap(context);
  m.device = wrap(device);
  if (programs == nullptr) programs = std::make_shared<ProgramCache>(context);
  if (programs->context() != context)
    throw Error("VolumePass: the shared ProgramCache belongs to another OpenCL context than the pass");
  m.programs = std::move(programs);
  m.traits = device_traits(device, codegen);
  m.host_align = with_cl_errors([&] { return detail::host_ptr_alignment(m.device); });
  m.images = with_cl_errors([&] { return m.device.getInfo<CL_DEVICE_IMAGE_SUPPORT>() == CL_TRUE; });
  m.noise_device.cpu = m.traits.cpu;
  m.noise_device.images = m.images;
  if (m.images)  // the format noise_on_device creates its image with
    m.noise_device.rgba_unorm8_3d = with_cl_errors([&] {
      std::vector<cl::ImageFormat> formats;
      m.context.getSupportedImageFormats(CL_MEM_READ_ONLY, CL_MEM_OBJECT_IMAGE3D, &formats);
      for (const cl::ImageFormat& f : formats)
        if (f.image_channel_order == CL_RGBA && f.image_channel_data_type == CL_UNORM_INT8) return true;
      return false;
    });
}

VolumePass::VolumePass(const Runtime& runtime, std::shared_ptr<ProgramCache> programs, const CpuCodegen& codegen)
    : VolumePass(runtime.context(), runtime.device(), std::move(programs), codegen) {
  impl_->queue = wrap(runtime.queue());
}

VolumePass::Impl& VolumePass::impl() const {
  if (impl_ == nullptr) throw Error("VolumePass used after move: assign a pass to it before calling it again");
  return *impl_;
}

VolumePass::~VolumePass() = default;
VolumePass::VolumePass(VolumePass&&) noexcept = default;
VolumePass& VolumePass::operator=(VolumePass&&) noexcept = default;

const VolumePassStats& VolumePass::stats() const { return impl().stats; }
const ProgramCache& VolumePass::programs() const { return *impl().programs; }
const std::shared_ptr<ProgramCache>& VolumePass::program_cache() const { return impl().programs; }
const std::string& VolumePass::last_march_options() const { return impl().last_march_options; }
const std::string& VolumePass::last_composite_options() const { return impl().last_composite_options; }
NoiseSampling VolumePass::noise_sampling(NoiseSampling requested) const {
  return resolve_noise_sampling(requested, impl().noise_device);
}

const cl::Memory& VolumePass::Impl::noise_on_device(const cl::CommandQueue& q, const VolumeSettings& settings,
                                                    std::vector<cl::Event>& waits) {
  const bool image = settings.noise_sampling == NoiseSampling::image;
  const auto key = std::make_tuple(settings.noise_size, unsigned(settings.noise_seed), int(image));
  auto it = noise.find(key);
  if (it == noise.end()) {
    const NoiseTexture& tex = detail::shared_noise_texture(settings.noise_size, settings.noise_seed);
    const std::size_t n = std::size_t(tex.size);
    cl::Event uploaded;
    cl::Memory memory;
    // The texels live for the whole process (shared_noise_texture), so the upload need not block.
    if (image) {
      cl::Image3D img(context, CL_MEM_READ_ONLY, cl::ImageFormat(CL_RGBA, CL_UNORM_INT8), n, n, n);
      q.enqueueWriteImage(img, CL_FALSE, {0, 0, 0}, {n, n, n}, 0, 0, const_cast<std::uint8_t*>(tex.texels.data()),
                          nullptr, &uploaded);
      memory = img;
    } else {
      // One texel of slack past the end: the march's lanes read texels (x, x + 1) as one 8-byte
      // word (kernels/volume_march.cl) and at the last texel the second half is never used. CPU
      // devices (the lanes) get the 2 x 2 blocks of R after it.
      const std::size_t bytes = tex.texels.size() + 4;
      const std::vector<std::uint8_t>* blocks = traits.cpu ? &detail::shared_noise_r_blocks(tex) : nullptr;
      cl::Buffer buf(context, CL_MEM_READ_ONLY, bytes + (blocks ? blocks->size() : 0));
      std::vector<cl::Event> writes(blocks ? 2 : 1);
      q.enqueueWriteBuffer(buf, CL_FALSE, 0, tex.texels.size(), tex.texels.data(), nullptr, &writes[0]);
      if (blocks) q.enqueueWriteBuffer(buf, CL_FALSE, bytes, blocks->size(), blocks->data(), nullptr, &writes[1]);
      q.enqueueMarkerWithWaitList(&writes, &uploaded);
      memory = buf;
    }
    ++stats.noise_uploads;
    it = noise.emplace(key, std::make_pair(memory, uploaded)).first;
  }
  waits.push_back(it->second.second);
  return it->second.first;
}

void VolumePass::prepare(const CameraParams& camera, const VolumeScene& scene, const VolumeSettings& requested,
                         ColorFormat storage, const ShadowMapParams* shadow) {
  Impl& m = impl();
  const VolumeSettings settings = m.resolved(requested);
  if (settings.noise_sampling == NoiseSampling::image && !m.images)
    throw Error("noise sampling 'image' needs a device with image support; " + device_name(m.device()) +
                " has none (use 'buffer')");
  const detail::PackedVolumeFrame f =
      detail::pack_volume_frame(1, 1, camera, scene, settings, storage, shadow, 1, 1, INFINITY);
  if (f.nothing_to_march()) return;
  m.build(kMarch, detail::volume_march_options(f.variant, m.traits),
          detail::volume_march_private_bytes(f.variant, m.traits));
  m.build(kComposite, detail::volume_composite_options(f.variant, m.traits),
          detail::volume_composite_private_bytes(f.variant, m.traits));
}

cl_event VolumePass::enqueue(cl_command_queue queue_handle, const FrameBuffers& fb, const CameraParams& camera,
                             const VolumeScene& scene, const VolumeSettings& requested, const ShadowMapBuffer* shadow,
                             const std::vector<cl_event>& wait_list, float max_eye) {
  validate(camera, fb.width, fb.height);
  detail::check_wait_list(wait_list, "VolumePass::enqueue");
  return detail::host_call("VolumePass::enqueue", [&] {
    return with_cl_errors([&] {
      const cl::CommandQueue queue =
          detail::checked_queue(queue_handle, impl().context, impl().device, "VolumePass::enqueue");
      std::vector<cl::Event> waits;
      for (cl_event e : wait_list) waits.push_back(wrap(e));
      return share(impl().enqueue_frame(queue, fb, camera, scene, requested, shadow, std::move(waits), {}, {}, max_eye));
    });
  });
}

VolumePass::Impl::Scratch* VolumePass::Impl::take_scratch(const cl::CommandQueue& queue,
                                                          const detail::PackedVolumeFrame& f,
                                                          std::vector<cl::Event>& writes) {
  Scratch* s = nullptr;
  for (Scratch& c : scratch)  // complete, or ended in an error (< CL_COMPLETE): no reader left
    if (c.done() == nullptr || c.done.getInfo<CL_EVENT_COMMAND_EXECUTION_STATUS>() <= CL_COMPLETE) {
      s = &c;
      break;
    }
  if (s == nullptr) {
    if (scratch.size() == kScratchSets) return nullptr;
    s = &scratch.emplace_back();
  }
  fit_buffer(context, s->frame, f.frame.size() * sizeof(float), CL_MEM_READ_ONLY);
  fit_buffer(context, s->volumes, f.volumes.size() * sizeof(float), CL_MEM_READ_ONLY);
  fit_march_output(context, f, s->low, s->low_key);
  s->frame_host.assign(f.frame.begin(), f.frame.end());
  s->volumes_host.assign(f.volumes.begin(), f.volumes.end());
  cl::Event e;
  queue.enqueueWriteBuffer(s->frame, CL_FALSE, 0, f.frame.size() * sizeof(float), s->frame_host.data(), nullptr, &e);
  writes.push_back(e);
  queue.enqueueWriteBuffer(s->volumes, CL_FALSE, 0, f.volumes.size() * sizeof(float), s->volumes_host.data(),
                           nullptr, &e);
  writes.push_back(e);
  s->done = e;  // busy from here: until the composite's event replaces this one, or on its own
  return s;
}

cl::Event VolumePass::Impl::enqueue_frame(const cl::CommandQueue& queue, const FrameBuffers& fb,
                                          const CameraParams& camera, const VolumeScene& scene,
                                          const VolumeSettings& requested, const ShadowMapBuffer* shadow,
                                          std::vector<cl::Event> waits,
                                          const detail::HostStaging::UploadDepth& upload_depth,
                                          const AfterMarch& after_march, float max_eye, std::vector<RowsReady>* rows) {
  Impl& m = *this;
  const VolumeSettings settings = m.resolved(requested);
  const detail::PackedVolumeFrame f =
      detail::pack_volume_frame(fb.width, fb.height, camera, scene, settings, fb.format,
                                shadow ? &shadow->params : nullptr, shadow ? shadow->width : 0,
                                shadow ? shadow->height : 0, max_eye);
  detail::check_frame_buffers(fb, m.context);
  if (shadow) {
    if (shadow->depth == nullptr) throw Error("shadow map buffer is not set (null cl_mem)");
    const std::size_t needed = depth_buffer_bytes(shadow->width, shadow->height);
    const std::size_t size = wrap(shadow->depth).getInfo<CL_MEM_SIZE>();
    if (size != needed)
      throw Error("shadow map buffer holds " + std::to_string(size) + " bytes but a " +
                  std::to_string(shadow->width) + "x" + std::to_string(shadow->height) +
                  " float32 map needs exactly " + std::to_string(needed));
  }
  cl::Event done;
  m.stats.volumes_culled += scene.volumes.size() - f.visible.size();
  if (f.nothing_to_march()) {  // nothing to draw: no kernel, the output is the input
    m.last_march_options.clear();
    m.last_composite_options.clear();
    ++m.stats.frames_without_volumes;
    if (after_march) waits.push_back(after_march());
    if (fb.color_out == fb.color_in)
      queue.enqueueMarkerWithWaitList(waits.empty() ? nullptr : &waits, &done);
    else
      queue.enqueueCopyBuffer(wrap(fb.color_in), wrap(fb.color_out), 0, 0,
                              color_buffer_bytes(fb.width, fb.height, fb.format), waits.empty() ? nullptr : &waits,
                              &done);
    if (rows != nullptr) rows->push_back({fb.height, done});
    return done;
  }
  const std::string march_options = detail::volume_march_options(f.variant, m.traits);
  const std::string composite_options = detail::volume_composite_options(f.variant, m.traits);
  Impl::KernelEntry& march_entry =
      m.prepared_kernel(kMarch, march_options, detail::volume_march_private_bytes(f.variant, m.traits));
  Impl::KernelEntry& composite_entry =
      m.prepared_kernel(kComposite, composite_options, detail::volume_composite_private_bytes(f.variant, m.traits));
  cl::Kernel& march = march_entry.kernel;
  cl::Kernel& composite = composite_entry.kernel;
  m.last_march_options = march_options;
  m.last_composite_options = composite_options;
  Scratch* scratch_set = m.take_scratch(queue, f, waits);
  cl::Buffer frame, volumes, low, low_key;
  if (scratch_set != nullptr) {
    frame = scratch_set->frame;
    volumes = scratch_set->volumes;
    low = scratch_set->low;
    low_key = scratch_set->low_key;
  } else {  // every set in flight: this frame's own, released with this call (OpenCL keeps them
            // until the kernels that use them are done)
    frame = constant_buffer(m.context, f.frame.data(), f.frame.size());
    volumes = constant_buffer(m.context, f.volumes.data(), f.volumes.size());
    fit_march_output(m.context, f, low, low_key);
  }
  const cl::Buffer depth = wrap(fb.depth);
  int arg = 0;
  march.setArg(arg++, depth);
  march.setArg(arg++, frame);
  march.setArg(arg++, volumes);
  march.setArg(arg++, cl_int(f.visible.size()));
  if (f.needs_noise()) {
    march.setArg(arg++, m.noise_on_device(queue, settings, waits));
    march.setArg(arg++, cl_int(settings.noise_size));
  } else {
    march.setArg(arg++, frame);  // unused: a variant without noise never reads it
    march.setArg(arg++, cl_int(0));
  }
  march.setArg(arg++, shadow ? wrap(shadow->depth) : frame);
  march.setArg(arg++, cl_uint(scene.frame_index));
  march.setArg(arg++, low);
  march.setArg(arg++, low_key);
  const int march_lanes = detail::volume_march_lanes(f.variant, m.traits);  // target pixels per work-item
  const std::size_t march_x = std::size_t((f.low_width + march_lanes - 1) / march_lanes);
  const auto global = detail::volume_composite_global(f.variant, m.traits, fb.width, fb.height);
  composite.setArg(0, wrap(fb.color_in));
  composite.setArg(1, depth);
  composite.setArg(2, wrap(fb.color_out));
  composite.setArg(3, frame);
  composite.setArg(4, low);
  composite.setArg(5, low_key);
  // Bands (rows: staged calls on devices of one pixel per work-item; else one band): whole
  // work-groups of target rows, frame rows `scale` times as many. Composite band b reads the
  // target rows of march band b, upsampled also the first of band b + 1 (the 2 x 2 taps), and goes
  // right after the last march it reads, so that its download runs while later bands march. Two
  // marches go first, so that the device marches while after_march sends the color up: at scale 1
  // the queue runs march 0, march 1, composite 0, composite 1, march 2, composite 2, ...;
  // upsampled march 0, march 1, composite 0, march 2, composite 1, ...
  const std::size_t low_height = std::size_t(f.low_height), scale = std::size_t(f.variant.scale);
  std::vector<std::size_t> band_start{0};  // each band's first target row, then the end
  if (rows != nullptr && march_lanes == 1 && global[1] == std::size_t(fb.height)) {
    const std::size_t group = std::max(march_entry.shape.y, composite_entry.shape.y);
    std::size_t shares = 0, total = 0;
    for (const std::size_t share : kBandShares) total += share;
    for (std::size_t b = 0; b + 1 < std::size(kBandShares); ++b) {
      shares += kBandShares[b];
      const std::size_t end = (low_height * shares / total + group - 1) / group * group;
      if (end > band_start.back() && end < low_height) band_start.push_back(end);
    }
  }
  band_start.push_back(low_height);
  const std::size_t bands = band_start.size() - 1, look_ahead = scale > 1 ? 1 : 0;
  const auto frame_rows_end = [&](std::size_t b) {  // of band b: target rows times scale
    return b + 1 == bands ? fb.height : int(std::min(band_start[b + 1] * scale, std::size_t(fb.height)));
  };
  std::vector<cl::Event> marched(bands);
  std::size_t marches = 0;
  const auto march_band = [&] {
    const std::size_t first = band_start[marches];
    std::vector<cl::Event> after = marches == 0 ? waits : std::vector<cl::Event>();
    if (upload_depth) {  // the band's rows of the depth: the first band marches while the rest are copied
      const int rows_end = frame_rows_end(marches);
      for (const cl::Event& e : detail::HostStaging::rows_events(upload_depth(rows_end), rows_end)) after.push_back(e);
    }
    queue.enqueueNDRangeKernel(march, cl::NDRange(0, first),
                               march_entry.shape.global(march_x, band_start[marches + 1] - first),
                               march_entry.shape.local(), after.empty() ? nullptr : &after, &marched[marches]);
    ++marches;
    ++m.stats.march_dispatches;
  };
  while (marches < std::min<std::size_t>(2, bands)) march_band();
  std::vector<cl::Event> uploaded;
  if (after_march) {
    queue.flush();  // the march may start while after_march works
    uploaded.push_back(after_march());
  }
  for (std::size_t b = 0; b < bands; ++b) {
    while (marches < std::min(b + 1 + look_ahead, bands)) march_band();
    const std::size_t first = band_start[b] * scale;
    const int end = frame_rows_end(b);
    std::vector<cl::Event> after = uploaded;
    after.insert(after.end(), marched.begin(), marched.begin() + marches);
    queue.enqueueNDRangeKernel(composite, cl::NDRange(0, first),
                               composite_entry.shape.global(global[0], b + 1 == bands ? global[1] - first : end - first),
                               composite_entry.shape.local(), &after, &done);
    ++m.stats.composite_dispatches;
    if (rows != nullptr) rows->push_back({end, done});
    if (bands > 1) queue.flush();  // the band's download waits for it on another queue
  }
  if (scratch_set != nullptr) scratch_set->done = done;
  return done;
}

void VolumePass::set_host_transfer(HostTransfer transfer) { impl().transfers.choice = transfer; }
HostTransfer VolumePass::host_transfer() const {
  return impl().staged() ? HostTransfer::staged : HostTransfer::direct;
}

void VolumePass::apply(const ColorImage& in, const DepthImage& depth, ColorImage& out, const CameraParams& camera,
                       const VolumeScene& scene, const VolumeSettings& settings, const ShadowMap* shadow) {
  impl();
  detail::host_call("VolumePass::apply", [&] {
    detail::size_output(in, depth, out, camera);
    apply(in.view(), depth.view(), out.view(), camera, scene, settings, shadow);
  });
}

void VolumePass::apply(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                       const CameraParams& camera, const VolumeScene& scene, const VolumeSettings& settings,
                       const ShadowMap* shadow) {
  Impl& m = impl();
  detail::host_call("VolumePass::apply", [&] { m.apply(*this, in, depth, out, camera, scene, settings, shadow); });
}

void VolumePass::Impl::apply(VolumePass& pass, const ConstColorView& in, const ConstDepthView& depth,
                             const ColorView& out, const CameraParams& camera, const VolumeScene& scene,
                             const VolumeSettings& settings, const ShadowMap* shadow) {
  Impl& m = *this;
  validate_frame(in, depth, out);
  validate(camera, in.width(), in.height());
  const bool in_place = out.data() == in.data();
  // Pinned staging (runtime/host_staging.h), the GPU default. There the culling scan is on the
  // critical path of the round trip: the staging's threads share it.
  detail::HostStaging* staging = m.staged() ? &m.transfers.staging_of(m.context, m.device) : nullptr;
  // Views the kernels can take: packed rows, on CPU devices at the device's alignment.
  detail::PackedFrame views(in, depth, out, m.traits.cpu && staging == nullptr ? m.host_align : 1);
  const float max_eye = detail::max_eye_depth(views.depth, camera, staging ? &staging->scan_workers() : nullptr);
  // Culling first: a frame without visible volumes touches no device at all.
  const detail::PackedVolumeFrame f = detail::pack_volume_frame(
      in.width(), in.height(), camera, scene, settings, in.format(), shadow ? &shadow->params : nullptr,
      shadow ? shadow->depth.width() : 0, shadow ? shadow->depth.height() : 0, max_eye);
  if (f.nothing_to_march()) {
    ++m.stats.frames_without_volumes;
    m.stats.volumes_culled += scene.volumes.size();
    m.last_march_options.clear();
    m.last_composite_options.clear();
    if (!in_place) detail::copy_pixels(in, out);
    return;
  }
  pass.prepare(camera, scene, settings, in.format(), shadow ? &shadow->params : nullptr);  // apply blocks anyway
  with_cl_errors([&] {
    if (m.queue() == nullptr) m.queue = cl::CommandQueue(m.context, m.device, CL_QUEUE_PROFILING_ENABLE);
    ShadowMapBuffer sm;
    cl::Buffer shadow_buffer;
    if (shadow) {
      sm.width = shadow->depth.width();
      sm.height = shadow->depth.height();
      sm.params = shadow->params;
      shadow_buffer = cl::Buffer(m.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, shadow->depth.size_bytes(),
                                 const_cast<float*>(shadow->depth.data()));
      sm.depth = shadow_buffer();
    }
    if (staging != nullptr) {
      detail::StagedFrame staged = staging->start(
          views.in, views.depth, views.out,
          [&](const FrameBuffers& fb, const detail::HostStaging::UploadDepth& upload_depth,
              const detail::HostStaging::UploadColor& upload_color) {
            // The march reads the depth only: it runs while the color is sent up.
            std::vector<Impl::RowsReady> rows;
            m.enqueue_frame(m.queue, fb, camera, scene, settings, shadow ? &sm : nullptr, {}, upload_depth,
                            upload_color, max_eye, &rows);
            m.queue.flush();
            return rows;
          });
      staging->finish(staged, views.out);
      ++m.stats.copied_frames;
    } else {
      const detail::HostFrame frame =
          detail::host_frame(m.context, m.traits.cpu, views.in, views.depth, views.out, views.in_place);
      const cl::Event done = adopt(pass.enqueue(m.queue(), frame.raw, camera, scene, settings, shadow ? &sm : nullptr,
                                                {}, max_eye));
      if (detail::read_back(m.queue, m.traits.cpu, frame, done, views.out) && !views.copied())
        ++m.stats.zero_copy_frames;
      else
        ++m.stats.copied_frames;
    }
    views.write_back();
  });
}

}  // namespace fogcl
