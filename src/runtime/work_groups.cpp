// The passes' work-groups. With cl::NullRange as the local size the driver picks the group, and
// PoCL's CPU device picked whole frames: the march's 20 x 180 work-items at 320x180 (full
// resolution) as one group of 3600. On a CPU device a work-group runs on one worker thread, one
// work-item after another, and PoCL keeps the private arrays of all its work-items at once on that
// thread's stack (the work-item loops' per-group "context arrays", local size x the work-item's
// private memory: github.com/pocl/pocl/issues/1525; the physical march's work-group function reserved
// 6.4 KB per work-item, 23 MB for those 3600 against an 8 MiB stack, and crashed). A CPU gains
// nothing from a larger group (parallelism comes from the number of groups), so the host chooses:
// the smallest efficient group, bounded by the stack. GPUs keep the private memory in registers
// and scratch the driver accounts for in CL_KERNEL_WORK_GROUP_SIZE; there the group is the usual
// 256 work-items (8 warps of 32, 4 wavefronts of 64) in rows of 32, each a coalesced row of pixels.
// One shape per kernel object, whatever the frame: the global size is rounded up to whole groups
// and the kernels return early from the work-items past their range. PoCL compiles a work-group
// function per local size, so a fixed shape also means one compile per variant, not one per size.
#include "runtime/work_groups.h"

#include <algorithm>
#include <vector>

#include <pthread.h>
#include <sys/resource.h>

namespace fogcl::detail {

std::size_t cpu_work_group_stack_bytes() {
  // PoCL's worker threads run the work-groups. PoCL 3.1 (Debian 12's) creates them with the
  // default thread attributes, so their stack is the process's default thread stack size (glibc:
  // the RLIMIT_STACK soft limit, 8 MiB typically, 2 MiB when unlimited); PoCL's current sources set
  // 8 MiB and let a work-group take 3/4 of it, keeping the rest for the thread's own frames
  // (HOST_CPU_ENABLE_STACK_SIZE_CHECK, lib/CL/devices/pthread/pthread_scheduler.c). The same share
  // of the smaller of the two here. (ulimit -s 32768 let the 23 MB group above run.)
  std::size_t stack = 0;
#if defined(__GLIBC__)
  pthread_attr_t attr;
  if (pthread_getattr_default_np(&attr) == 0) {
    pthread_attr_getstacksize(&attr, &stack);
    pthread_attr_destroy(&attr);
  }
#endif
  if (stack == 0) {
    rlimit limit{};
    stack = getrlimit(RLIMIT_STACK, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY ? std::size_t(limit.rlim_cur)
                                                                                   : std::size_t(2) << 20;
  }
  return std::min(stack, std::size_t(8) << 20) / 4 * 3;
}

WorkGroupShape work_group_shape(const cl::Kernel& kernel, const cl::Device& device, std::size_t private_bytes) {
  const bool cpu = (device.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_CPU) != 0;
  const std::vector<std::size_t> item_sizes = device.getInfo<CL_DEVICE_MAX_WORK_ITEM_SIZES>();
  std::size_t limit = std::min(device.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>(),
                               kernel.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device));
  // The driver's preferred multiple of the group size: PoCL's vector width across work-items
  // (8), a GPU's warp or wavefront (32, 64).
  const std::size_t multiple =
      std::max<std::size_t>(1, kernel.getWorkGroupInfo<CL_KERNEL_PREFERRED_WORK_GROUP_SIZE_MULTIPLE>(device));
  WorkGroupShape s;
  if (cpu) {
    // Every work-item's private memory on the stack at once: the larger of the driver's figure and
    // the host's bound (PoCL 3.1 reports 1024 bytes for every kernel).
    const std::size_t per_item = std::max<std::size_t>(
        {std::size_t(1), private_bytes, std::size_t(kernel.getWorkGroupInfo<CL_KERNEL_PRIVATE_MEM_SIZE>(device))});
    limit = std::min(limit, std::max<std::size_t>(1, cpu_work_group_stack_bytes() / per_item));
    // One row of `multiple` work-items: 128 pixels of a row with the CPU kernels' 16 lanes. As fast
    // as PoCL's own choice at 1080p (march and composite), larger groups were not faster, and
    // taller ones slowed the composite by half.
    s.x = std::min(multiple, limit);
  } else {
    const std::size_t items = std::min<std::size_t>(limit, 256);
    s.x = std::min(items, (32 + multiple - 1) / multiple * multiple);
    s.y = items / s.x;
  }
  s.x = std::max<std::size_t>(1, std::min(s.x, item_sizes.at(0)));
  s.y = std::max<std::size_t>(1, std::min(s.y, item_sizes.size() > 1 ? item_sizes[1] : 1));
  return s;
}

}  // namespace fogcl::detail
