// Volumetric pass benchmarks (Google Benchmark, one binary, so ratios come from one run): the demo
// scene with its four fog volumes, 64 steps, noise on.
//   BM_VolumeDevice/integrator/divisor/noise_image/width   OpenCL device time of the whole pass
//        (profiling events; march = from a marker enqueued just before it to the composite's start,
//        composite = the composite kernel), counters march_ms, composite_ms and
//        steps_x_pixels_per_s = steps x target pixels / march time; max_err against the scalar
//        double path at 480x270
//   BM_VolumeHostCall/integrator/divisor/noise_image/width   the convenience call, host images in
//        and out (enqueue to finish): on a GPU the host round trip, upload + pass + download
//   BM_VolumeScalar/integrator/width   the scalar float path, one thread
//   BM_VolumeNothingVisible   enqueue of a frame whose volumes are all culled: no kernel, the
//        host-side cost of the call
// Widths: 480 (480x270: scalar and OpenCL in the same run) and 1920 (1080p, OpenCL only).
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <tuple>

#include <benchmark/benchmark.h>

#include "fogcl/demo_scene.h"
#include "fogcl/fogcl.h"
#include "fogcl/volume_pass.h"
#include "fogcl/volume_scalar.h"
#include "runtime/clhpp.h"

namespace {

using namespace fogcl;
constexpr int kSteps = 64;

int height_of(int width) { return width * 9 / 16; }

const DemoFrame& frame(int width) {
  static std::map<int, DemoFrame> cache;
  auto it = cache.find(width);
  if (it == cache.end()) it = cache.emplace(width, render_demo_scene(width, height_of(width))).first;
  return it->second;
}

VolumeScene scene(VolumeIntegrator integrator) {
  const DemoView view;
  VolumeScene s;
  s.pose.eye = view.eye;
  s.pose.forward = view.target - view.eye;
  s.light = demo_light();
  s.volumes = demo_fog_volumes(integrator);
  return s;
}

VolumeSettings settings(VolumeIntegrator integrator, int divisor, bool image) {
  VolumeSettings s;
  s.integrator = integrator;
  s.steps = kSteps;
  s.resolution_divisor = divisor;
  s.noise_sampling = image ? NoiseSampling::image : NoiseSampling::buffer;
  return s;
}

// The scalar double path at 480x270, per variant (the reference of max_err).
const VolumeResult<double>& reference(VolumeIntegrator integrator, int divisor) {
  static std::map<std::pair<int, int>, VolumeResult<double>> cache;
  const auto key = std::make_pair(int(integrator), divisor);
  auto it = cache.find(key);
  if (it == cache.end()) {
    VolumeSettings s = settings(integrator, divisor, false);
    const DemoFrame& f = frame(480);
    it = cache.emplace(key, volumes_scalar<double>(f.color, f.depth, f.params, scene(integrator), s)).first;
  }
  return it->second;
}

Runtime& runtime() {
  static Runtime rt;
  return rt;
}

double event_ms(const cl::Event& a, cl_profiling_info from, const cl::Event& b, cl_profiling_info to) {
  cl_ulong t0 = 0, t1 = 0;
  a.getProfilingInfo(from, &t0);
  b.getProfilingInfo(to, &t1);
  return double(t1 - t0) * 1e-6;
}

void BM_VolumeDevice(benchmark::State& state) {
  const auto integrator = VolumeIntegrator(state.range(0));
  const int divisor = int(state.range(1)), width = int(state.range(3));
  const bool image = state.range(2) != 0;
  const DemoFrame& f = frame(width);
  const VolumeScene s = scene(integrator);
  const VolumeSettings st = settings(integrator, divisor, image);
  VolumePass pass(runtime());
  pass.prepare(f.params, s, st, ColorFormat::rgba32f);
  const cl::Context ctx = wrap(runtime().context());
  const cl::CommandQueue queue(ctx, wrap(runtime().device()), CL_QUEUE_PROFILING_ENABLE);
  const cl::Buffer color(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, f.color.size_bytes(), const_cast<void*>(f.color.data()));
  const cl::Buffer depth(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, f.depth.size_bytes(), const_cast<float*>(f.depth.data()));
  const cl::Buffer out(ctx, CL_MEM_READ_WRITE, f.color.size_bytes());
  FrameBuffers fb;
  fb.width = f.color.width();
  fb.height = f.color.height();
  fb.color_in = color();
  fb.depth = depth();
  fb.color_out = out();
  const float max_eye = max_eye_depth(f.depth, f.params);
  adopt(pass.enqueue(queue(), fb, f.params, s, st, nullptr, {}, max_eye)).wait();  // uploads the noise
  double march_ms = 0, composite_ms = 0;
  for (auto _ : state) {
    cl::Event before;
    queue.enqueueMarkerWithWaitList(nullptr, &before);
    const cl::Event done = adopt(pass.enqueue(queue(), fb, f.params, s, st, nullptr, {}, max_eye));
    done.wait();
    const double m = event_ms(before, CL_PROFILING_COMMAND_END, done, CL_PROFILING_COMMAND_START);
    const double c = event_ms(done, CL_PROFILING_COMMAND_START, done, CL_PROFILING_COMMAND_END);
    march_ms += m;
    composite_ms += c;
    state.SetIterationTime((m + c) * 1e-3);
  }
  const double n = double(state.iterations());
  const double low_pixels = double((fb.width + divisor - 1) / divisor) * double((fb.height + divisor - 1) / divisor);
  state.counters["march_ms"] = march_ms / n;
  state.counters["composite_ms"] = composite_ms / n;
  state.counters["steps_x_pixels_per_s"] = kSteps * low_pixels / (march_ms / n * 1e-3);
  if (width == 480) {
    ColorImage result(fb.width, fb.height);
    queue.enqueueReadBuffer(out, CL_TRUE, 0, result.size_bytes(), result.data());
    state.counters["max_err"] = max_abs_rgb_error(result, reference(integrator, divisor));
  }
}

void BM_VolumeHostCall(benchmark::State& state) {
  const auto integrator = VolumeIntegrator(state.range(0));
  const int divisor = int(state.range(1)), width = int(state.range(3));
  const DemoFrame& f = frame(width);
  const VolumeScene s = scene(integrator);
  const VolumeSettings st = settings(integrator, divisor, state.range(2) != 0);
  VolumePass pass(runtime());
  ColorImage out;
  pass.apply(f.color, f.depth, out, f.params, s, st);  // builds the variant, uploads the noise
  for (auto _ : state) pass.apply(f.color, f.depth, out, f.params, s, st);
}

void BM_VolumeScalar(benchmark::State& state) {
  const auto integrator = VolumeIntegrator(state.range(0));
  const int width = int(state.range(1));
  const DemoFrame& f = frame(width);
  const VolumeScene s = scene(integrator);
  const VolumeSettings st = settings(integrator, 2, false);
  ColorImage out;
  for (auto _ : state) apply_volumes_scalar(f.color, f.depth, out, f.params, s, st);
  const double low_pixels = double((width + 1) / 2) * double((height_of(width) + 1) / 2);
  state.counters["steps_x_pixels_per_s"] =
      benchmark::Counter(kSteps * low_pixels * double(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["max_err"] = max_abs_rgb_error(out, reference(integrator, 2));
}

void BM_VolumeNothingVisible(benchmark::State& state) {
  const DemoFrame& f = frame(1920);
  VolumeScene s = scene(VolumeIntegrator::stylized);
  for (FogVolume& v : s.volumes) v.center = s.pose.eye - 100.0f * glm::normalize(s.pose.forward);  // behind
  const VolumeSettings st = settings(VolumeIntegrator::stylized, 2, false);
  VolumePass pass(runtime());
  const cl::Context ctx = wrap(runtime().context());
  const cl::CommandQueue queue(ctx, wrap(runtime().device()));
  const cl::Buffer color(ctx, CL_MEM_READ_WRITE, f.color.size_bytes());
  const cl::Buffer depth(ctx, CL_MEM_READ_ONLY, f.depth.size_bytes());
  FrameBuffers fb;
  fb.width = f.color.width();
  fb.height = f.color.height();
  fb.color_in = fb.color_out = color();  // in place: a marker
  fb.depth = depth();
  for (auto _ : state) adopt(pass.enqueue(queue(), fb, f.params, s, st)).wait();
  state.counters["dispatches"] = double(pass.stats().march_dispatches + pass.stats().composite_dispatches);
}

}  // namespace

BENCHMARK(BM_VolumeDevice)
    ->ArgNames({"integrator", "divisor", "noise_image", "width"})
    ->ArgsProduct({{0, 1}, {1, 2, 4}, {0, 1}, {480}})
    ->ArgsProduct({{0, 1}, {1, 2}, {0, 1}, {1920}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);
BENCHMARK(BM_VolumeHostCall)
    ->ArgNames({"integrator", "divisor", "noise_image", "width"})
    ->ArgsProduct({{0, 1}, {1, 2}, {0, 1}, {1920}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);
BENCHMARK(BM_VolumeScalar)
    ->ArgNames({"integrator", "width"})
    ->ArgsProduct({{0, 1}, {480}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK(BM_VolumeNothingVisible)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
