#include "fogcl/volume_scalar.h"

#include <cmath>
#include <cstring>

#include <Imath/half.h>

#include "fogcl/error.h"
#include "fogcl/volume_pass.h"
#include "image/packed_frame.h"
#include "runtime/host_call.h"
#include "volume/volume_formulas.h"
#include "volume/volume_params.h"

namespace fogcl {

namespace {
template <class T>
VolumeResult<T> volumes_in(const ConstColorView& in, const ConstDepthView& depth_view, const CameraParams& camera,
                           const VolumeScene& scene, const VolumeSettings& settings, const ShadowMap* shadow) {
  using namespace volume_formulas;
  validate_frame(in, depth_view);
  const int w = in.width(), h = in.height();
  validate(camera, w, h);
  DepthImage depth_copy;  // the march reads packed rows: padded ones are copied once
  const ConstDepthView depth = detail::packed_depth(depth_view, depth_copy);
  const detail::PackedVolumeFrame f = detail::pack_volume_frame(
      w, h, camera, scene, settings, in.format(), shadow ? &shadow->params : nullptr,
      shadow ? shadow->depth.width() : 0, shadow ? shadow->depth.height() : 0, max_eye_depth(depth, camera));
  VolumeResult<T> r;
  r.width = w;
  r.height = h;
  r.visible = f.visible.size();
  r.rgba.resize(4 * in.pixel_count());
  r.coverage.assign(in.pixel_count(), T(0));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::vec4 c = in.pixel(x, y);
      for (int k = 0; k < 4; ++k) r.rgba[4 * (std::size_t(y) * w + x) + k] = T(c[k]);
    }
  if (f.nothing_to_march()) return r;

  const detail::VolumeVariant& v = f.variant;
  const std::uint8_t* noise = f.needs_noise()
                                  ? detail::shared_noise_texture(settings.noise_size, settings.noise_seed).texels.data()
                                  : nullptr;
  const int projection = int(v.projection), reversed = v.reversed_z, kind = int(v.depth_kind);
  const float* shadow_map = shadow ? shadow->depth.data() : nullptr;
  const int integrator = detail::integrator_code(v.integrator);
  r.low_width = f.low_width;
  r.low_height = f.low_height;
  const int stride = detail::target_floats(v);
  r.low_floats = stride;
  r.low.resize(std::size_t(stride) * f.low_width * f.low_height);
  r.low_key.resize(std::size_t(f.low_width) * f.low_height);
  for (int ly = 0; ly < f.low_height; ++ly)
    for (int lx = 0; lx < f.low_width; ++lx) {
      const std::size_t i = std::size_t(ly) * f.low_width + lx;
      T key, coverage[3];
      glm::vec<4, T> p = vol_march_pixel<T>(
          lx, ly, depth.data(), f.frame.data(), f.volumes.data(), int(f.visible.size()), noise, settings.noise_size,
          shadow_map, scene.frame_index, integrator, v.steps, v.features, v.height_features, v.jitter, projection,
          reversed, kind, &key, coverage);
      if (stride == 8) {  // kernels/volume_composite.h's layout, as the kernel stores it
        p.w = std::fmax(coverage[0], std::fmax(coverage[1], coverage[2]));
        for (int k = 0; k < 3; ++k) r.low[8 * i + 4 + k] = coverage[k];
        r.low[8 * i + 7] = T(0);
      }
      for (int k = 0; k < 4; ++k) r.low[std::size_t(stride) * i + k] = p[k];
      r.low_key[i] = key;
    }
  const float* k = f.frame.data();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * w + x;
      const T rho = v.depth_aware && v.scale > 1 ? vol_inverse_eye_depth(T(depth.data()[i]), k, projection, reversed, kind)
                                                 : T(0);
      std::size_t at[4];
      T weight[4];
      const int normalise = vol_upsample_weights(x, y, rho, r.low_key.data(), f.low_width, f.low_height, v.scale,
                                                 v.depth_aware, at, weight);
      const glm::vec<4, T> fog = vol_upsample_taps(r.low.data(), stride, 0, at, weight, normalise, v.scale);
      const glm::vec<4, T> cover =
          stride == 8 ? vol_upsample_taps(r.low.data(), stride, 4, at, weight, normalise, v.scale) : glm::vec<4, T>(fog.w);
      r.coverage[i] = fog.w;
      if (fog.w == T(0)) continue;
      for (int c = 0; c < 3; ++c) r.rgba[4 * i + c] = vol_composite(r.rgba[4 * i + c], fog[c], cover[c]);
    }
  return r;
}

}  // namespace

template <class T>
VolumeResult<T> volumes_scalar(const ConstColorView& in, const ConstDepthView& depth, const CameraParams& camera,
                               const VolumeScene& scene, const VolumeSettings& settings, const ShadowMap* shadow) {
  return detail::host_call("volumes_scalar", [&] { return volumes_in<T>(in, depth, camera, scene, settings, shadow); });
}

template VolumeResult<float> volumes_scalar<float>(const ConstColorView&, const ConstDepthView&, const CameraParams&,
                                                   const VolumeScene&, const VolumeSettings&, const ShadowMap*);
template VolumeResult<double> volumes_scalar<double>(const ConstColorView&, const ConstDepthView&, const CameraParams&,
                                                     const VolumeScene&, const VolumeSettings&, const ShadowMap*);

void apply_volumes_scalar(const ColorImage& in, const DepthImage& depth, ColorImage& out, const CameraParams& camera,
                          const VolumeScene& scene, const VolumeSettings& settings, const ShadowMap* shadow) {
  detail::host_call("apply_volumes_scalar", [&] {
    detail::size_output(in, depth, out, camera);
    apply_volumes_scalar(in.view(), depth.view(), out.view(), camera, scene, settings, shadow);
  });
}

void apply_volumes_scalar(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                          const CameraParams& camera, const VolumeScene& scene, const VolumeSettings& settings,
                          const ShadowMap* shadow) {
  validate_frame(in, depth, out);
  const VolumeResult<float> r = volumes_scalar<float>(in, depth, camera, scene, settings, shadow);
  detail::copy_pixels(in, out);  // A == 0 pixels and alpha keep their bits (nothing when in place)
  for (int y = 0; y < in.height(); ++y)
    for (int x = 0; x < in.width(); ++x) {
      const std::size_t i = std::size_t(y) * in.width() + x;
      if (r.coverage[i] == 0.0f) continue;
      const glm::vec4 o(r.rgba[4 * i], r.rgba[4 * i + 1], r.rgba[4 * i + 2], 0.0f);
      if (in.format() == ColorFormat::rgba16f) {
        auto* p = reinterpret_cast<std::uint16_t*>(out.row(y)) + 4 * x;
        for (int k = 0; k < 3; ++k) p[k] = Imath::half(o[k]).bits();
      } else {
        auto* p = reinterpret_cast<float*>(out.row(y)) + 4 * x;
        for (int k = 0; k < 3; ++k) p[k] = o[k];
      }
    }
}

double max_abs_rgb_error(const ConstColorView& image, const VolumeResult<double>& ref) {
  if (image.width() != ref.width || image.height() != ref.height)
    throw Error("max_abs_rgb_error: image and reference sizes differ");
  double worst = 0.0;
  for (int y = 0; y < ref.height; ++y)
    for (int x = 0; x < ref.width; ++x) {
      const glm::vec4 c = image.pixel(x, y);
      for (int k = 0; k < 3; ++k) {
        const double d = std::fabs(double(c[k]) - ref.rgba[4 * (std::size_t(y) * ref.width + x) + k]);
        worst = std::isnan(d) ? INFINITY : std::fmax(worst, d);
        if (std::isinf(worst)) return worst;
      }
    }
  return worst;
}

}  // namespace fogcl
