// fogcl on a frame in a Vulkan renderer's memory (docs/library.md, "From a GPU renderer"):
//  - Vulkan allocates the color and depth buffers exportable (VK_KHR_external_memory_fd, opaque
//    fd) and exports their memory; fogcl imports it (fogcl::ExternalMemory: no copy) and binds
//    the frame (fogcl::ExternalFrame) to fog it in place;
//  - Vulkan makes two binary semaphores exportable (VK_KHR_external_semaphore_fd), "frame ready"
//    and "fog done", and fogcl imports both (an OpenCL device may export none: NVIDIA's driver 580
//    does not);
//  - one frame: Vulkan uploads it from a staging buffer (vkCmdCopyBuffer; a renderer's draws would
//    write it), releases the buffers to the external API and signals "ready"; fogcl waits for it,
//    fogs, signals "done"; Vulkan waits for "done", takes the buffers back and reads the frame.
//    No host wait between them. Without semaphore support on either side, the host waits in
//    between (the fallback);
//  - as a check (not part of the pattern), the frame must equal FogPass::apply on host images
//    bit for bit: exit status 0 when it does, 1 when not or on an error, 77 (skipped) when this
//    machine has no OpenCL device that imports opaque-fd memory or no Vulkan device on the same
//    GPU that exports it (the reason is printed).
// Renderers draw into optimally tiled images, whose layout is the driver's own: copy such an image
// into an exported buffer on the GPU (vkCmdCopyImageToBuffer) and back, or render into the buffer.
//
// Usage: vulkan_exporter [WIDTH HEIGHT]. The OpenCL device: FOGCL_DEVICE's choice (default: cpu,
// which exits 77; FOGCL_DEVICE=gpu on an NVIDIA machine).
#include <fogcl/external_memory.h>
#include <fogcl/fogcl.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "vulkan_producer.h"

namespace {

constexpr int kSkipped = 77;

int skipped(const std::string& why) {
  std::printf("skipped: %s\n", why.c_str());
  return kSkipped;
}

// The "renderer's" frame: a pattern in color, and raw conventional-Z depth from near to the far
// plane (1.0) over the top rows.
void render(int w, int h, fogcl::ColorImage& color, fogcl::DepthImage& depth) {
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const unsigned hash = (unsigned(x) * 73856093u) ^ (unsigned(y) * 19349663u);
      color.set_pixel(x, y, {float(x) / float(w), float(y) / float(h), float(hash % 1024u) / 1024.0f, 1.0f});
      depth.at(x, y) = y < h / 4 ? 1.0f : float(x + y) / float(w + h);
    }
}

}  // namespace

int main(int argc, char** argv) try {
  const int w = argc > 2 ? std::atoi(argv[1]) : 1280, h = argc > 2 ? std::atoi(argv[2]) : 720;
  if (w < 1 || h < 1) {
    std::fprintf(stderr, "vulkan_exporter: WIDTH and HEIGHT must be positive integers (got %dx%d)\n", w, h);
    return 1;
  }
  const fogcl::ColorFormat format = fogcl::ColorFormat::rgba16f;

  // ---- The OpenCL device, and the Vulkan device that is the same GPU ----
  const cl_device_id device = fogcl::find_device(fogcl::resolve_device_choice());
  const fogcl::ExternalSupport support = fogcl::external_support(device);
  std::printf("OpenCL device: %s (%s)\n", fogcl::device_name(device).c_str(), support.describe().c_str());
  if (!support.imports_memory(fogcl::ExternalHandle::opaque_fd))
    return skipped("the OpenCL device imports no opaque-fd memory (cl_khr_external_memory_opaque_fd)");
  std::uint8_t uuid[CL_UUID_SIZE_KHR] = {};
  if (clGetDeviceInfo(device, CL_DEVICE_UUID_KHR, sizeof uuid, uuid, nullptr) != CL_SUCCESS)
    return skipped("the OpenCL device reports no CL_DEVICE_UUID_KHR to find its Vulkan device by");
  vkp::Producer vulkan;
  if (const std::string why = vulkan.open(uuid); !why.empty()) return skipped(why);
  std::printf("Vulkan device: %s\n", vulkan.properties().deviceName);

  // ---- The renderer's frame: color and depth buffers with exportable memory, a staging and a
  // read-back buffer ----
  const std::size_t color_bytes = fogcl::color_buffer_bytes(w, h, format);
  const std::size_t depth_bytes = fogcl::depth_buffer_bytes(w, h);
  vkp::Buffer color_buffer, depth_buffer;
  if (std::string why = vulkan.exportable_buffer(color_bytes, color_buffer); !why.empty()) return skipped(why);
  if (std::string why = vulkan.exportable_buffer(depth_bytes, depth_buffer); !why.empty()) return skipped(why);
  const vkp::Buffer staging = vulkan.host_buffer(color_bytes + depth_bytes);
  const vkp::Buffer readback = vulkan.host_buffer(color_bytes);
  fogcl::ColorImage color(w, h, format);
  fogcl::DepthImage depth(w, h);
  render(w, h, color, depth);
  std::memcpy(staging.mapped, color.data(), color_bytes);
  std::memcpy(static_cast<unsigned char*>(staging.mapped) + color_bytes, depth.data(), depth_bytes);

  // ---- fogcl: import both allocations (each fd becomes the OpenCL implementation's), bind the
  // frame, prepare the pass (load time) ----
  cl_int err = CL_SUCCESS;
  cl_context context = clCreateContext(nullptr, 1, &device, nullptr, nullptr, &err);
  cl_command_queue queue = err == CL_SUCCESS ? clCreateCommandQueueWithProperties(context, device, nullptr, &err)
                                             : nullptr;
  if (err != CL_SUCCESS) {
    std::fprintf(stderr, "vulkan_exporter: no OpenCL context/queue: %s\n", fogcl::cl_error_name(err));
    return 1;
  }
  const fogcl::ExternalMemory color_memory(context, device, vulkan.export_fd(color_buffer), color_buffer.bytes);
  const fogcl::ExternalMemory depth_memory(context, device, vulkan.export_fd(depth_buffer), depth_buffer.bytes);
  fogcl::ExternalFrameLayout layout;
  layout.width = w;
  layout.height = h;
  layout.format = format;
  layout.color_in = {&color_memory, 0, 0};  // color_out left empty: in place
  layout.depth = {&depth_memory, 0, 0};
  fogcl::ExternalFrame frame(context, device, layout);
  fogcl::PerspectiveCamera lens;
  lens.aspect = float(w) / float(h);
  const fogcl::CameraParams camera = fogcl::make_camera_params(lens);
  fogcl::FogSettings settings;
  settings.mode = fogcl::FogMode::exp;
  settings.density = 0.03f;
  fogcl::FogPass pass(context, device);
  pass.prepare(settings, camera, format);

  // ---- Vulkan's two command buffers: upload and release; acquire and read back ----
  const auto begin = vkp::make<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  const VkCommandBuffer upload = vulkan.command_buffer();
  vkp::check(vkBeginCommandBuffer(upload, &begin), "vkBeginCommandBuffer");
  const VkBufferCopy color_region{0, 0, color_bytes}, depth_region{color_bytes, 0, depth_bytes};
  vkCmdCopyBuffer(upload, staging.buffer, color_buffer.buffer, 1, &color_region);
  vkCmdCopyBuffer(upload, staging.buffer, depth_buffer.buffer, 1, &depth_region);
  vulkan.release_to_external(upload, {color_buffer.buffer, depth_buffer.buffer});
  vkp::check(vkEndCommandBuffer(upload), "vkEndCommandBuffer");
  const VkCommandBuffer read = vulkan.command_buffer();
  vkp::check(vkBeginCommandBuffer(read, &begin), "vkBeginCommandBuffer");
  vulkan.acquire_from_external(read, {color_buffer.buffer, depth_buffer.buffer});
  const VkBufferCopy read_region{0, 0, color_bytes};
  vkCmdCopyBuffer(read, color_buffer.buffer, readback.buffer, 1, &read_region);
  auto to_host = vkp::make<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(read, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0, nullptr,
                       0, nullptr);
  vkp::check(vkEndCommandBuffer(read), "vkEndCommandBuffer");
  const VkFence read_done = vulkan.fence();

  // ---- One frame: semaphores where both sides have them, else host waits ----
  if (vulkan.semaphore_export() && support.imports_semaphore(fogcl::ExternalHandle::opaque_fd)) {
    const VkSemaphore ready = vulkan.exportable_semaphore(), done = vulkan.exportable_semaphore();
    const fogcl::ExternalSemaphore fog_ready = fogcl::ExternalSemaphore::import_fd(context, device, vulkan.export_fd(ready));
    const fogcl::ExternalSemaphore fog_done = fogcl::ExternalSemaphore::import_fd(context, device, vulkan.export_fd(done));
    vkp::submit(vulkan.queue(), upload, {}, {ready}, VK_NULL_HANDLE);
    // fogcl flushes its signal before returning: Vulkan's wait below has its signal submitted, as
    // a binary semaphore's wait must.
    clReleaseEvent(frame.enqueue(pass, queue, camera, settings, {{&fog_ready}, {&fog_done}, {}}));
    vkp::submit(vulkan.queue(), read, {done}, {}, read_done, VK_PIPELINE_STAGE_TRANSFER_BIT);
    std::printf("synchronised on the GPU: Vulkan signals, fogcl waits, fogs, signals, Vulkan waits\n");
    vulkan.wait(read_done);
  } else {
    std::printf("no shared semaphores (%s): the host waits between Vulkan and fogcl\n",
                vulkan.semaphore_export() ? "the OpenCL device imports none"
                                          : "the Vulkan device lacks " VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME);
    const VkFence uploaded = vulkan.fence();
    vkp::submit(vulkan.queue(), upload, {}, {}, uploaded);
    vulkan.wait(uploaded);
    cl_event done = frame.enqueue(pass, queue, camera, settings);
    clWaitForEvents(1, &done);
    clReleaseEvent(done);
    vkp::submit(vulkan.queue(), read, {}, {}, read_done);
    vulkan.wait(read_done);
  }

  // ---- The check against the host-image path ----
  fogcl::ColorImage expected;
  pass.apply(color, depth, expected, camera, settings);
  const bool equal = std::memcmp(readback.mapped, expected.data(), color_bytes) == 0;
  std::printf("%dx%d %s fogged in Vulkan's memory: %s FogPass::apply on host images\n", w, h,
              fogcl::to_string(format), equal ? "equal bit for bit to" : "DIFFERENT from");
  clReleaseCommandQueue(queue);
  clReleaseContext(context);
  return equal ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "vulkan_exporter: %s\n", e.what());
  return 1;
}
