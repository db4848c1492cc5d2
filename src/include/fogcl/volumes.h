// Volumetric fog volumes (docs/volumetric.md): spheres of noisy fog placed in the world,
// ray-marched per pixel into a reduced-resolution target, upsampled and composited onto the lit
// color. When the deferred fog runs too, the volumes are composited first.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "fogcl/camera.h"
#include "fogcl/fog_settings.h"
#include "fogcl/image.h"

namespace fogcl {

// One fog volume: a sphere with the seed's parameters ("Rendering Volumetric Fog Using Custom URP
// Render Pass", vertexfragment.com), same names in snake_case and the same defaults. Lengths are
// world units; a fade width of 0 means no fade.
struct FogVolume {
  glm::vec3 center{0.0f};               // [world], finite
  float radius = 1.0f;                  // [world], finite, > 0
  // Stylized: the seed's density scale of the final alpha, >= 0. Physical: the extinction
  // coefficient sigma_t [1/world unit] at full noise, >= 0.
  float density = 0.1f;
  float max_y = 100.0f;                 // height fade: fog thins out towards this world y
  float fade_y = 2.0f;                  // height fade width [world], >= 0 (0: no height fade)
  float fade_edge = 20.0f;              // edge fade width in from the sphere's surface [world], >= 0
  float proximity_fade = 10.0f;         // fog thins out within this distance of the camera [world], >= 0
  float fog_exponent = 1.0f;            // shape noise exponent, > 0
  float fog_cutoff = 0.0f;              // noise below this is no fog, in [0, 1)
  float detail_exponent = 1.0f;         // detail noise exponent, > 0
  float detail_strength = 0.75f;        // how much detail noise erodes the shape, in [0, 1]
  glm::vec4 fog_color{1.0f};            // linear RGBA, each in [0, 65504]; alpha scales coverage
  glm::vec4 directional_fog_color{1.0f};  // color looking toward the light (stylized)
  float directional_falloff = 1.0f;     // exponent of the toward-the-light lobe, > 0
  float light_contribution = 1.0f;      // stylized: light color weight, >= 0
  float directional_light_contribution = 1.0f;  // stylized: weight inside the lobe, >= 0
  float shadow_strength = 1.0f;         // stylized: darkening by shadowed samples, >= 0
  float shadow_reverse_strength = 1.0f; // stylized: recovery by lit samples, >= 0
  glm::vec3 tiling{0.015f};             // shape noise uvw per world unit, finite
  glm::vec3 speed{1.75f, -0.5f, 0.1f};  // shape noise scroll [world units / s], finite
  glm::vec3 detail_tiling{0.015f};      // detail noise uvw per world unit, finite
  float detail_speed_modifier = 2.0f;   // detail scroll = speed * this, finite
  float occluder_overshoot = 5.0f;      // stylized: march this many times past an occluder, >= 0
  bool noise = true;                    // false: the density field is 1 inside the sphere
  // Physical integrator only.
  std::optional<glm::vec3> albedo;      // single-scattering albedo in [0, 1]; default fog_color.rgb
  float anisotropy = 0.0f;              // Henyey-Greenstein g in (-1, 1)
  std::optional<glm::vec3> ambient;     // ambient radiance RGB >= 0; default 0.1 * light color
};

// CameraPose (the camera's position and orientation) is in fogcl/camera.h.

// A local light's shape (LocalLight::kind).
enum class LightKind {
  point,  // shines in every direction
  spot,   // shines into a cone around LocalLight::direction
};

// A point or spot light that glows in the fog (docs/volumetric.md#local-lights): the physical
// integrator scatters it toward the eye in the fog volumes and in the marched height fog, with
// each medium's phase function and the same transmittance as the main light. Unshadowed.
// A medium point at distance d from the light scatters toward the eye the radiance
//   intensity * color * phase * sigma_s * window(d) * cone / (d^2 + radius^2),
// window(d) = (1 - d^2 / range^2)^2 for d < range, else 0 (1 at the light, 0 with zero slope at
// the range: the light adds exactly 0 beyond it). A volume's sigma_s = albedo * its extinction.
struct LocalLight {
  LightKind kind = LightKind::point;
  glm::vec3 position{0.0f};             // [world], finite
  glm::vec3 color{1.0f};                // linear RGB, finite, >= 0
  // Radiant intensity of color 1 [radiance x world^2, the main light's irradiance x world^2]:
  // finite, >= 0. intensity * max(color) * max(1, 1 / radius^2) must be <= 1e30 (the peak stays
  // in float).
  float intensity = 1.0f;
  float range = 10.0f;                  // [world], finite, in (0, 1e15]: nothing beyond it
  // Source radius [world], finite, in [1e-6, range]: the inverse square is 1 / (d^2 + radius^2), so
  // a sample at the light (or a ray through it) sees a finite peak intensity / radius^2.
  float radius = 0.05f;
  // Spot only. The cone's axis, from the light outward: finite, non-zero (normalised by the pass).
  glm::vec3 direction{0.0f, -1.0f, 0.0f};
  // Spot only: half-angles from the axis [degrees], 0 <= inner_angle <= outer_angle, outer_angle
  // in (0, 90]. Full intensity within inner_angle, 0 beyond outer_angle; between them the factor
  // saturate((cos a - cos outer) / max(cos inner - cos outer, 1e-4))^2 of the angle a to the axis.
  float inner_angle = 30.0f;
  float outer_angle = 45.0f;
};

// At most this many local lights reach the volumes and the marched fog in one frame (lights
// whose range meets no visible medium, or that are black, do not count).
inline constexpr std::size_t kMaxLocalLights = 32;

// The main (directional) light.
struct MainLight {
  glm::vec3 direction{0.0f, 1.0f, 0.0f};  // from the scene toward the light, non-zero
  glm::vec3 color{1.0f};                  // linear RGB >= 0 (physical: irradiance)
};

// The main light's shadow map as the integration API sees it: a float32 raw-depth image of the
// light (row 0 = top) and the world -> light clip matrix. Clip xy in [-1, 1] map to the map's uv
// (v = 0 at the bottom row); clip z / w is the stored depth, in [0, 1]. A sample point is lit
// when it is nearer the light than the map's depth + bias.
struct ShadowMapParams {
  glm::mat4 world_to_light_clip{1.0f};  // column-major (GLM); finite, invertible
  bool reversed_z = false;              // the map holds 1 at the light's near plane
  float bias = 1e-3f;                   // in depth units, finite, >= 0
};

// A host-side shadow map (convenience API).
struct ShadowMap {
  DepthImage depth;                     // >= 1x1
  ShadowMapParams params;
};

enum class VolumeIntegrator {
  stylized,  // the seed's accumulator, for visual parity with it
  physical,  // energy-conserving (Hillaire 2015), exact for piecewise-constant extinction
  // The physical model with the textbook left Riemann sum per segment (I += T * sigma_s * L * d):
  // for comparison only (fogcl report --volumetric), it overshoots by up to sigma_t * d in dense
  // media. Never picked by fogcl; no CLI flag selects it.
  riemann,
};

enum class VolumeUpsampling {
  depth_aware,  // bilinear weights x depth similarity: no fog bleeding across silhouettes
  bilinear,     // the seed's blit
};

enum class NoiseSampling {
  buffer,     // a buffer of unorm8 texels, trilinear filtering in the kernel (exact, any device)
  image,      // an OpenCL 3D image with the sampler's linear filtering (hardware on GPUs)
  automatic,  // the device's: image where the texture unit filters, else buffer (resolve_noise_sampling)
};

// What NoiseSampling::automatic is resolved from: facts of the OpenCL device the pass runs on.
struct NoiseSamplingDevice {
  bool cpu = true;              // CL_DEVICE_TYPE_CPU (else a GPU or an accelerator)
  bool images = false;          // CL_DEVICE_IMAGE_SUPPORT
  bool rgba_unorm8_3d = false;  // CL_RGBA / CL_UNORM_INT8 among the context's read-only 3D image formats
};

// `requested` when it is buffer or image; for automatic, image on a device that is not a CPU, has
// images and reads the noise's CL_RGBA / CL_UNORM_INT8 3D image (linear filtering applies to every
// normalized format), else buffer. CPU devices keep the buffer: PoCL samples images in software,
// 1.34x slower for the same error; a GPU's texture unit is 2.1-2.8x faster than the buffer on the
// H100 (docs/gpu.md). The image's error budget: docs/accuracy.md#noise-sampling-on-gpus.
NoiseSampling resolve_noise_sampling(NoiseSampling requested, const NoiseSamplingDevice& device);

// Quality choices of the pass; each is a kernel build option (docs/volumetric.md §Variants and culling).
struct VolumeSettings {
  VolumeIntegrator integrator = VolumeIntegrator::stylized;
  int steps = 50;                        // march steps per ray, in [1, 4096]; the seed's 50
  int resolution_divisor = 2;            // 1 full, 2 half (the seed's), 4 quarter
  VolumeUpsampling upsampling = VolumeUpsampling::depth_aware;
  bool jitter = true;                    // per-ray start jitter from (pixel, frame index)
  bool adaptive_steps = true;            // stylized: the seed's step refinement at fog onset
  int noise_size = 64;                   // noise texels per side: 32, 64 or 128
  std::uint32_t noise_seed = 1;
  NoiseSampling noise_sampling = NoiseSampling::automatic;  // resolved per device by the pass
  // The height fog marched with the volumes (docs/DESIGN.md §6.5): light shafts where the shadow
  // map shadows the sun. Unset (default): no height fog in this pass, and no code for it. Set: its
  // mode must be FogMode::height; the fog is §6's (FogSettings::height, color, density,
  // fog_skybox), with the physical integrator (extinction and in-scattering may differ per
  // channel), maximum opacity 1, and at most 31 visible volumes. The
  // lobe's direction is FogSettings::height.sun's (give it the main light's direction). The
  // deferred pass must then not also apply the height fog: this pass's composite replaces it.
  std::optional<FogSettings> height_fog;
};

// What changes from frame to frame.
struct VolumeScene {
  std::vector<FogVolume> volumes;
  CameraPose pose;
  MainLight light;
  // Point and spot lights: the physical integrator only (the stylized one refuses them).
  std::vector<LocalLight> lights;
  float time = 0.0f;                     // [s], finite: noise scrolls by speed * time
  std::uint32_t frame_index = 0;         // seeds the per-ray jitter
};

// Throw fogcl::Error naming the value (and the volume's index) and the rule.
void validate(const FogVolume& volume, std::size_t index = 0);
void validate(const CameraPose& pose);
void validate(const MainLight& light);
// "light 2: range must be finite and in (0, 1e15] (got -1)".
void validate(const LocalLight& light, std::size_t index = 0);
void validate(const ShadowMapParams& shadow);
void validate(const VolumeSettings& settings);
void validate(const VolumeScene& scene);

const char* to_string(VolumeIntegrator integrator);
const char* to_string(VolumeUpsampling upsampling);
const char* to_string(LightKind kind);  // "point", "spot"
const char* to_string(NoiseSampling sampling);
// VolumeSettings::resolution_divisor's name: 1 "full", 2 "half", 4 "quarter".
const char* resolution_name(int divisor);

}  // namespace fogcl
