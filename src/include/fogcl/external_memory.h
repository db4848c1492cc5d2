// Frames in another API's GPU memory (a Vulkan or CUDA renderer's), fogged where they lie:
// cl_khr_external_memory imports the renderer's allocation, cl_khr_external_semaphore orders the
// pass between the renderer's "frame ready" and "fog done" on the GPU, with no host wait and no
// copy over the bus. docs/library.md, "From a GPU renderer".
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fogcl/fog_pass.h"
#include "fogcl/opencl_types.h"
#include "fogcl/volume_pass.h"

#include <CL/cl_ext.h>  // cl_semaphore_khr (OpenCL headers of 2022 or later)

namespace fogcl {

// The kinds of exported memory and semaphore handles fogcl imports (Linux).
enum class ExternalHandle {
  opaque_fd,  // CL_EXTERNAL_MEMORY_HANDLE_OPAQUE_FD_KHR / CL_SEMAPHORE_HANDLE_OPAQUE_FD_KHR:
              // Vulkan's VK_EXTERNAL_*_HANDLE_TYPE_OPAQUE_FD_BIT, CUDA's POSIX file descriptor
  dma_buf,    // CL_EXTERNAL_MEMORY_HANDLE_DMA_BUF_KHR (memory only)
};
const char* to_string(ExternalHandle handle);

// What a device offers, from its extensions and CL_DEVICE_{EXTERNAL_MEMORY_IMPORT,
// SEMAPHORE_IMPORT, SEMAPHORE_EXPORT}_HANDLE_TYPES_KHR. The lists hold the handle types fogcl
// knows (a device may report others).
struct ExternalSupport {
  bool memory_extension = false;     // cl_khr_external_memory
  bool semaphore_extension = false;  // cl_khr_external_semaphore (with cl_khr_semaphore)
  std::vector<ExternalHandle> memory_imports;
  std::vector<ExternalHandle> semaphore_imports;
  std::vector<ExternalHandle> semaphore_exports;
  bool imports_memory(ExternalHandle h) const;
  bool imports_semaphore(ExternalHandle h) const;
  bool exports_semaphore(ExternalHandle h) const;
  std::string describe() const;  // one line, e.g. "memory import: opaque_fd; semaphores: import opaque_fd, no export"
};
ExternalSupport external_support(cl_device_id device);

// One imported allocation: an OpenCL buffer over the renderer's memory (no copy). Move-only; the
// destructor releases the buffer (the renderer's allocation lives on while it holds it).
class ExternalMemory {
 public:
  // Imports `size` bytes (<= the exported allocation's size) from the file descriptor `fd` of
  // kind `handle` into `context`, for `device` (CL_DEVICE_HANDLE_LIST_KHR).
  // File descriptor: on success the OpenCL implementation owns it (the extension's rule: the
  // caller must not use or close it afterwards; export another one for another import); when
  // this throws, the caller still owns it.
  // Throws fogcl::Error when the device does not offer cl_khr_external_memory or that handle
  // type (naming the extension and what the device imports), or for a negative fd or size 0;
  // fogcl::ClError when the import fails (a bad fd, a size beyond the allocation).
  ExternalMemory(cl_context context, cl_device_id device, int fd, std::size_t size,
                 ExternalHandle handle = ExternalHandle::opaque_fd);
  ~ExternalMemory();
  ExternalMemory(ExternalMemory&&) noexcept;
  ExternalMemory& operator=(ExternalMemory&&) noexcept;

  cl_mem buffer() const;  // borrowed, valid while this lives
  std::size_t size() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A binary semaphore shared with the renderer. Move-only; the destructor releases it.
class ExternalSemaphore {
 public:
  // Imports the renderer's semaphore (its opaque-fd export, e.g. vkGetSemaphoreFdKHR). The fd's
  // ownership as for ExternalMemory: the implementation's on success, the caller's on a throw.
  // Throws fogcl::Error when the device does not offer cl_khr_external_semaphore with opaque-fd
  // import, fogcl::ClError when the import fails.
  static ExternalSemaphore import_fd(cl_context context, cl_device_id device, int fd);
  // A semaphore made by fogcl, exportable as an opaque fd (export_fd) for the renderer to import
  // (CUDA's cuImportExternalSemaphore, Vulkan's vkImportSemaphoreFdKHR). Throws fogcl::Error when
  // the device exports no opaque-fd semaphores (CL_DEVICE_SEMAPHORE_EXPORT_HANDLE_TYPES_KHR; none
  // on NVIDIA's driver 580: import the renderer's instead).
  static ExternalSemaphore exportable(cl_context context, cl_device_id device);

  ExternalSemaphore();
  ~ExternalSemaphore();
  ExternalSemaphore(ExternalSemaphore&&) noexcept;
  ExternalSemaphore& operator=(ExternalSemaphore&&) noexcept;

  // A new fd of an exportable semaphore's payload, owned by the caller (close it, or import it
  // elsewhere, which passes it on). Throws fogcl::Error for an imported semaphore.
  int export_fd() const;
  cl_semaphore_khr handle() const;  // borrowed

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Where one image of the frame lies in imported memory: pixel (x, y) (row 0 = top) at byte
// offset + y * row_pitch + x * pixel bytes.
struct ExternalPlane {
  const ExternalMemory* memory = nullptr;  // borrowed: must outlive the ExternalFrame
  std::size_t offset = 0;                  // bytes from the allocation's start
  std::size_t row_pitch = 0;               // bytes from one row's start to the next; 0: packed
};

// A frame in imported memory. color: RGBA in `format` (16 or 8 bytes a pixel); depth: float32
// raw device depth (or eye/radial depth as CameraParams::depth_kind says, as every path).
struct ExternalFrameLayout {
  int width = 0;   // >= 1
  int height = 0;  // >= 1
  ColorFormat format = ColorFormat::rgba32f;
  ExternalPlane color_in;
  ExternalPlane depth;
  ExternalPlane color_out;  // memory null (or color_in's plane): in place
};

// What one ExternalFrame::enqueue waits for before touching the frame and signals after it.
struct ExternalSync {
  std::vector<const ExternalSemaphore*> wait;    // the renderer's "frame ready" (borrowed)
  std::vector<const ExternalSemaphore*> signal;  // "fog done" for the renderer (borrowed)
  std::vector<cl_event> wait_events;             // OpenCL events of the same context (borrowed)
};

// A frame layout bound to a context and device: validated once, its planes made into the packed
// buffers the passes take (sub-buffers of the imported memory where a plane is packed and its
// offset is a multiple of CL_DEVICE_MEM_BASE_ADDR_ALIGN; else device scratch buffers with a
// rectangle copy on the GPU each way, no bus transfer). Reused frame after frame.
class ExternalFrame {
 public:
  // Throws fogcl::Error naming the plane and the rule: a null memory, a plane beyond its
  // allocation, a row pitch below the row's bytes or not a multiple of 4, color_out overlapping
  // color_in or depth without being color_in.
  ExternalFrame(cl_context context, cl_device_id device, const ExternalFrameLayout& layout);
  ~ExternalFrame();
  ExternalFrame(ExternalFrame&&) noexcept;
  ExternalFrame& operator=(ExternalFrame&&) noexcept;

  // The pass on the frame, all on `queue` (the pass's context and device), nothing on the host:
  // wait for sync.wait's semaphores and sync.wait_events, acquire the imported memory
  // (clEnqueueAcquireExternalMemObjectsKHR), copy pitched planes in, run the pass, copy out,
  // release the memory, signal sync.signal's semaphores, then clFlush (a signal left in an
  // unflushed queue would never reach the renderer). Returns the event of the last command (a
  // new reference the caller owns): with no semaphores, the renderer's API waits on it (or the
  // host does) before reusing the memory. The pass must be prepared (FogPass::prepare).
  cl_event enqueue(FogPass& pass, cl_command_queue queue, const CameraParams& camera, const FogSettings& settings,
                   const ExternalSync& sync = {});
  cl_event enqueue(VolumePass& pass, cl_command_queue queue, const CameraParams& camera, const VolumeScene& scene,
                   const VolumeSettings& settings, const ExternalSync& sync = {},
                   const ShadowMapBuffer* shadow = nullptr);
  // Any pass: `run` enqueues it on the packed buffers after the wait list it is given and returns
  // its last event (a new reference, as FogPass::enqueue's).
  using PassFn = std::function<cl_event(const FrameBuffers& frame, const std::vector<cl_event>& wait_list)>;
  cl_event enqueue(cl_command_queue queue, const PassFn& run, const ExternalSync& sync = {});

  // The packed buffers the passes read and write (borrowed, valid while this lives).
  const FrameBuffers& buffers() const;
  // Whether every plane is used where it lies (no rectangle copies).
  bool zero_copy() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fogcl
