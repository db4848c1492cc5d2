// A Vulkan renderer's side of a frame fogcl fogs in its memory (docs/library.md, "From a GPU
// renderer"): a device on the OpenCL device's GPU (same UUID), buffers whose memory is exported as
// opaque file descriptors (VK_KHR_external_memory_fd), binary semaphores exported the same way
// (VK_KHR_external_semaphore_fd), and the few submissions around the hand-over. Built against the
// Vulkan headers and loader (Debian: libvulkan-dev). Errors throw std::runtime_error naming the call.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace vkp {

// A Vulkan info struct, zeroed, of type `type`, chaining `next`.
template <class T>
T make(VkStructureType type, const void* next = nullptr) {
  T t{};
  t.sType = type;
  t.pNext = const_cast<void*>(next);  // output structs' pNext is void*
  return t;
}

inline void check(VkResult r, const char* call) {
  if (r != VK_SUCCESS) throw std::runtime_error(std::string(call) + " failed (VkResult " + std::to_string(r) + ")");
}

// A buffer and its own allocation. `bytes` is the allocation's size: what an importer is told.
struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize bytes = 0;
  void* mapped = nullptr;  // host-visible buffers only
};

class Producer {
 public:
  Producer() = default;
  Producer(const Producer&) = delete;
  Producer& operator=(const Producer&) = delete;
  ~Producer() {
    if (device_ != VK_NULL_HANDLE) {
      vkDeviceWaitIdle(device_);
      for (VkSemaphore s : semaphores_) vkDestroySemaphore(device_, s, nullptr);
      for (const Buffer& b : buffers_) {
        vkDestroyBuffer(device_, b.buffer, nullptr);
        vkFreeMemory(device_, b.memory, nullptr);
      }
      for (VkFence f : fences_) vkDestroyFence(device_, f, nullptr);
      if (pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(device_, pool_, nullptr);
      vkDestroyDevice(device_, nullptr);
    }
    if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
  }

  // Opens the Vulkan device whose deviceUUID is `uuid` with external memory export, and semaphore
  // export where the device has it (semaphore_export()); `timeline`: also timeline semaphores
  // (Vulkan 1.2). "" when open, else why not (no driver, no such device, an extension missing).
  std::string open(const std::uint8_t uuid[VK_UUID_SIZE], bool timeline = false) {
    auto app = make<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
    app.pApplicationName = "fogcl vulkan producer";
    app.apiVersion = VK_API_VERSION_1_2;
    auto ici = make<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
    ici.pApplicationInfo = &app;
    if (VkResult r = vkCreateInstance(&ici, nullptr, &instance_); r != VK_SUCCESS)
      return "vkCreateInstance failed (VkResult " + std::to_string(r) + "): no Vulkan driver";
    std::uint32_t count = 0;
    vkEnumeratePhysicalDevices(instance_, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(instance_, &count, devices.data());
    for (VkPhysicalDevice d : devices) {
      auto id = make<VkPhysicalDeviceIDProperties>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES);
      auto p = make<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &id);
      vkGetPhysicalDeviceProperties2(d, &p);
      if (std::memcmp(id.deviceUUID, uuid, VK_UUID_SIZE) == 0) {
        physical_ = d;
        properties_ = p.properties;
      }
    }
    if (physical_ == VK_NULL_HANDLE)
      return "no Vulkan device has the OpenCL device's UUID (" + std::to_string(count) + " Vulkan devices)";
    const std::string name = properties_.deviceName;
    std::vector<const char*> extensions = {VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME};
    if (!has_extension(VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME))
      return name + " lacks " VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME;
    semaphore_export_ = has_extension(VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME);
    if (semaphore_export_) extensions.push_back(VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME);
    auto timeline_features =
        make<VkPhysicalDeviceTimelineSemaphoreFeatures>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_TIMELINE_SEMAPHORE_FEATURES);
    if (timeline) {
      auto f = make<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &timeline_features);
      vkGetPhysicalDeviceFeatures2(physical_, &f);
      if (properties_.apiVersion < VK_API_VERSION_1_2 || !timeline_features.timelineSemaphore)
        return name + " has no timeline semaphores (Vulkan 1.2)";
    }

    // One queue of a family that can copy and write timestamps (a graphics or compute family can).
    std::uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &families, nullptr);
    std::vector<VkQueueFamilyProperties> family(families);
    vkGetPhysicalDeviceQueueFamilyProperties(physical_, &families, family.data());
    family_ = families;
    for (std::uint32_t i = 0; i < families && family_ == families; ++i)
      if (family[i].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) family_ = i;
    if (family_ == families) return name + " has no graphics or compute queue";
    timestamp_bits_ = family[family_].timestampValidBits;
    const float priority = 1.0f;
    auto qci = make<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
    qci.queueFamilyIndex = family_;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    auto dci = make<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, timeline ? &timeline_features : nullptr);
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    dci.enabledExtensionCount = std::uint32_t(extensions.size());
    dci.ppEnabledExtensionNames = extensions.data();
    if (VkResult r = vkCreateDevice(physical_, &dci, nullptr, &device_); r != VK_SUCCESS)
      return "vkCreateDevice on " + name + " failed (VkResult " + std::to_string(r) + ")";
    vkGetDeviceQueue(device_, family_, 0, &queue_);
    get_memory_fd_ = reinterpret_cast<PFN_vkGetMemoryFdKHR>(vkGetDeviceProcAddr(device_, "vkGetMemoryFdKHR"));
    get_semaphore_fd_ =
        reinterpret_cast<PFN_vkGetSemaphoreFdKHR>(vkGetDeviceProcAddr(device_, "vkGetSemaphoreFdKHR"));
    auto pci = make<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = family_;
    check(vkCreateCommandPool(device_, &pci, nullptr, &pool_), "vkCreateCommandPool");
    return "";
  }

  // A device-local buffer for transfers, its memory exportable as an opaque fd: "" with `out`
  // set, or why the device cannot export such a buffer.
  std::string exportable_buffer(VkDeviceSize size, Buffer& out) {
    const VkBufferUsageFlags usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    auto query = make<VkPhysicalDeviceExternalBufferInfo>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_BUFFER_INFO);
    query.usage = usage;
    query.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
    auto answer = make<VkExternalBufferProperties>(VK_STRUCTURE_TYPE_EXTERNAL_BUFFER_PROPERTIES);
    vkGetPhysicalDeviceExternalBufferProperties(physical_, &query, &answer);
    const VkExternalMemoryFeatureFlags features = answer.externalMemoryProperties.externalMemoryFeatures;
    if (!(features & VK_EXTERNAL_MEMORY_FEATURE_EXPORTABLE_BIT))
      return std::string(properties_.deviceName) + " exports no opaque-fd buffer memory";
    auto external = make<VkExternalMemoryBufferCreateInfo>(VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO);
    external.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
    auto export_info = make<VkExportMemoryAllocateInfo>(VK_STRUCTURE_TYPE_EXPORT_MEMORY_ALLOCATE_INFO);
    export_info.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
    out = make_buffer(size, usage, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, &external, &export_info,
                      (features & VK_EXTERNAL_MEMORY_FEATURE_DEDICATED_ONLY_BIT) != 0);
    return "";
  }
  // A host-visible, coherent, mapped buffer: the staging and read-back buffers.
  Buffer host_buffer(VkDeviceSize size) {
    Buffer b = make_buffer(size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                           VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, nullptr,
                           nullptr, false);
    check(vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
    return b;
  }
  // A new fd of the buffer's memory, owned by the caller (an importer takes it over).
  int export_fd(const Buffer& b) const {
    auto info = make<VkMemoryGetFdInfoKHR>(VK_STRUCTURE_TYPE_MEMORY_GET_FD_INFO_KHR);
    info.memory = b.memory;
    info.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
    int fd = -1;
    check(get_memory_fd_(device_, &info, &fd), "vkGetMemoryFdKHR");
    return fd;
  }

  // A binary semaphore exportable as an opaque fd (needs semaphore_export()).
  VkSemaphore exportable_semaphore() {
    auto export_info = make<VkExportSemaphoreCreateInfo>(VK_STRUCTURE_TYPE_EXPORT_SEMAPHORE_CREATE_INFO);
    export_info.handleTypes = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
    return semaphore(&export_info);
  }
  // A timeline semaphore at 0 (open(uuid, true)).
  VkSemaphore timeline_semaphore() {
    auto type = make<VkSemaphoreTypeCreateInfo>(VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO);
    type.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
    return semaphore(&type);
  }
  // A new fd of the semaphore's payload, owned by the caller.
  int export_fd(VkSemaphore s) const {
    auto info = make<VkSemaphoreGetFdInfoKHR>(VK_STRUCTURE_TYPE_SEMAPHORE_GET_FD_INFO_KHR);
    info.semaphore = s;
    info.handleType = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
    int fd = -1;
    check(get_semaphore_fd_(device_, &info, &fd), "vkGetSemaphoreFdKHR");
    return fd;
  }

  VkCommandBuffer command_buffer() const {
    auto info = make<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
    info.commandPool = pool_;
    info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    info.commandBufferCount = 1;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    check(vkAllocateCommandBuffers(device_, &info, &cb), "vkAllocateCommandBuffers");
    return cb;
  }
  VkFence fence() {
    auto info = make<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
    VkFence f = VK_NULL_HANDLE;
    check(vkCreateFence(device_, &info, nullptr, &f), "vkCreateFence");
    fences_.push_back(f);
    return f;
  }
  // The fence signalled, then reset for its next submission.
  void wait(VkFence f) const {
    check(vkWaitForFences(device_, 1, &f, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    check(vkResetFences(device_, 1, &f), "vkResetFences");
  }

  // The buffers' ownership between this queue family and the other API (VK_QUEUE_FAMILY_EXTERNAL):
  // released after this queue's last transfer write, acquired before its next transfer.
  void release_to_external(VkCommandBuffer cb, const std::vector<VkBuffer>& buffers) const {
    ownership(cb, buffers, family_, VK_QUEUE_FAMILY_EXTERNAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
              VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, 0);
  }
  void acquire_from_external(VkCommandBuffer cb, const std::vector<VkBuffer>& buffers) const {
    ownership(cb, buffers, VK_QUEUE_FAMILY_EXTERNAL, family_, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
              VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
  }

  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  bool semaphore_export() const { return semaphore_export_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  std::uint32_t timestamp_bits() const { return timestamp_bits_; }

 private:
  bool has_extension(const char* wanted) const {
    std::uint32_t n = 0;
    vkEnumerateDeviceExtensionProperties(physical_, nullptr, &n, nullptr);
    std::vector<VkExtensionProperties> all(n);
    vkEnumerateDeviceExtensionProperties(physical_, nullptr, &n, all.data());
    for (const VkExtensionProperties& e : all)
      if (std::strcmp(e.extensionName, wanted) == 0) return true;
    return false;
  }
  Buffer make_buffer(VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags wanted,
                     const void* buffer_next, void* memory_next, bool dedicated) {
    Buffer b;
    auto bci = make<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO, buffer_next);
    bci.size = size;
    bci.usage = usage;
    bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    check(vkCreateBuffer(device_, &bci, nullptr, &b.buffer), "vkCreateBuffer");
    buffers_.push_back(b);  // destroyed with the device, allocated or not
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, b.buffer, &req);
    VkPhysicalDeviceMemoryProperties memory;
    vkGetPhysicalDeviceMemoryProperties(physical_, &memory);
    std::uint32_t type = memory.memoryTypeCount;
    for (std::uint32_t i = 0; i < memory.memoryTypeCount && type == memory.memoryTypeCount; ++i)
      if ((req.memoryTypeBits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & wanted) == wanted) type = i;
    if (type == memory.memoryTypeCount) throw std::runtime_error("no Vulkan memory type for the buffer");
    auto dedicated_info = make<VkMemoryDedicatedAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO, memory_next);
    dedicated_info.buffer = b.buffer;
    auto mai = make<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, dedicated ? &dedicated_info : memory_next);
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = type;
    check(vkAllocateMemory(device_, &mai, nullptr, &b.memory), "vkAllocateMemory");
    buffers_.back().memory = b.memory;
    check(vkBindBufferMemory(device_, b.buffer, b.memory, 0), "vkBindBufferMemory");
    b.bytes = req.size;
    return b;
  }
  VkSemaphore semaphore(const void* next) {
    auto info = make<VkSemaphoreCreateInfo>(VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, next);
    VkSemaphore s = VK_NULL_HANDLE;
    check(vkCreateSemaphore(device_, &info, nullptr, &s), "vkCreateSemaphore");
    semaphores_.push_back(s);
    return s;
  }
  static void ownership(VkCommandBuffer cb, const std::vector<VkBuffer>& buffers, std::uint32_t from,
                        std::uint32_t to, VkPipelineStageFlags src_stage, VkPipelineStageFlags dst_stage,
                        VkAccessFlags src_access, VkAccessFlags dst_access) {
    std::vector<VkBufferMemoryBarrier> barriers;
    for (VkBuffer b : buffers) {
      auto m = make<VkBufferMemoryBarrier>(VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER);
      m.srcAccessMask = src_access;
      m.dstAccessMask = dst_access;
      m.srcQueueFamilyIndex = from;
      m.dstQueueFamilyIndex = to;
      m.buffer = b;
      m.size = VK_WHOLE_SIZE;
      barriers.push_back(m);
    }
    vkCmdPipelineBarrier(cb, src_stage, dst_stage, 0, 0, nullptr, std::uint32_t(barriers.size()), barriers.data(), 0,
                         nullptr);
  }

  VkInstance instance_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t family_ = 0;
  std::uint32_t timestamp_bits_ = 0;
  bool semaphore_export_ = false;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  PFN_vkGetMemoryFdKHR get_memory_fd_ = nullptr;
  PFN_vkGetSemaphoreFdKHR get_semaphore_fd_ = nullptr;
  std::vector<Buffer> buffers_;
  std::vector<VkSemaphore> semaphores_;
  std::vector<VkFence> fences_;
};

// One vkQueueSubmit of `cb` (may be null): waits for `waits` (at `wait_stage`), signals `signals`,
// then `fence` (may be null). Timeline semaphores among the waits wait for `wait_values`' entry.
inline void submit(VkQueue queue, VkCommandBuffer cb, const std::vector<VkSemaphore>& waits,
                   const std::vector<VkSemaphore>& signals, VkFence fence,
                   VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                   const std::vector<std::uint64_t>& wait_values = {}) {
  const std::vector<VkPipelineStageFlags> stages(waits.size(), wait_stage);
  auto values = make<VkTimelineSemaphoreSubmitInfo>(VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO);
  values.waitSemaphoreValueCount = std::uint32_t(wait_values.size());
  values.pWaitSemaphoreValues = wait_values.data();
  auto info = make<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO, wait_values.empty() ? nullptr : &values);
  info.waitSemaphoreCount = std::uint32_t(waits.size());
  info.pWaitSemaphores = waits.data();
  info.pWaitDstStageMask = stages.data();
  info.commandBufferCount = cb != VK_NULL_HANDLE ? 1 : 0;
  info.pCommandBuffers = &cb;
  info.signalSemaphoreCount = std::uint32_t(signals.size());
  info.pSignalSemaphores = signals.data();
  check(vkQueueSubmit(queue, 1, &info, fence), "vkQueueSubmit");
}

}  // namespace vkp
