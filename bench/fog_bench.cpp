// Scalar C++ vs OpenCL vs a memory-copy baseline on the demo scene, in one run so ratios are
// meaningful. Every benchmark sets bytes processed; fog benchmarks also report their max color
// error against the float64 path (counter max_err), so speed always comes with its error.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>

#include <benchmark/benchmark.h>

#include "fogcl/demo_scene.h"
#include "fogcl/fogcl.h"

namespace {

using namespace fogcl;

// Bytes a fog pass moves per pixel: color in and out, depth in.
std::size_t frame_bytes(const DemoFrame& f) {
  return f.color.size_bytes() * 2 + f.depth.size_bytes();
}

const DemoFrame& frame(int w, int h, ColorFormat format) {
  static std::map<std::tuple<int, int, ColorFormat>, DemoFrame> cache;
  auto key = std::make_tuple(w, h, format);
  auto it = cache.find(key);
  if (it == cache.end()) it = cache.emplace(key, render_demo_scene(w, h, {}, {}, format)).first;
  return it->second;
}

FogSettings settings(int mode, bool distance) {
  FogSettings s;
  s.mode = mode == 0 ? FogMode::linear : mode == 1 ? FogMode::exp : FogMode::exp2;
  s.start = 2.0f;
  s.end = 70.0f;
  s.density = 0.03f;
  s.metric = distance ? FogMetric::distance : FogMetric::depth;
  return s;
}

double max_error(const ColorImage& out, const DemoFrame& f, const FogSettings& s) {
  const FogResult<double> ref = fog_scalar<double>(f.color, f.depth, f.params, s);
  double worst = 0;
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x)
      for (int c = 0; c < 3; ++c)
        worst = std::max(worst, std::fabs(double(out.pixel(x, y)[c]) -
                                          ref.rgba[4 * (std::size_t(y) * out.width() + x) + c]));
  return worst;
}

void set_common(benchmark::State& state, const DemoFrame& f) {
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(frame_bytes(f)));
  state.counters["Mpix/s"] = benchmark::Counter(double(f.color.pixel_count()) * double(state.iterations()),
                                                benchmark::Counter::kIsRate);
}

// The physical limit of a memory-bound pass: copying the same bytes (1 thread).
void BM_Memcpy(benchmark::State& state) {
  const DemoFrame& f = frame(int(state.range(0)), int(state.range(1)), ColorFormat::rgba32f);
  ColorImage out(f.color.width(), f.color.height());
  DepthImage depth_copy(f.depth.width(), f.depth.height());
  for (auto _ : state) {
    std::memcpy(out.data(), f.color.data(), f.color.size_bytes());
    std::memcpy(depth_copy.data(), f.depth.data(), f.depth.size_bytes());
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  set_common(state, f);
}

void BM_Scalar(benchmark::State& state) {
  const DemoFrame& f = frame(int(state.range(0)), int(state.range(1)), ColorFormat(state.range(4)));
  const FogSettings s = settings(int(state.range(2)), state.range(3) != 0);
  ColorImage out;
  for (auto _ : state) {
    apply_fog_scalar(f.color, f.depth, out, f.params, s);
    benchmark::DoNotOptimize(out.data());
  }
  set_common(state, f);
  state.counters["max_err"] = max_error(out, f, s);
}

// OpenCL through the integration API on zero-copy buffers; device time from profiling events.
void BM_OpenCL(benchmark::State& state) {
  static std::unique_ptr<Runtime> rt;
  if (!rt) {
    try {
      rt = std::make_unique<Runtime>();
    } catch (const std::exception& e) {
      state.SkipWithError(e.what());
      return;
    }
  }
  const DemoFrame& f = frame(int(state.range(0)), int(state.range(1)), ColorFormat(state.range(4)));
  const FogSettings s = settings(int(state.range(2)), state.range(3) != 0);
  ColorImage out(f.color.width(), f.color.height(), f.color.format());
  FogPass pass(*rt);
  const cl_mem_flags host = rt->is_cpu() ? CL_MEM_USE_HOST_PTR : CL_MEM_COPY_HOST_PTR;
  FrameBuffers fb;
  fb.width = f.color.width();
  fb.height = f.color.height();
  fb.format = f.color.format();
  fb.color_in = cl::Buffer(rt->context(), CL_MEM_READ_ONLY | host, f.color.size_bytes(), const_cast<void*>(f.color.data()));
  fb.depth = cl::Buffer(rt->context(), CL_MEM_READ_ONLY | host, f.depth.size_bytes(), const_cast<float*>(f.depth.data()));
  fb.color_out = cl::Buffer(rt->context(), CL_MEM_WRITE_ONLY | host, out.size_bytes(), out.data());
  pass.enqueue(rt->queue(), fb, f.params, s).wait();  // builds the variant
  for (auto _ : state) {
    cl::Event e = pass.enqueue(rt->queue(), fb, f.params, s);
    e.wait();
    const double ns = double(e.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                             e.getProfilingInfo<CL_PROFILING_COMMAND_START>());
    state.SetIterationTime(ns * 1e-9);
  }
  rt->queue().enqueueReadBuffer(fb.color_out, CL_TRUE, 0, out.size_bytes(), out.data());
  set_common(state, f);
  state.counters["max_err"] = max_error(out, f, s);
}

void Args(benchmark::internal::Benchmark* b, bool with_variants) {
  b->ArgNames({"w", "h", "mode", "dist", "f16"});
  for (auto [w, h] : {std::pair{1920, 1080}}) {
    if (!with_variants) {
      b->Args({w, h, 0, 0, 0});
      continue;
    }
    for (int mode : {0, 1, 2})
      for (int dist : {0, 1})
        for (int f16 : {0, 1}) b->Args({w, h, mode, dist, f16});
  }
  b->Unit(benchmark::kMillisecond);
}

BENCHMARK(BM_Memcpy)->Apply([](auto* b) { Args(b, false); });
BENCHMARK(BM_Scalar)->Apply([](auto* b) { Args(b, true); });
BENCHMARK(BM_OpenCL)->Apply([](auto* b) { Args(b, true); })->UseManualTime();

}  // namespace

BENCHMARK_MAIN();
