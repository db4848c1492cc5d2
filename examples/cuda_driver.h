// The few CUDA driver-API declarations a CUDA producer of fogcl's frames needs, loaded at run time
// from libcuda.so.1 (dlopen): builds with no CUDA toolkit, links without libcuda, and says why
// when the driver is missing. Types and values as CUDA 12's cuda.h defines them (driver ABI);
// functions by their exported names (the _v2 ones where cuda.h maps the plain name to one).
#pragma once

#include <dlfcn.h>

#include <cstddef>
#include <cstring>
#include <string>
#include <type_traits>

namespace cuda {

using CUresult = int;
using CUdevice = int;
using CUdeviceptr = unsigned long long;
using CUmemGenericAllocationHandle = unsigned long long;
using CUcontext = struct CUctx_st*;
using CUstream = struct CUstream_st*;
using CUevent = struct CUevent_st*;
using CUexternalSemaphore = struct CUextSemaphore_st*;
using CUhostFn = void (*)(void* user_data);

constexpr CUresult CUDA_SUCCESS = 0;
constexpr int CU_MEM_ALLOCATION_TYPE_PINNED = 1;
constexpr int CU_MEM_HANDLE_TYPE_POSIX_FILE_DESCRIPTOR = 1;
constexpr int CU_MEM_LOCATION_TYPE_DEVICE = 1;
constexpr int CU_MEM_ACCESS_FLAGS_PROT_READWRITE = 3;
constexpr int CU_MEM_ALLOC_GRANULARITY_MINIMUM = 0;
constexpr int CU_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD = 1;
constexpr unsigned CU_STREAM_NON_BLOCKING = 1;

struct CUmemLocation {
  int type;
  int id;
};
struct CUmemAllocationProp {
  int type;
  int requestedHandleTypes;
  CUmemLocation location;
  void* win32HandleMetaData;
  struct {
    unsigned char compressionType;
    unsigned char gpuDirectRDMACapable;
    unsigned short usage;
    unsigned char reserved[4];
  } allocFlags;
};
struct CUmemAccessDesc {
  CUmemLocation location;
  int flags;
};
struct CUDA_EXTERNAL_SEMAPHORE_HANDLE_DESC {
  int type;
  union {
    int fd;
    struct {
      void* handle;
      const void* name;
    } win32;
    const void* nvSciSyncObj;
  } handle;
  unsigned int flags;
  unsigned int reserved[16];
};
struct CUDA_EXTERNAL_SEMAPHORE_SIGNAL_PARAMS {
  struct {
    struct {
      unsigned long long value;
    } fence;
    union {
      void* fence;
      unsigned long long reserved;
    } nvSciSync;
    struct {
      unsigned long long key;
    } keyedMutex;
    unsigned int reserved[12];
  } params;
  unsigned int flags;
  unsigned int reserved[16];
};
struct CUDA_EXTERNAL_SEMAPHORE_WAIT_PARAMS {
  struct {
    struct {
      unsigned long long value;
    } fence;
    union {
      void* fence;
      unsigned long long reserved;
    } nvSciSync;
    struct {
      unsigned long long key;
      unsigned int timeoutMs;
    } keyedMutex;
    unsigned int reserved[10];
  } params;
  unsigned int flags;
  unsigned int reserved[16];
};

// The driver's entry points, resolved once by load().
struct Driver {
  void* library = nullptr;
  CUresult (*cuInit)(unsigned) = nullptr;
  CUresult (*cuGetErrorName)(CUresult, const char**) = nullptr;
  CUresult (*cuDeviceGet)(CUdevice*, int) = nullptr;
  CUresult (*cuDeviceGetCount)(int*) = nullptr;
  CUresult (*cuDeviceGetUuid)(char uuid[16], CUdevice) = nullptr;
  CUresult (*cuDevicePrimaryCtxRetain)(CUcontext*, CUdevice) = nullptr;
  CUresult (*cuDevicePrimaryCtxRelease)(CUdevice) = nullptr;
  CUresult (*cuCtxSetCurrent)(CUcontext) = nullptr;
  CUresult (*cuMemGetAllocationGranularity)(std::size_t*, const CUmemAllocationProp*, int) = nullptr;
  CUresult (*cuMemCreate)(CUmemGenericAllocationHandle*, std::size_t, const CUmemAllocationProp*,
                          unsigned long long) = nullptr;
  CUresult (*cuMemRelease)(CUmemGenericAllocationHandle) = nullptr;
  CUresult (*cuMemExportToShareableHandle)(void*, CUmemGenericAllocationHandle, int, unsigned long long) = nullptr;
  CUresult (*cuMemAddressReserve)(CUdeviceptr*, std::size_t, std::size_t, CUdeviceptr, unsigned long long) = nullptr;
  CUresult (*cuMemAddressFree)(CUdeviceptr, std::size_t) = nullptr;
  CUresult (*cuMemMap)(CUdeviceptr, std::size_t, std::size_t, CUmemGenericAllocationHandle, unsigned long long) = nullptr;
  CUresult (*cuMemUnmap)(CUdeviceptr, std::size_t) = nullptr;
  CUresult (*cuMemSetAccess)(CUdeviceptr, std::size_t, const CUmemAccessDesc*, std::size_t) = nullptr;
  CUresult (*cuMemAlloc)(CUdeviceptr*, std::size_t) = nullptr;
  CUresult (*cuMemFree)(CUdeviceptr) = nullptr;
  CUresult (*cuMemsetD8)(CUdeviceptr, unsigned char, std::size_t) = nullptr;
  CUresult (*cuMemcpyHtoD)(CUdeviceptr, const void*, std::size_t) = nullptr;
  CUresult (*cuMemcpyDtoH)(void*, CUdeviceptr, std::size_t) = nullptr;
  CUresult (*cuMemcpyDtoDAsync)(CUdeviceptr, CUdeviceptr, std::size_t, CUstream) = nullptr;
  CUresult (*cuStreamCreate)(CUstream*, unsigned) = nullptr;
  CUresult (*cuStreamDestroy)(CUstream) = nullptr;
  CUresult (*cuStreamSynchronize)(CUstream) = nullptr;
  CUresult (*cuStreamQuery)(CUstream) = nullptr;  // CUDA_SUCCESS when done, else not ready (600)
  CUresult (*cuEventCreate)(CUevent*, unsigned) = nullptr;
  CUresult (*cuEventDestroy)(CUevent) = nullptr;
  CUresult (*cuEventRecord)(CUevent, CUstream) = nullptr;
  CUresult (*cuEventSynchronize)(CUevent) = nullptr;
  CUresult (*cuEventElapsedTime)(float*, CUevent, CUevent) = nullptr;
  CUresult (*cuLaunchHostFunc)(CUstream, CUhostFn, void*) = nullptr;
  CUresult (*cuStreamWaitValue32)(CUstream, CUdeviceptr, unsigned, unsigned) = nullptr;  // flags 0: >=
  CUresult (*cuImportExternalSemaphore)(CUexternalSemaphore*, const CUDA_EXTERNAL_SEMAPHORE_HANDLE_DESC*) = nullptr;
  CUresult (*cuDestroyExternalSemaphore)(CUexternalSemaphore) = nullptr;
  CUresult (*cuSignalExternalSemaphoresAsync)(const CUexternalSemaphore*, const CUDA_EXTERNAL_SEMAPHORE_SIGNAL_PARAMS*,
                                              unsigned, CUstream) = nullptr;
  CUresult (*cuWaitExternalSemaphoresAsync)(const CUexternalSemaphore*, const CUDA_EXTERNAL_SEMAPHORE_WAIT_PARAMS*,
                                            unsigned, CUstream) = nullptr;

  // Opens libcuda.so.1 and resolves every entry point; false with `why` set when the library or
  // one of them is missing (no NVIDIA driver here, or one older than CUDA 11.2's).
  bool load(std::string& why) {
    library = dlopen("libcuda.so.1", RTLD_NOW | RTLD_LOCAL);
    if (library == nullptr) {
      const char* e = dlerror();
      why = std::string("libcuda.so.1 not loadable (no NVIDIA driver): ") + (e != nullptr ? e : "?");
      return false;
    }
    bool ok = true;
    auto get = [&](auto& fn, const char* name) {
      fn = reinterpret_cast<std::remove_reference_t<decltype(fn)>>(dlsym(library, name));
      if (fn == nullptr && ok) {
        why = std::string("libcuda.so.1 lacks ") + name;
        ok = false;
      }
    };
    get(cuInit, "cuInit");
    get(cuGetErrorName, "cuGetErrorName");
    get(cuDeviceGet, "cuDeviceGet");
    get(cuDeviceGetCount, "cuDeviceGetCount");
    get(cuDeviceGetUuid, "cuDeviceGetUuid");
    get(cuDevicePrimaryCtxRetain, "cuDevicePrimaryCtxRetain");
    get(cuDevicePrimaryCtxRelease, "cuDevicePrimaryCtxRelease_v2");
    get(cuCtxSetCurrent, "cuCtxSetCurrent");
    get(cuMemGetAllocationGranularity, "cuMemGetAllocationGranularity");
    get(cuMemCreate, "cuMemCreate");
    get(cuMemRelease, "cuMemRelease");
    get(cuMemExportToShareableHandle, "cuMemExportToShareableHandle");
    get(cuMemAddressReserve, "cuMemAddressReserve");
    get(cuMemAddressFree, "cuMemAddressFree");
    get(cuMemMap, "cuMemMap");
    get(cuMemUnmap, "cuMemUnmap");
    get(cuMemSetAccess, "cuMemSetAccess");
    get(cuMemAlloc, "cuMemAlloc_v2");
    get(cuMemFree, "cuMemFree_v2");
    get(cuMemsetD8, "cuMemsetD8_v2");
    get(cuMemcpyHtoD, "cuMemcpyHtoD_v2");
    get(cuMemcpyDtoH, "cuMemcpyDtoH_v2");
    get(cuMemcpyDtoDAsync, "cuMemcpyDtoDAsync_v2");
    get(cuStreamCreate, "cuStreamCreate");
    get(cuStreamDestroy, "cuStreamDestroy_v2");
    get(cuStreamSynchronize, "cuStreamSynchronize");
    get(cuStreamQuery, "cuStreamQuery");
    get(cuEventCreate, "cuEventCreate");
    get(cuEventDestroy, "cuEventDestroy_v2");
    get(cuEventRecord, "cuEventRecord");
    get(cuEventSynchronize, "cuEventSynchronize");
    get(cuEventElapsedTime, "cuEventElapsedTime");
    get(cuLaunchHostFunc, "cuLaunchHostFunc");
    get(cuStreamWaitValue32, "cuStreamWaitValue32_v2");
    get(cuImportExternalSemaphore, "cuImportExternalSemaphore");
    get(cuDestroyExternalSemaphore, "cuDestroyExternalSemaphore");
    get(cuSignalExternalSemaphoresAsync, "cuSignalExternalSemaphoresAsync");
    get(cuWaitExternalSemaphoresAsync, "cuWaitExternalSemaphoresAsync");
    return ok;
  }

  // "cuMemCreate: CUDA_ERROR_INVALID_VALUE (1)", or an empty string for success.
  std::string error(CUresult r, const char* call) const {
    if (r == CUDA_SUCCESS) return {};
    const char* name = nullptr;
    if (cuGetErrorName == nullptr || cuGetErrorName(r, &name) != CUDA_SUCCESS || name == nullptr) name = "?";
    return std::string(call) + ": " + name + " (" + std::to_string(r) + ")";
  }

  // Makes current the primary context of the CUDA device whose UUID is `uuid` (the OpenCL
  // device's CL_DEVICE_UUID_KHR): "" on success, else why not.
  std::string open_device(const unsigned char uuid[16], CUdevice& device, CUcontext& context) const {
    if (CUresult r = cuInit(0); r != CUDA_SUCCESS) return error(r, "cuInit");
    int count = 0;
    if (CUresult r = cuDeviceGetCount(&count); r != CUDA_SUCCESS) return error(r, "cuDeviceGetCount");
    for (int i = 0; i < count; ++i) {
      char id[16] = {};
      if (cuDeviceGet(&device, i) != CUDA_SUCCESS || cuDeviceGetUuid(id, device) != CUDA_SUCCESS) continue;
      if (std::memcmp(id, uuid, 16) != 0) continue;
      if (CUresult r = cuDevicePrimaryCtxRetain(&context, device); r != CUDA_SUCCESS)
        return error(r, "cuDevicePrimaryCtxRetain");
      if (CUresult r = cuCtxSetCurrent(context); r != CUDA_SUCCESS) return error(r, "cuCtxSetCurrent");
      return {};
    }
    return "no CUDA device has the OpenCL device's UUID (" + std::to_string(count) + " CUDA devices)";
  }
};

// Device memory made to be exported (cuMemCreate with a POSIX fd handle type) and mapped into the
// current context's address space at `ptr`: what a renderer's frame would be. Released by the
// destructor (the imports elsewhere keep the memory alive until they are released too).
struct ExportableAllocation {
  const Driver* cu = nullptr;
  CUmemGenericAllocationHandle handle = 0;
  CUdeviceptr ptr = 0;
  std::size_t size = 0;

  ExportableAllocation() = default;
  ExportableAllocation(const ExportableAllocation&) = delete;
  ExportableAllocation& operator=(const ExportableAllocation&) = delete;
  ~ExportableAllocation() {
    if (cu == nullptr) return;
    if (ptr != 0) {
      cu->cuMemUnmap(ptr, size);
      cu->cuMemAddressFree(ptr, size);
    }
    if (handle != 0) cu->cuMemRelease(handle);
  }

  // At least `bytes` (rounded up to the allocation granularity) on `device`: "" or the error.
  std::string create(const Driver& driver, CUdevice device, std::size_t bytes) {
    cu = &driver;
    CUmemAllocationProp prop{};
    prop.type = CU_MEM_ALLOCATION_TYPE_PINNED;
    prop.requestedHandleTypes = CU_MEM_HANDLE_TYPE_POSIX_FILE_DESCRIPTOR;
    prop.location = {CU_MEM_LOCATION_TYPE_DEVICE, device};
    std::size_t granularity = 0;
    if (CUresult r = cu->cuMemGetAllocationGranularity(&granularity, &prop, CU_MEM_ALLOC_GRANULARITY_MINIMUM); r)
      return cu->error(r, "cuMemGetAllocationGranularity");
    const std::size_t rounded = (bytes + granularity - 1) / granularity * granularity;
    if (CUresult r = cu->cuMemCreate(&handle, rounded, &prop, 0); r) return cu->error(r, "cuMemCreate");
    if (CUresult r = cu->cuMemAddressReserve(&ptr, rounded, 0, 0, 0); r) return cu->error(r, "cuMemAddressReserve");
    size = rounded;
    if (CUresult r = cu->cuMemMap(ptr, rounded, 0, handle, 0); r) {
      cu->cuMemAddressFree(ptr, rounded);
      ptr = 0;
      return cu->error(r, "cuMemMap");
    }
    const CUmemAccessDesc access{{CU_MEM_LOCATION_TYPE_DEVICE, device}, CU_MEM_ACCESS_FLAGS_PROT_READWRITE};
    if (CUresult r = cu->cuMemSetAccess(ptr, rounded, &access, 1); r) return cu->error(r, "cuMemSetAccess");
    return {};
  }
  // A new fd of the allocation, owned by the caller (an OpenCL import takes it over), or -1.
  int export_fd() const {
    int fd = -1;
    return cu->cuMemExportToShareableHandle(&fd, handle, CU_MEM_HANDLE_TYPE_POSIX_FILE_DESCRIPTOR, 0) == CUDA_SUCCESS
               ? fd
               : -1;
  }
};

}  // namespace cuda
