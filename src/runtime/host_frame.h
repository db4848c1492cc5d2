// Host images as device buffers for one convenience call (FogPass::apply, VolumePass::apply): on
// CPU devices the images' own page-aligned memory (CL_MEM_USE_HOST_PTR, nothing copied), on other
// devices copies; and the read-back that makes `out` hold the result.
#pragma once

#include "fogcl/cl.h"
#include "fogcl/fog_pass.h"
#include "fogcl/image.h"

namespace fogcl::detail {

// in and depth as buffers; color_out is in's buffer when &out == &in (in place). out must
// already have in's size and format.
FrameBuffers host_frame_buffers(const cl::Context& context, bool cpu, const ColorImage& in, const DepthImage& depth,
                                ColorImage& out);

// Blocks until `out` holds color_out's contents after `done`. Returns true when nothing was copied
// (a CPU device's map of host memory).
bool read_back(const cl::CommandQueue& queue, bool cpu, const FrameBuffers& frame, const cl::Event& done, ColorImage& out);

}  // namespace fogcl::detail
