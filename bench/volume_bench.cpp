// Volumetric pass benchmarks (Google Benchmark, one binary, so ratios come from one run): the demo
// scene with its four fog volumes, 64 steps, noise on.
//   BM_VolumeDevice/integrator/divisor/noise_image/width   OpenCL device time of the whole pass
//        (profiling events; march = from a marker enqueued just before it to the composite's start,
//        composite = the composite kernel), counters march_ms, composite_ms and
//        steps_x_pixels_per_s = steps x target pixels / march time; max_err against the scalar
//        double path at 480x270
//   BM_VolumeHostCall/integrator/divisor/noise_image/width/f16   the convenience call, host images
//        in and out (enqueue to finish), RGBA32F or (f16 1) RGBA16F: on a GPU the host round trip,
//        upload + pass + download; width 3840 (4K) on GPUs only
//   BM_VolumeScalar/integrator/width   the scalar float path, one thread
//   BM_VolumeNothingVisible   enqueue of a frame whose volumes are all culled: no kernel, the
//        host-side cost of the call
//   BM_VolumeOpenMP/integrator/width   the OpenMP-SIMD C++ peer of the march (2 threads, -O3
//        -march=native, bench/volume_openmp_peer.cpp), half resolution; max_err of its target
//        against the scalar double march at 480x270
//   BM_VolumeScaling/steps/divisor/volumes   the OpenCL pass at 480x270 along three sweeps (steps
//        8..256; full/half/quarter; 1..16 volumes): work = sum over target pixels of steps x the
//        volumes the pixel's ray enters before the scene, ns_per_work = device time / work (flat
//        if the cost grows as the work does; bench/plot_volume.py draws it)
//   BM_VolumeStepCost/integrator/ablation/frame   what a step is made of: the OpenCL march, adaptive
//        steps off so the work is fixed, ns_per_work = march time / work (on a CPU one thread's
//        share: x threads for the time a core spends). frame 0: the cache-resident 320x180 frame
//        at half resolution (160x90 targets), the noise as a buffer; frame 1: 1080p at full
//        resolution with the noise as an image (a GPU's default, enough work to fill one).
//        Ablations take parts out of the scene: 0 all (noise, detail noise, fades), 1 no detail
//        noise, 2 no noise, 3 no noise and no fades, 4 all with the physical model's Riemann sum
//        (no expm1 or division per step; physical only), 5 all with noise exponents 1.5 (four pow
//        per step; the demo's exponents are 1, which skips pow)
//   BM_VolumeComposite/integrator/f16/bilinear/sparse   the upsample + composite of BM_VolumeDevice at
//        1080p half resolution (noise buffer) in both storages (RGBA32F, RGBA16F) and both
//        upsamplings (depth-aware, bilinear); sparse 1: the scene without the haze around the camera
//        (the other three volumes cover part of the frame, and blocks with no coverage are copies)
//   BM_VolumeCompositeKernel/f16/bilinear   the same kernel alone, dispatched back to back on a
//        fixed target (the scalar march of the stylized scene): hundreds of iterations, for A/B
//   BM_VolumeHeight/path/volumes/rgb   the march with the marched height fog (docs/DESIGN.md §6.5:
//        falloff, sun lobe, fogged sky) at 1080p half resolution, 64 steps, physical, no shadow
//        map; volumes 1: with the demo's four volumes; rgb 1: the extinction per channel. path 0:
//        the OpenCL pass (march_ms: its march; on CPU devices the 16-pixel lanes), 1: the same
//        device one pixel per work-item (CpuCodegen::one_pixel_per_work_item), 2: the scalar float
//        pass, one thread (march_ms: the whole pass, whose composite is a small part), 3: the
//        OpenMP peer's march (2 threads); cpu_ms: the process's CPU time per frame (all threads:
//        on a loaded machine the wall time is the load's as much as the code's); lights N: N
//        street-lamp point lights (street_lamps) in the fog: N = 0, 1, 2, 4 give each light's cost
// BM_VolumeDevice, BM_VolumeComposite and BM_VolumeCompositeKernel also time a 2-thread memcpy of
// the frame's color (in its storage) and depth (memcpy2_ms) for composite_vs_memcpy2 = composite
// time / that copy: the median of 7 after the loop, or (BM_VolumeCompositeKernel) one copy after
// every dispatch and the ratio of the two medians.
// Widths: 480 (480x270: scalar and OpenCL in the same run) and 1920 (1080p, OpenCL only).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <cstring>
#include <map>
#include <memory>
#include <thread>
#include <tuple>
#include <vector>

#include <benchmark/benchmark.h>

#include "fogcl/demo_scene.h"
#include "fogcl/fogcl.h"
#include "fogcl/volume_pass.h"
#include "fogcl/volume_scalar.h"
#include "runtime/clhpp.h"
#include "runtime/host_staging.h"
#include "runtime/work_groups.h"
#include "volume/volume_formulas.h"
#include "volume/volume_params.h"
#include "volume_composite_cl.h"
#include "volume_openmp_peer.h"

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

// Copies of the frame's color and depth with 2 threads: the composite's ceiling. once() times one
// copy [ms] (destinations allocated and touched beforehand).
class FrameCopy {
 public:
  FrameCopy(const ColorImage& color, const DepthImage& depth)
      : in_color_(color), in_depth_(depth), color_(color.size_bytes()), depth_(depth.size_bytes()) {}
  double once() {
    const auto a = std::chrono::steady_clock::now();
    std::thread second([this] { part(1); });
    part(0);
    second.join();
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count();
  }

 private:
  void part(int t) {
    const std::size_t cb = color_.size(), db = depth_.size();
    std::memcpy(color_.data() + cb * t / 2, static_cast<const std::byte*>(in_color_.data()) + cb * t / 2,
                cb / 2 + t * (cb % 2));
    std::memcpy(depth_.data() + db * t / 2, reinterpret_cast<const std::byte*>(in_depth_.data()) + db * t / 2,
                db / 2 + t * (db % 2));
  }
  const ColorImage& in_color_;
  const DepthImage& in_depth_;
  std::vector<std::byte> color_, depth_;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// Median of 7 copies [ms].
double memcpy2_ms(const ColorImage& in_color, const DepthImage& in_depth) {
  FrameCopy copy(in_color, in_depth);
  std::vector<double> ms;
  for (int i = 0; i < 7; ++i) ms.push_back(copy.once());
  return median(ms);
}

// The march's work: over the target pixels, steps x the visible volumes whose sphere the pixel's
// ray enters before the scene (the same ray, occluder and sphere test as the kernel).
double march_work(const DemoFrame& f, const VolumeScene& s, const VolumeSettings& st) {
  using namespace volume_formulas;
  const detail::PackedVolumeFrame p = detail::pack_volume_frame(
      f.color.width(), f.color.height(), f.params, s, st, f.color.format(), nullptr, 0, 0, max_eye_depth(f.depth, f.params));
  const float* fr = p.frame.data();
  const detail::VolumeVariant& v = p.variant;
  const int scale = int(fr[VOL_F_SCALE]);
  double hits = 0;
  for (int ly = 0; ly < p.low_height; ++ly)
    for (int lx = 0; lx < p.low_width; ++lx) {
      const float eye = vol_block_eye_depth<float>(f.depth.data(), lx, ly, scale, f.color.width(), f.color.height(),
                                                   int(v.projection), v.reversed_z, int(v.depth_kind), fr[VOL_F_ZX], fr[VOL_F_ZY],
                                                   fr[VOL_F_NEAR], fr[VOL_F_FAR]);
      glm::vec3 origin, dir;
      float t_per_eye;
      vol_pixel_ray<float>(float(lx * scale) + 0.5f * float(scale), float(ly * scale) + 0.5f * float(scale), fr,
                           int(v.projection), &origin, &dir, &t_per_eye);
      const float t_scene = vol_scene_distance<float>(eye, fr[VOL_F_NEAR], t_per_eye);
      for (std::size_t i = 0; i < p.visible.size(); ++i) {
        const float* vol = p.volumes.data() + i * VOL_V_STRIDE;
        float t0, t1;
        if (vol_sphere_hit<float>(origin, dir, glm::vec3(vol[VOL_V_CENTER], vol[VOL_V_CENTER + 1], vol[VOL_V_CENTER + 2]),
                                  vol[VOL_V_RADIUS], &t0, &t1) &&
            t0 < t_scene)
          hits += 1;
      }
    }
  return hits * st.steps;
}

// The march's and the composite's mean ms per frame, and the composite against a 2-thread
// memcpy of the frame's color (in its storage) and depth.
void composite_counters(benchmark::State& state, double composite_ms, double copy_ms) {
  state.counters["composite_ms"] = composite_ms;
  state.counters["memcpy2_ms"] = copy_ms;
  state.counters["composite_vs_memcpy2"] = composite_ms / copy_ms;
}

void pass_counters(benchmark::State& state, double march_ms, double composite_ms, const ColorImage& color,
                   const DepthImage& depth) {
  state.counters["march_ms"] = march_ms;
  composite_counters(state, composite_ms, memcpy2_ms(color, depth));
}

// A prepared pass and the frame's buffers in device memory on a profiling queue, as a renderer
// holds them; run() times one frame from profiling events.
struct DeviceFrame {
  DeviceFrame(const DemoFrame& f, const VolumeScene& s, const VolumeSettings& st,
              ColorFormat storage = ColorFormat::rgba32f, const CpuCodegen& codegen = {})
      : frame(f), scene(s), settings(st), pass(runtime(), nullptr, codegen), max_eye(max_eye_depth(f.depth, f.params)),
        input(convert(f.color, storage)) {
    pass.prepare(f.params, s, st, storage);
    const cl::Context ctx = wrap(runtime().context());
    queue = cl::CommandQueue(ctx, wrap(runtime().device()), CL_QUEUE_PROFILING_ENABLE);
    color = cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, input.size_bytes(), input.data());
    depth = cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, f.depth.size_bytes(), const_cast<float*>(f.depth.data()));
    out = cl::Buffer(ctx, CL_MEM_READ_WRITE, input.size_bytes());
    fb.width = f.color.width();
    fb.height = f.color.height();
    fb.format = storage;
    fb.color_in = color();
    fb.depth = depth();
    fb.color_out = out();
    run();  // uploads the noise
  }
  // {march ms (from a marker enqueued just before the pass to the composite's start), composite ms}.
  std::pair<double, double> run() {
    cl::Event before;
    queue.enqueueMarkerWithWaitList(nullptr, &before);
    const cl::Event done = adopt(pass.enqueue(queue(), fb, frame.params, scene, settings, nullptr, {}, max_eye));
    done.wait();
    return {event_ms(before, CL_PROFILING_COMMAND_END, done, CL_PROFILING_COMMAND_START),
            event_ms(done, CL_PROFILING_COMMAND_START, done, CL_PROFILING_COMMAND_END)};
  }
  ColorImage result() {
    ColorImage image(fb.width, fb.height);
    queue.enqueueReadBuffer(out, CL_TRUE, 0, image.size_bytes(), image.data());
    return image;
  }

  const DemoFrame& frame;
  VolumeScene scene;
  VolumeSettings settings;
  VolumePass pass;
  float max_eye;
  ColorImage input;
  cl::CommandQueue queue;
  cl::Buffer color, depth, out;
  FrameBuffers fb;
};

void BM_VolumeDevice(benchmark::State& state) {
  const auto integrator = VolumeIntegrator(state.range(0));
  const int divisor = int(state.range(1)), width = int(state.range(3));
  const bool image = state.range(2) != 0;
  const DemoFrame& f = frame(width);
  DeviceFrame d(f, scene(integrator), settings(integrator, divisor, image));
  double march_ms = 0, composite_ms = 0;
  for (auto _ : state) {
    const auto [m, c] = d.run();
    march_ms += m;
    composite_ms += c;
    state.SetIterationTime((m + c) * 1e-3);
  }
  const double n = double(state.iterations());
  const double low_pixels = double((d.fb.width + divisor - 1) / divisor) * double((d.fb.height + divisor - 1) / divisor);
  pass_counters(state, march_ms / n, composite_ms / n, d.input, f.depth);
  state.counters["steps_x_pixels_per_s"] = kSteps * low_pixels / (march_ms / n * 1e-3);
  if (width == 480) state.counters["max_err"] = max_abs_rgb_error(d.result(), reference(integrator, divisor));
}

// The marched height fog of BM_VolumeHeight: a ground fog thinning upward, the demo light's sun
// lobe, the sky fogged; rgb: the extinction per channel (a bluish haze's proportions).
FogSettings marched_height_fog(bool rgb) {
  FogSettings f;
  f.mode = FogMode::height;
  f.color = glm::vec3(0.6f, 0.68f, 0.8f);
  f.density = 0.08f;
  if (rgb) f.height.extinction = glm::vec3(0.05f, 0.08f, 0.14f);
  f.height.falloff = 0.3f;
  f.height.base_height = 0.0f;
  f.fog_skybox = true;
  SunLobe sun;
  sun.direction = demo_light().direction;
  sun.color = glm::vec3(1.2f, 1.0f, 0.8f);
  sun.exponent = 8.0f;
  f.height.sun = sun;
  return f;
}

// n point lights along the demo's view (lamps 6 world units apart on both sides), each reaching
// 12 world units: every light lights a part of the fog in the frame.
std::vector<LocalLight> street_lamps(int n) {
  std::vector<LocalLight> lights;
  for (int i = 0; i < n; ++i) {
    LocalLight l;
    l.position = glm::vec3(i % 2 ? 2.5f : -2.5f, 2.5f, 2.0f + 6.0f * float(i / 2) + 3.0f * float(i % 2));
    l.color = glm::vec3(1.0f, 0.8f, 0.55f);
    l.intensity = 8.0f;
    l.range = 12.0f;
    l.radius = 0.1f;
    lights.push_back(l);
  }
  return lights;
}

void BM_VolumeHeight(benchmark::State& state) {
  const int path = int(state.range(0));
  const DemoFrame& f = frame(1920);
  VolumeScene s = scene(VolumeIntegrator::physical);
  if (!state.range(1)) s.volumes.clear();
  s.lights = street_lamps(int(state.range(3)));
  VolumeSettings st = settings(VolumeIntegrator::physical, 2, false);
  st.height_fog = marched_height_fog(state.range(2) != 0);
  double march_ms = 0;
  std::clock_t cpu_start = 0;  // the process's CPU time, every thread's, from the first timed frame
  if (path <= 1) {
    CpuCodegen codegen;
    codegen.one_pixel_per_work_item = path == 1;
    if (path == 1 && !runtime().is_cpu()) return state.SkipWithError("one pixel per work-item is a CPU device's choice");
    DeviceFrame d(f, s, st, ColorFormat::rgba32f, codegen);
    cpu_start = std::clock();
    for (auto _ : state) {
      const auto [m, c] = d.run();
      march_ms += m;
      state.SetIterationTime(m * 1e-3);
    }
    state.SetLabel(d.pass.last_march_options().find("VOL_LANES=16") != std::string::npos ? "lanes" : "one pixel");
  } else {
    std::vector<float> low;
    cpu_start = std::clock();
    for (auto _ : state) {
      const auto a = std::chrono::steady_clock::now();
      if (path == 2) {
        benchmark::DoNotOptimize(volumes_scalar<float>(f.color, f.depth, f.params, s, st).low.data());
      } else {
        bench::openmp_simd_march(f.color, f.depth, f.params, s, st, 2, low);
      }
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count();
      march_ms += ms;
      state.SetIterationTime(ms * 1e-3);
    }
  }
  state.counters["march_ms"] = march_ms / double(state.iterations());
  // On a shared machine the wall time depends on the load; the CPU time per frame less so.
  state.counters["cpu_ms"] = double(std::clock() - cpu_start) * 1e3 / CLOCKS_PER_SEC / double(state.iterations());
}

void BM_VolumeComposite(benchmark::State& state) {
  const auto integrator = VolumeIntegrator(state.range(0));
  const ColorFormat storage = state.range(1) ? ColorFormat::rgba16f : ColorFormat::rgba32f;
  const DemoFrame& f = frame(1920);
  VolumeSettings st = settings(integrator, 2, false);
  st.upsampling = state.range(2) ? VolumeUpsampling::bilinear : VolumeUpsampling::depth_aware;
  VolumeScene s = scene(integrator);
  if (state.range(3)) s.volumes.erase(s.volumes.begin());  // sparse: not the haze around the camera
  DeviceFrame d(f, s, st, storage);
  double march_ms = 0, composite_ms = 0;
  for (auto _ : state) {
    const auto [m, c] = d.run();
    march_ms += m;
    composite_ms += c;
    state.SetIterationTime(c * 1e-3);
  }
  const double n = double(state.iterations());
  pass_counters(state, march_ms / n, composite_ms / n, d.input, f.depth);
}

// The upsample + composite kernel alone, dispatched back to back on one fixed target: the scalar
// march of the demo scene (stylized, 1080p half), built once. Hundreds of iterations instead of
// BM_VolumeComposite's two (each of which marches the frame again), for A/B of the kernel's code.
void BM_VolumeCompositeKernel(benchmark::State& state) {
  const ColorFormat storage = state.range(0) ? ColorFormat::rgba16f : ColorFormat::rgba32f;
  const DemoFrame& f = frame(1920);
  VolumeSettings st = settings(VolumeIntegrator::stylized, 2, false);
  st.upsampling = state.range(1) ? VolumeUpsampling::bilinear : VolumeUpsampling::depth_aware;
  const VolumeScene s = scene(VolumeIntegrator::stylized);
  static const VolumeResult<float> target = volumes_scalar<float>(f.color, f.depth, f.params, s, st);
  const detail::PackedVolumeFrame packed = detail::pack_volume_frame(
      f.color.width(), f.color.height(), f.params, s, st, storage, nullptr, 0, 0, max_eye_depth(f.depth, f.params));

  const cl::Device device = wrap(runtime().device());
  const cl::Context ctx = wrap(runtime().context());
  const DeviceTraits traits = device_traits(device());
  // Built as the pass builds it (ProgramCache: CL error names and the build log on failure).
  ProgramCache programs(ctx());
  cl::Kernel kernel;
  try {
    const cl_program program = programs.get(device(), "volume_composite.cl", volume_composite_cl,
                                            detail::volume_composite_options(packed.variant, traits));
    kernel = cl::Kernel(cl::Program(program, true), "volume_composite");
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  const ColorImage input = convert(f.color, storage);
  const auto buffer = [&](const void* p, std::size_t bytes) {
    return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes, const_cast<void*>(p));
  };
  const cl::Buffer in = buffer(input.data(), input.size_bytes()), d = buffer(f.depth.data(), f.depth.size_bytes());
  const cl::Buffer k = buffer(packed.frame.data(), sizeof(packed.frame));
  const cl::Buffer low = buffer(target.low.data(), target.low.size() * 4);
  const cl::Buffer key = buffer(target.low_key.data(), target.low_key.size() * 4);
  const cl::Buffer out(ctx, CL_MEM_WRITE_ONLY, input.size_bytes());
  int arg = 0;
  for (const cl::Buffer* b : {&in, &d, &out, &k, &low, &key}) kernel.setArg(arg++, *b);
  const cl::CommandQueue queue(ctx, device, CL_QUEUE_PROFILING_ENABLE);
  // Launched as the pass launches it: its work-group shape, the global size rounded up to it.
  const detail::WorkGroupShape shape = detail::work_group_shape(
      kernel, device, detail::volume_composite_private_bytes(packed.variant, traits));
  const auto size = detail::volume_composite_global(packed.variant, traits, f.color.width(), f.color.height());
  const cl::NDRange global = shape.global(size[0], size[1]);
  // A copy of the frame's bytes after each dispatch, so that the two medians share the machine's
  // minutes (a copy measured after the loop moved by +-40 % against the composite's minutes).
  FrameCopy copy(input, f.depth);
  std::vector<double> composite_ms, copy_ms;
  for (auto _ : state) {
    cl::Event done;
    queue.enqueueNDRangeKernel(kernel, cl::NullRange, global, shape.local(), nullptr, &done);
    done.wait();
    const double ms = event_ms(done, CL_PROFILING_COMMAND_START, done, CL_PROFILING_COMMAND_END);
    composite_ms.push_back(ms);
    state.SetIterationTime(ms * 1e-3);
    state.PauseTiming();
    copy_ms.push_back(copy.once());
    state.ResumeTiming();
  }
  composite_counters(state, median(composite_ms), median(copy_ms));
}

void BM_VolumeHostCall(benchmark::State& state) {
  const auto integrator = VolumeIntegrator(state.range(0));
  const int divisor = int(state.range(1)), width = int(state.range(3));
  if (width > 1920 && runtime().is_cpu()) return state.SkipWithError("4K round trips are for GPUs");
  const DemoFrame& f = frame(width);
  const ColorImage in = convert(f.color, state.range(4) ? ColorFormat::rgba16f : ColorFormat::rgba32f);
  const VolumeScene s = scene(integrator);
  const VolumeSettings st = settings(integrator, divisor, state.range(2) != 0);
  VolumePass pass(runtime());
  ColorImage out;
  pass.apply(in, f.depth, out, f.params, s, st);  // builds the variant, uploads the noise
  for (auto _ : state) pass.apply(in, f.depth, out, f.params, s, st);
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
  if (width == 480) state.counters["max_err"] = max_abs_rgb_error(out, reference(integrator, 2));
}

void BM_VolumeOpenMP(benchmark::State& state) {
  const auto integrator = VolumeIntegrator(state.range(0));
  const int width = int(state.range(1));
  const DemoFrame& f = frame(width);
  const VolumeScene s = scene(integrator);
  const VolumeSettings st = settings(integrator, 2, false);
  std::vector<float> low;
  std::size_t pixels = 0;
  for (auto _ : state) pixels = bench::openmp_simd_march(f.color, f.depth, f.params, s, st, 2, low);
  state.counters["steps_x_pixels_per_s"] =
      benchmark::Counter(kSteps * double(pixels) * double(state.iterations()), benchmark::Counter::kIsRate);
  if (width == 480) {
    const VolumeResult<double>& ref = reference(integrator, 2);
    double err = 0;
    for (std::size_t i = 0; i < low.size(); ++i) err = std::max(err, std::fabs(double(low[i]) - ref.low[i]));
    state.counters["max_err"] = err;  // of the target (premultiplied RGB and coverage)
  }
}

// 16 volumes: the demo's four, and copies shifted along the ground (the sweep takes the first n).
std::vector<FogVolume> many_volumes(int n) {
  const std::vector<FogVolume> demo = demo_fog_volumes(VolumeIntegrator::stylized);
  std::vector<FogVolume> out;
  for (int i = 0; out.size() < std::size_t(n); ++i) {
    FogVolume v = demo[std::size_t(i) % demo.size()];
    v.center += glm::vec3(1.5f * float(i / int(demo.size())), 0.0f, -2.0f * float(i / int(demo.size())));
    out.push_back(v);
  }
  return out;
}

void BM_VolumeScaling(benchmark::State& state) {
  const int steps = int(state.range(0)), divisor = int(state.range(1)), count = int(state.range(2));
  const DemoFrame& f = frame(480);
  VolumeScene s = scene(VolumeIntegrator::stylized);
  s.volumes = many_volumes(count);
  VolumeSettings st = settings(VolumeIntegrator::stylized, divisor, false);
  st.steps = steps;
  st.adaptive_steps = false;  // the work is steps per entered volume
  DeviceFrame d(f, s, st);
  double total_ms = 0;
  for (auto _ : state) {
    const auto [m, c] = d.run();
    total_ms += m + c;
    state.SetIterationTime((m + c) * 1e-3);
  }
  const double work = march_work(f, s, st);
  state.counters["work"] = work;
  state.counters["ns_per_work"] = total_ms / double(state.iterations()) * 1e6 / std::max(work, 1.0);
}

void ScalingArgs(benchmark::internal::Benchmark* b) {
  b->ArgNames({"steps", "divisor", "volumes"});
  for (int steps : {8, 16, 32, 64, 128, 256}) b->Args({steps, 2, 4});
  for (int divisor : {1, 4}) b->Args({64, divisor, 4});
  for (int volumes : {1, 2, 8, 16}) b->Args({64, 2, volumes});
  b->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(0.3);
}

void BM_VolumeStepCost(benchmark::State& state) {
  const auto integrator = VolumeIntegrator(state.range(0));
  const int ablation = int(state.range(1));
  const bool full_hd = state.range(2) == 1;
  if (full_hd && runtime().is_cpu()) return state.SkipWithError("frame 1 is for GPUs (PoCL's images take seconds)");
  const DemoFrame& f = frame(full_hd ? 1920 : 320);
  VolumeScene s = scene(integrator);
  for (FogVolume& v : s.volumes) {
    if (ablation == 1) v.detail_strength = 0.0f;
    if (ablation >= 2 && ablation <= 3) v.noise = false;
    if (ablation == 3) v.fade_edge = v.fade_y = v.proximity_fade = 0.0f, v.max_y = 1e4f;
    if (ablation == 5) v.fog_exponent = v.detail_exponent = 1.5f;
  }
  VolumeSettings st = settings(ablation == 4 ? VolumeIntegrator::riemann : integrator, full_hd ? 1 : 2, full_hd);
  st.adaptive_steps = false;  // the work is steps per entered volume
  DeviceFrame d(f, s, st);
  double march_ms = 0;
  for (auto _ : state) {
    const auto [m, c] = d.run();
    march_ms += m;
    state.SetIterationTime(m * 1e-3);
  }
  const double work = march_work(f, s, st);
  state.counters["ns_per_work"] = march_ms / double(state.iterations()) * 1e6 / std::max(work, 1.0);
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

// The host's culling input of every VolumePass::apply: the farthest eye depth of the 1080p frame.
// sky:1 the demo frame (the first sky pixel ends the scan), sky:0 the same frame with its sky
// replaced by the far ground (every pixel read); threads 8: the chunks on 8 copy threads, as a staged
// (GPU) call scans them.
void BM_MaxEyeDepth(benchmark::State& state) {
  const DemoFrame& f = frame(1920);
  DepthImage depth = f.depth;
  if (state.range(0) == 0) {
    float ground = 0.0f;
    for (std::size_t i = 0; i < depth.pixel_count(); ++i)
      if (depth.data()[i] < 0.999f) ground = std::max(ground, depth.data()[i]);
    for (std::size_t i = 0; i < depth.pixel_count(); ++i) depth.data()[i] = std::min(depth.data()[i], ground);
  }
  // threads > 1: the scan's chunks on that many copy threads, as a staged call runs it.
  std::unique_ptr<detail::CopyWorkers> workers;
  if (state.range(1) > 1) workers = std::make_unique<detail::CopyWorkers>(int(state.range(1)));
  float farthest = 0.0f;
  for (auto _ : state) benchmark::DoNotOptimize(farthest = detail::max_eye_depth(depth, f.params, workers.get()));
  state.counters["farthest"] = farthest;
}

}  // namespace

BENCHMARK(BM_MaxEyeDepth)
    ->ArgNames({"sky", "threads"})
    ->ArgsProduct({{0, 1}, {1, 8}})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_VolumeDevice)
    ->ArgNames({"integrator", "divisor", "noise_image", "width"})
    ->ArgsProduct({{0, 1}, {1, 2, 4}, {0, 1}, {480}})
    ->ArgsProduct({{0, 1}, {1, 2}, {0, 1}, {1920}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);
BENCHMARK(BM_VolumeHeight)
    ->ArgNames({"path", "volumes", "rgb", "lights"})
    ->ArgsProduct({{0, 1, 3}, {0, 1}, {0, 1}, {0}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);
BENCHMARK(BM_VolumeHeight)  // each point light's cost: the OpenCL pass and the OpenMP peer
    ->ArgNames({"path", "volumes", "rgb", "lights"})
    ->ArgsProduct({{0, 3}, {0, 1}, {0}, {1, 2, 4}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);
BENCHMARK(BM_VolumeHeight)  // the scalar march: seconds a frame
    ->ArgNames({"path", "volumes", "rgb", "lights"})
    ->ArgsProduct({{2}, {0, 1}, {0}, {0, 4}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK(BM_VolumeComposite)
    ->ArgNames({"integrator", "f16", "bilinear", "sparse"})
    ->ArgsProduct({{0, 1}, {0, 1}, {0, 1}, {0}})
    ->Args({0, 0, 0, 1})
    ->Args({0, 1, 0, 1})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(2);  // each iteration marches the frame again (1-2 s)
BENCHMARK(BM_VolumeCompositeKernel)
    ->ArgNames({"f16", "bilinear"})
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);
BENCHMARK(BM_VolumeHostCall)
    ->ArgNames({"integrator", "divisor", "noise_image", "width", "f16"})
    ->ArgsProduct({{0, 1}, {1, 2}, {0, 1}, {1920, 3840}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);
BENCHMARK(BM_VolumeScalar)
    ->ArgNames({"integrator", "width"})
    ->ArgsProduct({{0, 1}, {480, 1920}})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);
BENCHMARK(BM_VolumeOpenMP)
    ->ArgNames({"integrator", "width"})
    ->ArgsProduct({{0, 1}, {480, 1920}})
    ->UseRealTime()  // its threads' work is not the main thread's CPU time
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);
BENCHMARK(BM_VolumeScaling)->Apply(ScalingArgs);
BENCHMARK(BM_VolumeStepCost)
    ->ArgNames({"integrator", "ablation", "frame"})
    ->ArgsProduct({{0}, {0, 1, 2, 3, 5}, {0, 1}})
    ->ArgsProduct({{1}, {0, 1, 2, 3, 4, 5}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.3);
BENCHMARK(BM_VolumeNothingVisible)->Unit(benchmark::kMicrosecond);

BENCHMARK_MAIN();
