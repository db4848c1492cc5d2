// The local size of the passes' 2D launches, chosen by the host from the device's and the kernel's
// limits and the kernel's private memory, never left to the driver (cl::NullRange): why, and the
// rule, in work_groups.cpp.
#pragma once

#include <cstddef>

#include "runtime/clhpp.h"

namespace fogcl::detail {

struct WorkGroupShape {
  std::size_t x = 1, y = 1;  // work-items of a group along x (a row) and y
  cl::NDRange local() const { return cl::NDRange(x, y); }
  // items_x x items_y work-items rounded up to whole groups: the kernels return early from the
  // work-items past their range.
  cl::NDRange global(std::size_t items_x, std::size_t items_y) const {
    return cl::NDRange((items_x + x - 1) / x * x, (items_y + y - 1) / y * y);
  }
};

// The local size of `kernel`'s 2D launches on `device`, whatever the global size (one shape per
// kernel object, so PoCL compiles its work-group function once, not once per frame size).
// private_bytes: the host's upper bound of one work-item's private memory (its private arrays),
// used where the device reports less (PoCL 3.1 reports 1024 bytes whatever the kernel holds).
// Reads the device and kernel (clGetKernelWorkGroupInfo): call once per kernel object.
WorkGroupShape work_group_shape(const cl::Kernel& kernel, const cl::Device& device, std::size_t private_bytes);

// What a work-group's private memory may take on a CPU device [bytes]: the part of a worker
// thread's stack PoCL lets a work-group use (work_groups.cpp).
std::size_t cpu_work_group_stack_bytes();

}  // namespace fogcl::detail
