// The kernel variant a scene needs (docs/DESIGN.md §3): every feature is a -D switch, and a feature
// the scene does not use is not compiled at all. select_variant() and build_options() are the one
// place where settings and camera become build options.
#pragma once

#include <string>

#include "fogcl/camera.h"
#include "fogcl/fog_settings.h"
#include "fogcl/image.h"
#include "fogcl/opencl_types.h"

namespace fogcl {

enum class KernelMode {
  none,         // no pass: fog off, or exp/exp2 with density 0 (f == 1 everywhere)
  linear,       // FOG_MODE=1
  linear_step,  // FOG_MODE=2: linear with start == end
  exp,          // FOG_MODE=3
  exp2,         // FOG_MODE=4
  height,       // FOG_MODE=5: height and atmospheric fog (docs/DESIGN.md §6)
};

// What a height-fog variant uses (Variant::height_features; kernels/fog_math.h FOG_HF_*), each
// a build option of its own: FOG_HEIGHT_FALLOFF, _RGB, _START, _CUTOFF, _MAX_OPACITY, _SUN,
// _SUN_START, _SAME_IN (the sky: FOG_SKYBOX).
enum HeightFeature : int {
  kHeightFalloff = 1,     // k != 0
  kHeightRgb = 2,         // per-channel coefficients (else grey: one channel computed)
  kHeightStart = 4,       // start > 0
  kHeightCutoff = 8,      // finite cut-off
  kHeightMaxOpacity = 16, // maximum opacity < 1
  kHeightSun = 32,        // the sun lobe
  kHeightSunStart = 64,   // the lobe starts after the fog's start
  kHeightSameIn = 256,    // in-scattering == extinction in every channel: T and J from one exp
};

struct Variant {
  KernelMode mode = KernelMode::none;
  bool distance = false;    // FOG_DISTANCE
  bool fog_skybox = false;  // FOG_SKYBOX (no sky test)
  bool reversed_z = false;  // REVERSED_Z
  bool sky_infinite = false;  // FOG_SKY_INFINITE (with fog_skybox): the sky fully fogged
  DepthKind depth_kind = DepthKind::raw;  // FOG_DEPTH_KIND (1 eye depth, 2 radial distance)
  Projection projection = Projection::perspective;  // FOG_PROJECTION (1 infinite far, 2 orthographic)
  ColorFormat storage = ColorFormat::rgba32f;  // FOG_COLOR_HALF
  Precision precision = Precision::precise;    // FOG_NATIVE_MATH + -cl-fast-relaxed-math
  int height_features = 0;  // KernelMode::height: HeightFeature bits

  bool needs_pass() const { return mode != KernelMode::none; }
  bool operator==(const Variant& o) const {
    return mode == o.mode && distance == o.distance && fog_skybox == o.fog_skybox &&
           reversed_z == o.reversed_z && sky_infinite == o.sky_infinite && depth_kind == o.depth_kind &&
           projection == o.projection && storage == o.storage &&
           precision == o.precision && height_features == o.height_features;
  }
};

// Validates the settings and derives the variant. Throws fogcl::Error on invalid settings.
Variant select_variant(const FogSettings& settings, const CameraParams& camera, ColorFormat storage);

// Code generation choices of the CPU kernel path, for benchmarks and tests; the defaults are
// what fogcl uses.
struct CpuCodegen {
  // Non-temporal stores of RGBA32F output (no read-for-ownership of the output lines: a third
  // less memory traffic for a write). by_frame_size (the default): for frames whose pass traffic
  // (color in and out, depth) is at least half the device's last-level cache
  // (CL_DEVICE_GLOBAL_MEM_CACHE_SIZE, counted up to 32 MiB; from 1280x720 up on a 32 MiB L3),
  // which cannot stay in that cache anyway; smaller frames keep ordinary stores, so a following
  // pass finds them in cache. The kernel reads the frame size, so one program serves every size.
  // On the 2-core EPYC (PoCL 3.1, 2 threads) streaming took 0.78-0.92x the time at 720p,
  // 0.69-0.81x at 1080p and 0.73-0.77x at 4K; on the 16-core Xeon VM (PoCL 5.0) 0.66x at 1080p
  // (docs/performance.md#streaming-stores). always / never: for the benchmark's
  // A/B and the tests.
  enum class Streaming { by_frame_size, always, never };
  Streaming streaming_stores = Streaming::by_frame_size;
  // Use the target's SIMD builtins where the kernel has them (x86 AVX-512: lane masks, 16-wide
  // half conversions). false builds the portable OpenCL C path that other CPUs run, so that
  // tests on an AVX-512 machine cover it too.
  bool target_intrinsics = true;
  // Build the kernel other devices (GPUs) run, one pixel per work-item, on this CPU device:
  // for tests, so that PoCL checks that kernel text (its vector accesses, the device's exp in
  // height fog) against the float64 reference where there is no GPU. Slower than the blocks.
  bool one_pixel_per_work_item = false;
};

// What the build options depend on besides the scene.
struct DeviceTraits {
  std::string opencl_c_version = "OpenCL C 1.2";  // CL_DEVICE_OPENCL_C_VERSION
  bool cpu = true;                                // CL_DEVICE_TYPE_CPU
  unsigned long long cache_bytes = 0;             // CL_DEVICE_GLOBAL_MEM_CACHE_SIZE (0: unknown)
  CpuCodegen codegen;                             // read on CPU devices only
};

// The traits of an OpenCL device, read from it (type, OpenCL C version, cache size), with `codegen`.
DeviceTraits device_traits(cl_device_id device, const CpuCodegen& codegen = {});

// The smallest frame [pixels] whose RGBA32F output a CPU kernel writes with non-temporal stores
// (CpuCodegen::streaming_stores); 0 = every frame; -1 = none.
long long streaming_min_pixels(const DeviceTraits& device);
// " -D FOG_STREAMING_MIN_PIXELS=N" for a kernel writing `storage` on `device`, or "": the option
// both passes' CPU kernels take (kernels/fog_cpu_avx512.h, FOG_STREAMS).
std::string streaming_store_option(const DeviceTraits& device, ColorFormat storage);

// Pixels each work-item fogs: 16 (one SIMD vector of pixels) on CPU devices, 1 elsewhere, in
// every mode (height fog too: its formulas run on 16 lanes like the others').
int pixels_per_work_item(const DeviceTraits& device);

// "-cl-std=CL1.2 -D FOG_MODE=4 -D FOG_DISTANCE ... -D FOG_VECTOR_WIDTH=16". Deterministic: equal
// inputs give equal strings, so the string is the program cache key.
std::string build_options(const Variant& variant, const DeviceTraits& device = {});

// "-cl-std=CL1.2" (or CL1.1): the newest OpenCL C the kernels need that the device has. Throws
// fogcl::Error for an unreadable or older version.
std::string cl_std_option(const DeviceTraits& device);

// Human-readable, e.g. "exp2 depth sky-test conventional-z rgba32f precise".
std::string describe(const Variant& variant);

const char* to_string(KernelMode mode);

}  // namespace fogcl
