#include "fogcl/volume_pass.h"

#include <cstring>

#include "fogcl/error.h"
#include "runtime/host_frame.h"
#include "volume/volume_params.h"
#include "volume_composite_cl.h"
#include "volume_march_cl.h"

namespace fogcl {

namespace {
void check_buffer(const cl::Buffer& buffer, const char* name, std::size_t needed) {
  if (buffer() == nullptr) throw Error(std::string("buffer ") + name + " is not set");
  const std::size_t size = buffer.getInfo<CL_MEM_SIZE>();
  if (size < needed)
    throw Error(std::string("buffer ") + name + " holds " + std::to_string(size) + " bytes but needs " +
                std::to_string(needed));
}

cl::Buffer constant_buffer(const cl::Context& ctx, const float* data, std::size_t count) {
  // Copied at creation, so the host arrays may go before the kernel runs.
  return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, count * sizeof(float), const_cast<float*>(data));
}
}  // namespace

VolumePass::VolumePass(cl::Context context, cl::Device device)
    : device_(std::move(device)), programs_(std::move(context)) {
  with_cl_errors([&] {
    traits_.cpu = device_is_cpu(device_);
    traits_.opencl_c_version = device_opencl_c_version(device_);
    images_ = device_.getInfo<CL_DEVICE_IMAGE_SUPPORT>() == CL_TRUE;
  });
}

VolumePass::VolumePass(const Runtime& runtime) : VolumePass(runtime.context(), runtime.device()) {
  queue_ = runtime.queue();
}

cl::Kernel& VolumePass::kernel(const std::string& source_name, const char* source, const char* kernel_name,
                               const std::string& options) {
  const std::string key = source_name + '\n' + options;
  auto it = kernels_.find(key);
  if (it == kernels_.end()) {
    cl::Program program = programs_.get(device_, source_name, source, options);
    it = kernels_.emplace(key, with_cl_errors([&] { return cl::Kernel(program, kernel_name); })).first;
  }
  return it->second;
}

const cl::Memory& VolumePass::noise_on_device(const cl::CommandQueue& queue, const VolumeSettings& settings,
                                              std::vector<cl::Event>& waits) {
  const bool image = settings.noise_sampling == NoiseSampling::image;
  if (image && !images_)
    throw Error("noise sampling 'image' needs a device with image support; " +
                device_.getInfo<CL_DEVICE_NAME>() + " has none (use 'buffer')");
  const auto key = std::make_tuple(settings.noise_size, unsigned(settings.noise_seed), int(image));
  auto it = noise_.find(key);
  if (it == noise_.end()) {
    const NoiseTexture& tex = detail::shared_noise_texture(settings.noise_size, settings.noise_seed);
    const std::size_t n = std::size_t(tex.size);
    cl::Event uploaded;
    cl::Memory memory;
    // The texels live for the whole process (shared_noise_texture), so the upload need not block.
    if (image) {
      cl::Image3D img(programs_.context(), CL_MEM_READ_ONLY, cl::ImageFormat(CL_RGBA, CL_UNORM_INT8), n, n, n);
      queue.enqueueWriteImage(img, CL_FALSE, {0, 0, 0}, {n, n, n}, 0, 0, const_cast<std::uint8_t*>(tex.texels.data()),
                              nullptr, &uploaded);
      memory = img;
    } else {
      cl::Buffer buf(programs_.context(), CL_MEM_READ_ONLY, tex.texels.size());
      queue.enqueueWriteBuffer(buf, CL_FALSE, 0, tex.texels.size(), tex.texels.data(), nullptr, &uploaded);
      memory = buf;
    }
    ++stats_.noise_uploads;
    it = noise_.emplace(key, std::make_pair(memory, uploaded)).first;
  }
  waits.push_back(it->second.second);
  return it->second.first;
}

void VolumePass::prepare(const CameraParams& camera, const VolumeScene& scene, const VolumeSettings& settings,
                         ColorFormat storage, bool with_shadow_map) {
  ShadowMapParams shadow;
  const detail::PackedVolumeFrame f = detail::pack_volume_frame(1, 1, camera, scene, settings, storage,
                                                                with_shadow_map ? &shadow : nullptr, 1, 1, INFINITY);
  if (f.visible.empty()) return;
  kernel("volume_march.cl", volume_march_cl, "volume_march", detail::volume_march_options(f.variant, traits_));
  kernel("volume_composite.cl", volume_composite_cl, "volume_composite",
         detail::volume_composite_options(f.variant, traits_));
}

cl::Event VolumePass::enqueue(const cl::CommandQueue& queue, const FrameBuffers& fb, const CameraParams& camera,
                              const VolumeScene& scene, const VolumeSettings& settings, const ShadowMapBuffer* shadow,
                              const std::vector<cl::Event>& wait_list, float max_eye) {
  const detail::PackedVolumeFrame f =
      detail::pack_volume_frame(fb.width, fb.height, camera, scene, settings, fb.format,
                                shadow ? &shadow->params : nullptr, shadow ? shadow->width : 0,
                                shadow ? shadow->height : 0, max_eye);
  const std::size_t pixels = std::size_t(fb.width) * std::size_t(fb.height);
  const std::size_t color_bytes = pixels * bytes_per_pixel(fb.format);
  stats_.volumes_culled += scene.volumes.size() - f.visible.size();
  return with_cl_errors([&] {
    check_buffer(fb.color_in, "color_in", color_bytes);
    check_buffer(fb.depth, "depth", pixels * sizeof(float));
    check_buffer(fb.color_out, "color_out", color_bytes);
    if (shadow) check_buffer(shadow->depth, "shadow map", std::size_t(shadow->width) * shadow->height * sizeof(float));
    std::vector<cl::Event> waits = wait_list;
    cl::Event done;
    if (f.visible.empty()) {  // nothing to draw: no kernel, the output is the input
      last_march_options_.clear();
      last_composite_options_.clear();
      ++stats_.frames_without_volumes;
      if (fb.color_out() == fb.color_in())
        queue.enqueueMarkerWithWaitList(waits.empty() ? nullptr : &waits, &done);
      else
        queue.enqueueCopyBuffer(fb.color_in, fb.color_out, 0, 0, color_bytes, waits.empty() ? nullptr : &waits, &done);
      return done;
    }
    last_march_options_ = detail::volume_march_options(f.variant, traits_);
    last_composite_options_ = detail::volume_composite_options(f.variant, traits_);
    cl::Kernel& march = kernel("volume_march.cl", volume_march_cl, "volume_march", last_march_options_);
    cl::Kernel& composite = kernel("volume_composite.cl", volume_composite_cl, "volume_composite",
                                   last_composite_options_);
    const cl::Context& ctx = programs_.context();
    const cl::Buffer frame = constant_buffer(ctx, f.frame.data(), f.frame.size());
    const cl::Buffer volumes = constant_buffer(ctx, f.volumes.data(), f.volumes.size());
    const std::size_t low_pixels = std::size_t(f.low_width) * std::size_t(f.low_height);
    // Released with this call: OpenCL keeps them until the kernels that use them are done.
    const cl::Buffer low(ctx, CL_MEM_READ_WRITE, low_pixels * 4 * sizeof(float));
    const cl::Buffer low_key(ctx, CL_MEM_READ_WRITE, low_pixels * sizeof(float));
    int arg = 0;
    march.setArg(arg++, fb.depth);
    march.setArg(arg++, frame);
    march.setArg(arg++, volumes);
    march.setArg(arg++, cl_int(f.visible.size()));
    if (f.needs_noise()) {
      march.setArg(arg++, noise_on_device(queue, settings, waits));
      march.setArg(arg++, cl_int(settings.noise_size));
    } else {
      march.setArg(arg++, frame);  // unused: a variant without noise never reads it
      march.setArg(arg++, cl_int(0));
    }
    march.setArg(arg++, shadow ? shadow->depth : frame);
    march.setArg(arg++, cl_uint(scene.frame_index));
    march.setArg(arg++, low);
    march.setArg(arg++, low_key);
    cl::Event marched;
    queue.enqueueNDRangeKernel(march, cl::NullRange, cl::NDRange(f.low_width, f.low_height), cl::NullRange,
                               waits.empty() ? nullptr : &waits, &marched);
    ++stats_.march_dispatches;
    composite.setArg(0, fb.color_in);
    composite.setArg(1, fb.depth);
    composite.setArg(2, fb.color_out);
    composite.setArg(3, frame);
    composite.setArg(4, low);
    composite.setArg(5, low_key);
    const std::vector<cl::Event> after{marched};
    queue.enqueueNDRangeKernel(composite, cl::NullRange, cl::NDRange(fb.width, fb.height), cl::NullRange, &after,
                               &done);
    ++stats_.composite_dispatches;
    return done;
  });
}

void VolumePass::apply(const ColorImage& in, const DepthImage& depth, ColorImage& out, const CameraParams& camera,
                       const VolumeScene& scene, const VolumeSettings& settings, const ShadowMap* shadow) {
  validate_frame(in, depth);
  const float max_eye = max_eye_depth(depth, camera);
  const bool in_place = &out == &in;
  if (!in_place && (out.width() != in.width() || out.height() != in.height() || out.format() != in.format()))
    out = ColorImage(in.width(), in.height(), in.format());
  // Culling first: a frame without visible volumes touches no device at all.
  const detail::PackedVolumeFrame f = detail::pack_volume_frame(
      in.width(), in.height(), camera, scene, settings, in.format(), shadow ? &shadow->params : nullptr,
      shadow ? shadow->depth.width() : 0, shadow ? shadow->depth.height() : 0, max_eye);
  if (f.visible.empty()) {
    ++stats_.frames_without_volumes;
    stats_.volumes_culled += scene.volumes.size();
    last_march_options_.clear();
    last_composite_options_.clear();
    if (!in_place) std::memcpy(out.data(), in.data(), in.size_bytes());
    return;
  }
  with_cl_errors([&] {
    if (queue_() == nullptr) queue_ = cl::CommandQueue(programs_.context(), device_, CL_QUEUE_PROFILING_ENABLE);
    const FrameBuffers fb = detail::host_frame_buffers(programs_.context(), traits_.cpu, in, depth, out);
    ShadowMapBuffer sm;
    if (shadow) {
      sm.width = shadow->depth.width();
      sm.height = shadow->depth.height();
      sm.params = shadow->params;
      sm.depth = cl::Buffer(programs_.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, shadow->depth.size_bytes(),
                            const_cast<float*>(shadow->depth.data()));
    }
    const cl::Event done = enqueue(queue_, fb, camera, scene, settings, shadow ? &sm : nullptr, {}, max_eye);
    detail::read_back(queue_, traits_.cpu, fb, done, out);
  });
}

}  // namespace fogcl
