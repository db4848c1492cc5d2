// Binary semaphores exportable as opaque file descriptors, made by Vulkan (libvulkan.so.1 loaded at
// run time): what a Vulkan renderer hands fogcl and its other consumers. CUDA can only import such
// a semaphore, and an OpenCL device may offer no semaphore export (NVIDIA's driver 580 offers
// none): a process whose producer is CUDA takes them from Vulkan. The few Vulkan declarations are
// written here, values as vulkan_core.h (1.1) defines them: no Vulkan headers are needed to build.
#pragma once

#include <dlfcn.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace vk {

using VkResult = int;
using VkInstance = struct VkInstance_T*;
using VkPhysicalDevice = struct VkPhysicalDevice_T*;
using VkDevice = struct VkDevice_T*;
using VkSemaphore = std::uint64_t;
using PFN_vkVoidFunction = void (*)();

struct ApplicationInfo {
  int sType = 0;  // VK_STRUCTURE_TYPE_APPLICATION_INFO
  const void* pNext = nullptr;
  const char* pApplicationName = nullptr;
  std::uint32_t applicationVersion = 0;
  const char* pEngineName = nullptr;
  std::uint32_t engineVersion = 0;
  std::uint32_t apiVersion = (1u << 22) | (1u << 12);  // VK_API_VERSION_1_1
};
struct InstanceCreateInfo {
  int sType = 1;
  const void* pNext = nullptr;
  std::uint32_t flags = 0;
  const ApplicationInfo* pApplicationInfo = nullptr;
  std::uint32_t enabledLayerCount = 0;
  const char* const* ppEnabledLayerNames = nullptr;
  std::uint32_t enabledExtensionCount = 0;
  const char* const* ppEnabledExtensionNames = nullptr;
};
struct DeviceQueueCreateInfo {
  int sType = 2;
  const void* pNext = nullptr;
  std::uint32_t flags = 0;
  std::uint32_t queueFamilyIndex = 0;
  std::uint32_t queueCount = 1;
  const float* pQueuePriorities = nullptr;
};
struct DeviceCreateInfo {
  int sType = 3;
  const void* pNext = nullptr;
  std::uint32_t flags = 0;
  std::uint32_t queueCreateInfoCount = 1;
  const DeviceQueueCreateInfo* pQueueCreateInfos = nullptr;
  std::uint32_t enabledLayerCount = 0;
  const char* const* ppEnabledLayerNames = nullptr;
  std::uint32_t enabledExtensionCount = 0;
  const char* const* ppEnabledExtensionNames = nullptr;
  const void* pEnabledFeatures = nullptr;
};
struct ExportSemaphoreCreateInfo {
  int sType = 1000077000;
  const void* pNext = nullptr;
  std::uint32_t handleTypes = 1;  // VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT
};
struct SemaphoreCreateInfo {
  int sType = 9;
  const void* pNext = nullptr;
  std::uint32_t flags = 0;
};
struct SemaphoreGetFdInfoKHR {
  int sType = 1000079001;
  const void* pNext = nullptr;
  VkSemaphore semaphore = 0;
  std::uint32_t handleType = 1;  // opaque fd
};
struct PhysicalDeviceIDProperties {
  int sType = 1000071004;
  void* pNext = nullptr;
  std::uint8_t deviceUUID[16] = {};
  std::uint8_t driverUUID[16] = {};
  std::uint8_t deviceLUID[8] = {};
  std::uint32_t deviceNodeMask = 0;
  std::uint32_t deviceLUIDValid = 0;
};
struct PhysicalDeviceProperties2 {
  int sType = 1000059001;
  void* pNext = nullptr;
  alignas(8) unsigned char properties[2048] = {};  // VkPhysicalDeviceProperties (824 bytes) and room
};

// One Vulkan device on the GPU whose UUID is given (the CUDA and OpenCL device's), and the
// semaphores made on it. Everything is released by the destructor.
class ExportableSemaphores {
 public:
  ExportableSemaphores() = default;
  ExportableSemaphores(const ExportableSemaphores&) = delete;
  ExportableSemaphores& operator=(const ExportableSemaphores&) = delete;
  ~ExportableSemaphores() {
    for (VkSemaphore s : semaphores_) destroy_semaphore_(device_, s, nullptr);
    if (device_ != nullptr) destroy_device_(device_, nullptr);
    if (instance_ != nullptr) destroy_instance_(instance_, nullptr);
    if (library_ != nullptr) dlclose(library_);
  }

  // false with `why` set when there is no Vulkan loader, driver, or device of that UUID.
  bool open(const unsigned char uuid[16], std::string& why) {
    library_ = dlopen("libvulkan.so.1", RTLD_NOW | RTLD_LOCAL);
    if (library_ == nullptr) return fail(why, "libvulkan.so.1 not loadable (no Vulkan loader)");
    auto get_instance_proc = reinterpret_cast<PFN_vkVoidFunction (*)(VkInstance, const char*)>(
        dlsym(library_, "vkGetInstanceProcAddr"));
    if (get_instance_proc == nullptr) return fail(why, "libvulkan.so.1 lacks vkGetInstanceProcAddr");
    auto create_instance = reinterpret_cast<VkResult (*)(const InstanceCreateInfo*, const void*, VkInstance*)>(
        get_instance_proc(nullptr, "vkCreateInstance"));
    ApplicationInfo app;
    app.pApplicationName = "fogcl semaphores";
    InstanceCreateInfo ici;
    ici.pApplicationInfo = &app;
    if (create_instance == nullptr) return fail(why, "no vkCreateInstance");
    if (VkResult r = create_instance(&ici, nullptr, &instance_); r != 0)
      return fail(why, "vkCreateInstance failed (" + std::to_string(r) + "): no Vulkan driver");
    auto proc = [&](const char* name) { return get_instance_proc(instance_, name); };
    destroy_instance_ = reinterpret_cast<void (*)(VkInstance, const void*)>(proc("vkDestroyInstance"));
    auto enumerate = reinterpret_cast<VkResult (*)(VkInstance, std::uint32_t*, VkPhysicalDevice*)>(
        proc("vkEnumeratePhysicalDevices"));
    auto properties2 = reinterpret_cast<void (*)(VkPhysicalDevice, PhysicalDeviceProperties2*)>(
        proc("vkGetPhysicalDeviceProperties2"));
    auto create_device = reinterpret_cast<VkResult (*)(VkPhysicalDevice, const DeviceCreateInfo*, const void*,
                                                        VkDevice*)>(proc("vkCreateDevice"));
    auto get_device_proc = reinterpret_cast<PFN_vkVoidFunction (*)(VkDevice, const char*)>(
        proc("vkGetDeviceProcAddr"));
    if (!destroy_instance_ || !enumerate || !properties2 || !create_device || !get_device_proc)
      return fail(why, "the Vulkan 1.1 instance functions are missing");
    std::uint32_t count = 0;
    enumerate(instance_, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    enumerate(instance_, &count, devices.data());
    VkPhysicalDevice chosen = nullptr;
    for (VkPhysicalDevice d : devices) {
      PhysicalDeviceIDProperties id;
      PhysicalDeviceProperties2 p;
      p.pNext = &id;
      properties2(d, &p);
      if (std::memcmp(id.deviceUUID, uuid, 16) == 0) chosen = d;
    }
    if (chosen == nullptr)
      return fail(why, "no Vulkan device has the GPU's UUID (" + std::to_string(count) + " Vulkan devices)");
    const float priority = 1.0f;
    DeviceQueueCreateInfo qci;
    qci.pQueuePriorities = &priority;
    const char* extensions[] = {"VK_KHR_external_semaphore_fd"};
    DeviceCreateInfo dci;
    dci.pQueueCreateInfos = &qci;
    dci.enabledExtensionCount = 1;
    dci.ppEnabledExtensionNames = extensions;
    if (VkResult r = create_device(chosen, &dci, nullptr, &device_); r != 0)
      return fail(why, "vkCreateDevice with VK_KHR_external_semaphore_fd failed (" + std::to_string(r) + ")");
    auto dproc = [&](const char* name) { return get_device_proc(device_, name); };
    destroy_device_ = reinterpret_cast<void (*)(VkDevice, const void*)>(dproc("vkDestroyDevice"));
    create_semaphore_ = reinterpret_cast<VkResult (*)(VkDevice, const SemaphoreCreateInfo*, const void*,
                                                       VkSemaphore*)>(dproc("vkCreateSemaphore"));
    destroy_semaphore_ = reinterpret_cast<void (*)(VkDevice, VkSemaphore, const void*)>(dproc("vkDestroySemaphore"));
    get_fd_ = reinterpret_cast<VkResult (*)(VkDevice, const SemaphoreGetFdInfoKHR*, int*)>(
        dproc("vkGetSemaphoreFdKHR"));
    if (!destroy_device_ || !create_semaphore_ || !destroy_semaphore_ || !get_fd_)
      return fail(why, "the Vulkan device functions are missing");
    return true;
  }

  // A new binary semaphore; returns its index, or -1.
  int create() {
    ExportSemaphoreCreateInfo export_info;
    SemaphoreCreateInfo info;
    info.pNext = &export_info;
    VkSemaphore s = 0;
    if (create_semaphore_(device_, &info, nullptr, &s) != 0) return -1;
    semaphores_.push_back(s);
    return int(semaphores_.size()) - 1;
  }
  // A new file descriptor of semaphore `index`'s payload, owned by the caller (-1 on failure).
  int export_fd(int index) {
    SemaphoreGetFdInfoKHR info;
    info.semaphore = semaphores_.at(std::size_t(index));
    int fd = -1;
    return get_fd_(device_, &info, &fd) == 0 ? fd : -1;
  }

 private:
  static bool fail(std::string& why, const std::string& text) {
    why = text;
    return false;
  }
  void* library_ = nullptr;
  VkInstance instance_ = nullptr;
  VkDevice device_ = nullptr;
  std::vector<VkSemaphore> semaphores_;
  void (*destroy_instance_)(VkInstance, const void*) = nullptr;
  void (*destroy_device_)(VkDevice, const void*) = nullptr;
  VkResult (*create_semaphore_)(VkDevice, const SemaphoreCreateInfo*, const void*, VkSemaphore*) = nullptr;
  void (*destroy_semaphore_)(VkDevice, VkSemaphore, const void*) = nullptr;
  VkResult (*get_fd_)(VkDevice, const SemaphoreGetFdInfoKHR*, int*) = nullptr;
};

}  // namespace vk
