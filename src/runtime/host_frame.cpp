#include "runtime/host_frame.h"

namespace fogcl::detail {

FrameBuffers host_frame_buffers(const cl::Context& ctx, bool cpu, const ColorImage& in, const DepthImage& depth,
                                ColorImage& out) {
  const cl_mem_flags host = cpu ? CL_MEM_USE_HOST_PTR : CL_MEM_COPY_HOST_PTR;
  void* in_ptr = const_cast<void*>(in.data());
  FrameBuffers fb;
  fb.width = in.width();
  fb.height = in.height();
  fb.format = in.format();
  fb.depth = cl::Buffer(ctx, CL_MEM_READ_ONLY | host, depth.size_bytes(), const_cast<float*>(depth.data()));
  if (&out == &in) {
    fb.color_in = cl::Buffer(ctx, CL_MEM_READ_WRITE | host, in.size_bytes(), in_ptr);
    fb.color_out = fb.color_in;
  } else {
    fb.color_in = cl::Buffer(ctx, CL_MEM_READ_ONLY | host, in.size_bytes(), in_ptr);
    fb.color_out = cpu ? cl::Buffer(ctx, CL_MEM_WRITE_ONLY | CL_MEM_USE_HOST_PTR, out.size_bytes(), out.data())
                       : cl::Buffer(ctx, CL_MEM_WRITE_ONLY, out.size_bytes());
  }
  return fb;
}

bool read_back(const cl::CommandQueue& queue, bool cpu, const FrameBuffers& fb, const cl::Event& done, ColorImage& out) {
  const std::vector<cl::Event> after{done};
  if (cpu) {
    // Mapping is what makes a USE_HOST_PTR buffer's contents valid in host memory; on a CPU
    // device it returns the same pointer and copies nothing.
    void* mapped = queue.enqueueMapBuffer(fb.color_out, CL_TRUE, CL_MAP_READ, 0, out.size_bytes(), &after);
    queue.enqueueUnmapMemObject(fb.color_out, mapped);
    queue.finish();
    return true;
  }
  queue.enqueueReadBuffer(fb.color_out, CL_TRUE, 0, out.size_bytes(), out.data(), &after);
  return false;
}

}  // namespace fogcl::detail
