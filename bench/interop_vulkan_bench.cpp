// The hand-over of interop_bench.cpp with a Vulkan producer (examples/vulkan_producer.h), timed by
// Vulkan's timestamps on its queue:
//   BM_VulkanSignalToSignal  from Vulkan's "frame ready" signal to fogcl's "fog done" as Vulkan
//                            sees it: a timestamp at the end of the batch that signals "ready",
//                            one at the start of the batch that waits for "done". Manual time,
//                            median of 200; counters as BM_ExternalSignalToSignal's (pass_ms,
//                            median_ms, over_pass_us). Arguments:
//     what   0 the whole ExternalFrame::enqueue (wait, acquire, deferred pass, release, signal);
//            1 OpenCL waits and signals, nothing between; 2 no OpenCL: Vulkan waits for its own
//            "ready" (its semaphore round trip)
//     vol    0 the deferred pass (exp2); 1 the fog volumes (VolumePass, the demo scene's volumes
//            on its frame, default settings), whose target is a ratio: signal to signal <= 1.1x
//            the pass's device time (counter ratio; pass_ms from a marker before the march to the
//            composite's end, which includes the host's enqueue of the pass where that is slower
//            than the kernels: then an upper bound, and the ratio a lower one. Holding the queue
//            with a user event until the pass was enqueued hung on NVIDIA's driver 580)
//     order  0 fogcl's side is enqueued before Vulkan's signal runs: a timeline semaphore that
//            the host signals holds Vulkan's queue until then, so the figure is the GPU's
//            hand-over, not the host's enqueue (the batch waiting for "done" is submitted just
//            after the gate opens: a few µs of the host's, within the hand-over unless it is
//            shorter, as Vulkan's own round trip, what 2, may be); 1 fogcl's side is enqueued once the host has seen
//            the "ready" batch complete (its fence): the OpenCL wait finds the semaphore already
//            signalled, and the figure includes the host's wake-up and enqueue
//   BM_VulkanReadyAlreadySignalled  OpenCL's wait on a semaphore already signalled (its comment).
// Without a Vulkan device on the OpenCL device's GPU that exports memory and semaphores, or an
// OpenCL device that imports both, the rows report why they were skipped.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "../examples/vulkan_producer.h"
#include "fogcl/demo_scene.h"
#include "fogcl/external_memory.h"
#include "fogcl/fogcl.h"

namespace {

using namespace fogcl;

// The process-wide consumer and producer, with "ready", "done" and the host's gate.
struct VulkanInterop {
  std::unique_ptr<Runtime> runtime;
  cl_command_queue profiling_queue = nullptr;
  vkp::Producer vulkan;
  VkSemaphore ready = VK_NULL_HANDLE, done = VK_NULL_HANDLE, gate = VK_NULL_HANDLE;
  std::uint64_t gate_value = 0;
  std::unique_ptr<ExternalSemaphore> fog_ready, fog_done;
  VkQueryPool timestamps = VK_NULL_HANDLE;
  std::string why_not;
  ~VulkanInterop() {
    if (timestamps != VK_NULL_HANDLE) vkDestroyQueryPool(vulkan.device(), timestamps, nullptr);
  }
};

VulkanInterop& vulkan_interop() {
  static VulkanInterop* it = [] {
    auto* s = new VulkanInterop;
    try {
      s->runtime = std::make_unique<Runtime>();
      const cl_context context = s->runtime->context();
      const cl_device_id device = s->runtime->device();
      const ExternalSupport support = external_support(device);
      if (!support.imports_memory(ExternalHandle::opaque_fd) || !support.imports_semaphore(ExternalHandle::opaque_fd)) {
        s->why_not = device_name(device) + ": " + support.describe();
        return s;
      }
      std::uint8_t uuid[CL_UUID_SIZE_KHR] = {};
      clGetDeviceInfo(device, CL_DEVICE_UUID_KHR, sizeof uuid, uuid, nullptr);
      if (!(s->why_not = s->vulkan.open(uuid, true)).empty()) return s;
      if (!s->vulkan.semaphore_export()) {
        s->why_not = std::string(s->vulkan.properties().deviceName) + " lacks VK_KHR_external_semaphore_fd";
        return s;
      }
      if (s->vulkan.timestamp_bits() == 0) {
        s->why_not = "the Vulkan queue writes no timestamps";
        return s;
      }
      cl_int err = CL_SUCCESS;
      const cl_queue_properties profiling[] = {CL_QUEUE_PROPERTIES, CL_QUEUE_PROFILING_ENABLE, 0};
      s->profiling_queue = clCreateCommandQueueWithProperties(context, device, profiling, &err);
      if (err != CL_SUCCESS) {
        s->why_not = std::string("no profiling queue: ") + cl_error_name(err);
        return s;
      }
      s->ready = s->vulkan.exportable_semaphore();
      s->done = s->vulkan.exportable_semaphore();
      s->gate = s->vulkan.timeline_semaphore();
      s->fog_ready = std::make_unique<ExternalSemaphore>(
          ExternalSemaphore::import_fd(context, device, s->vulkan.export_fd(s->ready)));
      s->fog_done = std::make_unique<ExternalSemaphore>(
          ExternalSemaphore::import_fd(context, device, s->vulkan.export_fd(s->done)));
      auto pool = vkp::make<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
      pool.queryType = VK_QUERY_TYPE_TIMESTAMP;
      pool.queryCount = 2;
      vkp::check(vkCreateQueryPool(s->vulkan.device(), &pool, nullptr, &s->timestamps), "vkCreateQueryPool");
    } catch (const std::exception& e) {
      s->why_not = e.what();
    }
    return s;
  }();
  return *it;
}

// A w x h frame in two exportable Vulkan buffers (color, depth), imported and bound, a prepared
// exp2 pass or fog-volume pass for it, and the two command buffers around the hand-over:
//   start: release the buffers to the external API, timestamp 0 (then the batch signals "ready")
//   stop:  (after the wait for "done", which holds every stage) timestamp 1, acquire the buffers back
struct VulkanFrame {
  vkp::Buffer color, depth;
  std::unique_ptr<ExternalMemory> color_memory, depth_memory;
  std::unique_ptr<ExternalFrame> frame;
  std::unique_ptr<FogPass> pass;
  std::unique_ptr<VolumePass> volume;  // instead of pass
  CameraParams camera;
  FogSettings settings;  // exp2, as BM_ExternalSignalToSignal's
  VolumeScene scene;
  VolumeSettings volume_settings;
  VkCommandBuffer start = VK_NULL_HANDLE, stop = VK_NULL_HANDLE;
  VkFence started = VK_NULL_HANDLE, stopped = VK_NULL_HANDLE;
  std::string why_not;

  VulkanFrame(VulkanInterop& x, int w, int h, ColorFormat format, bool volumes) {
    const cl_context context = x.runtime->context();
    const cl_device_id device = x.runtime->device();
    vkp::Producer& vk = x.vulkan;
    const std::size_t color_bytes = color_buffer_bytes(w, h, format), depth_bytes = depth_buffer_bytes(w, h);
    if (!(why_not = vk.exportable_buffer(color_bytes, color)).empty()) return;
    if (!(why_not = vk.exportable_buffer(depth_bytes, depth)).empty()) return;
    // The deferred pass: sky and a depth ramp (its time does not depend on the pixels' values);
    // the volumes: the demo scene, whose depth decides where the march stops.
    PerspectiveCamera lens;
    lens.aspect = float(w) / float(h);
    camera = make_camera_params(lens);
    ColorImage c(w, h, format);
    DepthImage d(w, h);
    if (volumes) {
      DemoFrame demo = render_demo_scene(w, h, lens, {}, format);
      c = std::move(demo.color);
      d = std::move(demo.depth);
      camera = demo.params;
      const DemoView view;
      scene.pose.eye = view.eye;
      scene.pose.forward = view.target - view.eye;
      scene.light = demo_light();
      scene.volumes = demo_fog_volumes(volume_settings.integrator);
    } else {
      for (int y = 0; y < h; ++y)
        for (int px = 0; px < w; ++px) {
          c.set_pixel(px, y, {0.3f, 0.5f, 0.8f, 1.0f});
          d.at(px, y) = y < h / 3 ? 1.0f : float(y) / float(h);
        }
    }
    const vkp::Buffer staging = vk.host_buffer(color_bytes + depth_bytes);
    std::memcpy(staging.mapped, c.data(), color_bytes);
    std::memcpy(static_cast<unsigned char*>(staging.mapped) + color_bytes, d.data(), depth_bytes);
    const auto begin = vkp::make<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
    const VkCommandBuffer upload = vk.command_buffer();
    vkp::check(vkBeginCommandBuffer(upload, &begin), "vkBeginCommandBuffer");
    const VkBufferCopy color_region{0, 0, color_bytes}, depth_region{color_bytes, 0, depth_bytes};
    vkCmdCopyBuffer(upload, staging.buffer, color.buffer, 1, &color_region);
    vkCmdCopyBuffer(upload, staging.buffer, depth.buffer, 1, &depth_region);
    vkp::check(vkEndCommandBuffer(upload), "vkEndCommandBuffer");
    started = vk.fence();
    stopped = vk.fence();
    vkp::submit(vk.queue(), upload, {}, {}, started);
    vk.wait(started);

    start = vk.command_buffer();
    vkp::check(vkBeginCommandBuffer(start, &begin), "vkBeginCommandBuffer");
    vkCmdResetQueryPool(start, x.timestamps, 0, 2);
    vk.release_to_external(start, {color.buffer, depth.buffer});
    vkCmdWriteTimestamp(start, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, x.timestamps, 0);
    vkp::check(vkEndCommandBuffer(start), "vkEndCommandBuffer");
    stop = vk.command_buffer();
    vkp::check(vkBeginCommandBuffer(stop, &begin), "vkBeginCommandBuffer");
    vkCmdWriteTimestamp(stop, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, x.timestamps, 1);
    vk.acquire_from_external(stop, {color.buffer, depth.buffer});
    vkp::check(vkEndCommandBuffer(stop), "vkEndCommandBuffer");

    color_memory = std::make_unique<ExternalMemory>(context, device, vk.export_fd(color), color.bytes);
    depth_memory = std::make_unique<ExternalMemory>(context, device, vk.export_fd(depth), depth.bytes);
    ExternalFrameLayout layout;
    layout.width = w;
    layout.height = h;
    layout.format = format;
    layout.color_in = {color_memory.get(), 0, 0};
    layout.depth = {depth_memory.get(), 0, 0};
    frame = std::make_unique<ExternalFrame>(context, device, layout);
    if (volumes) {
      volume = std::make_unique<VolumePass>(context, device);
      volume->prepare(camera, scene, volume_settings, format);
    } else {
      pass = std::make_unique<FogPass>(context, device);
      settings.density = 0.002f;
      pass->prepare(settings, camera, format);
    }
  }

  // fogcl's side of one frame on `queue`.
  cl_event enqueue(cl_command_queue queue, const ExternalSync& sync) {
    return volume ? frame->enqueue(*volume, queue, camera, scene, volume_settings, sync)
                  : frame->enqueue(*pass, queue, camera, settings, sync);
  }
  // The pass's device time on the frame (acquired and released, no semaphores) on a profiling
  // queue: the deferred kernel's start to end; the volumes' marker before the march to the
  // composite's end (several kernels; the host's enqueue of them may be in it).
  double device_seconds(cl_command_queue profiling) {
    cl_event first = nullptr, last = nullptr;
    const cl_event released = frame->enqueue(profiling, [&](const FrameBuffers& fb, const std::vector<cl_event>& w) {
      if (volume) {
        clEnqueueMarkerWithWaitList(profiling, cl_uint(w.size()), w.empty() ? nullptr : w.data(), &first);
        last = volume->enqueue(profiling, fb, camera, scene, volume_settings, nullptr, {first});
      } else {
        last = pass->enqueue(profiling, fb, camera, settings, w);
      }
      clRetainEvent(last);
      return last;
    });
    clWaitForEvents(1, &released);
    clReleaseEvent(released);
    cl_ulong t0 = 0, t1 = 0;
    if (first != nullptr) {
      clGetEventProfilingInfo(first, CL_PROFILING_COMMAND_END, sizeof t0, &t0, nullptr);
      clReleaseEvent(first);
    } else {
      clGetEventProfilingInfo(last, CL_PROFILING_COMMAND_START, sizeof t0, &t0, nullptr);
    }
    clGetEventProfilingInfo(last, CL_PROFILING_COMMAND_END, sizeof t1, &t1, nullptr);
    clReleaseEvent(last);
    return double(t1 - t0) * 1e-9;
  }
};

// One hand-over; seconds between the two timestamps.
double hand_over(VulkanInterop& x, VulkanFrame& f, int what, int order) {
  vkp::Producer& vk = x.vulkan;
  const VkQueue q = vk.queue();
  auto consumer = [&] {
    if (what == 0) {
      clReleaseEvent(f.enqueue(x.runtime->queue(), {{x.fog_ready.get()}, {x.fog_done.get()}, {}}));
    } else if (what == 1) {
      cl_platform_id platform = nullptr;
      clGetDeviceInfo(x.runtime->device(), CL_DEVICE_PLATFORM, sizeof platform, &platform, nullptr);
      static const auto wait_fn = reinterpret_cast<clEnqueueWaitSemaphoresKHR_fn>(
          clGetExtensionFunctionAddressForPlatform(platform, "clEnqueueWaitSemaphoresKHR"));
      static const auto signal_fn = reinterpret_cast<clEnqueueSignalSemaphoresKHR_fn>(
          clGetExtensionFunctionAddressForPlatform(platform, "clEnqueueSignalSemaphoresKHR"));
      const cl_semaphore_khr ready = x.fog_ready->handle(), done = x.fog_done->handle();
      wait_fn(x.runtime->queue(), 1, &ready, nullptr, 0, nullptr, nullptr);
      signal_fn(x.runtime->queue(), 1, &done, nullptr, 0, nullptr, nullptr);
      clFlush(x.runtime->queue());
    }
  };
  const VkSemaphore back = what == 2 ? x.ready : x.done;  // what Vulkan waits for
  if (order == 0) {
    vkp::submit(q, f.start, {x.gate}, {x.ready}, VK_NULL_HANDLE, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                {++x.gate_value});
    consumer();
    auto open = vkp::make<VkSemaphoreSignalInfo>(VK_STRUCTURE_TYPE_SEMAPHORE_SIGNAL_INFO);
    open.semaphore = x.gate;
    open.value = x.gate_value;
    vkp::check(vkSignalSemaphore(vk.device(), &open), "vkSignalSemaphore");
    // After the gate opens: a driver may hold a submission that waits for a binary semaphore until
    // its signal's batch has left the host (Mesa's does), which the gate would never let happen.
    vkp::submit(q, f.stop, {back}, {}, f.stopped);
  } else {
    vkp::submit(q, f.start, {}, {x.ready}, f.started);
    vk.wait(f.started);
    consumer();
    vkp::submit(q, f.stop, {back}, {}, f.stopped);
  }
  vk.wait(f.stopped);
  std::uint64_t t[2] = {};
  vkp::check(vkGetQueryPoolResults(vk.device(), x.timestamps, 0, 2, sizeof t, t, sizeof t[0],
                                   VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
             "vkGetQueryPoolResults");
  const std::uint32_t bits = vk.timestamp_bits();
  const std::uint64_t mask = bits >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << bits) - 1;
  return double((t[1] - t[0]) & mask) * double(vk.properties().limits.timestampPeriod) * 1e-9;
}

void BM_VulkanSignalToSignal(benchmark::State& state) {
  VulkanInterop& x = vulkan_interop();
  if (!x.why_not.empty()) {
    state.SkipWithError(("no Vulkan interop: " + x.why_not).c_str());
    return;
  }
  const ColorFormat format = state.range(2) != 0 ? ColorFormat::rgba16f : ColorFormat::rgba32f;
  const int what = int(state.range(3)), order = int(state.range(4));
  VulkanFrame f(x, int(state.range(0)), int(state.range(1)), format, state.range(5) != 0);
  if (!f.why_not.empty()) {
    state.SkipWithError(f.why_not.c_str());
    return;
  }
  for (int i = 0; i < 3; ++i) hand_over(x, f, what, order);  // warm: first acquire, first kernel
  std::vector<double> times;
  for (auto _ : state) {
    times.push_back(hand_over(x, f, what, order));
    state.SetIterationTime(times.back());
  }
  std::vector<double> pass_s;
  for (int i = 0; i < 20; ++i) pass_s.push_back(f.device_seconds(x.profiling_queue));
  std::nth_element(pass_s.begin(), pass_s.begin() + 10, pass_s.end());
  std::nth_element(times.begin(), times.begin() + std::ptrdiff_t(times.size() / 2), times.end());
  state.counters["pass_ms"] = pass_s[10] * 1e3;
  state.counters["median_ms"] = times[times.size() / 2] * 1e3;
  state.counters["over_pass_us"] = (times[times.size() / 2] - pass_s[10]) * 1e6;
  state.counters["ratio"] = times[times.size() / 2] / pass_s[10];
}

BENCHMARK(BM_VulkanSignalToSignal)
    ->ArgNames({"w", "h", "f16", "what", "order", "vol"})
    ->Args({1920, 1080, 0, 0, 0, 0})
    ->Args({1920, 1080, 1, 0, 0, 0})
    ->Args({3840, 2160, 0, 0, 0, 0})
    ->Args({3840, 2160, 1, 0, 0, 0})
    ->Args({1920, 1080, 1, 0, 1, 0})
    ->Args({1920, 1080, 1, 1, 0, 0})
    ->Args({1920, 1080, 1, 1, 1, 0})
    ->Args({1920, 1080, 1, 2, 0, 0})
    ->Args({1920, 1080, 1, 0, 0, 1})
    ->Args({3840, 2160, 1, 0, 0, 1})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(200);

// OpenCL's wait on a "ready" that has already been signalled (Vulkan's batch has completed: its
// fence), on the host clock: from enqueueing the wait and a marker to the marker's event
// complete (clWaitForEvents). wait 0: the marker alone, the same host round trip without the
// wait; the difference is the wait's own cost when there is nothing to wait for.
void BM_VulkanReadyAlreadySignalled(benchmark::State& state) {
  VulkanInterop& x = vulkan_interop();
  if (!x.why_not.empty()) {
    state.SkipWithError(("no Vulkan interop: " + x.why_not).c_str());
    return;
  }
  const bool wait = state.range(0) != 0;
  cl_platform_id platform = nullptr;
  clGetDeviceInfo(x.runtime->device(), CL_DEVICE_PLATFORM, sizeof platform, &platform, nullptr);
  const auto wait_fn = reinterpret_cast<clEnqueueWaitSemaphoresKHR_fn>(
      clGetExtensionFunctionAddressForPlatform(platform, "clEnqueueWaitSemaphoresKHR"));
  const cl_command_queue queue = x.runtime->queue();
  const cl_semaphore_khr ready = x.fog_ready->handle();
  const VkFence signalled = x.vulkan.fence();
  auto one = [&] {
    if (wait) {
      vkp::submit(x.vulkan.queue(), VK_NULL_HANDLE, {}, {x.ready}, signalled);
      x.vulkan.wait(signalled);
    }
    const auto t0 = std::chrono::steady_clock::now();
    if (wait) wait_fn(queue, 1, &ready, nullptr, 0, nullptr, nullptr);
    cl_event marker = nullptr;
    clEnqueueMarkerWithWaitList(queue, 0, nullptr, &marker);
    clFlush(queue);
    clWaitForEvents(1, &marker);
    const auto t1 = std::chrono::steady_clock::now();
    clReleaseEvent(marker);
    return std::chrono::duration<double>(t1 - t0).count();
  };
  for (int i = 0; i < 3; ++i) one();
  for (auto _ : state) state.SetIterationTime(one());
}

BENCHMARK(BM_VulkanReadyAlreadySignalled)
    ->ArgName("wait")
    ->Arg(0)
    ->Arg(1)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(200);

}  // namespace
