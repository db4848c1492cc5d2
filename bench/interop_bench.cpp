// A GPU renderer's frame fogged where it lies (fogcl/external_memory.h), timed on the GPU:
//   BM_ExternalSignalToSignal  from the producer's "frame ready" signal to fogcl's "fog done" as the
//                              producer sees it: CUDA events around CUDA's semaphore signal and
//                              wait, with fogcl's wait, acquire, deferred pass, release and signal
//                              in between (manual time). A host callback holds the CUDA stream
//                              until fogcl's commands are enqueued, so the figure is the GPU's
//                              hand-over, not the host's enqueue. Counters: pass_ms, the deferred
//                              pass's kernel on the same buffers (profiling START -> END, median of
//                              20), and over_pass_us, the hand-over's cost beyond the kernel.
//   BM_ExternalHandOverParts   where that time goes (its comment lists the parts).
// The producer is CUDA (libcuda.so.1), the semaphores Vulkan's (libvulkan.so.1), as in
// tests/gpu_interop_test.cpp; without them, or on a device without cl_khr_external_memory, the
// rows report why they were skipped. FOGCL_DEVICE chooses the device (gpu on the GPU machine).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "../examples/cuda_driver.h"
#include "../examples/vulkan_semaphores.h"
#include "fogcl/external_memory.h"
#include "fogcl/fogcl.h"

namespace {

using namespace fogcl;

// The process-wide producer and consumer: OpenCL device, CUDA context, Vulkan semaphores.
struct Interop {
  std::unique_ptr<Runtime> runtime;
  cl_command_queue profiling_queue = nullptr;
  cuda::Driver cu;
  cuda::CUdevice device = 0;
  cuda::CUcontext context = nullptr;
  cuda::CUstream stream = nullptr;
  vk::ExportableSemaphores vulkan;
  std::unique_ptr<ExternalSemaphore> ready, done;
  cuda::CUexternalSemaphore cu_ready = nullptr, cu_done = nullptr;
  std::string why_not;
};

Interop& interop() {
  static Interop* it = [] {
    auto* s = new Interop;
    try {
      s->runtime = std::make_unique<Runtime>();
      const cl_device_id device = s->runtime->device();
      const ExternalSupport support = external_support(device);
      if (!support.imports_memory(ExternalHandle::opaque_fd) || !support.imports_semaphore(ExternalHandle::opaque_fd)) {
        s->why_not = device_name(device) + ": " + support.describe();
        return s;
      }
      unsigned char uuid[16] = {};
      clGetDeviceInfo(device, CL_DEVICE_UUID_KHR, sizeof uuid, uuid, nullptr);
      if (!s->cu.load(s->why_not)) return s;
      if (!(s->why_not = s->cu.open_device(uuid, s->device, s->context)).empty()) return s;
      if (!s->vulkan.open(uuid, s->why_not)) return s;
      cl_int err = CL_SUCCESS;
      const cl_queue_properties profiling[] = {CL_QUEUE_PROPERTIES, CL_QUEUE_PROFILING_ENABLE, 0};
      s->profiling_queue = clCreateCommandQueueWithProperties(s->runtime->context(), device, profiling, &err);
      if (err != CL_SUCCESS) {
        s->why_not = std::string("no profiling queue: ") + cl_error_name(err);
        return s;
      }
      const int ready = s->vulkan.create(), done = s->vulkan.create();
      s->ready = std::make_unique<ExternalSemaphore>(
          ExternalSemaphore::import_fd(s->runtime->context(), device, s->vulkan.export_fd(ready)));
      s->done = std::make_unique<ExternalSemaphore>(
          ExternalSemaphore::import_fd(s->runtime->context(), device, s->vulkan.export_fd(done)));
      cuda::CUDA_EXTERNAL_SEMAPHORE_HANDLE_DESC desc{};
      desc.type = cuda::CU_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD;
      desc.handle.fd = s->vulkan.export_fd(ready);
      std::string e = s->cu.error(s->cu.cuImportExternalSemaphore(&s->cu_ready, &desc), "cuImportExternalSemaphore");
      desc.handle.fd = s->vulkan.export_fd(done);
      if (e.empty()) e = s->cu.error(s->cu.cuImportExternalSemaphore(&s->cu_done, &desc), "cuImportExternalSemaphore");
      if (e.empty()) e = s->cu.error(s->cu.cuStreamCreate(&s->stream, cuda::CU_STREAM_NON_BLOCKING), "cuStreamCreate");
      s->why_not = e;
    } catch (const std::exception& e) {
      s->why_not = e.what();
    }
    return s;
  }();
  if (it->context != nullptr) it->cu.cuCtxSetCurrent(it->context);
  return *it;
}

// Holds the CUDA stream until the host has enqueued fogcl's side (cuLaunchHostFunc).
std::atomic<int> gate{0};
void wait_for_gate(void*) {
  while (gate.load(std::memory_order_acquire) == 0) {
  }
  gate.store(0, std::memory_order_relaxed);
}

// A w x h frame in one exportable CUDA allocation (color, then depth at a 64 KiB boundary, then a
// counter word at the end), imported, bound, and a prepared exp2 pass for it.
struct SharedFrame {
  cuda::ExportableAllocation memory;
  std::size_t depth_at = 0;
  std::unique_ptr<ExternalMemory> imported;
  std::unique_ptr<ExternalFrame> frame;
  std::unique_ptr<FogPass> pass;
  CameraParams camera;
  FogSettings settings;  // exp2, Unity's default
  std::string why_not;

  SharedFrame(Interop& x, int w, int h, ColorFormat format) {
    const cl_context context = x.runtime->context();
    const cl_device_id device = x.runtime->device();
    const std::size_t color_bytes = color_buffer_bytes(w, h, format);
    depth_at = (color_bytes + 65535) / 65536 * 65536;
    if (!(why_not = memory.create(x.cu, x.device, depth_at + depth_buffer_bytes(w, h) + 4096)).empty()) return;
    // Sky and a depth ramp (the pass's time does not depend on the pixels' values).
    PerspectiveCamera lens;
    lens.aspect = float(w) / float(h);
    camera = make_camera_params(lens);
    ColorImage color(w, h, format);
    DepthImage depth(w, h);
    for (int y = 0; y < h; ++y)
      for (int px = 0; px < w; ++px) {
        color.set_pixel(px, y, {0.3f, 0.5f, 0.8f, 1.0f});
        depth.at(px, y) = y < h / 3 ? 1.0f : float(y) / float(h);
      }
    x.cu.cuMemsetD8(memory.ptr, 0, memory.size);
    x.cu.cuMemcpyHtoD(memory.ptr, color.data(), color_bytes);
    x.cu.cuMemcpyHtoD(memory.ptr + depth_at, depth.data(), depth.size_bytes());
    imported = std::make_unique<ExternalMemory>(context, device, memory.export_fd(), memory.size);
    ExternalFrameLayout layout;
    layout.width = w;
    layout.height = h;
    layout.format = format;
    layout.color_in = {imported.get(), 0, 0};
    layout.depth = {imported.get(), depth_at, 0};
    frame = std::make_unique<ExternalFrame>(context, device, layout);
    pass = std::make_unique<FogPass>(context, device);
    settings.density = 0.002f;
    pass->prepare(settings, camera, format);
  }
  std::size_t counter_at() const { return memory.size - 256; }
};

// One hand-over on the GPU, as the producer sees it: CUDA's stream is held at a gate, records
// `start`, runs `producer` (its signal and wait), records `stop`; the host meanwhile runs
// `consumer` (enqueues OpenCL's side), then opens the gate. Seconds from start to stop.
template <class Producer, class Consumer>
double hand_over(Interop& x, cuda::CUevent start, cuda::CUevent stop, Producer&& producer, Consumer&& consumer) {
  x.cu.cuLaunchHostFunc(x.stream, wait_for_gate, nullptr);
  x.cu.cuEventRecord(start, x.stream);
  producer();
  x.cu.cuEventRecord(stop, x.stream);
  consumer();
  gate.store(1, std::memory_order_release);
  x.cu.cuEventSynchronize(stop);
  float ms = 0;
  x.cu.cuEventElapsedTime(&ms, start, stop);
  return double(ms) * 1e-3;
}

struct CudaEvents {
  Interop& x;
  cuda::CUevent start = nullptr, stop = nullptr;
  explicit CudaEvents(Interop& i) : x(i) {
    x.cu.cuEventCreate(&start, 0);
    x.cu.cuEventCreate(&stop, 0);
  }
  ~CudaEvents() {
    x.cu.cuEventDestroy(start);
    x.cu.cuEventDestroy(stop);
  }
};

// CUDA's side of a frame: signal "ready", wait for "done".
void signal_ready(Interop& x) {
  cuda::CUDA_EXTERNAL_SEMAPHORE_SIGNAL_PARAMS signal{};
  x.cu.cuSignalExternalSemaphoresAsync(&x.cu_ready, &signal, 1, x.stream);
}
void wait_done(Interop& x, cuda::CUexternalSemaphore which) {
  cuda::CUDA_EXTERNAL_SEMAPHORE_WAIT_PARAMS wait{};
  x.cu.cuWaitExternalSemaphoresAsync(&which, &wait, 1, x.stream);
}

bool usable(benchmark::State& state, Interop& x, const SharedFrame* f = nullptr) {
  const std::string why = !x.why_not.empty() ? "no CUDA interop: " + x.why_not : f != nullptr ? f->why_not : "";
  if (!why.empty()) state.SkipWithError(why.c_str());
  return why.empty();
}

void BM_ExternalSignalToSignal(benchmark::State& state) {
  Interop& x = interop();
  if (!usable(state, x)) return;
  const ColorFormat format = state.range(2) != 0 ? ColorFormat::rgba16f : ColorFormat::rgba32f;
  SharedFrame f(x, int(state.range(0)), int(state.range(1)), format);
  if (!usable(state, x, &f)) return;
  const ExternalSync sync{{x.ready.get()}, {x.done.get()}, {}};
  CudaEvents ev(x);
  auto one_frame = [&] {
    return hand_over(
        x, ev.start, ev.stop,
        [&] {
          signal_ready(x);
          wait_done(x, x.cu_done);
        },
        [&] { clReleaseEvent(f.frame->enqueue(*f.pass, x.runtime->queue(), f.camera, f.settings, sync)); });
  };
  for (int i = 0; i < 3; ++i) one_frame();  // warm: first acquire, first kernel
  std::vector<double> times;
  for (auto _ : state) {
    times.push_back(one_frame());
    state.SetIterationTime(times.back());
  }
  // The deferred pass's kernel on the same frame (acquired and released, no semaphores): its
  // device time.
  std::vector<double> pass_s;
  for (int i = 0; i < 20; ++i) {
    cl_event e = nullptr;
    const cl_event last = f.frame->enqueue(x.profiling_queue, [&](const FrameBuffers& fb, const std::vector<cl_event>& w) {
      e = f.pass->enqueue(x.profiling_queue, fb, f.camera, f.settings, w);
      clRetainEvent(e);
      return e;
    });
    clWaitForEvents(1, &last);
    clReleaseEvent(last);
    cl_ulong t0 = 0, t1 = 0;
    clGetEventProfilingInfo(e, CL_PROFILING_COMMAND_START, sizeof t0, &t0, nullptr);
    clGetEventProfilingInfo(e, CL_PROFILING_COMMAND_END, sizeof t1, &t1, nullptr);
    clReleaseEvent(e);
    pass_s.push_back(double(t1 - t0) * 1e-9);
  }
  std::nth_element(pass_s.begin(), pass_s.begin() + 10, pass_s.end());
  std::nth_element(times.begin(), times.begin() + std::ptrdiff_t(times.size() / 2), times.end());
  state.counters["pass_ms"] = pass_s[10] * 1e3;
  state.counters["median_ms"] = times[times.size() / 2] * 1e3;
  state.counters["over_pass_us"] = (times[times.size() / 2] - pass_s[10]) * 1e6;
}

BENCHMARK(BM_ExternalSignalToSignal)
    ->ArgNames({"w", "h", "f16"})
    ->Args({1920, 1080, 0})
    ->Args({1920, 1080, 1})
    ->Args({3840, 2160, 0})
    ->Args({3840, 2160, 1})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(200);

// Where the hand-over's time goes, at 1080p RGBA16F:
//   0  CUDA signals and waits on one semaphore alone (no OpenCL)
//   1  OpenCL waits and signals (clEnqueueWaitSemaphoresKHR, clEnqueueSignalSemaphoresKHR, nothing
//      between)
//   2  1 plus acquire and release around a marker (ExternalFrame::enqueue of no pass)
//   3  the whole ExternalFrame::enqueue of BM_ExternalSignalToSignal
//   4  no semaphores: the host waits for the producer's point (a CUDA event), enqueues the frame,
//      waits for its event, then lets the producer's stream go on
//   5  OpenCL signals alone (CUDA waits from the moment the host has flushed the signal)
//   6  1 on a queue without profiling
//   7  OpenCL waits for "ready", then writes a counter into the imported memory
//      (clEnqueueFillBuffer), which CUDA waits for on the GPU (cuStreamWaitValue32): no OpenCL
//      signal
void BM_ExternalHandOverParts(benchmark::State& state) {
  Interop& x = interop();
  if (!usable(state, x)) return;
  const int part = int(state.range(0));
  SharedFrame f(x, 1920, 1080, ColorFormat::rgba16f);
  if (!usable(state, x, &f)) return;
  const cl_context context = x.runtime->context();
  const cl_device_id device = x.runtime->device();
  const cl_command_queue queue = x.runtime->queue();
  cl_platform_id platform = nullptr;
  clGetDeviceInfo(device, CL_DEVICE_PLATFORM, sizeof platform, &platform, nullptr);
  auto fn = [&](const char* name) { return clGetExtensionFunctionAddressForPlatform(platform, name); };
  const auto wait_fn = reinterpret_cast<clEnqueueWaitSemaphoresKHR_fn>(fn("clEnqueueWaitSemaphoresKHR"));
  const auto signal_fn = reinterpret_cast<clEnqueueSignalSemaphoresKHR_fn>(fn("clEnqueueSignalSemaphoresKHR"));
  const auto acquire_fn =
      reinterpret_cast<clEnqueueAcquireExternalMemObjectsKHR_fn>(fn("clEnqueueAcquireExternalMemObjectsKHR"));
  const auto release_fn =
      reinterpret_cast<clEnqueueReleaseExternalMemObjectsKHR_fn>(fn("clEnqueueReleaseExternalMemObjectsKHR"));
  cl_int err = CL_SUCCESS;
  const cl_command_queue plain_queue = clCreateCommandQueueWithProperties(context, device, nullptr, &err);
  const ExternalSync sync{{x.ready.get()}, {x.done.get()}, {}};
  cl_semaphore_khr ready = x.ready->handle(), done = x.done->handle();
  cl_uint counter = 0;
  CudaEvents ev(x);
  auto cl_wait_signal = [&](cl_command_queue q) {
    wait_fn(q, 1, &ready, nullptr, 0, nullptr, nullptr);
    signal_fn(q, 1, &done, nullptr, 0, nullptr, nullptr);
    clFlush(q);
  };
  auto both_ways = [&] {
    signal_ready(x);
    wait_done(x, x.cu_done);
  };
  auto one_frame = [&]() -> double {
    switch (part) {
      case 0:
        return hand_over(
            x, ev.start, ev.stop,
            [&] {
              signal_ready(x);
              wait_done(x, x.cu_ready);
            },
            [] {});
      case 1: return hand_over(x, ev.start, ev.stop, both_ways, [&] { cl_wait_signal(queue); });
      case 2:
        return hand_over(x, ev.start, ev.stop, both_ways, [&] {
          clReleaseEvent(f.frame->enqueue(
              queue,
              [&](const FrameBuffers&, const std::vector<cl_event>& w) {
                cl_event e = nullptr;
                clEnqueueMarkerWithWaitList(queue, cl_uint(w.size()), w.data(), &e);
                return e;
              },
              sync));
        });
      case 3:
        return hand_over(x, ev.start, ev.stop, both_ways, [&] {
          clReleaseEvent(f.frame->enqueue(*f.pass, queue, f.camera, f.settings, sync));
        });
      case 4: {
        x.cu.cuEventRecord(ev.start, x.stream);
        x.cu.cuLaunchHostFunc(x.stream, wait_for_gate, nullptr);
        x.cu.cuEventRecord(ev.stop, x.stream);
        x.cu.cuEventSynchronize(ev.start);
        cl_event e = f.frame->enqueue(*f.pass, queue, f.camera, f.settings);
        clWaitForEvents(1, &e);
        clReleaseEvent(e);
        gate.store(1, std::memory_order_release);
        x.cu.cuEventSynchronize(ev.stop);
        float ms = 0;
        x.cu.cuEventElapsedTime(&ms, ev.start, ev.stop);
        return double(ms) * 1e-3;
      }
      case 5:
        return hand_over(x, ev.start, ev.stop, [&] { wait_done(x, x.cu_done); }, [&] {
          signal_fn(queue, 1, &done, nullptr, 0, nullptr, nullptr);
          clFlush(queue);
        });
      case 6: return hand_over(x, ev.start, ev.stop, both_ways, [&] { cl_wait_signal(plain_queue); });
      default:
        ++counter;
        return hand_over(
            x, ev.start, ev.stop,
            [&] {
              signal_ready(x);
              x.cu.cuStreamWaitValue32(x.stream, f.memory.ptr + f.counter_at(), counter, 0);
            },
            [&] {
              cl_event waited = nullptr, filled = nullptr;
              const cl_mem whole = f.imported->buffer();
              wait_fn(queue, 1, &ready, nullptr, 0, nullptr, &waited);
              acquire_fn(queue, 1, &whole, 1, &waited, nullptr);
              clEnqueueFillBuffer(queue, whole, &counter, sizeof counter, f.counter_at(), sizeof counter, 0, nullptr,
                                  &filled);
              release_fn(queue, 1, &whole, 1, &filled, nullptr);
              clReleaseEvent(waited);
              clReleaseEvent(filled);
              clFlush(queue);
            });
    }
  };
  for (int i = 0; i < 3; ++i) one_frame();
  for (auto _ : state) state.SetIterationTime(one_frame());
  clReleaseCommandQueue(plain_queue);
}

BENCHMARK(BM_ExternalHandOverParts)
    ->ArgName("part")
    ->DenseRange(0, 7)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(200);

}  // namespace

BENCHMARK_MAIN();
