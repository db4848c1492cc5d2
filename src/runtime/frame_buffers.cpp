#include "runtime/frame_buffers.h"

#include <algorithm>

namespace fogcl::detail {

namespace {
void check_buffer(cl_mem buffer, const char* name, const cl::Context& context, std::size_t needed,
                  const std::string& frame, std::size_t other_format_bytes, ColorFormat other_format) {
  if (buffer == nullptr) throw Error(std::string("frame buffer ") + name + " is not set (null cl_mem)");
  const cl::Buffer b = wrap(buffer);
  if (b.getInfo<CL_MEM_CONTEXT>()() != context())
    throw Error(std::string("frame buffer ") + name + " belongs to another OpenCL context than the pass");
  const std::size_t size = b.getInfo<CL_MEM_SIZE>();
  if (size == needed) return;
  std::string msg = std::string("frame buffer ") + name + " holds " + std::to_string(size) + " bytes but a " +
                    frame + " frame needs exactly " + std::to_string(needed) +
                    " (frames are packed and buffers exact-size; use a sub-buffer for part of a larger one)";
  if (other_format_bytes != 0 && size == other_format_bytes)
    msg += std::string(": that is the size of a ") + to_string(other_format) +
           " frame, is FrameBuffers::format right?";
  throw Error(msg);
}
}  // namespace

void check_frame_buffers(const FrameBuffers& fb, const cl::Context& context) {
  if (fb.width < 1 || fb.height < 1)
    throw Error("frame size must be at least 1x1 (got " + std::to_string(fb.width) + "x" +
                std::to_string(fb.height) + ")");
  const std::string frame = std::to_string(fb.width) + "x" + std::to_string(fb.height) + " " + to_string(fb.format);
  const ColorFormat other = fb.format == ColorFormat::rgba32f ? ColorFormat::rgba16f : ColorFormat::rgba32f;
  const std::size_t color_bytes = color_buffer_bytes(fb.width, fb.height, fb.format);
  const std::size_t other_bytes = color_buffer_bytes(fb.width, fb.height, other);
  check_buffer(fb.color_in, "color_in", context, color_bytes, frame, other_bytes, other);
  check_buffer(fb.depth, "depth", context, depth_buffer_bytes(fb.width, fb.height), frame, 0, other);
  check_buffer(fb.color_out, "color_out", context, color_bytes, frame, other_bytes, other);
}

cl::CommandQueue checked_queue(cl_command_queue handle, const cl::Context& context, const cl::Device& device,
                               const char* who) {
  if (handle == nullptr) throw Error(std::string(who) + ": the queue is null");
  cl::CommandQueue queue = wrap(handle);
  if (queue.getInfo<CL_QUEUE_CONTEXT>()() != context())
    throw Error(std::string(who) + ": the queue belongs to another OpenCL context than the pass");
  if (queue.getInfo<CL_QUEUE_DEVICE>()() != device())
    throw Error(std::string(who) + ": the queue is on another device than the pass (" +
                device_name(queue.getInfo<CL_QUEUE_DEVICE>()()) + ", pass: " + device_name(device()) + ")");
  return queue;
}

HostFrame host_frame(const cl::Context& ctx, bool cpu, const ConstColorView& in, const ConstDepthView& depth,
                     const ColorView& out, bool in_place) {
  const cl_mem_flags host = cpu ? CL_MEM_USE_HOST_PTR : CL_MEM_COPY_HOST_PTR;
  void* in_ptr = const_cast<void*>(in.data());
  const std::size_t color_bytes = in.span_bytes();
  HostFrame f;
  f.depth = cl::Buffer(ctx, CL_MEM_READ_ONLY | host, depth.span_bytes(), const_cast<float*>(depth.data()));
  if (in_place) {
    f.color_in = cl::Buffer(ctx, CL_MEM_READ_WRITE | host, color_bytes, in_ptr);
    f.color_out = f.color_in;
  } else {
    f.color_in = cl::Buffer(ctx, CL_MEM_READ_ONLY | host, color_bytes, in_ptr);
    f.color_out = cpu ? cl::Buffer(ctx, CL_MEM_WRITE_ONLY | CL_MEM_USE_HOST_PTR, color_bytes, out.data())
                      : cl::Buffer(ctx, CL_MEM_WRITE_ONLY, color_bytes);
  }
  f.raw.width = in.width();
  f.raw.height = in.height();
  f.raw.format = in.format();
  f.raw.color_in = f.color_in();
  f.raw.depth = f.depth();
  f.raw.color_out = f.color_out();
  return f;
}

bool read_back(const cl::CommandQueue& queue, bool cpu, const HostFrame& f, const cl::Event& done,
               const ColorView& out) {
  const std::vector<cl::Event> after{done};
  if (cpu) {
    // Mapping is what makes a USE_HOST_PTR buffer's contents valid in host memory (the spec: the
    // host_ptr holds the latest bits once the map has completed); on a CPU device it returns the
    // same pointer and copies nothing. The map is not blocking and the unmap is queued behind it,
    // so the host waits once (clFinish) for kernel, map and unmap: a blocking map, then the unmap
    // and a finish, was a second round trip through PoCL's queue, 25-30 us a call
    // (BM_HostCallParts, way 4 against way 7). Nothing writes the buffer after the map, and the
    // buffers are released after the finish, so `out` keeps the mapped bits. clEnqueueReadBuffer
    // into the host_ptr itself (also defined for USE_HOST_PTR) would be one command, but PoCL
    // copies the buffer onto itself then (way 3: +0.35 ms at 1080p).
    void* mapped = queue.enqueueMapBuffer(f.color_out, CL_FALSE, CL_MAP_READ, 0, out.span_bytes(), &after);
    queue.enqueueUnmapMemObject(f.color_out, mapped);
    queue.finish();
    return true;
  }
  queue.enqueueReadBuffer(f.color_out, CL_TRUE, 0, out.span_bytes(), out.data(), &after);
  return false;
}

std::size_t host_ptr_alignment(const cl::Device& device) {
  // The spec's rule for a buffer's base address, in bits. PoCL takes host memory at this alignment
  // in place and copies memory that is not (docs/library.md#images-and-views).
  const cl_uint bits = device.getInfo<CL_DEVICE_MEM_BASE_ADDR_ALIGN>();
  return std::max<std::size_t>(bits / 8, 1);
}

}  // namespace fogcl::detail
