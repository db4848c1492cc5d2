// Host memory the device's DMA engine reads and writes directly (page-locked: CL_MEM_ALLOC_HOST_PTR
// on NVIDIA), for images that cross the bus without a staging copy (FogPass::pinned_color_image).
#pragma once

#include <cstddef>

#include "fogcl/image.h"
#include "runtime/clhpp.h"

namespace fogcl::detail {

// `size` zeroed bytes of pinned host memory of `context`: a CL_MEM_ALLOC_HOST_PTR buffer mapped
// for the storage's life (the storage keeps the buffer, and so the context, alive).
AlignedBytes pinned_bytes(const cl::Context& context, const cl::Device& device, std::size_t size);

// Whether [p, p + size) lies within one pinned_bytes() allocation of `context`.
bool is_pinned(const void* p, std::size_t size, cl_context context);

}  // namespace fogcl::detail
