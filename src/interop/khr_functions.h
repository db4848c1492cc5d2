// The external memory and semaphore entry points of a device's platform: extension functions come
// from clGetExtensionFunctionAddressForPlatform (the ICD loader does not export them), and
// clCreateBufferWithProperties (OpenCL 3.0) is looked up in the loaded OpenCL library, so that
// fogcl still loads with a 1.2 loader and says what is missing when the call is made.
#pragma once

#include <string>

#include "runtime/clhpp.h"

#include <CL/cl_ext.h>

namespace fogcl::detail {

struct KhrFunctions {
  clEnqueueAcquireExternalMemObjectsKHR_fn acquire = nullptr;
  clEnqueueReleaseExternalMemObjectsKHR_fn release = nullptr;
  clCreateSemaphoreWithPropertiesKHR_fn create_semaphore = nullptr;
  clEnqueueWaitSemaphoresKHR_fn wait_semaphores = nullptr;
  clEnqueueSignalSemaphoresKHR_fn signal_semaphores = nullptr;
  clGetSemaphoreHandleForTypeKHR_fn semaphore_handle = nullptr;
  clReleaseSemaphoreKHR_fn release_semaphore = nullptr;
  using CreateBufferWithProperties = cl_mem(CL_API_CALL*)(cl_context, const cl_properties*, cl_mem_flags,
                                                          size_t, void*, cl_int*);
  CreateBufferWithProperties create_buffer = nullptr;
};

// The functions of `device`'s platform (looked up once per platform). Missing ones stay null.
const KhrFunctions& khr_functions(cl_device_id device);

// Whether the device's CL_DEVICE_EXTENSIONS holds `name` as a whole word.
bool has_extension(cl_device_id device, const std::string& name);

}  // namespace fogcl::detail
