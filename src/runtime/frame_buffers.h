// What both passes do with a frame's device buffers: the checks of the integration API (exact
// sizes, context, queue; docs/DESIGN.md §1.1), and host images as buffers for one convenience call
// (on CPU devices the images' own page-aligned memory, CL_MEM_USE_HOST_PTR; copies elsewhere)
// with the read-back that makes `out` hold the result.
#pragma once

#include <string>

#include "fogcl/fog_pass.h"
#include "fogcl/image.h"
#include "runtime/clhpp.h"

namespace fogcl::detail {

// Throws fogcl::Error naming the buffer, its size and the frame's when a buffer is null, of
// another context, or not exactly the frame's size (a larger one is how a wrong format shows).
void check_frame_buffers(const FrameBuffers& frame, const cl::Context& context);
// Throws fogcl::Error when the queue is null or of another context or device than the pass's.
cl::CommandQueue checked_queue(cl_command_queue queue, const cl::Context& context, const cl::Device& device,
                               const char* who);

// A convenience call's frame: owns the buffers that `raw` names.
struct HostFrame {
  cl::Buffer color_in, depth, color_out;
  FrameBuffers raw;
};
// Packed views (image/packed_frame.h), out of in's size and format; color_out is color_in when
// in_place. On a CPU device their memory must be at host_ptr_alignment().
HostFrame host_frame(const cl::Context& context, bool cpu, const ConstColorView& in, const ConstDepthView& depth,
                     const ColorView& out, bool in_place);
// Blocks until `out` holds color_out after `done`. Returns true when nothing was copied (a CPU
// device maps the host memory the kernel wrote).
bool read_back(const cl::CommandQueue& queue, bool cpu, const HostFrame& frame, const cl::Event& done,
               const ColorView& out);
// The alignment [bytes] at which the device takes host memory as it is (CL_MEM_USE_HOST_PTR
// without a copy): CL_DEVICE_MEM_BASE_ADDR_ALIGN in bytes.
std::size_t host_ptr_alignment(const cl::Device& device);

}  // namespace fogcl::detail
