#include "runtime/pinned_memory.h"

#include <cstring>
#include <map>
#include <mutex>

namespace fogcl::detail {

namespace {
struct Allocation {
  std::size_t size;
  cl_context context;
};
// Every live pinned allocation by its first byte: images carry no handle, their pointer is looked up.
std::mutex registry_mutex;
std::map<const std::byte*, Allocation>& registry() {
  static std::map<const std::byte*, Allocation> r;
  return r;
}

struct PinnedBlock {
  cl::Buffer buffer;
  cl::CommandQueue queue;
  std::byte* data = nullptr;
  ~PinnedBlock() {
    {
      const std::lock_guard<std::mutex> lock(registry_mutex);
      registry().erase(data);
    }
    try {
      queue.enqueueUnmapMemObject(buffer, data);
      queue.finish();
    } catch (...) {
      // The buffer is released with the block either way.
    }
  }
};
}  // namespace

AlignedBytes pinned_bytes(const cl::Context& context, const cl::Device& device, std::size_t size) {
  return with_cl_errors([&] {
    auto block = std::make_shared<PinnedBlock>();
    const std::size_t bytes = size == 0 ? 1 : size;
    block->buffer = cl::Buffer(context, CL_MEM_READ_WRITE | CL_MEM_ALLOC_HOST_PTR, bytes);
    block->queue = cl::CommandQueue(context, device);
    block->data = static_cast<std::byte*>(
        block->queue.enqueueMapBuffer(block->buffer, CL_TRUE, CL_MAP_READ | CL_MAP_WRITE, 0, bytes));
    std::memset(block->data, 0, bytes);
    {
      const std::lock_guard<std::mutex> lock(registry_mutex);
      registry()[block->data] = {bytes, context()};
    }
    std::byte* data = block->data;
    return AlignedBytes(data, size, std::move(block));
  });
}

bool is_pinned(const void* p, std::size_t size, cl_context context) {
  const auto* b = static_cast<const std::byte*>(p);
  const std::lock_guard<std::mutex> lock(registry_mutex);
  auto it = registry().upper_bound(b);
  if (it == registry().begin()) return false;
  --it;
  return it->second.context == context && b >= it->first && b + size <= it->first + it->second.size;
}

}  // namespace fogcl::detail
