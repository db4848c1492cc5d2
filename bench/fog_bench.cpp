// fogcl benchmarks (Google Benchmark, one binary, so ratios come from one run).
//
// Per resolution (1280x720, 1920x1080, 3840x2160), fog mode (linear, exp, exp2), metric (depth,
// distance) and color storage (RGBA32F, RGBA16F):
//   BM_Memcpy, BM_CopyLoop, BM_CopyStream, BM_CopyHalide  the same bytes copied with 1 and 2
//                        threads by glibc's memcpy, a loop of ordinary vector stores, a loop of
//                        non-temporal stores and a Halide copy pipeline (bench/copy_peer.h): the
//                        ceiling is the fastest of them, whichever the machine's caches favour
//   BM_Scalar            fogcl's scalar C++ path (one thread, as built for users)
//   BM_OpenMPSimd        the OpenMP + SIMD C++ peer (-O3 -march=native, 2 threads)
//   BM_OpenMPSimdFastMath  the same with -ffast-math (vectorised exp2; no NaN/Inf guarantees)
//   BM_Halide            the Halide 14 peer (JIT for the host, 2 threads; built when Halide is
//                        found): one whole realize() per iteration, compiled before the loop
//   BM_OpenCLDevice      the OpenCL pass, zero-copy buffers, device time from profiling events
//   BM_OpenCLHostCall    the convenience call, host images in and out (enqueue to finish); on a
//                        GPU the host round trip: upload + kernel + download. kernel_ms: its own
//                        kernel's profiling time; call_vs_kernel: the call over it, same iterations
//   BM_OpenCLHostCallPinned  the same with the host images in pinned memory (pinned_color_image):
//                        on a GPU no staging copy, the images themselves cross the bus (exp2 only)
//   BM_DeviceCopy        clEnqueueCopyBuffer of the pass's color and depth into device buffers
//                        (profiling events): the device's own bandwidth ceiling, for GPUs
//   BM_PinnedTransfer    the bytes a host round trip moves (color and depth up, color down) between
//                        host memory and device buffers, from pageable (host 0) or pinned (host 1)
//                        memory: the bus's ceiling of BM_OpenCLHostCall and BM_VolumeHostCall
//   BM_OpenCLDeviceCacheResident  BM_OpenCLDevice on a 512x256 frame that stays in the caches
//                        (its compute cost; BM_Memcpy also runs at 512x256)
// Counters: bytes_per_second; vs_copy = ceiling_ms / (this time), ceiling_ms the fastest 2-thread
// copy of the same bytes (memcpy2_ms, loop_copy2_ms, stream_copy2_ms, halide_copy2_ms, each
// measured interleaved with this benchmark's iterations, one way after each in turn; ceiling_way
// names it); frame_vs_llc = the pass's bytes / the LLC the OS reports; ns_per_16px; max_err =
// max |color - float64 path| (speed always comes with its error). BM_OpenCLDevice also times a
// device-side copy of color and depth (outside its timing; after each iteration on a GPU, five
// times after the loop on a CPU device, whose LLC the extra buffers would flush): copy_ms, and
// bw_vs_copy = (pass bytes / pass time) / (copied bytes read + written / copy time).
// BM_OpticalDepth: exp fog at density * d ~ 1, 1e2 (denormal factors), 1e3, 1e20.
// Start-up: BM_ProgramBuild (cold: a never-seen option string; warm: PoCL's disk cache),
// BM_FirstDispatch, BM_DispatchOverhead (1x1 frame), BM_StartToFirstFrame (whole process path:
// platform, context, build, one 1080p frame; run it in a fresh process with an empty
// POCL_CACHE_DIR for the cold figure). bench/run.sh runs everything, PoCL with 1 and 2 threads.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <thread>
#include <tuple>
#include <vector>

#include <benchmark/benchmark.h>

#include "deferred_fog_cl.h"
#include "fogcl/demo_scene.h"
#include "fogcl/fogcl.h"
#include "runtime/clhpp.h"
#include "runtime/frame_buffers.h"
#include "copy_peer.h"
#include "openmp_peer.h"
#ifdef FOGCL_HAVE_HALIDE
#include <dlfcn.h>

#include "halide_peer.h"
#endif

namespace {

using namespace fogcl;
using Clock = std::chrono::steady_clock;

constexpr int kThreads = 2;  // the CI / development machine

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

const DemoFrame& frame(int w, int h, ColorFormat format) {
  static std::map<std::tuple<int, int, ColorFormat>, DemoFrame> cache;
  const auto key = std::make_tuple(w, h, format);
  auto it = cache.find(key);
  if (it == cache.end()) {
    it = cache.emplace(key, render_demo_scene(w, h, {}, {}, format)).first;
    const DemoView view;  // height fog (modes 3, 4) needs the pose; the other modes ignore it
    it->second.params.pose = CameraPose{view.eye, view.target - view.eye, glm::vec3(0.0f, 1.0f, 0.0f)};
  }
  return it->second;
}

// Bytes a fog pass moves: color read and written, depth read.
std::size_t pass_bytes(const DemoFrame& f) { return 2 * f.color.size_bytes() + f.depth.size_bytes(); }

#ifdef FOGCL_HAVE_HALIDE
// The Halide peer's module (bench/CMakeLists.txt), loaded on first use with its own LLVM kept out
// of the global scope (RTLD_LOCAL, and RTLD_DEEPBIND so that it binds to its own dependencies).
struct HalidePeer {
  bench::HalidePrepare* prepare = nullptr;
  bench::HalideFog* fog = nullptr;
  bench::HalideCopy* copy = nullptr;
  std::string error;
};

const HalidePeer& halide_peer() {
  static const HalidePeer peer = [] {
    HalidePeer p;
    void* module = dlopen(FOGCL_HALIDE_PEER_MODULE, RTLD_NOW | RTLD_LOCAL | RTLD_DEEPBIND);
    if (module == nullptr) {
      p.error = std::string("cannot load the Halide peer: ") + dlerror();
      return p;
    }
    p.prepare = reinterpret_cast<bench::HalidePrepare*>(dlsym(module, "fogcl_halide_prepare"));
    p.fog = reinterpret_cast<bench::HalideFog*>(dlsym(module, "fogcl_halide_fog"));
    p.copy = reinterpret_cast<bench::HalideCopy*>(dlsym(module, "fogcl_halide_copy"));
    if (p.prepare == nullptr || p.fog == nullptr || p.copy == nullptr) p.error = "the Halide peer module lacks its entry points";
    return p;
  }();
  return peer;
}
#endif

// The copy ceiling (bench/copy_peer.h): the pass's bytes (color in -> out, depth -> scratch)
// copied on the pass's threads in each of these ways; the fastest is the ceiling of every
// "vs copy" ratio (vs_copy). Halide's only when its module loads.
enum CopyWay { kCopyMemcpy, kCopyLoop, kCopyStream, kCopyHalide, kCopyWays };
const char* const kCopyCounters[kCopyWays] = {"memcpy2_ms", "loop_copy2_ms", "stream_copy2_ms", "halide_copy2_ms"};

bool copy_way_available(int way) {
#ifdef FOGCL_HAVE_HALIDE
  if (way == kCopyHalide) return halide_peer().error.empty();
#endif
  return way < kCopyHalide;
}

void copy_bytes(const DemoFrame& f, ColorImage& out, DepthImage& scratch, int threads, int way = kCopyMemcpy) {
#ifdef FOGCL_HAVE_HALIDE
  if (way == kCopyHalide) {
    const auto& peer = halide_peer();
    peer.copy(f.color.data(), out.data(), f.color.size_bytes() / std::size_t(f.color.height()), f.color.height(), threads);
    peer.copy(f.depth.data(), scratch.data(), f.depth.size_bytes() / std::size_t(f.depth.height()), f.depth.height(), threads);
    return;
  }
#endif
  const auto kind = way == kCopyLoop ? bench::CopyKind::loop : way == kCopyStream ? bench::CopyKind::stream : bench::CopyKind::memcpy;
  bench::run_parts(threads, [&](int t) {
    const std::size_t cb = f.color.size_bytes(), db = f.depth.size_bytes();
    const std::size_t c0 = cb * t / threads / 64 * 64, c1 = t + 1 == threads ? cb : cb * (t + 1) / threads / 64 * 64;
    const std::size_t d0 = db * t / threads / 64 * 64, d1 = t + 1 == threads ? db : db * (t + 1) / threads / 64 * 64;
    bench::copy_span(kind, static_cast<char*>(out.data()) + c0, static_cast<const char*>(f.color.data()) + c0, c1 - c0);
    bench::copy_span(kind, reinterpret_cast<char*>(scratch.data()) + d0, reinterpret_cast<const char*>(f.depth.data()) + d0, d1 - d0);
  });
}

// Copy times of each way [s], summed over the copies made: the ceiling's figures.
struct CopyTimes {
  double sum[kCopyWays] = {};
  int count[kCopyWays] = {};
  int next = 0;

  // One copy of `way`, timed.
  void copy(const DemoFrame& f, ColorImage& out, DepthImage& scratch, int way) {
    const auto a = Clock::now();
    copy_bytes(f, out, scratch, kThreads, way);
    sum[way] += seconds_since(a);
    ++count[way];
  }
  // One copy of the next available way (round robin), timed.
  void copy_one(const DemoFrame& f, ColorImage& out, DepthImage& scratch) {
    while (!copy_way_available(next % kCopyWays)) ++next;
    copy(f, out, scratch, next++ % kCopyWays);
  }
  // Copies until every available way has `n` copies.
  void fill(const DemoFrame& f, ColorImage& out, DepthImage& scratch, int n) {
    for (int way = 0; way < kCopyWays; ++way)
      while (copy_way_available(way) && count[way] < n) copy(f, out, scratch, way);
  }
  double mean(int way) const { return count[way] ? sum[way] / count[way] : 0.0; }
  // The fastest way's mean time [s] and the way.
  std::pair<double, int> ceiling() const {
    std::pair<double, int> best{0.0, -1};
    for (int way = 0; way < kCopyWays; ++way)
      if (count[way] && (best.second < 0 || mean(way) < best.first)) best = {mean(way), way};
    return best;
  }
};

// Each way's copy of a frame's bytes on the pass's threads, 15 times each, for the rows whose
// copies are not interleaved with their iterations.
CopyTimes copy_ceiling(const DemoFrame& f) {
  ColorImage out(f.color.width(), f.color.height(), f.color.format());
  DepthImage scratch(f.depth.width(), f.depth.height());
  CopyTimes t;
  t.fill(f, out, scratch, 1);  // first touch, JIT
  t = CopyTimes{};
  t.fill(f, out, scratch, 15);
  return t;
}

// The last-level cache the OS reports [bytes] (0: unknown), from sysfs.
std::size_t llc_bytes() {
  static const std::size_t bytes = [] {
    std::size_t best = 0;
    for (int i = 0; i < 8; ++i) {
      const std::string dir = "/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(i) + "/";
      std::FILE* level = std::fopen((dir + "level").c_str(), "r");
      std::FILE* size = std::fopen((dir + "size").c_str(), "r");
      int l = 0;
      unsigned long long kib = 0;
      char unit = 'K';
      if (level != nullptr && size != nullptr && std::fscanf(level, "%d", &l) == 1 &&
          std::fscanf(size, "%llu%c", &kib, &unit) >= 1 && l >= 2)
        best = std::size_t(kib) << (unit == 'M' ? 20 : 10);
      if (level != nullptr) std::fclose(level);
      if (size != nullptr) std::fclose(size);
    }
    return best;
  }();
  return bytes;
}

// clEnqueueCopyBuffer of a frame's color and depth into scratch buffers of the same device: the
// device's copy bandwidth over the bytes the pass touches. Buffers live in device memory (no host
// pointer), as a renderer's own buffers do.
class DeviceCopy {
 public:
  DeviceCopy(const cl::Context& ctx, const DemoFrame& f)
      : color_bytes_(f.color.size_bytes()), depth_bytes_(f.depth.size_bytes()),
        color_in_(ctx, CL_MEM_READ_WRITE, color_bytes_), color_out_(ctx, CL_MEM_READ_WRITE, color_bytes_),
        depth_in_(ctx, CL_MEM_READ_WRITE, depth_bytes_), depth_out_(ctx, CL_MEM_READ_WRITE, depth_bytes_) {}

  // Seconds from the first copy's start to the second's end (profiling events).
  double seconds(const cl::CommandQueue& queue) const {
    cl::Event a, b;
    queue.enqueueCopyBuffer(color_in_, color_out_, 0, 0, color_bytes_, nullptr, &a);
    queue.enqueueCopyBuffer(depth_in_, depth_out_, 0, 0, depth_bytes_, nullptr, &b);
    b.wait();
    return double(b.getProfilingInfo<CL_PROFILING_COMMAND_END>() - a.getProfilingInfo<CL_PROFILING_COMMAND_START>()) * 1e-9;
  }

  // Bytes a copy reads and writes.
  std::size_t bytes_moved() const { return 2 * (color_bytes_ + depth_bytes_); }

 private:
  std::size_t color_bytes_, depth_bytes_;
  cl::Buffer color_in_, color_out_, depth_in_, depth_out_;
};

// One DeviceCopy per frame, kept across benchmark runs (4K buffers are 330 MB of device memory).
const DeviceCopy& device_copy(const cl::Context& ctx, const DemoFrame& f) {
  static std::map<const DemoFrame*, std::unique_ptr<DeviceCopy>> copies;
  auto& c = copies[&f];
  if (!c) c = std::make_unique<DeviceCopy>(ctx, f);
  return *c;
}

struct Case {
  int w, h;
  FogSettings settings;
  ColorFormat format;
};

Case case_of(const benchmark::State& s) {
  Case c{int(s.range(0)), int(s.range(1)), {}, s.range(4) ? ColorFormat::rgba16f : ColorFormat::rgba32f};
  c.settings.mode = s.range(2) == 0 ? FogMode::linear : s.range(2) == 1 ? FogMode::exp : FogMode::exp2;
  c.settings.start = 2.0f;
  c.settings.end = 70.0f;
  c.settings.density = 0.03f;
  c.settings.metric = s.range(3) ? FogMetric::distance : FogMetric::depth;
  c.settings.color = glm::vec3(0.62f, 0.68f, 0.76f);
  // Height fog (docs/DESIGN.md §6): 3 a valley fog (grey, falloff); 4 an atmospheric haze (per
  // channel, falloff, a sun lobe, the sky fogged as an infinite ray). dist does not apply.
  if (s.range(2) >= 3) {
    c.settings.mode = FogMode::height;
    c.settings.density = 0.08f;
    c.settings.height.falloff = 0.6f;
    if (s.range(2) == 4) {
      c.settings.height.extinction = glm::vec3(0.01f, 0.02f, 0.045f);
      c.settings.height.falloff = 0.05f;
      c.settings.fog_skybox = true;
      SunLobe sun;
      sun.direction = glm::vec3(0.35f, 0.3f, 1.0f);
      sun.color = glm::vec3(1.5f, 1.2f, 0.8f);
      sun.exponent = 12.0f;
      c.settings.height.sun = sun;
    }
  }
  return c;
}

double max_error(const ColorImage& out, const DemoFrame& f, const FogSettings& s) {
  return max_abs_rgb_error(out, fog_scalar<double>(f.color, f.depth, f.params, s));
}

// Per-iteration seconds of the timed loop: manual time if set, else real time. copies: the copy
// ceiling's ways over the same bytes, measured in the same loop (see timed_fog) or apart.
// Counters: each way's 2-thread copy time (memcpy2_ms, loop_copy2_ms, stream_copy2_ms,
// halide_copy2_ms), ceiling_ms (the fastest of them) and ceiling_way (0 memcpy, 1 loop, 2 stream,
// 3 Halide), vs_copy = ceiling_ms / this time, frame_vs_llc = the pass's bytes / the last-level
// cache the OS reports, ns_per_16px: the time per block of 16 pixels (a CPU device's work-item),
// comparable across frame sizes.
void finish(benchmark::State& state, const DemoFrame& f, double seconds_per_iteration, const CopyTimes& copies) {
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(pass_bytes(f)));
  for (int way = 0; way < kCopyWays; ++way)
    if (copies.count[way]) state.counters[kCopyCounters[way]] = copies.mean(way) * 1e3;
  const auto [ceiling, way] = copies.ceiling();
  state.counters["ceiling_ms"] = ceiling * 1e3;
  state.counters["ceiling_way"] = way;
  state.counters["vs_copy"] = ceiling / seconds_per_iteration;
  if (llc_bytes() != 0) state.counters["frame_vs_llc"] = double(pass_bytes(f)) / double(llc_bytes());
  state.counters["ns_per_16px"] = seconds_per_iteration * 1e9 * 16.0 / (double(f.color.width()) * f.color.height());
}

// The copy ceiling's ways each as a benchmark of its own (BM_Memcpy, BM_CopyLoop, BM_CopyStream,
// BM_CopyHalide) on 1 and 2 threads; counters as the pass rows (the 2-thread ceiling apart).
void copy_benchmark(benchmark::State& state, int way) {
  if (!copy_way_available(way)) return state.SkipWithError("the Halide peer is not loaded");
  const DemoFrame& f = frame(int(state.range(0)), int(state.range(1)), ColorFormat::rgba32f);
  const int threads = int(state.range(2));
  ColorImage out(f.color.width(), f.color.height());
  DepthImage scratch(f.depth.width(), f.depth.height());
  copy_bytes(f, out, scratch, threads, way);  // first touch (and Halide's JIT)
  double total = 0;
  for (auto _ : state) {
    const auto a = Clock::now();
    copy_bytes(f, out, scratch, threads, way);
    benchmark::ClobberMemory();
    const double s = seconds_since(a);
    state.SetIterationTime(s);
    total += s;
  }
  finish(state, f, total / double(state.iterations()), copy_ceiling(f));
}
void BM_Memcpy(benchmark::State& state) { copy_benchmark(state, kCopyMemcpy); }
void BM_CopyLoop(benchmark::State& state) { copy_benchmark(state, kCopyLoop); }
void BM_CopyStream(benchmark::State& state) { copy_benchmark(state, kCopyStream); }
void BM_CopyHalide(benchmark::State& state) { copy_benchmark(state, kCopyHalide); }

double host_time(const std::function<void()>& fn) {
  const auto a = Clock::now();
  fn();
  return seconds_since(a);
}

// path: names the benchmark, so that its error is measured once across repetitions.
// interleave_memcpy: false for a GPU's device-time benchmark, whose ceiling is the device's own
// copy (the host copies are then measured once, after the loop).
template <class Run>
void timed_fog(benchmark::State& state, const char* path, Run&& run, bool interleave_memcpy = true) {
  const Case c = case_of(state);
  const DemoFrame& f = frame(c.w, c.h, c.format);
  ColorImage out(f.color.width(), f.color.height(), f.color.format());
  // The copy ceiling is measured interleaved with the pass, one copy after each iteration (outside
  // the timing, its ways in turn), so that both see the same machine: on a shared 2-core VM a
  // ceiling measured once drifts by +-30 % against passes measured minutes later.
  static ColorImage copy_out;
  static DepthImage copy_depth;
  if (copy_out.width() != f.color.width() || copy_out.height() != f.color.height() || copy_out.format() != f.color.format()) {
    copy_out = ColorImage(f.color.width(), f.color.height(), f.color.format());
    copy_depth = DepthImage(f.depth.width(), f.depth.height());
  }
  double total = 0;
  CopyTimes copies;
  for (auto _ : state) {
    const double s = run(f, out, c.settings);
    state.SetIterationTime(s);
    total += s;
    if (interleave_memcpy) copies.copy_one(f, copy_out, copy_depth);  // not counted
  }
  const double n = double(state.iterations());
  if (interleave_memcpy) copies.fill(f, copy_out, copy_depth, 1);  // a way the few iterations missed
  finish(state, f, total / n, interleave_memcpy ? copies : copy_ceiling(f));
  // Every path is deterministic: measure its error once per benchmark, not per repetition.
  static std::map<std::string, double> errors;
  std::string key = path;
  for (int i = 0; i < 5; ++i) key += "/" + std::to_string(state.range(i));
  auto it = errors.find(key);
  if (it == errors.end()) it = errors.emplace(key, max_error(out, f, c.settings)).first;
  state.counters["max_err"] = it->second;
}

void BM_Scalar(benchmark::State& state) {
  timed_fog(state, "scalar", [](const DemoFrame& f, ColorImage& out, const FogSettings& s) {
    return host_time([&] { apply_fog_scalar(f.color, f.depth, out, f.params, s); });
  });
}

void BM_OpenMPSimd(benchmark::State& state) {
  timed_fog(state, "openmp", [](const DemoFrame& f, ColorImage& out, const FogSettings& s) {
    return host_time([&] { bench::openmp_simd_fog(f.color, f.depth, out, f.params, s, kThreads); });
  });
}

void BM_OpenMPSimdFastMath(benchmark::State& state) {
  timed_fog(state, "openmp-fastmath", [](const DemoFrame& f, ColorImage& out, const FogSettings& s) {
    return host_time([&] { bench::openmp_simd_fastmath_fog(f.color, f.depth, out, f.params, s, kThreads); });
  });
}

#ifdef FOGCL_HAVE_HALIDE
void BM_Halide(benchmark::State& state) {
  const HalidePeer& peer = halide_peer();
  if (!peer.error.empty()) return state.SkipWithError(peer.error.c_str());
  const Case c = case_of(state);
  if (c.settings.mode == FogMode::height) return state.SkipWithError("the Halide peer has no height fog");
  peer.prepare(frame(c.w, c.h, c.format).params, c.settings, c.format, kThreads);  // JIT, not timed
  // inplace=1 in FOGCL_HALIDE_SCHEDULE (the schedule exploration, bench/halide_peer.cpp): the
  // output written over its input, a copy of the frame's color placed there before each call (not
  // timed).
  static const bool in_place = [] {
    const char* schedule = std::getenv("FOGCL_HALIDE_SCHEDULE");
    return schedule != nullptr && std::string(schedule).find("inplace=1") != std::string::npos;
  }();
  timed_fog(state, "halide", [&](const DemoFrame& f, ColorImage& out, const FogSettings& s) {
    if (in_place) {
      std::memcpy(out.data(), f.color.data(), f.color.size_bytes());
      return host_time([&] { peer.fog(out, f.depth, out, f.params, s, kThreads); });
    }
    return host_time([&] { peer.fog(f.color, f.depth, out, f.params, s, kThreads); });
  });
}
#endif

Runtime* runtime(benchmark::State& state) {
  static std::unique_ptr<Runtime> rt;
  static std::string error;
  if (!rt && error.empty()) {
    try {
      rt = std::make_unique<Runtime>();
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  if (!rt) state.SkipWithError(error.c_str());
  return rt.get();
}

// nt: the RGBA32F store path, as BM_OpenCLDevice's range "nt": 0 ordinary stores, 1 non-temporal
// stores, 2 by frame size (CpuCodegen's default: what users get).
FogPass& shared_pass(Runtime& rt, int nt = 2) {
  using S = CpuCodegen::Streaming;
  const auto codegen = [](S s) { CpuCodegen c; c.streaming_stores = s; return c; };
  static FogPass plain(rt, codegen(S::never)), streaming(rt, codegen(S::always)), by_size(rt);
  return nt == 0 ? plain : nt == 1 ? streaming : by_size;
}

void BM_OpenCLDevice(benchmark::State& state) {
  Runtime* rt = runtime(state);
  if (rt == nullptr) return;
  FogPass& pass = shared_pass(*rt, int(state.range(5)));
  const cl_mem_flags host = rt->is_cpu() ? CL_MEM_USE_HOST_PTR : CL_MEM_COPY_HOST_PTR;
  const Case c = case_of(state);
  const DemoFrame& frame_in = frame(c.w, c.h, c.format);
  const DeviceCopy& copy = device_copy(wrap(rt->context()), frame_in);
  double pass_s = 0, copy_s = 0;
  bool read_back = false, first = true;
  timed_fog(state, state.range(5) == 0 ? "opencl-device-plain" : state.range(5) == 1 ? "opencl-device-nt" : "opencl-device", [&](const DemoFrame& f, ColorImage& out, const FogSettings& s) {
    // Buffers wrap the same host memory every time (created once per frame and output).
    // The cl::Buffers own the handles; FrameBuffers borrows them.
    struct Buffers {
      cl::Buffer color_in, depth, color_out;
      FrameBuffers fb;
    };
    static std::map<std::tuple<const void*, const void*, const FogPass*>, Buffers> buffers;
    // On a CPU the output wraps `out` (new each run); a GPU's buffers are its own, one set per frame.
    auto key = std::make_tuple(f.color.data(), rt->is_cpu() ? static_cast<const void*>(out.data()) : nullptr, &pass);
    auto it = buffers.find(key);
    const cl::Context ctx = wrap(rt->context());
    const cl::CommandQueue queue = wrap(rt->queue());
    if (it == buffers.end()) {
      Buffers b;
      b.color_in = cl::Buffer(ctx, CL_MEM_READ_ONLY | host, f.color.size_bytes(), const_cast<void*>(f.color.data()));
      b.depth = cl::Buffer(ctx, CL_MEM_READ_ONLY | host, f.depth.size_bytes(), const_cast<float*>(f.depth.data()));
      b.color_out = cl::Buffer(ctx, CL_MEM_READ_WRITE | host, out.size_bytes(), out.data());
      b.fb.width = f.color.width();
      b.fb.height = f.color.height();
      b.fb.format = f.color.format();
      b.fb.color_in = b.color_in();
      b.fb.depth = b.depth();
      b.fb.color_out = b.color_out();
      it = buffers.emplace(key, b).first;
    }
    if (first) {  // build the variant (a cache hit after the first run) and dispatch it once
      pass.prepare(s, f.params, f.color.format());
      adopt(pass.enqueue(rt->queue(), it->second.fb, f.params, s)).wait();
      first = false;
    }
    const cl::Event e = adopt(pass.enqueue(rt->queue(), it->second.fb, f.params, s));
    e.wait();
    // A GPU's ceiling, its own copy, interleaved, outside the pass's time. A CPU device's copy is
    // timed after the loop: in the loop, another frame's worth of buffers written each iteration
    // would evict the pass's frame from the LLC, which the other paths' rows (one host copy after
    // each iteration) do not have to bear.
    // FOGCL_BENCH_DEVICE_COPY_EACH=1 restores the copy after each iteration on CPUs too (the A/B
    // of docs/performance.md's ceiling section).
    static const bool each = std::getenv("FOGCL_BENCH_DEVICE_COPY_EACH") != nullptr;
    if (!rt->is_cpu() || each) copy_s += copy.seconds(queue);
    if (!rt->is_cpu()) {  // the result, for the error, once per run: a 4K read-back is ~10 ms
      if (!read_back) queue.enqueueReadBuffer(it->second.color_out, CL_TRUE, 0, out.size_bytes(), out.data());
      read_back = true;
    } else {  // make the host view of the USE_HOST_PTR output valid (no copy on CPU devices)
      queue.enqueueUnmapMemObject(it->second.color_out,
                                  queue.enqueueMapBuffer(it->second.color_out, CL_TRUE, CL_MAP_READ, 0, out.size_bytes()));
    }
    const double seconds =
        double(e.getProfilingInfo<CL_PROFILING_COMMAND_END>() - e.getProfilingInfo<CL_PROFILING_COMMAND_START>()) * 1e-9;
    pass_s += seconds;
    return seconds;
  }, rt->is_cpu());
  if (rt->is_cpu() && pass_s > 0 && copy_s == 0) {
    const cl::CommandQueue queue = wrap(rt->queue());
    for (int i = 0; i < 5; ++i) copy_s += copy.seconds(queue);
    copy_s *= double(state.iterations()) / 5.0;
  }
  if (pass_s > 0 && copy_s > 0) {
    state.counters["copy_ms"] = copy_s / double(state.iterations()) * 1e3;
    state.counters["bw_vs_copy"] = (double(pass_bytes(frame_in)) / pass_s) / (double(copy.bytes_moved()) / copy_s);
  }
}

void BM_DeviceCopy(benchmark::State& state) {
  Runtime* rt = runtime(state);
  if (rt == nullptr) return;
  const DemoFrame& f = frame(int(state.range(0)), int(state.range(1)), state.range(2) ? ColorFormat::rgba16f : ColorFormat::rgba32f);
  const DeviceCopy& copy = device_copy(wrap(rt->context()), f);
  const cl::CommandQueue queue = wrap(rt->queue());
  copy.seconds(queue);  // first touch of the buffers
  for (auto _ : state) state.SetIterationTime(copy.seconds(queue));
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(copy.bytes_moved()));
}

// BM_OpenCLHostCall with the host images in pinned memory of the pass's context
// (pinned_color_image / pinned_depth_image): on a GPU the staged call moves them over the bus
// from where they are, without the staging copies. The output is copied to the row's `out`
// outside the timing, for max_err.
void BM_OpenCLHostCallPinned(benchmark::State& state) {
  Runtime* rt = runtime(state);
  if (rt == nullptr) return;
  FogPass& pass = shared_pass(*rt);
  ColorImage in, pinned_out;
  DepthImage depth;
  double kernel_ms = 0;
  timed_fog(state, "opencl-host-pinned", [&](const DemoFrame& f, ColorImage& out, const FogSettings& s) {
    if (in.width() != f.color.width() || in.format() != f.color.format()) {
      in = pinned_color_image(rt->context(), rt->device(), f.color.width(), f.color.height(), f.color.format());
      pinned_out = pinned_color_image(rt->context(), rt->device(), f.color.width(), f.color.height(), f.color.format());
      depth = pinned_depth_image(rt->context(), rt->device(), f.depth.width(), f.depth.height());
      std::memcpy(in.data(), f.color.data(), f.color.size_bytes());
      std::memcpy(depth.data(), f.depth.data(), f.depth.size_bytes());
    }
    const double call = host_time([&] { pass.apply(in, depth, pinned_out, f.params, s); });
    kernel_ms += pass.stats().last_kernel_ms;
    std::memcpy(out.data(), pinned_out.data(), out.size_bytes());
    return call;
  });
  state.counters["kernel_ms"] = kernel_ms / double(state.iterations());
}

// The bus's ceiling of a host round trip: a frame's input bytes (color_in and depth) written to
// device buffers, then its output bytes (color_out) read back, on the pass's device and queue
// (FOGCL_DEVICE). Both passes' convenience calls (FogPass::apply, VolumePass::apply) move exactly
// these three buffers, so one row per frame size and storage serves both. Range "host": where the
// host side lives, 0 ordinary pageable memory (a page-aligned allocation, touched before the
// loop), 1 pinned memory (three CL_MEM_ALLOC_HOST_PTR buffers mapped once, the mapped pointers the
// source and destination of clEnqueueWriteBuffer / clEnqueueReadBuffer, the usual way to get
// page-locked memory in OpenCL). Device buffers are made once, outside the loop. Time: wall clock
// from the first write's enqueue to the clFinish after the read; the host waits (clFinish) once
// between the writes and the read, so that each direction is timed on its own (up_ms, down_ms).
// Counters: up_ms, down_ms, GBps = the bytes moved / the time, bytes = the bytes moved per
// iteration (color_in + depth + color_out).
void BM_PinnedTransfer(benchmark::State& state) {
  Runtime* rt = runtime(state);
  if (rt == nullptr) return;
  const int w = int(state.range(0)), h = int(state.range(1));
  const ColorFormat format = state.range(2) ? ColorFormat::rgba16f : ColorFormat::rgba32f;
  const bool pinned = state.range(3) != 0;
  const std::size_t color_bytes = std::size_t(w) * std::size_t(h) * bytes_per_pixel(format);
  const std::size_t depth_bytes = std::size_t(w) * std::size_t(h) * sizeof(float);
  const std::size_t bytes = 2 * color_bytes + depth_bytes;
  const cl::Context ctx = wrap(rt->context());
  const cl::CommandQueue queue = wrap(rt->queue());
  const cl::Buffer dev_color_in(ctx, CL_MEM_READ_ONLY, color_bytes), dev_depth(ctx, CL_MEM_READ_ONLY, depth_bytes);
  const cl::Buffer dev_color_out(ctx, CL_MEM_WRITE_ONLY, color_bytes);
  // The host side: three regions, the inputs' sources and the output's destination.
  const std::size_t sizes[3] = {color_bytes, depth_bytes, color_bytes};
  void* host[3] = {};
  cl::Buffer staging[3];                // pinned: the CL_MEM_ALLOC_HOST_PTR buffers behind host[]
  fogcl::detail::AlignedBytes pageable[3];  // pageable: page-aligned, as the images' own storage
  for (int i = 0; i < 3; ++i) {
    if (pinned) {
      staging[i] = cl::Buffer(ctx, CL_MEM_READ_WRITE | CL_MEM_ALLOC_HOST_PTR, sizes[i]);
      host[i] = queue.enqueueMapBuffer(staging[i], CL_TRUE, CL_MAP_READ | CL_MAP_WRITE, 0, sizes[i]);
    } else {
      pageable[i] = fogcl::detail::AlignedBytes(sizes[i]);
      host[i] = pageable[i].data();
    }
    std::memset(host[i], 0x3c, sizes[i]);  // first touch, outside the timing
  }
  double up = 0, down = 0;
  const auto round_trip = [&] {
    const auto a = Clock::now();
    queue.enqueueWriteBuffer(dev_color_in, CL_FALSE, 0, color_bytes, host[0]);
    queue.enqueueWriteBuffer(dev_depth, CL_FALSE, 0, depth_bytes, host[1]);
    queue.finish();
    const auto b = Clock::now();
    queue.enqueueReadBuffer(dev_color_out, CL_FALSE, 0, color_bytes, host[2]);
    queue.finish();
    const auto c = Clock::now();
    return std::pair{std::chrono::duration<double>(b - a).count(), std::chrono::duration<double>(c - b).count()};
  };
  round_trip();  // the device buffers' first use (allocation on first touch), not timed
  for (auto _ : state) {
    const auto [u, d] = round_trip();
    up += u;
    down += d;
    state.SetIterationTime(u + d);
  }
  for (int i = 0; i < 3; ++i)
    if (pinned) queue.enqueueUnmapMemObject(staging[i], host[i]);
  queue.finish();
  const double n = double(state.iterations());
  state.counters["up_ms"] = up / n * 1e3;
  state.counters["down_ms"] = down / n * 1e3;
  state.counters["GBps"] = double(bytes) * n / (up + down) * 1e-9;
  state.counters["bytes"] = double(bytes);
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(bytes));
}

void BM_OpenCLHostCall(benchmark::State& state) {
  Runtime* rt = runtime(state);
  if (rt == nullptr) return;
  FogPass& pass = shared_pass(*rt);
  double kernel_ms = 0, call_ms = 0;
  timed_fog(state, "opencl-host", [&](const DemoFrame& f, ColorImage& out, const FogSettings& s) {
    const double call = host_time([&] { pass.apply(f.color, f.depth, out, f.params, s); });
    kernel_ms += pass.stats().last_kernel_ms;
    call_ms += call * 1e3;
    return call;
  });
  // The whole call against its own kernel in the same iterations: two benchmarks minutes apart
  // see different machines (docs/performance.md, "The host call").
  state.counters["kernel_ms"] = kernel_ms / double(state.iterations());
  state.counters["call_vs_kernel"] = kernel_ms > 0 ? call_ms / kernel_ms : 0.0;
}

// Where a convenience call's time goes on a CPU device: FogPass::apply's steps, each timed on the
// host, in four ways (range "way"):
//   0  as apply ran them before host-call caching: three clCreateBuffer(CL_MEM_USE_HOST_PTR) on the
//      images, the kernel, its event waited for, then a blocking map, the unmap and clFinish
//   1  new buffers, the kernel, then one blocking clEnqueueReadBuffer into the output's own host
//      pointer (the spec's defined read-back of a USE_HOST_PTR buffer: no map, no unmap, one wait)
//   2  buffers kept across calls, each input made current by a non-blocking clEnqueueWriteBuffer
//      from its own host pointer before the kernel, the read-back of way 1
//   3  buffers kept across calls, no write before the kernel, the read-back of way 1
//   4  apply's sequence before caching: new buffers, the kernel, a blocking map that waits for it
//      (one wait), the unmap and clFinish
//   5  buffers kept across calls and mapped between them (the host's, by the spec's protocol for
//      USE_HOST_PTR memory the host changes): the three unmaps, the kernel, the three maps, the
//      last blocking (one wait)
//   6  buffers kept across calls, the kernel, the blocking map, the unmap and clFinish
//   7  new buffers, the kernel, a non-blocking map and the unmap enqueued behind it, then one
//      clFinish: the map's guarantee (USE_HOST_PTR: host_ptr holds the latest bits once the map
//      completes) with a single wait
// Range "memcpy" 1: a 2-thread memcpy of the frame's bytes after each iteration (not timed), as
// BM_OpenCLHostCall's timed_fog does, so that the parts are measured under the same conditions.
// Counters [us per call]: create_us (buffers made or found), check_us (the integration API's checks:
// queue and buffer getInfo), sync_us (way 2's writes enqueued), enqueue_us (FogPass::enqueue: checks,
// 13 setArg, clEnqueueNDRangeKernel; the kernel often starts and runs before it returns), wait_us
// (until the kernel's event completes: way 0; the blocking read-back: ways 1-3), readback_us (way 0's
// map + unmap + finish), release_us, device_us (the kernel's profiling START -> END), launch_us (its
// QUEUED -> START: PoCL's scheduler and worker wake-up). The time is the call's (all but check_us,
// which enqueue_us contains); parts_vs_device = that / device time, the host call against the
// kernel in the same iterations.
void BM_HostCallParts(benchmark::State& state) {
  Runtime* rt = runtime(state);
  if (rt == nullptr) return;
  if (!rt->is_cpu()) return state.SkipWithError("host-call parts are measured on CPU devices");
  FogPass& pass = shared_pass(*rt);
  const Case c = case_of(state);
  const int way = int(state.range(5));
  const bool interleave = state.range(6) != 0;
  const DemoFrame& f = frame(c.w, c.h, c.format);
  ColorImage copy_out(f.color.width(), f.color.height(), f.color.format());
  DepthImage copy_depth(f.depth.width(), f.depth.height());
  ColorImage out(f.color.width(), f.color.height(), f.color.format());
  pass.prepare(c.settings, f.params, c.format);
  pass.apply(f.color, f.depth, out, f.params, c.settings);  // first touch of `out`
  const cl::Context ctx = wrap(rt->context());
  const cl::CommandQueue queue = wrap(rt->queue());
  const cl::Device device = wrap(rt->device());
  std::unique_ptr<detail::HostFrame> kept;
  const bool keep = way == 2 || way == 3 || way == 5 || way == 6;
  if (keep) kept = std::make_unique<detail::HostFrame>(detail::host_frame(ctx, true, f.color, f.depth, out, false));
  void *mapped_in = nullptr, *mapped_depth = nullptr, *mapped_out = nullptr;  // way 5
  double create = 0, check = 0, sync = 0, enq = 0, wait = 0, dev = 0, launch = 0, read = 0, release = 0;
  for (auto _ : state) {
    const auto begin = Clock::now();
    auto a = begin;
    std::unique_ptr<detail::HostFrame> fresh;
    if (!keep) fresh = std::make_unique<detail::HostFrame>(detail::host_frame(ctx, true, f.color, f.depth, out, false));
    const detail::HostFrame& hf = keep ? *kept : *fresh;
    create += seconds_since(a);
    a = Clock::now();
    detail::checked_queue(queue(), ctx, device, "parts");
    detail::check_frame_buffers(hf.raw, ctx);
    const double check_seconds = seconds_since(a);
    check += check_seconds;
    a = Clock::now();
    if (way == 2) {
      queue.enqueueWriteBuffer(hf.color_in, CL_FALSE, 0, f.color.size_bytes(), f.color.data());
      queue.enqueueWriteBuffer(hf.depth, CL_FALSE, 0, f.depth.size_bytes(), f.depth.data());
    }
    if (way == 5 && mapped_in != nullptr) {
      queue.enqueueUnmapMemObject(hf.color_in, mapped_in);
      queue.enqueueUnmapMemObject(hf.depth, mapped_depth);
      queue.enqueueUnmapMemObject(hf.color_out, mapped_out);
    }
    sync += seconds_since(a);
    a = Clock::now();
    const cl::Event done = adopt(pass.enqueue(queue(), hf.raw, f.params, c.settings));
    enq += seconds_since(a);
    a = Clock::now();
    if (way == 0) {
      done.wait();
      wait += seconds_since(a);
      a = Clock::now();
      void* mapped = queue.enqueueMapBuffer(hf.color_out, CL_TRUE, CL_MAP_READ, 0, out.size_bytes());
      queue.enqueueUnmapMemObject(hf.color_out, mapped);
      queue.finish();
      read += seconds_since(a);
    } else if (way == 4 || way == 6) {
      const std::vector<cl::Event> after{done};
      void* mapped = queue.enqueueMapBuffer(hf.color_out, CL_TRUE, CL_MAP_READ, 0, out.size_bytes(), &after);
      wait += seconds_since(a);
      a = Clock::now();
      queue.enqueueUnmapMemObject(hf.color_out, mapped);
      queue.finish();
      read += seconds_since(a);
    } else if (way == 7) {
      const std::vector<cl::Event> after{done};
      void* mapped = queue.enqueueMapBuffer(hf.color_out, CL_FALSE, CL_MAP_READ, 0, out.size_bytes(), &after);
      queue.enqueueUnmapMemObject(hf.color_out, mapped);
      queue.finish();
      wait += seconds_since(a);
    } else if (way == 5) {
      mapped_in = queue.enqueueMapBuffer(hf.color_in, CL_FALSE, CL_MAP_WRITE, 0, f.color.size_bytes());
      mapped_depth = queue.enqueueMapBuffer(hf.depth, CL_FALSE, CL_MAP_WRITE, 0, f.depth.size_bytes());
      mapped_out = queue.enqueueMapBuffer(hf.color_out, CL_TRUE, CL_MAP_READ | CL_MAP_WRITE, 0, out.size_bytes());
      wait += seconds_since(a);
    } else {
      queue.enqueueReadBuffer(hf.color_out, CL_TRUE, 0, out.size_bytes(), out.data());
      wait += seconds_since(a);
    }
    const auto queued = done.getProfilingInfo<CL_PROFILING_COMMAND_QUEUED>();
    const auto start = done.getProfilingInfo<CL_PROFILING_COMMAND_START>();
    dev += double(done.getProfilingInfo<CL_PROFILING_COMMAND_END>() - start) * 1e-9;
    launch += double(start - queued) * 1e-9;
    a = Clock::now();
    fresh.reset();
    release += seconds_since(a);
    state.SetIterationTime(seconds_since(begin) - check_seconds);
    if (interleave) copy_bytes(f, copy_out, copy_depth, kThreads);  // not counted: as in timed_fog
  }
  if (mapped_in != nullptr) {
    queue.enqueueUnmapMemObject(kept->color_in, mapped_in);
    queue.enqueueUnmapMemObject(kept->depth, mapped_depth);
    queue.enqueueUnmapMemObject(kept->color_out, mapped_out);
    queue.finish();
  }
  const double n = double(state.iterations());
  const double total = create + sync + enq + wait + read + release;
  for (auto [name, v] : {std::pair{"create_us", create}, {"check_us", check}, {"sync_us", sync}, {"enqueue_us", enq},
                         {"wait_us", wait}, {"device_us", dev}, {"launch_us", launch}, {"readback_us", read},
                         {"release_us", release}})
    state.counters[name] = v / n * 1e6;
  state.counters["parts_vs_device"] = total / dev;
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(pass_bytes(f)));
  // The output must be the pass's whatever the way (a read-back that copied nothing still has it).
  state.counters["max_err"] = max_error(out, f, c.settings);
}

// Linear against exp and exp2 fog under the same machine conditions: each iteration runs the three
// modes back to back on the same 1080p/4K frame and zero-copy buffers (device time from profiling),
// so DRAM noise of the shared VM moves all three alike; counters: each mode's median ms and the
// ratios linear / exp2 and linear / exp. Also counted on the host (fogcl's scalar factors, the
// kernel's bits): the share of 16-pixel blocks the kernel blends each way (fog_cpu_blocks.h):
// all f = 1 (copy), all f = 0 (fog color), none at 0 or 1 (the mix alone), mixed (per-lane tests).
void BM_ModeAB(benchmark::State& state) {
  Runtime* rt = runtime(state);
  if (rt == nullptr) return;
  if (!rt->is_cpu()) return state.SkipWithError("zero-copy buffers: a CPU device");
  FogPass& pass = shared_pass(*rt);
  const int w = int(state.range(0)), h = int(state.range(1));
  const ColorFormat format = state.range(3) ? ColorFormat::rgba16f : ColorFormat::rgba32f;
  const DemoFrame& f = frame(w, h, format);
  ColorImage out(w, h, format);
  const cl::Context ctx = wrap(rt->context());
  const cl::CommandQueue queue = wrap(rt->queue());
  const detail::HostFrame hf = detail::host_frame(ctx, true, f.color, f.depth, out, false);
  std::vector<FogSettings> modes;
  for (int m = 0; m < 3; ++m) {
    FogSettings s;
    s.mode = m == 0 ? FogMode::linear : m == 1 ? FogMode::exp : FogMode::exp2;
    s.start = 2.0f;
    s.end = 70.0f;
    s.density = 0.03f;
    s.metric = state.range(2) ? FogMetric::distance : FogMetric::depth;
    s.color = glm::vec3(0.62f, 0.68f, 0.76f);
    pass.prepare(s, f.params, format);
    adopt(pass.enqueue(queue(), hf.raw, f.params, s)).wait();
    modes.push_back(s);
  }
  std::vector<double> t[3];
  for (auto _ : state) {
    double sum = 0;
    for (int m = 0; m < 3; ++m) {
      const cl::Event e = adopt(pass.enqueue(queue(), hf.raw, f.params, modes[m]));
      e.wait();
      const double sec =
          double(e.getProfilingInfo<CL_PROFILING_COMMAND_END>() - e.getProfilingInfo<CL_PROFILING_COMMAND_START>()) * 1e-9;
      t[m].push_back(sec);
      sum += sec;
    }
    state.SetIterationTime(sum);
  }
  const char* names[3] = {"linear_ms", "exp_ms", "exp2_ms"};
  double med[3];
  for (int m = 0; m < 3; ++m) {
    std::sort(t[m].begin(), t[m].end());
    med[m] = t[m][t[m].size() / 2];
    state.counters[names[m]] = med[m] * 1e3;
  }
  state.counters["linear_vs_exp2"] = med[0] / med[2];
  state.counters["linear_vs_exp"] = med[0] / med[1];
  // Block classes from the scalar factors (probe: color 1, fog color 0, so the output is f).
  static std::map<std::tuple<int, int, int>, std::array<double, 12>> classes;
  auto& cls = classes[{w, h, int(state.range(2))}];
  if (cls[0] + cls[1] + cls[2] + cls[3] == 0) {
    ColorImage ones(w, h);
    std::fill(ones.rgba32f(), ones.rgba32f() + 4 * std::size_t(w) * std::size_t(h), 1.0f);
    for (int m = 0; m < 3; ++m) {
      FogSettings probe = modes[m];
      probe.color = glm::vec3(0.0f);
      ColorImage fac;
      apply_fog_scalar(ones, f.depth, fac, f.params, probe);
      std::size_t n[4] = {0, 0, 0, 0};
      for (int y = 0; y < h; ++y)
        for (int x0 = 0; x0 < w; x0 += 16) {
          int one = 0, zero = 0, len = std::min(16, w - x0);
          for (int x = x0; x < x0 + len; ++x) {
            const float v = fac.rgba32f()[4 * (std::size_t(y) * w + x)];
            one += v == 1.0f;
            zero += v == 0.0f;
          }
          ++n[one == len ? 0 : zero == len ? 1 : one + zero == 0 ? 2 : 3];
        }
      const double blocks = double(n[0] + n[1] + n[2] + n[3]);
      for (int k = 0; k < 4; ++k) cls[4 * m + k] = n[k] / blocks;
    }
  }
  const char* kinds[4] = {"copy", "fog", "mix", "lanes"};
  for (int m = 0; m < 3; ++m)
    for (int k = 0; k < 4; ++k)
      state.counters[std::string(m == 0 ? "lin_" : m == 1 ? "exp_" : "exp2_") + kinds[k]] = cls[4 * m + k];
}

// Optical depth density * d across the frame ~ 10^range(0) at the demo scene's distances: 1 (f in
// the normal range), 100 (exp(-100) = 4e-44: f is a float denormal), 1e3 and 1e20 (f underflows
// to 0). Shows whether denormal factors slow the pass down (x86 microcode assists).
void BM_OpticalDepth(benchmark::State& state) {
  Runtime* rt = runtime(state);
  if (rt == nullptr) return;
  FogPass& pass = shared_pass(*rt);
  const DemoFrame& f = frame(1920, 1080, ColorFormat::rgba32f);
  FogSettings s;
  s.mode = FogMode::exp;
  s.density = float(std::pow(10.0, double(state.range(0))) / 20.0);  // demo distances ~2..70
  ColorImage out;
  pass.apply(f.color, f.depth, out, f.params, s);
  for (auto _ : state) {
    const auto a = Clock::now();
    pass.apply(f.color, f.depth, out, f.params, s);
    state.SetIterationTime(seconds_since(a));
  }
  state.SetBytesProcessed(int64_t(state.iterations()) * int64_t(pass_bytes(f)));
}

Variant bench_variant(ColorFormat format = ColorFormat::rgba32f) {
  FogSettings s;
  s.mode = FogMode::exp2;
  return select_variant(s, make_camera_params(PerspectiveCamera{}), format);
}

// Cold: an option string PoCL has never seen (a nonce define) forces a full compile.
void BM_ProgramBuild(benchmark::State& state) {
  Runtime* rt = runtime(state);
  if (rt == nullptr) return;
  const bool cold = state.range(0) != 0;
  const FogPass probe(*rt);
  const std::string base = probe.build_options_for(bench_variant());
  std::mt19937_64 rng(std::random_device{}());
  for (auto _ : state) {
    ProgramCache cache(rt->context());  // empty in-memory cache: only PoCL's disk cache can help
    const std::string options = cold ? base + " -D FOGCL_NONCE=" + std::to_string(rng()) : base;
    const auto a = Clock::now();
    cache.get(rt->device(), "deferred_fog.cl", deferred_fog_cl, options);
    state.SetIterationTime(seconds_since(a));
  }
}

// First dispatch of a new FogPass (program from PoCL's disk cache): kernel creation + launch.
void BM_FirstDispatch(benchmark::State& state) {
  Runtime* rt = runtime(state);
  if (rt == nullptr) return;
  const DemoFrame& f = frame(1920, 1080, ColorFormat::rgba32f);
  FogSettings s;
  ColorImage out;
  for (auto _ : state) {
    FogPass pass(*rt);
    pass.prepare(select_variant(s, f.params, f.color.format()));  // build outside the timing
    const auto a = Clock::now();
    pass.apply(f.color, f.depth, out, f.params, s);
    state.SetIterationTime(seconds_since(a));
  }
}

// Steady per-dispatch overhead: enqueue to completion of a 1x1 frame.
void BM_DispatchOverhead(benchmark::State& state) {
  Runtime* rt = runtime(state);
  if (rt == nullptr) return;
  FogPass& pass = shared_pass(*rt);
  const DemoFrame& f = frame(1, 1, ColorFormat::rgba32f);
  const cl::Context ctx = wrap(rt->context());
  const cl::Buffer color(ctx, CL_MEM_READ_WRITE, 16), depth(ctx, CL_MEM_READ_WRITE, 4), color_out(ctx, CL_MEM_READ_WRITE, 16);
  FrameBuffers fb;
  fb.width = fb.height = 1;
  fb.color_in = color();
  fb.depth = depth();
  fb.color_out = color_out();
  FogSettings s;
  pass.prepare(s, f.params, fb.format);
  adopt(pass.enqueue(rt->queue(), fb, f.params, s)).wait();
  for (auto _ : state) {
    const auto a = Clock::now();
    adopt(pass.enqueue(rt->queue(), fb, f.params, s)).wait();
    state.SetIterationTime(seconds_since(a));
  }
}

// Process start to first fogged 1080p frame: platform + context + build + frame. Meant to run
// once per process (bench/run.sh: cold with an empty POCL_CACHE_DIR, then warm).
void BM_StartToFirstFrame(benchmark::State& state) {
  const DemoFrame& f = frame(1920, 1080, ColorFormat::rgba32f);
  FogSettings s;
  ColorImage out;
  for (auto _ : state) {
    const auto a = Clock::now();
    Runtime rt;
    FogPass pass(rt);
    pass.apply(f.color, f.depth, out, f.params, s);
    state.SetIterationTime(seconds_since(a));
  }
}

void FogArgs(benchmark::internal::Benchmark* b) {
  b->ArgNames({"w", "h", "mode", "dist", "f16"});
  for (auto [w, h] : {std::pair{1280, 720}, std::pair{1920, 1080}, std::pair{3840, 2160}})
    for (int mode : {0, 1, 2, 3, 4})
      for (int dist : {0, 1})
        for (int f16 : {0, 1})
          if (mode < 3 || dist == 0) b->Args({w, h, mode, dist, f16});
  b->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(0.2);
}

// As FogArgs, plus nt (shared_pass): the default store path (2, by frame size) on every case, and
// for RGBA32F ordinary (0) and non-temporal (1) stores forced, to show what each is worth.
void DeviceArgs(benchmark::internal::Benchmark* b) {
  b->ArgNames({"w", "h", "mode", "dist", "f16", "nt"});
  for (auto [w, h] : {std::pair{1280, 720}, std::pair{1920, 1080}, std::pair{3840, 2160}})
    for (int mode : {0, 1, 2, 3, 4})
      for (int dist : {0, 1}) {
        if (mode >= 3 && dist == 1) continue;  // height fog: along the ray always
        for (int f16 : {0, 1}) b->Args({w, h, mode, dist, f16, 2});
        if (mode < 3)  // the height kernel has no non-temporal store path
          for (int nt : {0, 1}) b->Args({w, h, mode, dist, 0, nt});
      }
  b->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(0.2);
}

// A 512x256 frame (4.7 MB of RGBA32F pass traffic) stays in the caches between iterations: the
// pass's compute cost without DRAM, which on the shared development VM moves by +-30 % between
// runs. PoCL runs a grid this small on one thread.
void CacheResidentArgs(benchmark::internal::Benchmark* b) {
  b->ArgNames({"w", "h", "mode", "dist", "f16", "nt"});
  for (int mode : {0, 1, 2, 3, 4})
    for (int dist : {0, 1})
      for (int f16 : {0, 1})
        if (mode < 3 || dist == 0) b->Args({512, 256, mode, dist, f16, 2});
  b->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(0.2);
}

void MemcpyArgs(benchmark::internal::Benchmark* b) {
  b->ArgNames({"w", "h", "threads"});
  for (auto [w, h] : {std::pair{512, 256}, std::pair{1280, 720}, std::pair{1920, 1080}, std::pair{3840, 2160}})
    for (int t : {1, 2}) b->Args({w, h, t});
  b->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(0.2);
}

BENCHMARK(BM_Memcpy)->Apply(MemcpyArgs);
BENCHMARK(BM_CopyLoop)->Apply(MemcpyArgs);
BENCHMARK(BM_CopyStream)->Apply(MemcpyArgs);
#ifdef FOGCL_HAVE_HALIDE
BENCHMARK(BM_CopyHalide)->Apply(MemcpyArgs);
#endif
BENCHMARK(BM_Scalar)->Apply(FogArgs);
BENCHMARK(BM_OpenMPSimd)->Apply(FogArgs);
BENCHMARK(BM_OpenMPSimdFastMath)->Apply(FogArgs);
#ifdef FOGCL_HAVE_HALIDE
BENCHMARK(BM_Halide)->Apply(FogArgs);
#endif
BENCHMARK(BM_OpenCLDevice)->Apply(DeviceArgs);
BENCHMARK(BM_OpenCLDevice)->Name("BM_OpenCLDeviceCacheResident")->Apply(CacheResidentArgs);
BENCHMARK(BM_OpenCLHostCall)->Apply(FogArgs);
BENCHMARK(BM_HostCallParts)
    ->ArgNames({"w", "h", "mode", "dist", "f16", "way", "memcpy"})
    ->ArgsProduct({{64}, {64}, {2}, {0}, {0}, {0, 1, 2, 3, 4, 5, 6, 7}, {0}})
    ->ArgsProduct({{1920}, {1080}, {0, 2}, {0}, {0, 1}, {0, 1, 2, 3, 4, 5, 6, 7}, {0, 1}})
    ->ArgsProduct({{3840}, {2160}, {0, 2}, {0}, {0, 1}, {0, 4, 5, 6, 7}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.2);
BENCHMARK(BM_DeviceCopy)
    ->ArgNames({"w", "h", "f16"})
    ->ArgsProduct({{1920}, {1080}, {0, 1}})
    ->ArgsProduct({{3840}, {2160}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.2);
BENCHMARK(BM_OpenCLHostCallPinned)
    ->ArgNames({"w", "h", "mode", "dist", "f16"})
    ->ArgsProduct({{1920}, {1080}, {2}, {0}, {0, 1}})
    ->ArgsProduct({{3840}, {2160}, {2}, {0}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.2);
BENCHMARK(BM_PinnedTransfer)
    ->ArgNames({"w", "h", "f16", "host"})
    ->ArgsProduct({{1920}, {1080}, {0, 1}, {0, 1}})
    ->ArgsProduct({{3840}, {2160}, {0, 1}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.2);
BENCHMARK(BM_ModeAB)
    ->ArgNames({"w", "h", "dist", "f16"})
    ->ArgsProduct({{1920}, {1080}, {0, 1}, {0, 1}})
    ->ArgsProduct({{3840}, {2160}, {0, 1}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.3);
BENCHMARK(BM_OpticalDepth)->ArgName("log10_density_d")->Arg(0)->Arg(2)->Arg(3)->Arg(20)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ProgramBuild)->ArgName("cold")->Arg(1)->Arg(0)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_FirstDispatch)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(BM_DispatchOverhead)->UseManualTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StartToFirstFrame)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  // The cache the frames are compared with (frame_vs_llc), as the OS reports it.
  benchmark::AddCustomContext("llc_bytes", std::to_string(llc_bytes()));
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
