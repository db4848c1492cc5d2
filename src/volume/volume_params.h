// What the host hands the volumetric kernels and the scalar path alike: the packed per-frame and
// per-volume arrays (layouts in kernels/volume_common.h), the variant a frame needs and its
// build options, and the process-wide noise textures.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fogcl/camera.h"
#include "fogcl/image.h"
#include "fogcl/noise.h"
#include "fogcl/variant.h"
#include "fogcl/volumes.h"

namespace fogcl::detail {

// Everything a frame's march and composite are specialised on.
struct VolumeVariant {
  VolumeIntegrator integrator = VolumeIntegrator::stylized;
  int steps = 50;
  int features = 0;           // VOL_FEATURE_* bits
  int height_features = 0;    // VOL_FEATURE_HEIGHT: the marched height fog's FOG_HF_* bits (VOL_HEIGHT_FEATURES)
  bool jitter = true;
  Projection projection = Projection::perspective;
  bool reversed_z = false;
  DepthKind depth_kind = DepthKind::raw;  // VOL_DEPTH_KIND: raw or eye (radial distance arrives as eye depth)
  NoiseSampling noise_sampling = NoiseSampling::buffer;
  int scale = 2;
  bool depth_aware = true;
  ColorFormat storage = ColorFormat::rgba32f;
};

// A frame ready to march: the visible volumes packed, the frame constants, the variant.
struct PackedVolumeFrame {
  std::array<float, 88> frame{};   // VOL_F_COUNT floats
  std::vector<float> volumes;      // VOL_V_STRIDE floats per visible volume
  std::vector<std::size_t> visible;  // indices into scene.volumes
  VolumeVariant variant;
  int low_width = 0, low_height = 0;
  bool needs_noise() const;
  // No volume visible and no marched height fog: the pass draws nothing, the output is the input.
  bool nothing_to_march() const;
};

class CopyWorkers;

// fogcl::max_eye_depth, the chunks of the scan spread over `workers`' threads where given (the
// same float: tests/volume_culling_test.cpp).
float max_eye_depth(const ConstDepthView& depth, const CameraParams& camera, CopyWorkers* workers);  // packed rows

// Validates everything and packs the frame (culling with max_eye_depth). Throws fogcl::Error.
// NoiseSampling::automatic packs as buffer (the host paths' filtering): a pass resolves it for its
// device first (resolve_noise_sampling), so a variant never holds automatic.
PackedVolumeFrame pack_volume_frame(int width, int height, const CameraParams& camera, const VolumeScene& scene,
                                    const VolumeSettings& settings, ColorFormat storage,
                                    const ShadowMapParams* shadow, int shadow_width, int shadow_height,
                                    float max_eye_depth);

// The camera's depth constants into a per-frame array (VOL_F_COUNT floats): VOL_F_NEAR, VOL_F_FAR,
// their reciprocals VOL_F_INV_NEAR, VOL_F_INV_FAR, and _ZBufferParams.xy (VOL_F_ZX, VOL_F_ZY).
void pack_depth_constants(float* frame, const CameraParams& camera);

// VOL_STYLIZED, VOL_PHYSICAL or VOL_RIEMANN (kernels/volume_common.h): the march's integrator switch.
int integrator_code(VolumeIntegrator integrator);

// Target pixels per work-item of the march (VOL_LANES): 16 on CPU devices where the lanes
// instance applies, else 1. The global size's x is ceil(low_width / lanes).
int volume_march_lanes(const VolumeVariant& variant, const DeviceTraits& device);
std::string volume_march_options(const VolumeVariant& variant, const DeviceTraits& device);
// Frame pixels per work-item of the composite (its VOL_LANES): pixels_per_work_item, but 1 for a
// target with a coverage per channel.
int volume_composite_lanes(const VolumeVariant& variant, const DeviceTraits& device);
// Floats per target pixel (kernels/volume_composite.h's layout): 4, or 8 with a coverage per
// channel (the marched height fog's extinction differs per channel).
int target_floats(const VolumeVariant& variant);
std::string volume_composite_options(const VolumeVariant& variant, const DeviceTraits& device);
// Upper bounds of one work-item's private memory [bytes] in the march and the composite of a
// variant, from the kernels' private arrays: what the launches' work-group shape is bounded by
// where the device reports less (runtime/work_groups.h).
std::size_t volume_march_private_bytes(const VolumeVariant& variant, const DeviceTraits& device);
std::size_t volume_composite_private_bytes(const VolumeVariant& variant, const DeviceTraits& device);
// The composite's global size for a width x height frame (kernels/volume_composite.cl): one
// work-item per frame pixel, or on CPU devices per 16 pixels of a row; there, at scale > 1, of the
// `scale` rows between two target rows (which share the target's windows).
std::array<std::size_t, 2> volume_composite_global(const VolumeVariant& variant, const DeviceTraits& device, int width,
                                                   int height);

// The noise texture of (size, seed), generated once per process and shared (thread-safe).
const NoiseTexture& shared_noise_texture(int size, std::uint32_t seed);

// The texture's R channel as 2 x 2 blocks for the CPU lanes of the march (kernels/volume_march.cl,
// vol_texel_plane_r_x16): N^3 words, the word of (x, y, z) holding R(x, y), R(x + 1, y),
// R(x, y + 1), R(x + 1, y + 1) of slice z from the lowest byte, coordinates wrapped. Made once per
// texture of shared_noise_texture (thread-safe).
const std::vector<std::uint8_t>& shared_noise_r_blocks(const NoiseTexture& texture);

}  // namespace fogcl::detail
