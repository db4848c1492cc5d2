// fogcl on a frame in a CUDA renderer's memory (docs/library.md, "From a GPU renderer"):
//  - CUDA allocates the frame exportable (cuMemCreate, POSIX fd) and writes color and depth;
//  - fogcl imports that memory (fogcl::ExternalMemory: no copy) and fogs the frame in place;
//  - the order between the two runs on the GPU through semaphores both import (made by Vulkan,
//    as a Vulkan renderer's would be: CUDA makes none to export): CUDA signals "ready", fogcl waits
//    for it, fogs, signals "done", CUDA waits for it and reads the frame. Without Vulkan, or
//    without semaphore support in the OpenCL device, the host waits in between (the fallback);
//  - as a check (not part of the pattern), the frame must equal FogPass::apply on host images
//    bit for bit. Exit status 0 when it does, 77 when this machine has no CUDA device shared
//    with an OpenCL device that imports opaque-fd memory.
// CUDA's and Vulkan's few declarations are in cuda_driver.h and vulkan_semaphores.h: no toolkit
// or SDK is needed to build, and libcuda.so.1 / libvulkan.so.1 are opened at run time.
//
// Usage: cuda_interop [WIDTH HEIGHT]. The OpenCL device: FOGCL_DEVICE's choice (default: cpu,
// which exits 77; FOGCL_DEVICE=gpu on an NVIDIA machine).
#include <fogcl/external_memory.h>
#include <fogcl/fogcl.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "cuda_driver.h"
#include "vulkan_semaphores.h"

namespace {

constexpr int kSkipped = 77;

bool cu_ok(const cuda::Driver& cu, cuda::CUresult r, const char* call) {
  if (r != cuda::CUDA_SUCCESS) std::fprintf(stderr, "cuda_interop: %s\n", cu.error(r, call).c_str());
  return r == cuda::CUDA_SUCCESS;
}

// The "renderer's" frame: a color gradient over a tilted ground (raw conventional-Z depth) and sky.
void render(int w, int h, const fogcl::CameraParams& camera, fogcl::ColorImage& color, fogcl::DepthImage& depth) {
  const float far_plane = camera.far_plane();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float u = (x + 0.5f) / float(w), v = (y + 0.5f) / float(h);
      const float eye = v > 0.45f ? 2.0f / (v - 0.45f) : INFINITY;  // ground below the horizon
      const bool sky = !(eye < far_plane);
      color.set_pixel(x, y, {0.2f + 0.6f * u, 0.3f + 0.4f * v, sky ? 0.9f : 0.25f, 1.0f});
      // Linear01Depth = eye / far = 1 / (zx * raw + zy)  =>  raw = (far / eye - zy) / zx
      const float raw = sky ? 1.0f : (far_plane / eye - camera.zbuffer_params.y) / camera.zbuffer_params.x;
      depth.at(x, y) = std::fmin(std::fmax(raw, 0.0f), 1.0f);
    }
}

}  // namespace

int main(int argc, char** argv) try {
  const int w = argc > 2 ? std::atoi(argv[1]) : 1280, h = argc > 2 ? std::atoi(argv[2]) : 720;
  const fogcl::ColorFormat format = fogcl::ColorFormat::rgba16f;

  // ---- The OpenCL device, and the CUDA device that is the same GPU ----
  const cl_device_id device = fogcl::find_device(fogcl::resolve_device_choice());
  const fogcl::ExternalSupport support = fogcl::external_support(device);
  std::printf("OpenCL device: %s (%s)\n", fogcl::device_name(device).c_str(), support.describe().c_str());
  if (!support.imports_memory(fogcl::ExternalHandle::opaque_fd)) {
    std::printf("skipped: the device imports no opaque-fd memory\n");
    return kSkipped;
  }
  unsigned char uuid[16] = {};
  clGetDeviceInfo(device, CL_DEVICE_UUID_KHR, sizeof uuid, uuid, nullptr);
  cuda::Driver cu;
  std::string why;
  cuda::CUdevice cu_device = 0;
  cuda::CUcontext cu_context = nullptr;
  if (!cu.load(why) || !(why = cu.open_device(uuid, cu_device, cu_context)).empty()) {
    std::printf("skipped: %s\n", why.c_str());
    return kSkipped;
  }
  cl_int err = CL_SUCCESS;
  cl_context context = clCreateContext(nullptr, 1, &device, nullptr, nullptr, &err);
  cl_command_queue queue = clCreateCommandQueueWithProperties(context, device, nullptr, &err);
  if (err != CL_SUCCESS) {
    std::fprintf(stderr, "cuda_interop: no OpenCL context/queue: %s\n", fogcl::cl_error_name(err));
    return 1;
  }

  // ---- The renderer: one exportable allocation holding color, then depth ----
  const std::size_t color_bytes = fogcl::color_buffer_bytes(w, h, format);
  const std::size_t depth_at = (color_bytes + 65535) / 65536 * 65536;  // a multiple of the base alignment
  cuda::ExportableAllocation frame_memory;
  if (const std::string e = frame_memory.create(cu, cu_device, depth_at + fogcl::depth_buffer_bytes(w, h)); !e.empty()) {
    std::fprintf(stderr, "cuda_interop: %s\n", e.c_str());
    return 1;
  }
  fogcl::PerspectiveCamera lens;
  lens.aspect = float(w) / float(h);
  const fogcl::CameraParams camera = fogcl::make_camera_params(lens);
  fogcl::ColorImage color(w, h, format);
  fogcl::DepthImage depth(w, h);
  render(w, h, camera, color, depth);  // a CUDA renderer's kernels would write these on the GPU
  if (!cu_ok(cu, cu.cuMemcpyHtoD(frame_memory.ptr, color.data(), color_bytes), "cuMemcpyHtoD") ||
      !cu_ok(cu, cu.cuMemcpyHtoD(frame_memory.ptr + depth_at, depth.data(), depth.size_bytes()), "cuMemcpyHtoD"))
    return 1;

  // ---- fogcl: import the memory (the fd becomes the OpenCL implementation's), bind the frame ----
  const fogcl::ExternalMemory memory(context, device, frame_memory.export_fd(), frame_memory.size);
  fogcl::ExternalFrameLayout layout;
  layout.width = w;
  layout.height = h;
  layout.format = format;
  layout.color_in = {&memory, 0, 0};  // color_out left empty: in place
  layout.depth = {&memory, depth_at, 0};
  fogcl::ExternalFrame frame(context, device, layout);
  fogcl::FogPass pass(context, device);
  fogcl::FogSettings settings;
  settings.mode = fogcl::FogMode::exp;
  settings.density = 0.03f;
  pass.prepare(settings, camera, format);  // load time: builds the kernel

  // ---- One frame: semaphores where both sides have them, else host waits ----
  cuda::CUstream stream = nullptr;
  if (!cu_ok(cu, cu.cuStreamCreate(&stream, cuda::CU_STREAM_NON_BLOCKING), "cuStreamCreate")) return 1;
  vk::ExportableSemaphores vulkan;
  const bool semaphores = support.imports_semaphore(fogcl::ExternalHandle::opaque_fd) && vulkan.open(uuid, why);
  if (semaphores) {
    const int ready = vulkan.create(), done = vulkan.create();
    const fogcl::ExternalSemaphore fog_ready = fogcl::ExternalSemaphore::import_fd(context, device, vulkan.export_fd(ready));
    const fogcl::ExternalSemaphore fog_done = fogcl::ExternalSemaphore::import_fd(context, device, vulkan.export_fd(done));
    cuda::CUexternalSemaphore cu_ready = nullptr, cu_done = nullptr;
    cuda::CUDA_EXTERNAL_SEMAPHORE_HANDLE_DESC desc{};
    desc.type = cuda::CU_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD;
    desc.handle.fd = vulkan.export_fd(ready);
    if (!cu_ok(cu, cu.cuImportExternalSemaphore(&cu_ready, &desc), "cuImportExternalSemaphore")) return 1;
    desc.handle.fd = vulkan.export_fd(done);
    if (!cu_ok(cu, cu.cuImportExternalSemaphore(&cu_done, &desc), "cuImportExternalSemaphore")) return 1;
    cuda::CUDA_EXTERNAL_SEMAPHORE_SIGNAL_PARAMS signal{};
    cuda::CUDA_EXTERNAL_SEMAPHORE_WAIT_PARAMS wait{};
    cu.cuSignalExternalSemaphoresAsync(&cu_ready, &signal, 1, stream);  // after the renderer's work
    clReleaseEvent(frame.enqueue(pass, queue, camera, settings, {{&fog_ready}, {&fog_done}, {}}));
    cu.cuWaitExternalSemaphoresAsync(&cu_done, &wait, 1, stream);  // before the renderer reads it
    std::printf("synchronised on the GPU: CUDA signals, fogcl waits, fogs, signals, CUDA waits\n");
    if (!cu_ok(cu, cu.cuStreamSynchronize(stream), "cuStreamSynchronize")) return 1;
    cu.cuDestroyExternalSemaphore(cu_ready);
    cu.cuDestroyExternalSemaphore(cu_done);
  } else {
    std::printf("no shared semaphores (%s): the host waits between CUDA and fogcl\n",
                support.imports_semaphore(fogcl::ExternalHandle::opaque_fd) ? why.c_str()
                                                                             : "the device imports none");
    if (!cu_ok(cu, cu.cuStreamSynchronize(stream), "cuStreamSynchronize")) return 1;
    cl_event done = frame.enqueue(pass, queue, camera, settings);
    clWaitForEvents(1, &done);
    clReleaseEvent(done);
  }

  // ---- The renderer reads the fogged frame; the check against the host-image path ----
  fogcl::ColorImage fogged(w, h, format), expected;
  if (!cu_ok(cu, cu.cuMemcpyDtoH(fogged.data(), frame_memory.ptr, color_bytes), "cuMemcpyDtoH")) return 1;
  pass.apply(color, depth, expected, camera, settings);
  const bool equal = std::memcmp(fogged.data(), expected.data(), color_bytes) == 0;
  std::printf("%dx%d %s fogged in CUDA's memory: %s FogPass::apply on host images\n", w, h,
              fogcl::to_string(format), equal ? "equal bit for bit to" : "DIFFERENT from");
  cu.cuStreamDestroy(stream);
  clReleaseCommandQueue(queue);
  clReleaseContext(context);
  return equal ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "cuda_interop: %s\n", e.what());
  return 1;
}
