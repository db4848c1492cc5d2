#include "volume/volume_params.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

#include "camera/camera_basis.h"
#include "fogcl/error.h"
#include "fogcl/volume_pass.h"
#include "image/packed_frame.h"
#include "runtime/format.h"
#include "runtime/host_staging.h"
#include "settings/fog_coefficients.h"
#include "volume/volume_formulas.h"

namespace fogcl {

namespace {
using detail::str;

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Checks of one volume: "volume 2: radius must be finite and > 0 (got -1)".
struct VolumeChecker {
  std::string where;
  void fail(const char* key, const std::string& rule, const std::string& got) const {
    throw Error(where + key + " " + rule + " (got " + got + ")");
  }
  void real(const char* key, float v, float lo, bool lo_open, float hi, bool hi_open, const char* rule) const {
    const bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
    if (!ok) fail(key, rule, str(v));
  }
  void vec(const char* key, const glm::vec3& v, float lo, float hi, const char* rule) const {
    for (int k = 0; k < 3; ++k)
      if (!(std::isfinite(v[k]) && v[k] >= lo && v[k] <= hi)) fail(key, rule, str(v));
  }
  void color(const char* key, const glm::vec4& c) const {
    for (int k = 0; k < 4; ++k)
      if (!(std::isfinite(c[k]) && c[k] >= 0.0f && c[k] <= 65504.0f))
        fail(key, "must be RGBA with each component in [0, 65504]", str(c));
  }
};
constexpr float kInf = INFINITY;
constexpr float kBig = 3.4e38f;
constexpr float kMaxLightRange = 1e15f;  // range^2 and the window's sums stay far inside float
constexpr double kMaxLightPeak = 1e30;
constexpr float kMinLightRadius = 1e-6f;  // radius^2 stays a normal float: the inverse square stays finite   // intensity * color / radius^2: sums over lights stay finite
}  // namespace

void validate(const FogVolume& v, std::size_t index) {
  const VolumeChecker c{"volume " + std::to_string(index) + ": "};
  c.vec("center", v.center, -kBig, kBig, "must be finite");
  c.real("radius", v.radius, 0.0f, true, kBig, false, "must be finite and > 0");
  c.real("density", v.density, 0.0f, false, kBig, false, "must be finite and >= 0");
  c.real("max_y", v.max_y, -kBig, false, kBig, false, "must be finite");
  c.real("fade_y", v.fade_y, 0.0f, false, kBig, false, "must be finite and >= 0 (0: no fade)");
  c.real("fade_edge", v.fade_edge, 0.0f, false, kBig, false, "must be finite and >= 0 (0: no fade)");
  c.real("proximity_fade", v.proximity_fade, 0.0f, false, kBig, false, "must be finite and >= 0 (0: no fade)");
  c.real("fog_exponent", v.fog_exponent, 0.0f, true, kBig, false, "must be finite and > 0");
  c.real("fog_cutoff", v.fog_cutoff, 0.0f, false, 1.0f, true, "must be in [0, 1)");
  c.real("detail_exponent", v.detail_exponent, 0.0f, true, kBig, false, "must be finite and > 0");
  c.real("detail_strength", v.detail_strength, 0.0f, false, 1.0f, false, "must be in [0, 1]");
  c.color("fog_color", v.fog_color);
  c.color("directional_fog_color", v.directional_fog_color);
  c.real("directional_falloff", v.directional_falloff, 0.0f, true, kBig, false, "must be finite and > 0");
  c.real("light_contribution", v.light_contribution, 0.0f, false, kBig, false, "must be finite and >= 0");
  c.real("directional_light_contribution", v.directional_light_contribution, 0.0f, false, kBig, false,
         "must be finite and >= 0");
  c.real("shadow_strength", v.shadow_strength, 0.0f, false, kBig, false, "must be finite and >= 0");
  c.real("shadow_reverse_strength", v.shadow_reverse_strength, 0.0f, false, kBig, false, "must be finite and >= 0");
  c.vec("tiling", v.tiling, -kBig, kBig, "must be finite");
  c.vec("speed", v.speed, -kBig, kBig, "must be finite");
  c.vec("detail_tiling", v.detail_tiling, -kBig, kBig, "must be finite");
  c.real("detail_speed_modifier", v.detail_speed_modifier, -kBig, false, kBig, false, "must be finite");
  c.real("occluder_overshoot", v.occluder_overshoot, 0.0f, false, kBig, false, "must be finite and >= 0");
  if (v.albedo) c.vec("albedo", *v.albedo, 0.0f, 1.0f, "must be RGB with each component in [0, 1]");
  c.real("anisotropy", v.anisotropy, -1.0f, true, 1.0f, true, "must be in (-1, 1)");
  if (v.ambient) c.vec("ambient", *v.ambient, 0.0f, kBig, "must be RGB, finite and >= 0");
}

void validate(const CameraPose& p) {
  if (!finite(p.eye)) throw Error("camera eye must be finite (got " + str(p.eye) + ")");
  if (!finite(p.forward) || glm::length(p.forward) == 0.0f)
    throw Error("camera forward must be a finite non-zero vector (got " + str(p.forward) + ")");
  if (!finite(p.up) || glm::length(p.up) == 0.0f)
    throw Error("camera up must be a finite non-zero vector (got " + str(p.up) + ")");
  if (detail::up_parallel_to_forward(p.up, p.forward))
    throw Error("camera up " + str(p.up) + " must not be parallel to forward " + str(p.forward));
}

void validate(const MainLight& l) {
  if (!finite(l.direction) || glm::length(l.direction) == 0.0f)
    throw Error("light direction must be a finite non-zero vector (got " + str(l.direction) + ")");
  for (int k = 0; k < 3; ++k)
    if (!(std::isfinite(l.color[k]) && l.color[k] >= 0.0f))
      throw Error("light color must be RGB, finite and >= 0 (got " + str(l.color) + ")");
}

void validate(const LocalLight& l, std::size_t index) {
  const VolumeChecker c{"light " + std::to_string(index) + ": "};
  if (l.kind != LightKind::point && l.kind != LightKind::spot)
    c.fail("kind", "must be point or spot", std::to_string(int(l.kind)));
  c.vec("position", l.position, -kBig, kBig, "must be finite");
  c.vec("color", l.color, 0.0f, kBig, "must be RGB, finite and >= 0");
  c.real("intensity", l.intensity, 0.0f, false, kBig, false, "must be finite and >= 0");
  c.real("range", l.range, 0.0f, true, kMaxLightRange, false, "must be finite and in (0, 1e15]");
  c.real("radius", l.radius, kMinLightRadius, false, l.range, false, "must be finite and in [1e-6, range]");
  const float brightest = std::max({l.color.x, l.color.y, l.color.z});
  const double peak =
      double(l.intensity) * double(brightest) * std::max(1.0, 1.0 / (double(l.radius) * double(l.radius)));
  if (!(peak <= kMaxLightPeak))
    c.fail("intensity",
           "* max(color) * max(1, 1 / radius^2) must be <= 1e30 (the light's peak at its source must stay within "
           "float range)",
           str(peak));
  if (l.kind != LightKind::spot) return;
  if (!finite(l.direction) || glm::length(l.direction) == 0.0f)
    c.fail("direction", "must be a finite non-zero vector", str(l.direction));
  c.real("outer_angle", l.outer_angle, 0.0f, true, 90.0f, false, "must be in (0, 90] degrees");
  c.real("inner_angle", l.inner_angle, 0.0f, false, l.outer_angle, false, "must be in [0, outer_angle] degrees");
}

void validate(const ShadowMapParams& s) {
  const glm::mat4& m = s.world_to_light_clip;
  double scale = 0.0;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) {
      if (!std::isfinite(m[c][r]))
        throw Error("light view-projection matrix element (row " + std::to_string(r) + ", column " +
                    std::to_string(c) + ") is not finite (got " + str(m[c][r]) + ")");
      scale = std::fmax(scale, std::fabs(double(m[c][r])));
    }
  const double det = glm::determinant(glm::dmat4(m));
  // Relative to the elements' scale: a determinant that is tiny against it is singular in float.
  const double bound = 1e-12 * std::pow(scale, 4);
  if (det == 0.0)
    throw Error("light view-projection matrix is singular (determinant 0): it must map world space one-to-one to "
                "light clip space");
  if (!(std::fabs(det) > bound))
    throw Error("light view-projection matrix is ill-conditioned: |determinant| " + str(std::fabs(det)) +
                " must be > 1e-12 x (largest |element| " + str(scale) + ")^4 = " + str(bound) +
                ", for it to map world space one-to-one to light clip space");
  if (!(std::isfinite(s.bias) && s.bias >= 0.0f))
    throw Error("shadow bias must be finite and >= 0 (got " + str(s.bias) + ")");
}

void validate(const VolumeSettings& s) {
  if (s.steps < 1 || s.steps > 4096) throw Error("volume steps must be in [1, 4096] (got " + std::to_string(s.steps) + ")");
  if (s.resolution_divisor != 1 && s.resolution_divisor != 2 && s.resolution_divisor != 4)
    throw Error("volume resolution divisor must be 1 (full), 2 (half) or 4 (quarter) (got " +
                std::to_string(s.resolution_divisor) + ")");
  if (s.noise_size != 32 && s.noise_size != 64 && s.noise_size != 128)
    throw Error("noise size must be 32, 64 or 128 (got " + std::to_string(s.noise_size) + ")");
  if (s.height_fog) {
    const FogSettings& f = *s.height_fog;
    if (f.mode != FogMode::height) throw Error("the marched height fog's mode must be height (VolumeSettings::height_fog)");
    validate(f);
    if (s.integrator == VolumeIntegrator::stylized)
      throw Error("the marched height fog needs the physical integrator (got stylized)");
    if (f.height.max_opacity != 1.0f)
      throw Error("the marched height fog's maximum opacity must be 1 (got " + str(f.height.max_opacity) +
                  "): a clamp of the whole ray cannot be applied per segment");
  }
}

void validate(const VolumeScene& s) {
  for (std::size_t i = 0; i < s.volumes.size(); ++i) validate(s.volumes[i], i);
  validate(s.pose);
  validate(s.light);
  for (std::size_t i = 0; i < s.lights.size(); ++i) validate(s.lights[i], i);
  if (!std::isfinite(s.time)) throw Error("time must be finite (got " + str(s.time) + ")");
}

const char* to_string(VolumeIntegrator i) {
  switch (i) {
    case VolumeIntegrator::stylized: return "stylized";
    case VolumeIntegrator::physical: return "physical";
    case VolumeIntegrator::riemann: return "riemann";
  }
  return "unknown";
}
const char* to_string(LightKind k) { return k == LightKind::spot ? "spot" : "point"; }
const char* to_string(VolumeUpsampling u) { return u == VolumeUpsampling::depth_aware ? "depth-aware" : "bilinear"; }
const char* resolution_name(int divisor) { return divisor == 1 ? "full" : divisor == 2 ? "half" : "quarter"; }
const char* to_string(NoiseSampling s) {
  switch (s) {
    case NoiseSampling::buffer: return "buffer";
    case NoiseSampling::image: return "image";
    case NoiseSampling::automatic: return "auto";
  }
  return "unknown";
}

NoiseSampling resolve_noise_sampling(NoiseSampling requested, const NoiseSamplingDevice& device) {
  if (requested != NoiseSampling::automatic) return requested;
  return !device.cpu && device.images && device.rgba_unorm8_3d ? NoiseSampling::image : NoiseSampling::buffer;
}

namespace {
// The camera's rotation, view -> world (camera/camera_basis.h) in float: columns right, up', forward.
struct Basis {
  glm::vec3 right, up, forward;
};
Basis float_basis(const CameraPose& p) {
  const detail::CameraBasis b = detail::camera_basis(p);
  return {glm::vec3(b.right), glm::vec3(b.up), glm::vec3(b.forward)};
}

// Culling in view space: side planes through the corner rays (or the orthographic box), near
// and far, and the depth buffer's farthest surface.
bool volume_visible(const FogVolume& v, const Basis& b, const CameraPose& pose, const CameraParams& cam,
                    float max_eye_depth) {
  const glm::dvec3 d = glm::dvec3(v.center) - glm::dvec3(pose.eye);
  const glm::dvec3 c(glm::dot(d, glm::dvec3(b.right)), glm::dot(d, glm::dvec3(b.up)), glm::dot(d, glm::dvec3(b.forward)));
  const double r = v.radius, n = cam.near_plane();
  // No far-plane test: sky pixels see infinitely far (t_scene = +inf, docs/volumetric.md §World and rays),
  // so a volume beyond the far plane still shows against the sky; the depth range hides it
  // wherever no pixel is sky.
  if (c.z + r < n) return false;
  if (c.z - r >= double(max_eye_depth)) return false;
  const auto& k = cam.frustum_corners;
  if (cam.projection == Projection::orthographic)
    return std::fabs(c.x) - r <= double(k[kTopRight].x) && std::fabs(c.y) - r <= double(k[kTopRight].y);
  // (edge a, edge b, a corner on the inside)
  const int planes[4][3] = {{kBottomLeft, kTopLeft, kBottomRight}, {kBottomRight, kTopRight, kBottomLeft},
                            {kBottomLeft, kBottomRight, kTopLeft}, {kTopLeft, kTopRight, kBottomLeft}};
  for (const auto& p : planes) {
    glm::dvec3 normal = glm::normalize(glm::cross(glm::dvec3(k[p[0]]), glm::dvec3(k[p[1]])));
    if (glm::dot(normal, glm::dvec3(k[p[2]])) < 0) normal = -normal;
    if (glm::dot(normal, c) < -r) return false;
  }
  return true;
}
}  // namespace

std::vector<std::size_t> visible_volumes(const VolumeScene& scene, const CameraParams& camera, float max_eye_depth) {
  validate(scene);
  validate(camera);
  const Basis b = float_basis(scene.pose);
  std::vector<std::size_t> visible;
  for (std::size_t i = 0; i < scene.volumes.size(); ++i)
    if (volume_visible(scene.volumes[i], b, scene.pose, camera, max_eye_depth)) visible.push_back(i);
  return visible;
}

namespace {
// The smallest and largest non-NaN value of values[0, n) folded into lo and hi, and whether one
// is NaN.
void value_range(const float* values, std::size_t n, float& lo, float& hi, bool& nan) {
  std::size_t i = 0;
#if defined(__SSE2__)
  // Four lanes (SSE2: every x86-64); the compiler keeps a float min/max reduction scalar.
  // minps/maxps return the second operand where the first is NaN, so NaN never enters.
  __m128 lo4 = _mm_set1_ps(lo), hi4 = _mm_set1_ps(hi), nan4 = _mm_setzero_ps();
  for (; i + 4 <= n; i += 4) {
    const __m128 v = _mm_loadu_ps(values + i);
    lo4 = _mm_min_ps(v, lo4);
    hi4 = _mm_max_ps(v, hi4);
    nan4 = _mm_or_ps(nan4, _mm_cmpunord_ps(v, v));
  }
  alignas(16) float l[4], h[4];
  _mm_store_ps(l, lo4);
  _mm_store_ps(h, hi4);
  for (int k = 0; k < 4; ++k) {
    lo = l[k] < lo ? l[k] : lo;
    hi = h[k] > hi ? h[k] : hi;
  }
  nan = nan || _mm_movemask_ps(nan4) != 0;
#endif
  for (; i < n; ++i) {
    const float v = values[i];
    lo = v < lo ? v : lo;
    hi = v > hi ? v : hi;
    nan = nan || v != v;
  }
}
}  // namespace

float max_eye_depth(const ConstDepthView& depth, const CameraParams& camera) {
  DepthImage copy;
  return detail::max_eye_depth(detail::packed_depth(depth, copy), camera, nullptr);
}

namespace detail {

float max_eye_depth(const ConstDepthView& depth, const CameraParams& camera, CopyWorkers* workers) {
  validate(camera);
  // Eye depth is monotonic in the stored value for every depth kind (a clamp, then a linear or
  // reciprocal map; NaN goes to the far end) but for the jumps to +inf (sky, nothing written) at
  // the ends of the range: the farthest pixel holds the smallest or the largest value, or a NaN.
  // So passes of compares find it and three eye depths (divisions) are taken per 64K pixels, not
  // one a pixel (6 ms a 1080p frame without sky, every call of the volume pass); the first sky
  // pixel still ends the scan. With workers, their threads scan the chunks (a staged call: the
  // upload's threads, before its copies start; 0.9 ms a 1080p frame without sky on one core of
  // the GPU host), each chunk ending all of them where it holds sky.
  const float zx = camera.zbuffer_params.x, zy = camera.zbuffer_params.y;
  const auto eye = [&](float v) {
    return volume_formulas::vol_eye_depth(v, int(camera.projection), camera.reversed_z, int(camera.depth_kind), zx,
                                          zy, camera.near_plane(), camera.far_plane());
  };
  // The farthest eye depth of a range of values, +inf where any of them is sky.
  const auto farthest_of = [&](float lo, float hi, bool nan) {
    float farthest = 0.0f;
    for (const float e : {lo <= hi ? eye(lo) : 0.0f, lo <= hi ? eye(hi) : 0.0f,
                          nan ? eye(std::numeric_limits<float>::quiet_NaN()) : 0.0f}) {
      if (!(e < kInf)) return kInf;
      farthest = std::fmax(farthest, e);
    }
    return farthest;
  };
  constexpr std::size_t kChunk = std::size_t(1) << 16;
  const std::size_t n = depth.pixel_count(), chunks = (n + kChunk - 1) / kChunk;
  // The first chunk here: sky in the top rows (most outdoor frames) ends the scan without waking
  // the threads. Eye depth being monotonic, the farthest of the chunks' joint range is the frame's.
  struct Range {
    float lo = kInf, hi = -kInf;
    bool nan = false;
  };
  std::vector<Range> ranges(chunks);
  std::atomic<bool> sky{false};
  const auto scan = [&](int c) {
    if (sky.load(std::memory_order_relaxed)) return;
    Range& r = ranges[std::size_t(c)];
    const std::size_t at = std::size_t(c) * kChunk;
    value_range(depth.data() + at, std::min(kChunk, n - at), r.lo, r.hi, r.nan);
    if (!(farthest_of(r.lo, r.hi, r.nan) < kInf)) sky.store(true, std::memory_order_relaxed);
  };
  scan(0);
  if (sky.load()) return kInf;
  if (workers != nullptr)
    workers->run(int(chunks - 1), [&](int c) { scan(c + 1); });
  else
    for (std::size_t c = 1; c < chunks; ++c) scan(int(c));
  if (sky.load()) return kInf;
  float lo = kInf, hi = -kInf;
  bool nan = false;
  for (const Range& r : ranges) {
    lo = std::min(lo, r.lo);
    hi = std::max(hi, r.hi);
    nan = nan || r.nan;
  }
  return farthest_of(lo, hi, nan);
}

bool PackedVolumeFrame::needs_noise() const { return (variant.features & VOL_FEATURE_NOISE) != 0; }
bool PackedVolumeFrame::nothing_to_march() const {
  return visible.empty() && !(variant.features & VOL_FEATURE_HEIGHT);
}

void pack_depth_constants(float* frame, const CameraParams& camera) {
  frame[VOL_F_NEAR] = camera.near_plane();
  frame[VOL_F_FAR] = camera.far_plane();
  frame[VOL_F_INV_NEAR] = 1.0f / frame[VOL_F_NEAR];
  frame[VOL_F_INV_FAR] = 1.0f / frame[VOL_F_FAR];
  frame[VOL_F_ZX] = camera.zbuffer_params.x;
  frame[VOL_F_ZY] = camera.zbuffer_params.y;
}

namespace {
// The marched height fog (docs/DESIGN.md §6.5) into the frame and the variant: the deferred pass's
// variant selection gives the FOG_HF_* bits (none: the fog is empty, no code for it).
void pack_height_fog(PackedVolumeFrame& out, const FogSettings& fog, const CameraParams& camera,
                     const CameraPose& pose) {
  CameraParams posed = camera;
  posed.pose = pose;
  const Variant fv = select_variant(fog, posed, ColorFormat::rgba32f);
  if (fv.mode != KernelMode::height) return;
  VolumeVariant& v = out.variant;
  v.features |= VOL_FEATURE_HEIGHT;
  v.height_features = fv.height_features | (fog.fog_skybox ? FOG_HF_SKYBOX : 0);
  // Only an extinction that differs per channel needs the target's coverage per channel.
  const glm::vec3 e = height_extinction(fog);
  if ((v.height_features & FOG_HF_RGB) && (e.x != e.y || e.x != e.z)) v.features |= VOL_FEATURE_HEIGHT_RGB;
  // The volumes' buffer is bound even when no volume is visible: one unread entry.
  if (out.volumes.empty()) out.volumes.assign(VOL_V_STRIDE, 0.0f);
  float* k = out.frame.data();
  const HeightCoefficients<float> hc = height_coefficients<float>(fog, posed);
  for (int i = 0; i < FOG_HP_COUNT; ++i) k[VOL_F_HEIGHT_P + i] = hc.p[i];
  k[VOL_F_HEIGHT_BASE] = fog.height.base_height;
  if (fog.height.sun) {
    const glm::vec3 l = glm::vec3(glm::normalize(glm::dvec3(fog.height.sun->direction)));
    k[VOL_F_HEIGHT_SUN] = l.x, k[VOL_F_HEIGHT_SUN + 1] = l.y, k[VOL_F_HEIGHT_SUN + 2] = l.z;
  }
  // An infinite ray marches to the far plane (an infinite far plane: no stretch, the tail alone).
  k[VOL_F_HEIGHT_REACH] = camera.projection == Projection::perspective_infinite_far ? 0.0f : camera.far_plane();
}
// The local lights that can add light (docs/volumetric.md#local-lights) after the volumes: a black
// light, or one whose range sphere meets no visible volume (without the marched height fog, which
// fills the view), adds exactly 0 and is left out; none left, no light code in the variant.
static_assert(kMaxLocalLights == VOL_MAX_LIGHTS, "fogcl/volumes.h and kernels/volume_integrate.h agree");
constexpr double kRadiansPerDegree = 3.14159265358979323846 / 180.0;
void pack_lights(PackedVolumeFrame& out, const VolumeScene& scene) {
  const bool height = (out.variant.features & VOL_FEATURE_HEIGHT) != 0;
  if (out.visible.empty() && !height) return;  // no medium to glow in
  std::vector<float> packed;
  int spots = 0;
  for (const LocalLight& l : scene.lights) {
    if (l.intensity == 0.0f || std::max({l.color.x, l.color.y, l.color.z}) == 0.0f) continue;
    bool reaches = height;
    for (std::size_t index : out.visible) {
      const FogVolume& v = scene.volumes[index];
      reaches = reaches || double(glm::length(glm::dvec3(l.position) - glm::dvec3(v.center))) <
                               double(l.range) + double(v.radius);
    }
    if (!reaches) continue;
    float p[VOL_L_STRIDE] = {};
    const auto put3 = [&](int at, const glm::vec3& x) { p[at] = x.x, p[at + 1] = x.y, p[at + 2] = x.z; };
    put3(VOL_L_POSITION, l.position);
    put3(VOL_L_RADIANCE, l.intensity * l.color);
    p[VOL_L_RANGE] = l.range;
    p[VOL_L_INV_RANGE2] = float(1.0 / (double(l.range) * double(l.range)));
    p[VOL_L_RADIUS2] = l.radius * l.radius;
    p[VOL_L_SPOT_SCALE] = 0.0f;  // a point light: the cone's factor is saturate(1)^2 = 1
    p[VOL_L_SPOT_OFFSET] = 1.0f;
    if (l.kind == LightKind::spot) {
      put3(VOL_L_AXIS, glm::vec3(glm::normalize(glm::dvec3(l.direction))));
      const double inner = std::cos(double(l.inner_angle) * kRadiansPerDegree);
      const double outer = std::cos(double(l.outer_angle) * kRadiansPerDegree);
      const double scale = 1.0 / std::max(inner - outer, 1e-4);
      p[VOL_L_SPOT_SCALE] = float(scale);
      p[VOL_L_SPOT_OFFSET] = float(-outer * scale);
      ++spots;
    }
    packed.insert(packed.end(), p, p + VOL_L_STRIDE);
  }
  const std::size_t n = packed.size() / VOL_L_STRIDE;
  if (n == 0) return;
  if (n > VOL_MAX_LIGHTS)
    throw Error(std::to_string(n) + " local lights reach a visible medium in this frame; at most " +
                std::to_string(VOL_MAX_LIGHTS) + " are supported");
  out.variant.features |= VOL_FEATURE_LIGHTS | (spots > 0 ? VOL_FEATURE_SPOT : 0);
  out.frame[VOL_F_LIGHT_COUNT] = float(n);
  out.frame[VOL_F_LIGHT_OFFSET] = float(out.volumes.size());
  out.volumes.insert(out.volumes.end(), packed.begin(), packed.end());
}
}  // namespace

PackedVolumeFrame pack_volume_frame(int width, int height, const CameraParams& camera, const VolumeScene& scene,
                                    const VolumeSettings& settings, ColorFormat storage,
                                    const ShadowMapParams* shadow, int shadow_width, int shadow_height,
                                    float max_eye_depth) {
  if (width < 1 || height < 1)
    throw Error("frame size must be at least 1x1 (got " + std::to_string(width) + "x" + std::to_string(height) + ")");
  validate(settings);
  if (camera.depth_kind == DepthKind::distance)
    throw Error("the volume pass reads raw or eye depth, not radial distance: convert it with to_eye_depth() "
                "(fogcl/depth_kinds.h), which keeps every digit");
  if (shadow) {
    validate(*shadow);
    if (shadow_width < 1 || shadow_height < 1)
      throw Error("shadow map size must be at least 1x1 (got " + std::to_string(shadow_width) + "x" +
                  std::to_string(shadow_height) + ")");
  }
  if (!scene.lights.empty() && settings.integrator == VolumeIntegrator::stylized)
    throw Error("local lights need the physical integrator (got stylized, with " + std::to_string(scene.lights.size()) +
                (scene.lights.size() == 1 ? " light" : " lights") +
                "): the seed's accumulator has no per-sample light to add them to (VolumeSettings::integrator; "
                "fogcl apply --integrator physical)");
  PackedVolumeFrame out;
  out.visible = visible_volumes(scene, camera, max_eye_depth);  // validates scene and camera
  if (out.visible.size() > VOL_MAX_VOLUMES)
    throw Error(std::to_string(out.visible.size()) + " fog volumes are visible in this frame; at most " +
                std::to_string(VOL_MAX_VOLUMES) + " are supported");
  if (settings.height_fog && out.visible.size() >= VOL_MAX_VOLUMES)
    throw Error(std::to_string(out.visible.size()) + " fog volumes are visible in this frame; at most " +
                std::to_string(VOL_MAX_VOLUMES - 1) + " are supported with the marched height fog");
  const int s = settings.resolution_divisor;
  out.low_width = (width + s - 1) / s;
  out.low_height = (height + s - 1) / s;

  VolumeVariant& v = out.variant;
  v.integrator = settings.integrator;
  v.steps = settings.steps;
  v.jitter = settings.jitter;
  v.projection = camera.projection;
  v.reversed_z = camera.reversed_z;
  v.depth_kind = camera.depth_kind;
  // The passes resolve automatic for their device before packing (VolumePass); the host paths
  // (the scalar march, the OpenMP peer) filter like the buffer, which is what automatic is there.
  v.noise_sampling = resolve_noise_sampling(settings.noise_sampling, NoiseSamplingDevice{});
  v.scale = s;
  v.depth_aware = settings.upsampling == VolumeUpsampling::depth_aware;
  v.storage = storage;
  if (settings.integrator == VolumeIntegrator::stylized && settings.adaptive_steps) v.features |= VOL_FEATURE_ADAPTIVE;
  if (shadow) v.features |= VOL_FEATURE_SHADOW | (shadow->reversed_z ? VOL_FEATURE_SHADOW_REVERSED : 0);

  const glm::vec3 light_dir = glm::normalize(scene.light.direction);
  for (std::size_t index : out.visible) {
    const FogVolume& f = scene.volumes[index];
    if (f.noise) v.features |= VOL_FEATURE_NOISE;
    if (f.noise && f.detail_strength > 0.0f) v.features |= VOL_FEATURE_DETAIL;
    if (f.fade_edge > 0.0f || f.fade_y > 0.0f || f.proximity_fade > 0.0f || f.max_y < f.center.y + f.radius)
      v.features |= VOL_FEATURE_FADES;
    float p[VOL_V_STRIDE] = {};
    const auto put3 = [&](int at, const glm::vec3& x) { p[at] = x.x, p[at + 1] = x.y, p[at + 2] = x.z; };
    const auto put4 = [&](int at, const glm::vec4& x) { put3(at, glm::vec3(x)), p[at + 3] = x.w; };
    put3(VOL_V_CENTER, f.center);
    p[VOL_V_RADIUS] = f.radius;
    p[VOL_V_DENSITY] = f.density;
    p[VOL_V_MAX_Y] = f.max_y;
    p[VOL_V_FADE_Y] = f.fade_y;
    p[VOL_V_FADE_EDGE] = f.fade_edge;
    p[VOL_V_PROXIMITY_FADE] = f.proximity_fade;
    p[VOL_V_FOG_EXPONENT] = f.fog_exponent;
    p[VOL_V_FOG_CUTOFF] = f.fog_cutoff;
    p[VOL_V_DETAIL_EXPONENT] = f.detail_exponent;
    p[VOL_V_DETAIL_STRENGTH] = f.detail_strength;
    put4(VOL_V_FOG_COLOR, f.fog_color);
    put4(VOL_V_DIR_FOG_COLOR, f.directional_fog_color);
    p[VOL_V_DIR_FALLOFF] = f.directional_falloff;
    p[VOL_V_LIGHT_CONTRIBUTION] = f.light_contribution;
    p[VOL_V_DIR_LIGHT_CONTRIBUTION] = f.directional_light_contribution;
    p[VOL_V_SHADOW_STRENGTH] = f.shadow_strength;
    p[VOL_V_SHADOW_REVERSE_STRENGTH] = f.shadow_reverse_strength;
    put3(VOL_V_TILING, f.tiling);
    put3(VOL_V_SPEED, f.speed);
    put3(VOL_V_DETAIL_TILING, f.detail_tiling);
    p[VOL_V_DETAIL_SPEED_MODIFIER] = f.detail_speed_modifier;
    p[VOL_V_OVERSHOOT] = f.occluder_overshoot;
    p[VOL_V_NOISE] = f.noise ? 1.0f : 0.0f;
    put3(VOL_V_ALBEDO, f.albedo.value_or(glm::vec3(f.fog_color)));
    p[VOL_V_ANISOTROPY] = f.anisotropy;
    put3(VOL_V_AMBIENT, f.ambient.value_or(0.1f * scene.light.color));
    out.volumes.insert(out.volumes.end(), p, p + VOL_V_STRIDE);
  }

  float* k = out.frame.data();
  const Basis b = float_basis(scene.pose);
  const auto put3 = [&](int at, const glm::vec3& x) { k[at] = x.x, k[at + 1] = x.y, k[at + 2] = x.z; };
  put3(VOL_F_EYE, scene.pose.eye);
  put3(VOL_F_RIGHT, b.right);
  put3(VOL_F_UP, b.up);
  put3(VOL_F_FORWARD, b.forward);
  for (int c = 0; c < 4; ++c) put3(VOL_F_CORNERS + 3 * c, camera.frustum_corners[c]);
  pack_depth_constants(k, camera);
  k[VOL_F_CORNER_Z] = camera.frustum_corners[kBottomLeft].z;
  put3(VOL_F_LIGHT_DIR, light_dir);
  put3(VOL_F_LIGHT_COLOR, scene.light.color);
  k[VOL_F_TIME] = scene.time;
  k[VOL_F_WIDTH] = float(width);
  k[VOL_F_HEIGHT] = float(height);
  k[VOL_F_SCALE] = float(s);
  k[VOL_F_LOW_WIDTH] = float(out.low_width);
  k[VOL_F_LOW_HEIGHT] = float(out.low_height);
  if (shadow) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) k[VOL_F_SHADOW_MATRIX + 4 * c + r] = shadow->world_to_light_clip[c][r];
    k[VOL_F_SHADOW_WIDTH] = float(shadow_width);
    k[VOL_F_SHADOW_HEIGHT] = float(shadow_height);
    k[VOL_F_SHADOW_BIAS] = shadow->bias;
  }
  if (settings.height_fog) pack_height_fog(out, *settings.height_fog, camera, scene.pose);
  pack_lights(out, scene);
  return out;
}

int integrator_code(VolumeIntegrator integrator) {
  switch (integrator) {
    case VolumeIntegrator::stylized: return VOL_STYLIZED;
    case VolumeIntegrator::physical: return VOL_PHYSICAL;
    case VolumeIntegrator::riemann: return VOL_RIEMANN;
  }
  throw Error("volume integrator " + std::to_string(int(integrator)) + " is not one of stylized, physical, riemann");
}

int volume_march_lanes(const VolumeVariant& v, const DeviceTraits& device) {
  // kernels/volume_march.cl, docs/volumetric.md §Lanes on CPU devices: PoCL vectorises only across
  // work-items, which the march's loops prevent; the lanes instance has no image sampling.
  const bool buffer = v.noise_sampling == NoiseSampling::buffer || !(v.features & VOL_FEATURE_NOISE);
  return pixels_per_work_item(device) == 16 && buffer ? 16 : 1;
}

int volume_composite_lanes(const VolumeVariant& v, const DeviceTraits& device) {
  // A target with a coverage per channel is composited one pixel per work-item (the CPU lanes'
  // quads hold one coverage per pixel).
  return target_floats(v) == 4 ? pixels_per_work_item(device) : 1;
}

int target_floats(const VolumeVariant& v) { return (v.features & VOL_FEATURE_HEIGHT_RGB) ? 8 : 4; }

std::string volume_march_options(const VolumeVariant& v, const DeviceTraits& device) {
  std::string o = cl_std_option(device);
  if (const int lanes = volume_march_lanes(v, device); lanes > 1) o += " -D VOL_LANES=" + std::to_string(lanes);
  o += " -D VOL_INTEGRATOR=" + std::to_string(integrator_code(v.integrator));
  o += " -D VOL_STEPS=" + std::to_string(v.steps);
  o += " -D VOL_FEATURES=" + std::to_string(v.features);
  if (v.features & VOL_FEATURE_HEIGHT) o += " -D VOL_HEIGHT_FEATURES=" + std::to_string(v.height_features);
  o += " -D VOL_JITTER=" + std::to_string(v.jitter ? 1 : 0);
  o += " -D FOG_PROJECTION=" + std::to_string(int(v.projection));
  if (v.reversed_z) o += " -D REVERSED_Z";
  if (v.depth_kind != DepthKind::raw) o += " -D VOL_DEPTH_KIND=" + std::to_string(int(v.depth_kind));
  if (v.noise_sampling == NoiseSampling::image && (v.features & VOL_FEATURE_NOISE)) o += " -D VOL_NOISE_IMAGE";
  if (v.noise_sampling == NoiseSampling::buffer && (v.features & VOL_FEATURE_NOISE) && !device.cpu)
    o += " -D VOL_TEXEL_WORD_LOADS";  // kernels/volume_noise.h: GPUs only
  if (device.cpu && !device.codegen.target_intrinsics) o += " -D FOG_PORTABLE";
  return o;
}

// The private arrays per target pixel (a lane) of kernels/volume_march.cl, in 4-byte words: the
// ray, its occluder, key, jitter and result (13); the staging of the noise and shadow-map helpers
// inlined into it (10); the stylized march's per-volume entries (7), or the physical walk's state
// (15) and its per-volume entry and exit distances (2 x VOL_MAX_VOLUMES); with the marched height
// fog its FOG_HP_* constants and its per-channel sums, their copies and the lanes' staging of
// them (60); with local lights their constants along the ray and the volumes' extinctions of a
// segment (VOL_LR_STRIDE x VOL_MAX_LIGHTS + VOL_MAX_VOLUMES). Twice that for what the
// compiler keeps besides (spilled vectors, copies): PoCL 3.1's work-group functions hold 0.9-1.15x
// the arrays per work-item (their stack frames: 6.4-6.8 KB physical, 1.7-2.2 KB stylized at 16
// lanes).
std::size_t volume_march_private_bytes(const VolumeVariant& v, const DeviceTraits& device) {
  const std::size_t per_lane =
      13 + 10 + (v.integrator == VolumeIntegrator::stylized ? 7 : 15 + 2 * VOL_MAX_VOLUMES) +
      ((v.features & VOL_FEATURE_HEIGHT) ? FOG_HP_COUNT + 60 : 0) +  // the marched fog's constants and sums
      ((v.features & VOL_FEATURE_LIGHTS) ? VOL_LR_STRIDE * VOL_MAX_LIGHTS + VOL_MAX_VOLUMES : 0);  // lights' ray constants, extinctions
  return 2 * 4 * per_lane * std::size_t(volume_march_lanes(v, device));
}

// kernels/volume_composite.h, volume_composite_cpu.h: the upsampling's distances, weights and
// taps (4 + 4 floats, 4 float4) and the half stores' staging (16 halves), twice over as above
// (97-145 bytes per work-item measured).
std::size_t volume_composite_private_bytes(const VolumeVariant&, const DeviceTraits&) {
  return 2 * (4 * (4 + 4 + 16) + 2 * 16);
}

std::string volume_composite_options(const VolumeVariant& v, const DeviceTraits& device) {
  std::string o = cl_std_option(device);
  o += " -D VOL_SCALE=" + std::to_string(v.scale);
  o += " -D VOL_DEPTH_AWARE=" + std::to_string(v.depth_aware ? 1 : 0);
  o += " -D FOG_PROJECTION=" + std::to_string(int(v.projection));
  if (v.reversed_z) o += " -D REVERSED_Z";
  if (v.depth_kind != DepthKind::raw) o += " -D VOL_DEPTH_KIND=" + std::to_string(int(v.depth_kind));
  if (v.storage == ColorFormat::rgba16f) o += " -D FOG_COLOR_HALF";
  const int lanes = volume_composite_lanes(v, device);
  o += " -D VOL_LANES=" + std::to_string(lanes);
  if (target_floats(v) == 8) o += " -D VOL_TARGET_RGB";
  if (lanes > 1) o += streaming_store_option(device, v.storage);  // as the deferred pass's (variant.h)
  if (device.cpu && !device.codegen.target_intrinsics) o += " -D FOG_PORTABLE";
  return o;
}

std::array<std::size_t, 2> volume_composite_global(const VolumeVariant& v, const DeviceTraits& device, int width,
                                                   int height) {
  const int lanes = volume_composite_lanes(v, device), s = v.scale;
  const std::size_t x = std::size_t((width + lanes - 1) / lanes);
  if (lanes == 1 || s == 1) return {x, std::size_t(height)};
  // Work-item m takes rows s m - s / 2 .. s m + s / 2 - 1 (vol_rows_of): the last one the row H - 1.
  return {x, std::size_t((height - 1 + s / 2) / s + 1)};
}

const NoiseTexture& shared_noise_texture(int size, std::uint32_t seed) {
  static std::mutex mutex;
  static std::map<std::pair<int, std::uint32_t>, std::unique_ptr<NoiseTexture>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[{size, seed}];
  if (!slot) slot = std::make_unique<NoiseTexture>(make_noise_texture(size, seed));
  return *slot;
}

const std::vector<std::uint8_t>& shared_noise_r_blocks(const NoiseTexture& texture) {
  static std::mutex mutex;
  static std::map<const NoiseTexture*, std::vector<std::uint8_t>> cache;
  std::lock_guard<std::mutex> lock(mutex);
  std::vector<std::uint8_t>& blocks = cache[&texture];
  if (blocks.empty()) {
    const int n = texture.size, mask = n - 1;
    const auto r = [&](int x, int y, int z) {
      return texture.texels[4 * ((std::size_t(z) * n + (y & mask)) * n + (x & mask))];
    };
    blocks.resize(4 * std::size_t(n) * n * n);
    std::uint8_t* w = blocks.data();
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x, w += 4) {
          w[0] = r(x, y, z);
          w[1] = r(x + 1, y, z);
          w[2] = r(x, y + 1, z);
          w[3] = r(x + 1, y + 1, z);
        }
  }
  return blocks;
}

}  // namespace detail
}  // namespace fogcl
