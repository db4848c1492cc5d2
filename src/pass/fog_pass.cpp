#include "fogcl/fog_pass.h"

#include <cstring>

#include "deferred_fog_cl.h"
#include "fogcl/error.h"
#include "settings/fog_coefficients.h"

namespace fogcl {

namespace {
cl_float4 f4(float x, float y, float z, float w) { return cl_float4{{x, y, z, w}}; }
cl_float4 f4(const glm::vec4& v) { return f4(v.x, v.y, v.z, v.w); }
cl_float4 f4(const glm::vec3& v) { return f4(v.x, v.y, v.z, 0.0f); }

void check_buffer(const cl::Buffer& buffer, const char* name, std::size_t needed) {
  if (buffer() == nullptr) throw Error(std::string("frame buffer ") + name + " is not set");
  const std::size_t size = buffer.getInfo<CL_MEM_SIZE>();
  if (size < needed)
    throw Error(std::string("frame buffer ") + name + " holds " + std::to_string(size) +
                " bytes but the frame needs " + std::to_string(needed));
}
}  // namespace

FogPass::FogPass(cl::Context context, cl::Device device)
    : device_(std::move(device)), programs_(std::move(context)) {
  with_cl_errors([&] {
    traits_.cpu = device_is_cpu(device_);
    traits_.opencl_c_version = device_opencl_c_version(device_);
  });
}

FogPass::FogPass(const Runtime& runtime, const CpuCodegen& codegen)
    : FogPass(runtime.context(), runtime.device()) {
  queue_ = runtime.queue();
  traits_.codegen = codegen;
}

cl::Kernel& FogPass::kernel_for(const Variant& variant) {
  if (last_kernel_ != nullptr && variant == last_kernel_variant_) return *last_kernel_;
  const std::string options = build_options(variant, traits_);
  auto it = kernels_.find(options);
  if (it == kernels_.end()) {
    cl::Program program = programs_.get(device_, "deferred_fog.cl", deferred_fog_cl, options);
    it = kernels_.emplace(options, with_cl_errors([&] { return cl::Kernel(program, "deferred_fog"); })).first;
  }
  last_kernel_variant_ = variant;
  last_kernel_ = &it->second;  // std::map nodes do not move
  return it->second;
}

void FogPass::prepare(const Variant& variant) {
  if (variant.needs_pass()) kernel_for(variant);
}

cl::Event FogPass::enqueue(const cl::CommandQueue& queue, const FrameBuffers& fb,
                           const CameraParams& camera, const FogSettings& settings,
                           const std::vector<cl::Event>& wait_list) {
  if (fb.width < 1 || fb.height < 1)
    throw Error("frame size must be at least 1x1 (got " + std::to_string(fb.width) + "x" +
                std::to_string(fb.height) + ")");
  validate(camera);
  const Variant v = select_variant(settings, camera, fb.format);
  const std::size_t pixels = std::size_t(fb.width) * std::size_t(fb.height);
  const std::size_t color_bytes = pixels * bytes_per_pixel(fb.format);
  return with_cl_errors([&] {
    check_buffer(fb.color_in, "color_in", color_bytes);
    check_buffer(fb.depth, "depth", pixels * sizeof(float));
    check_buffer(fb.color_out, "color_out", color_bytes);
    const std::vector<cl::Event>* waits = wait_list.empty() ? nullptr : &wait_list;
    cl::Event done;
    last_variant_ = v;
    if (!v.needs_pass()) {
      if (fb.color_out() == fb.color_in()) {
        queue.enqueueMarkerWithWaitList(waits, &done);
      } else {
        queue.enqueueCopyBuffer(fb.color_in, fb.color_out, 0, 0, color_bytes, waits, &done);
        ++stats_.buffer_copies;
      }
      return done;
    }
    const detail::FogCoefficients<float> k = detail::fog_coefficients<float>(settings, v.mode);
    cl::Kernel& kernel = kernel_for(v);
    const auto& c = camera.frustum_corners;
    kernel.setArg(0, fb.color_in);
    kernel.setArg(1, fb.depth);
    kernel.setArg(2, fb.color_out);
    kernel.setArg(3, cl_int(fb.width));
    kernel.setArg(4, cl_int(fb.height));
    kernel.setArg(5, f4(camera.zbuffer_params));
    kernel.setArg(6, f4(camera.projection_params));
    kernel.setArg(7, f4(c[kBottomLeft]));
    kernel.setArg(8, f4(c[kBottomRight]));
    kernel.setArg(9, f4(c[kTopLeft]));
    kernel.setArg(10, f4(c[kTopRight]));
    kernel.setArg(11, f4(k.a, k.b, 0.0f, 0.0f));
    kernel.setArg(12, f4(settings.color.r, settings.color.g, settings.color.b, 0.0f));
    const int per_item = pixels_per_work_item(traits_);
    queue.enqueueNDRangeKernel(kernel, cl::NullRange,
                               cl::NDRange((fb.width + per_item - 1) / per_item, fb.height),
                               cl::NullRange, waits, &done);
    ++stats_.kernel_dispatches;
    return done;
  });
}

void FogPass::apply(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                    const CameraParams& camera, const FogSettings& settings) {
  validate_frame(in, depth);
  validate(camera);
  const Variant v = select_variant(settings, camera, in.format());
  const bool in_place = &out == &in;
  if (!in_place && (out.width() != in.width() || out.height() != in.height() || out.format() != in.format()))
    out = ColorImage(in.width(), in.height(), in.format());
  if (!v.needs_pass()) {  // no device work at all
    last_variant_ = v;
    if (!in_place) std::memcpy(out.data(), in.data(), in.size_bytes());
    return;
  }
  with_cl_errors([&] {
    if (queue_() == nullptr) queue_ = cl::CommandQueue(programs_.context(), device_, CL_QUEUE_PROFILING_ENABLE);
    const cl::Context& ctx = programs_.context();
    // CPU devices read and write the host images where they are (page-aligned storage);
    // other devices get copies.
    const cl_mem_flags host = traits_.cpu ? CL_MEM_USE_HOST_PTR : CL_MEM_COPY_HOST_PTR;
    void* in_ptr = const_cast<void*>(in.data());
    FrameBuffers fb;
    fb.width = in.width();
    fb.height = in.height();
    fb.format = in.format();
    fb.depth = cl::Buffer(ctx, CL_MEM_READ_ONLY | host, depth.size_bytes(), const_cast<float*>(depth.data()));
    if (in_place) {
      fb.color_in = cl::Buffer(ctx, CL_MEM_READ_WRITE | host, in.size_bytes(), in_ptr);
      fb.color_out = fb.color_in;
    } else {
      fb.color_in = cl::Buffer(ctx, CL_MEM_READ_ONLY | host, in.size_bytes(), in_ptr);
      fb.color_out = traits_.cpu ? cl::Buffer(ctx, CL_MEM_WRITE_ONLY | CL_MEM_USE_HOST_PTR, out.size_bytes(), out.data())
                                 : cl::Buffer(ctx, CL_MEM_WRITE_ONLY, out.size_bytes());
    }
    const cl::Event done = enqueue(queue_, fb, camera, settings);
    const std::vector<cl::Event> after{done};
    if (traits_.cpu) {
      // Mapping is what makes a USE_HOST_PTR buffer's contents valid in host memory; on a CPU
      // device it returns the same pointer and copies nothing.
      void* mapped = queue_.enqueueMapBuffer(fb.color_out, CL_TRUE, CL_MAP_READ, 0, out.size_bytes(), &after);
      queue_.enqueueUnmapMemObject(fb.color_out, mapped);
      queue_.finish();
      ++stats_.zero_copy_frames;
    } else {
      queue_.enqueueReadBuffer(fb.color_out, CL_TRUE, 0, out.size_bytes(), out.data(), &after);
      ++stats_.copied_frames;
    }
  });
}

}  // namespace fogcl
