#include "fogcl/external_memory.h"

#include <dlfcn.h>

#include <algorithm>
#include <map>
#include <mutex>
#include <sstream>

#include "interop/khr_functions.h"

namespace fogcl {

namespace detail {

const KhrFunctions& khr_functions(cl_device_id device) {
  static std::mutex mutex;
  static std::map<cl_platform_id, KhrFunctions> by_platform;
  const cl_platform_id platform = with_cl_errors([&] { return wrap(device).getInfo<CL_DEVICE_PLATFORM>(); });
  std::lock_guard<std::mutex> lock(mutex);
  auto it = by_platform.find(platform);
  if (it != by_platform.end()) return it->second;
  KhrFunctions f;
  auto get = [&](auto& fn, const char* name) {
    fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(
        clGetExtensionFunctionAddressForPlatform(platform, name));
  };
  get(f.acquire, "clEnqueueAcquireExternalMemObjectsKHR");
  get(f.release, "clEnqueueReleaseExternalMemObjectsKHR");
  get(f.create_semaphore, "clCreateSemaphoreWithPropertiesKHR");
  get(f.wait_semaphores, "clEnqueueWaitSemaphoresKHR");
  get(f.signal_semaphores, "clEnqueueSignalSemaphoresKHR");
  get(f.semaphore_handle, "clGetSemaphoreHandleForTypeKHR");
  get(f.release_semaphore, "clReleaseSemaphoreKHR");
  // The loader fogcl is linked with (also when fogcl itself was opened RTLD_LOCAL), else any.
  void* loader = dlopen("libOpenCL.so.1", RTLD_LAZY | RTLD_NOLOAD);
  f.create_buffer = reinterpret_cast<KhrFunctions::CreateBufferWithProperties>(
      dlsym(loader != nullptr ? loader : RTLD_DEFAULT, "clCreateBufferWithProperties"));
  if (loader != nullptr) dlclose(loader);  // NOLOAD took a reference to a library that stays loaded
  return by_platform.emplace(platform, f).first->second;
}

bool has_extension(cl_device_id device, const std::string& name) {
  const std::string all = with_cl_errors([&] { return wrap(device).getInfo<CL_DEVICE_EXTENSIONS>(); });
  std::istringstream words(all);
  std::string w;
  while (words >> w)
    if (w == name) return true;
  return false;
}

}  // namespace detail

namespace {

constexpr cl_uint kMemoryHandle[] = {CL_EXTERNAL_MEMORY_HANDLE_OPAQUE_FD_KHR, CL_EXTERNAL_MEMORY_HANDLE_DMA_BUF_KHR};
constexpr const char* kMemoryExtension[] = {"cl_khr_external_memory_opaque_fd", "cl_khr_external_memory_dma_buf"};

// A device-info list of handle types; empty when the device does not answer the query (PoCL).
std::vector<cl_uint> handle_list(cl_device_id device, cl_device_info what) {
  std::size_t bytes = 0;
  if (clGetDeviceInfo(device, what, 0, nullptr, &bytes) != CL_SUCCESS || bytes == 0) return {};
  std::vector<cl_uint> v(bytes / sizeof(cl_uint));
  if (clGetDeviceInfo(device, what, bytes, v.data(), nullptr) != CL_SUCCESS) return {};
  return v;
}

bool contains(const std::vector<ExternalHandle>& v, ExternalHandle h) {
  return std::find(v.begin(), v.end(), h) != v.end();
}

std::string list_text(const std::vector<ExternalHandle>& v) {
  if (v.empty()) return "none";
  std::string s;
  for (ExternalHandle h : v) s += (s.empty() ? "" : ", ") + std::string(to_string(h));
  return s;
}

std::string device_label(cl_device_id device) { return "device '" + device_name(device) + "'"; }

}  // namespace

const char* to_string(ExternalHandle handle) {
  switch (handle) {
    case ExternalHandle::opaque_fd: return "opaque_fd";
    case ExternalHandle::dma_buf: return "dma_buf";
  }
  return "?";
}

bool ExternalSupport::imports_memory(ExternalHandle h) const { return memory_extension && contains(memory_imports, h); }
bool ExternalSupport::imports_semaphore(ExternalHandle h) const {
  return semaphore_extension && contains(semaphore_imports, h);
}
bool ExternalSupport::exports_semaphore(ExternalHandle h) const {
  return semaphore_extension && contains(semaphore_exports, h);
}

std::string ExternalSupport::describe() const {
  std::string s = memory_extension ? "memory import: " + list_text(memory_imports) : "no cl_khr_external_memory";
  s += semaphore_extension
           ? "; semaphores: import " + list_text(semaphore_imports) + ", export " + list_text(semaphore_exports)
           : "; no cl_khr_external_semaphore";
  return s;
}

ExternalSupport external_support(cl_device_id device) {
  if (device == nullptr) throw Error("external_support: the device is null");
  ExternalSupport s;
  s.memory_extension = detail::has_extension(device, "cl_khr_external_memory");
  s.semaphore_extension = detail::has_extension(device, "cl_khr_external_semaphore") &&
                          detail::has_extension(device, "cl_khr_semaphore");
  if (s.memory_extension)
    for (cl_uint t : handle_list(device, CL_DEVICE_EXTERNAL_MEMORY_IMPORT_HANDLE_TYPES_KHR)) {
      if (t == CL_EXTERNAL_MEMORY_HANDLE_OPAQUE_FD_KHR) s.memory_imports.push_back(ExternalHandle::opaque_fd);
      if (t == CL_EXTERNAL_MEMORY_HANDLE_DMA_BUF_KHR) s.memory_imports.push_back(ExternalHandle::dma_buf);
    }
  if (s.semaphore_extension) {
    for (cl_uint t : handle_list(device, CL_DEVICE_SEMAPHORE_IMPORT_HANDLE_TYPES_KHR))
      if (t == CL_SEMAPHORE_HANDLE_OPAQUE_FD_KHR) s.semaphore_imports.push_back(ExternalHandle::opaque_fd);
    for (cl_uint t : handle_list(device, CL_DEVICE_SEMAPHORE_EXPORT_HANDLE_TYPES_KHR))
      if (t == CL_SEMAPHORE_HANDLE_OPAQUE_FD_KHR) s.semaphore_exports.push_back(ExternalHandle::opaque_fd);
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
struct ExternalMemory::Impl {
  cl::Buffer buffer;
  std::size_t size = 0;
};

ExternalMemory::ExternalMemory(cl_context context, cl_device_id device, int fd, std::size_t size,
                               ExternalHandle handle)
    : impl_(std::make_unique<Impl>()) {
  if (context == nullptr || device == nullptr)
    throw Error("ExternalMemory needs a context and a device (got a null handle)");
  const ExternalSupport support = external_support(device);
  const int kind = handle == ExternalHandle::opaque_fd ? 0 : 1;
  if (!support.memory_extension)
    throw Error(device_label(device) + " does not offer cl_khr_external_memory (OpenCL external memory): it cannot " +
                "import a renderer's " + to_string(handle) + " memory; use a device that lists " +
                kMemoryExtension[kind] + ", or hand fogcl host images or its own buffers");
  if (!support.imports_memory(handle))
    throw Error(device_label(device) + " offers cl_khr_external_memory but not " + kMemoryExtension[kind] +
                " (CL_DEVICE_EXTERNAL_MEMORY_IMPORT_HANDLE_TYPES_KHR: " + list_text(support.memory_imports) + ")");
  if (fd < 0) throw Error("ExternalMemory: the file descriptor is negative (" + std::to_string(fd) + ")");
  if (size == 0) throw Error("ExternalMemory: the size is 0 bytes (must be the exported allocation's, or less)");
  const detail::KhrFunctions& f = detail::khr_functions(device);
  if (f.create_buffer == nullptr)
    throw Error("ExternalMemory: the OpenCL loader lacks clCreateBufferWithProperties (OpenCL 3.0), which "
                "cl_khr_external_memory needs: use an ICD loader of OpenCL 3.0");
  // cl_mem_properties (OpenCL 3.0) is cl_properties.
  const cl_properties props[] = {kMemoryHandle[kind], cl_properties(fd), CL_DEVICE_HANDLE_LIST_KHR,
                                 cl_properties(device), CL_DEVICE_HANDLE_LIST_END_KHR, 0};
  cl_int err = CL_SUCCESS;
  cl_mem mem = f.create_buffer(context, props, CL_MEM_READ_WRITE, size, nullptr, &err);
  if (mem == nullptr || err != CL_SUCCESS)
    throw ClError("clCreateBufferWithProperties (" + std::string(to_string(handle)) + " fd " + std::to_string(fd) +
                      ", " + std::to_string(size) + " bytes; is the size within the exported allocation?)",
                  err == CL_SUCCESS ? CL_INVALID_MEM_OBJECT : err);
  impl_->buffer = cl::Buffer(mem, false);
  impl_->size = size;
}

ExternalMemory::~ExternalMemory() = default;
ExternalMemory::ExternalMemory(ExternalMemory&&) noexcept = default;
ExternalMemory& ExternalMemory::operator=(ExternalMemory&&) noexcept = default;
cl_mem ExternalMemory::buffer() const { return impl_->buffer(); }
std::size_t ExternalMemory::size() const { return impl_->size; }

// ---------------------------------------------------------------------------------------------
struct ExternalSemaphore::Impl {
  cl_semaphore_khr handle = nullptr;
  clReleaseSemaphoreKHR_fn release = nullptr;
  clGetSemaphoreHandleForTypeKHR_fn export_handle = nullptr;
  cl_device_id device = nullptr;
  bool exportable = false;
  ~Impl() {
    if (handle != nullptr && release != nullptr) release(handle);
  }
};

namespace {
// The semaphore functions of `device`, or a fogcl::Error naming what is missing.
const detail::KhrFunctions& semaphore_functions(cl_device_id device, const ExternalSupport& support, bool for_export) {
  if (!support.semaphore_extension)
    throw Error(device_label(device) + " does not offer cl_khr_external_semaphore (OpenCL external semaphores): " +
                "it cannot share semaphores with a renderer; synchronise with events and host waits instead " +
                "(docs/library.md, \"From a GPU renderer\")");
  if (for_export ? !support.exports_semaphore(ExternalHandle::opaque_fd)
                 : !support.imports_semaphore(ExternalHandle::opaque_fd))
    throw Error(device_label(device) + " offers cl_khr_external_semaphore but " +
                (for_export ? "exports no opaque-fd semaphores (CL_DEVICE_SEMAPHORE_EXPORT_HANDLE_TYPES_KHR: " +
                                  list_text(support.semaphore_exports) +
                                  "): import the renderer's semaphores with ExternalSemaphore::import_fd"
                            : "imports no opaque-fd semaphores (cl_khr_external_semaphore_opaque_fd; "
                              "CL_DEVICE_SEMAPHORE_IMPORT_HANDLE_TYPES_KHR: " +
                                  list_text(support.semaphore_imports) + ")"));
  const detail::KhrFunctions& f = detail::khr_functions(device);
  if (f.create_semaphore == nullptr || f.release_semaphore == nullptr || f.wait_semaphores == nullptr ||
      f.signal_semaphores == nullptr || (for_export && f.semaphore_handle == nullptr))
    throw Error(device_label(device) + " lists cl_khr_external_semaphore but its platform returns no "
                "clCreateSemaphoreWithPropertiesKHR/clEnqueueWaitSemaphoresKHR/clEnqueueSignalSemaphoresKHR "
                "from clGetExtensionFunctionAddressForPlatform");
  return f;
}
}  // namespace

ExternalSemaphore ExternalSemaphore::import_fd(cl_context context, cl_device_id device, int fd) {
  if (context == nullptr || device == nullptr)
    throw Error("ExternalSemaphore::import_fd needs a context and a device (got a null handle)");
  const detail::KhrFunctions& f = semaphore_functions(device, external_support(device), false);
  if (fd < 0) throw Error("ExternalSemaphore::import_fd: the file descriptor is negative (" + std::to_string(fd) + ")");
  const cl_semaphore_properties_khr props[] = {CL_SEMAPHORE_TYPE_KHR, CL_SEMAPHORE_TYPE_BINARY_KHR,
                                               CL_SEMAPHORE_HANDLE_OPAQUE_FD_KHR, cl_semaphore_properties_khr(fd), 0};
  cl_int err = CL_SUCCESS;
  cl_semaphore_khr s = f.create_semaphore(context, props, &err);
  if (s == nullptr || err != CL_SUCCESS)
    throw ClError("clCreateSemaphoreWithPropertiesKHR (import of opaque fd " + std::to_string(fd) + ")",
                  err == CL_SUCCESS ? CL_INVALID_SEMAPHORE_KHR : err);
  ExternalSemaphore out;
  out.impl_ = std::make_unique<Impl>();
  out.impl_->handle = s;
  out.impl_->release = f.release_semaphore;
  out.impl_->device = device;
  return out;
}

ExternalSemaphore ExternalSemaphore::exportable(cl_context context, cl_device_id device) {
  if (context == nullptr || device == nullptr)
    throw Error("ExternalSemaphore::exportable needs a context and a device (got a null handle)");
  const detail::KhrFunctions& f = semaphore_functions(device, external_support(device), true);
  const cl_semaphore_properties_khr props[] = {CL_SEMAPHORE_TYPE_KHR,
                                               CL_SEMAPHORE_TYPE_BINARY_KHR,
                                               CL_SEMAPHORE_EXPORT_HANDLE_TYPES_KHR,
                                               CL_SEMAPHORE_HANDLE_OPAQUE_FD_KHR,
                                               CL_SEMAPHORE_EXPORT_HANDLE_TYPES_LIST_END_KHR,
                                               0};
  cl_int err = CL_SUCCESS;
  cl_semaphore_khr s = f.create_semaphore(context, props, &err);
  if (s == nullptr || err != CL_SUCCESS)
    throw ClError("clCreateSemaphoreWithPropertiesKHR (exportable as opaque fd)",
                  err == CL_SUCCESS ? CL_INVALID_SEMAPHORE_KHR : err);
  ExternalSemaphore out;
  out.impl_ = std::make_unique<Impl>();
  out.impl_->handle = s;
  out.impl_->release = f.release_semaphore;
  out.impl_->export_handle = f.semaphore_handle;
  out.impl_->device = device;
  out.impl_->exportable = true;
  return out;
}

ExternalSemaphore::ExternalSemaphore() = default;
ExternalSemaphore::~ExternalSemaphore() = default;
ExternalSemaphore::ExternalSemaphore(ExternalSemaphore&&) noexcept = default;
ExternalSemaphore& ExternalSemaphore::operator=(ExternalSemaphore&&) noexcept = default;

int ExternalSemaphore::export_fd() const {
  if (impl_ == nullptr) throw Error("ExternalSemaphore::export_fd: the semaphore is empty (moved from)");
  if (!impl_->exportable)
    throw Error("ExternalSemaphore::export_fd: an imported semaphore cannot be exported again (cl_khr_external_"
                "semaphore); export from the renderer's own semaphore");
  int fd = -1;
  const cl_int err = impl_->export_handle(impl_->handle, impl_->device, CL_SEMAPHORE_HANDLE_OPAQUE_FD_KHR, sizeof fd,
                                          &fd, nullptr);
  if (err != CL_SUCCESS) throw ClError("clGetSemaphoreHandleForTypeKHR (opaque fd)", err);
  return fd;
}

cl_semaphore_khr ExternalSemaphore::handle() const { return impl_ != nullptr ? impl_->handle : nullptr; }

}  // namespace fogcl
