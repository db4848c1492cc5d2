#include "fogcl/scalar.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <Imath/half.h>

#include "fogcl/error.h"
#include "fogcl/variant.h"
#include "pass/formulas.h"
#include "runtime/host_call.h"
#include "settings/fog_coefficients.h"

// The user-facing float path is compiled twice, for CPUs with FMA and for the x86-64 baseline,
// and the loader picks one (function multiversioning): without hardware FMA every fma() of the
// formulas is a libm call, which made the distance-based loop 2x slower. Its callees are forced
// inline so that they are compiled for the clone's target.
#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(undefined_behavior_sanitizer)
#define FOGCL_SANITIZED 1  // ifunc resolvers run before the sanitizer runtime is up
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define FOGCL_SANITIZED 1
#endif
#if defined(__x86_64__) && defined(__GNUC__) && defined(__ELF__) && !defined(FOGCL_SANITIZED)
#define FOGCL_TARGET_CLONES __attribute__((target_clones("fma", "default")))
#define FOGCL_INLINE [[gnu::always_inline]] inline
#else
#define FOGCL_TARGET_CLONES
#define FOGCL_INLINE inline
#endif

namespace fogcl {

namespace {

float load_channel(const float* p) { return *p; }
float load_channel(const std::uint16_t* p) {
  Imath::half h;
  h.setBits(*p);
  return float(h);
}

// The pixel loop shared by every scalar instantiation. Calls sink(i, f, amount, rgba) per pixel
// with the fog factor, the fog amount 1 - f (only if with_amount, else 0) and the blended color
// (alpha passed through), all in T.
template <class T, class Channel, class Sink>
FOGCL_INLINE void fog_pixels(const ConstColorView& in, const ConstDepthView& depth, const CameraParams& cam,
                const Variant& v, const FogSettings& s, bool with_amount, int y0, int y1, Sink&& sink) {
  using namespace detail;
  using namespace formulas;
  const int w = depth.width(), h = depth.height();
  const FogCoefficients<T> k = fog_coefficients<T>(s, v.mode);
  const T zx = T(cam.zbuffer_params.x), zy = T(cam.zbuffer_params.y);
  const T near_plane = T(cam.near_plane()), far_plane = T(cam.far_plane());
  const T fog[3] = {T(s.color.r), T(s.color.g), T(s.color.b)};
  const auto cn = fog_ray_corners(cam);
  const int mode = int(v.mode), distance = v.distance, skybox = v.fog_skybox, reversed = v.reversed_z;
  const int projection = int(v.projection), squared = FOG_SQUARED(mode, distance);
  const int kind = int(v.depth_kind), sky_infinite = v.sky_infinite;
  const int needs_ray = FOG_NEEDS_RAY(distance, kind), ray_squared = FOG_RAY_SQUARED(mode, distance, kind);
  const T inv_width = T(1) / T(w);
  // Height fog (docs/DESIGN.md §6): the FOG_HP_* constants, and for the fog factor and amount
  // the reference reports (with_amount) two probes: T of the red channel (color 1, no fog color,
  // no sun) and its J (color 0, fog color 1, no sun).
  const bool height = v.mode == KernelMode::height;
  HeightCoefficients<T> hc;
  T probe_t[FOG_HP_COUNT], probe_j[FOG_HP_COUNT];
  const int features = v.height_features | (v.fog_skybox ? FOG_HF_SKYBOX : 0);
  if (height) {
    hc = height_coefficients<T>(s, cam);
    for (int k = 0; k < FOG_HP_COUNT; ++k) probe_t[k] = probe_j[k] = hc.p[k];
    for (int c = 0; c < 3; ++c) {
      probe_t[FOG_HP_FOG + c] = probe_t[FOG_HP_SUN + c] = probe_j[FOG_HP_SUN + c] = T(0);
      probe_j[FOG_HP_FOG + c] = T(1);
    }
  }
  for (int y = y0; y < y1; ++y) {
    const T vv = fog_pixel_v(T(y), T(h));
    const auto* color = reinterpret_cast<const Channel*>(in.row(y));  // rows may be padded (views)
    const float* raw_depth = depth.row(y);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
      if (height) {
        T ray[3];
        fog_corner_ray(cn, fog_pixel_u(T(x), inv_width), vv, ray);
        int sky;
        T wy, d0, q_sun;
        const T s_hit = fog_height_geometry(T(raw_depth[x]), ray[0], ray[1], ray[2], kind, reversed, projection, zx, zy,
                                            near_plane, far_plane, hc.up[0], hc.up[1], hc.up[2], hc.light[0],
                                            hc.light[1], hc.light[2], (features & FOG_HF_SUN) != 0, hc.d0, &sky, &wy,
                                            &d0, &q_sun);
        const Channel* c = color + 4 * x;
        T rgba[4] = {T(load_channel(c)), T(load_channel(c + 1)), T(load_channel(c + 2)), T(load_channel(c + 3))};
        const int fogged = fog_height_pixel(rgba, s_hit, sky, wy, d0, q_sun, hc.p, features);
        T f = 1, amount = 0;
        if (with_amount && fogged) {
          T t[3] = {1, 1, 1}, j[3] = {0, 0, 0};
          fog_height_pixel(t, s_hit, sky, wy, d0, q_sun, probe_t, features);
          fog_height_pixel(j, s_hit, sky, wy, d0, q_sun, probe_j, features);
          f = t[0];
          amount = j[0];
        } else if (fogged) {
          f = T(0.5);  // not 1: the pixel changed (the half path copies the bits where f == 1)
        }
        sink(i, x, y, f, amount, rgba);
        continue;
      }
      const T ray = needs_ray ? fog_corner_ray_term(cn, fog_pixel_u(T(x), inv_width), vv, ray_squared) : T(0);
      T f = 1, amount = 0;
      if (v.needs_pass()) {
        int sky;
        const T q = fog_view_distance(T(raw_depth[x]), ray, kind, distance, reversed, projection, squared, zx,
                                      zy, near_plane, far_plane, &sky);
        f = fog_factor_at(q, sky, mode, squared, skybox, sky_infinite, k.a, k.b);
        if (with_amount) amount = fog_amount_at(q, sky, mode, squared, skybox, sky_infinite, k.a, k.b);
      }
      const Channel* c = color + 4 * x;
      T rgba[4];
      for (int ch = 0; ch < 3; ++ch) rgba[ch] = fog_blend(T(load_channel(c + ch)), fog[ch], f);
      rgba[3] = T(load_channel(c + 3));
      sink(i, x, y, f, amount, rgba);
    }
  }
}

// Runs fog_pixels with the channel type of the image's storage.
template <class T, class Sink>
FOGCL_INLINE void fog_image(const ConstColorView& in, const ConstDepthView& depth, const CameraParams& cam,
               const Variant& v, const FogSettings& s, bool with_amount, int y0, int y1, Sink&& sink) {
  if (in.format() == ColorFormat::rgba32f)
    fog_pixels<T, float>(in, depth, cam, v, s, with_amount, y0, y1, sink);
  else
    fog_pixels<T, std::uint16_t>(in, depth, cam, v, s, with_amount, y0, y1, sink);
}

Variant checked_variant(const ConstColorView& in, const ConstDepthView& depth, const CameraParams& cam,
                        const FogSettings& s) {
  validate_frame(in, depth);
  validate(cam, in.width(), in.height());
  return select_variant(s, cam, in.format());
}

// The float path of apply_fog_scalar (see FOGCL_TARGET_CLONES).
FOGCL_TARGET_CLONES void fog_into(const ConstColorView& in, const ConstDepthView& depth, const CameraParams& cam,
                                  const Variant& v, const FogSettings& s, const ColorView& out, int y0, int y1) {
  const std::size_t pixel_bytes = bytes_per_pixel(in.format());
  if (in.format() == ColorFormat::rgba32f) {
    fog_image<float>(in, depth, cam, v, s, false, y0, y1,
                     [&](std::size_t, int x, int y, float, float, const float* rgba) {
                       float* o = reinterpret_cast<float*>(out.row(y)) + 4 * x;
                       for (int c = 0; c < 4; ++c) o[c] = rgba[c];
                     });
  } else {
    fog_image<float>(in, depth, cam, v, s, false, y0, y1,
                     [&](std::size_t, int x, int y, float f, float, const float* rgba) {
                       const std::byte* src = in.row(y) + std::size_t(x) * pixel_bytes;
                       std::byte* dst = out.row(y) + std::size_t(x) * pixel_bytes;
                       if (f == 1.0f) {  // keep the bits: a half -> float -> half trip would quiet a signalling NaN
                         std::memmove(dst, src, pixel_bytes);  // in place: the same pixel
                         return;
                       }
                       auto* o = reinterpret_cast<std::uint16_t*>(dst);
                       const std::uint16_t alpha = reinterpret_cast<const std::uint16_t*>(src)[3];
                       for (int c = 0; c < 3; ++c) o[c] = Imath::half(rgba[c]).bits();
                       o[3] = alpha;
                     });
  }
}

// Rows [y0, y1) of `in` into `out` as they are (fog off), unless out is in.
void copy_rows(const ConstColorView& in, const ColorView& out, int y0, int y1) {
  if (out.data() == in.data()) return;
  for (int y = y0; y < y1; ++y) std::memcpy(out.row(y), in.row(y), in.row_bytes());
}

}  // namespace

void apply_fog_scalar(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                      const CameraParams& cam, const FogSettings& s) {
  detail::host_call("apply_fog_scalar", [&] {
    detail::size_output(in, depth, out, cam);
    apply_fog_scalar(in.view(), depth.view(), out.view(), cam, s);
  });
}

void apply_fog_scalar(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                      const CameraParams& cam, const FogSettings& s) {
  const Variant v = checked_variant(in, depth, cam, s);
  validate_frame(in, depth, out);
  if (!v.needs_pass()) {
    copy_rows(in, out, 0, in.height());
    return;
  }
  fog_into(in, depth, cam, v, s, out, 0, in.height());
}

void apply_fog_scalar_rows(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                           const CameraParams& cam, const FogSettings& s, int first_row, int end_row) {
  const Variant v = checked_variant(in, depth, cam, s);
  if (out.width() != in.width() || out.height() != in.height() || out.format() != in.format())
    throw Error("apply_fog_scalar_rows: the output must have the input's size and format (" +
                std::to_string(in.width()) + "x" + std::to_string(in.height()) + " " + to_string(in.format()) + ")");
  validate_frame(in, depth, out);
  if (first_row < 0 || end_row > in.height() || first_row > end_row)
    throw Error("apply_fog_scalar_rows: rows [" + std::to_string(first_row) + ", " + std::to_string(end_row) +
                ") are not inside [0, " + std::to_string(in.height()) + ")");
  if (!v.needs_pass()) {
    copy_rows(in, out, first_row, end_row);
    return;
  }
  fog_into(in, depth, cam, v, s, out, first_row, end_row);
}

template <class T>
FogResult<T> fog_scalar(const ConstColorView& in, const ConstDepthView& depth, const CameraParams& cam,
                        const FogSettings& s) {
  const Variant v = checked_variant(in, depth, cam, s);
  FogResult<T> r;
  r.width = in.width();
  r.height = in.height();
  detail::host_call("fog_scalar", [&] {
    r.rgba.resize(4 * in.pixel_count());
    r.factor.resize(in.pixel_count());
    r.amount.resize(in.pixel_count());
  });
  fog_image<T>(in, depth, cam, v, s, true, 0, in.height(), [&](std::size_t i, int, int, T f, T amount, const T* rgba) {
    r.factor[i] = f;
    r.amount[i] = amount;
    for (int c = 0; c < 4; ++c) r.rgba[4 * i + c] = rgba[c];
  });
  return r;
}

double max_abs_rgb_error(const ConstColorView& image, const FogResult<double>& reference) {
  double worst = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) {
      const glm::vec4 p = image.pixel(x, y);
      const std::size_t i = 4 * (std::size_t(y) * std::size_t(image.width()) + std::size_t(x));
      for (int c = 0; c < 3; ++c) {
        const double e = std::fabs(double(p[c]) - reference.rgba[i + c]);
        worst = std::max(worst, std::isnan(e) ? INFINITY : e);
      }
    }
  return worst;
}

double max_abs_factor_error(const ConstColorView& probe, const FogResult<double>& reference) {
  double worst = 0;
  for (int y = 0; y < probe.height(); ++y)
    for (int x = 0; x < probe.width(); ++x) {
      const glm::vec4 p = probe.pixel(x, y);
      const double f = reference.factor[std::size_t(y) * std::size_t(probe.width()) + std::size_t(x)];
      for (int c = 0; c < 3; ++c) {
        const double e = std::fabs(double(p[c]) - f);
        worst = std::max(worst, std::isnan(e) ? INFINITY : e);
      }
    }
  return worst;
}

template FogResult<float> fog_scalar<float>(const ConstColorView&, const ConstDepthView&, const CameraParams&,
                                            const FogSettings&);
template FogResult<double> fog_scalar<double>(const ConstColorView&, const ConstDepthView&,
                                              const CameraParams&, const FogSettings&);

}  // namespace fogcl
