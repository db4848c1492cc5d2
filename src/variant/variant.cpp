#include "fogcl/variant.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "fogcl/error.h"
#include "fogcl/runtime.h"
#include "fogcl/volumes.h"
#include "settings/fog_coefficients.h"

namespace fogcl {

namespace {
// Each HeightFeature's build option (FOG_HEIGHT_<option>) and its name in describe(), in bit order.
struct HeightFeatureName {
  int bit;
  const char* option;
  const char* label;
};
constexpr HeightFeatureName kHeightFeatureNames[] = {
    {kHeightFalloff, "FALLOFF", "falloff"},
    {kHeightRgb, "RGB", "rgb"},
    {kHeightStart, "START", "start"},
    {kHeightCutoff, "CUTOFF", "cutoff"},
    {kHeightMaxOpacity, "MAX_OPACITY", "max-opacity"},
    {kHeightSun, "SUN", "sun"},
    {kHeightSunStart, "SUN_START", "sun-start"},
    {kHeightSameIn, "SAME_IN", "same-in"},
};
}  // namespace

Variant select_variant(const FogSettings& s, const CameraParams& camera, ColorFormat storage) {
  validate(s);
  Variant v;
  switch (s.mode) {
    case FogMode::off:
      return v;
    case FogMode::linear:
      v.mode = s.start == s.end ? KernelMode::linear_step : KernelMode::linear;
      break;
    case FogMode::exp:
    case FogMode::exp2:
      // density 0 gives f = 1 for every finite distance: no pass, output = input bit for bit.
      if (s.density == 0.0f) return v;
      v.mode = s.mode == FogMode::exp ? KernelMode::exp : KernelMode::exp2;
      break;
    case FogMode::height: {
      if (!camera.pose)
        throw Error("height fog needs the camera pose (CameraParams::pose: eye, forward, up)");
      validate(*camera.pose);
      const HeightFogSettings& h = s.height;
      const glm::vec3 ext = detail::height_extinction(s), in = detail::height_inscattering(s);
      // Maximum opacity 0, or no extinction and no in-scattering: T = 1 and J = 0 everywhere (the
      // lobe scales J_sun, also 0): no pass, output = input bit for bit.
      if (h.max_opacity == 0.0f || (ext == glm::vec3(0.0f) && in == glm::vec3(0.0f))) return v;
      v.mode = KernelMode::height;
      int f = 0;
      if (h.falloff != 0.0f) f |= kHeightFalloff;
      if (ext.x != ext.y || ext.x != ext.z || in.x != in.y || in.x != in.z) f |= kHeightRgb;
      if (h.start > 0.0f) f |= kHeightStart;
      if (std::isfinite(h.cutoff)) f |= kHeightCutoff;
      if (h.max_opacity < 1.0f) f |= kHeightMaxOpacity;
      if (in == ext) f |= kHeightSameIn;
      if (h.sun && h.sun->color != glm::vec3(0.0f) && in != glm::vec3(0.0f)) {
        f |= kHeightSun;
        if (h.sun->start > h.start) f |= kHeightSunStart;
      }
      v.height_features = f;
      break;
    }
  }
  const bool height = v.mode == KernelMode::height;
  // Orthographic rays are parallel to the view axis: distance-based fog is depth-based fog, so
  // the variant carries no ray interpolation and no sqrt for it. Height fog is always along the
  // ray from the eye, and its sky an infinite ray (§6.2), never at the far plane: fogged with
  // fog_skybox, which SkyDistance::infinite implies in every mode.
  v.projection = camera.projection;
  v.distance = !height && s.metric == FogMetric::distance && camera.projection != Projection::orthographic;
  v.sky_infinite = !height && s.sky == SkyDistance::infinite;
  v.fog_skybox = s.fog_skybox || s.sky == SkyDistance::infinite;
  v.reversed_z = camera.reversed_z;
  v.depth_kind = camera.depth_kind;
  v.storage = storage;
  v.precision = s.precision;
  return v;
}

DeviceTraits device_traits(cl_device_id device, const CpuCodegen& codegen) {
  DeviceTraits traits;
  traits.cpu = device_is_cpu(device);
  traits.opencl_c_version = device_opencl_c_version(device);
  traits.cache_bytes = device_cache_bytes(device);
  traits.codegen = codegen;
  return traits;
}

int pixels_per_work_item(const DeviceTraits& device) {
  return device.cpu && !device.codegen.one_pixel_per_work_item ? 16 : 1;
}

long long streaming_min_pixels(const DeviceTraits& device) {
  if (pixels_per_work_item(device) == 1) return -1;  // GPUs' one pixel per work-item: their own stores
  switch (device.codegen.streaming_stores) {
    case CpuCodegen::Streaming::always: return 0;
    case CpuCodegen::Streaming::never: return -1;
    case CpuCodegen::Streaming::by_frame_size: break;
  }
  if (device.cache_bytes == 0) return -1;
  // From frames whose pass traffic (RGBA32F in and out, depth: 36 bytes a pixel) is half the
  // last-level cache: the output then evicts itself, and the inputs, before anyone reads it back,
  // and its read-for-ownership is a third of the pass's traffic spent for nothing. The cache
  // counted is at most 32 MiB: a server's (or a VM's) reported L3 is shared by many more cores
  // than the pass's threads (the 16-core Xeon VM reports 300 MiB, and streaming was 1.5x faster
  // there at 1080p with 2 threads).
  const unsigned long long cache = std::min(device.cache_bytes, 32ull << 20);
  return (long long)(cache / 2 / 36);
}

std::string streaming_store_option(const DeviceTraits& device, ColorFormat storage) {
  const long long from = streaming_min_pixels(device);
  if (from < 0 || storage != ColorFormat::rgba32f) return "";  // half output: ordinary stores
  return " -D FOG_STREAMING_MIN_PIXELS=" + std::to_string(from);
}

std::string cl_std_option(const DeviceTraits& device) {
  const std::string& version = device.opencl_c_version;
  int major = 0, minor = 0;
  if (std::sscanf(version.c_str(), "OpenCL C %d.%d", &major, &minor) != 2)
    throw Error("device reports an unreadable OpenCL C version '" + version + "'");
  if (major * 10 + minor < 11)
    throw Error("device OpenCL C version " + version + " is older than 1.1");
  // The kernels use nothing past OpenCL C 1.2; ask for the newest of 1.1 / 1.2 the device has.
  return major * 10 + minor >= 12 ? "-cl-std=CL1.2" : "-cl-std=CL1.1";
}

std::string build_options(const Variant& v, const DeviceTraits& device) {
  if (!v.needs_pass()) throw Error("build_options: the variant needs no kernel (fog is off)");
  std::string o = cl_std_option(device);
  o += " -D FOG_MODE=" + std::to_string(int(v.mode));
  if (v.distance) o += " -D FOG_DISTANCE";
  if (v.fog_skybox) o += " -D FOG_SKYBOX";
  if (v.reversed_z) o += " -D REVERSED_Z";
  if (v.sky_infinite) o += " -D FOG_SKY_INFINITE";
  if (v.depth_kind != DepthKind::raw) o += " -D FOG_DEPTH_KIND=" + std::to_string(int(v.depth_kind));
  if (v.projection != Projection::perspective) o += " -D FOG_PROJECTION=" + std::to_string(int(v.projection));
  if (v.storage == ColorFormat::rgba16f) o += " -D FOG_COLOR_HALF";
  if (v.precision == Precision::fast) o += " -D FOG_NATIVE_MATH -cl-fast-relaxed-math";
  if (v.mode == KernelMode::height)
    for (const HeightFeatureName& n : kHeightFeatureNames)
      if (v.height_features & n.bit) o += std::string(" -D FOG_HEIGHT_") + n.option;
  o += " -D FOG_VECTOR_WIDTH=" + std::to_string(pixels_per_work_item(device));
  o += streaming_store_option(device, v.storage);
  if (pixels_per_work_item(device) == 16 && !device.codegen.target_intrinsics) o += " -D FOG_PORTABLE";
  return o;
}

const char* to_string(KernelMode m) {
  switch (m) {
    case KernelMode::none: return "none";
    case KernelMode::linear: return "linear";
    case KernelMode::linear_step: return "linear-step";
    case KernelMode::exp: return "exp";
    case KernelMode::exp2: return "exp2";
    case KernelMode::height: return "height";
  }
  return "?";
}

std::string describe(const Variant& v) {
  if (!v.needs_pass()) return "none (no pass)";
  std::string d = to_string(v.mode);
  if (v.mode == KernelMode::height) {
    for (const HeightFeatureName& n : kHeightFeatureNames)
      if (v.height_features & n.bit) d += std::string(" ") + n.label;
    if (!(v.height_features & kHeightFalloff)) d += " no-falloff";
    if (!(v.height_features & kHeightRgb)) d += " grey";
  } else {
    d += v.distance ? " distance" : " depth";
  }
  d += v.sky_infinite ? " sky-infinite" : v.fog_skybox ? " fog-skybox" : " sky-test";
  if (v.depth_kind == DepthKind::eye) d += " eye-depth";
  if (v.depth_kind == DepthKind::distance) d += " radial-distance";
  d += v.reversed_z ? " reversed-z" : " conventional-z";
  d += v.projection == Projection::orthographic ? " orthographic "
       : v.projection == Projection::perspective_infinite_far ? " infinite-far " : " ";
  d += to_string(v.storage);
  d += ' ';
  d += to_string(v.precision);
  return d;
}

}  // namespace fogcl
