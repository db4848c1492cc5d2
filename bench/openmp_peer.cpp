#include "openmp_peer.h"

#include <immintrin.h>
#include <omp.h>

#include <type_traits>
#include <vector>

#include "fogcl/variant.h"
#include "pass/formulas.h"
#include "settings/fog_coefficients.h"

namespace fogcl::bench {

namespace {

// Half <-> float with F16C (x86-64-v3 and later, which -march=native has on any recent CPU).
inline float load(const float* p) { return *p; }
inline void store(float* p, float v) { *p = v; }
inline float load(const std::uint16_t* p) { return _cvtsh_ss(*p); }
inline void store(std::uint16_t* p, float v) { *p = _cvtss_sh(v, _MM_FROUND_TO_NEAREST_INT); }
// v in the storage of `like`.
inline float converted(float v, float) { return v; }
inline std::uint16_t converted(float v, std::uint16_t) { return _cvtss_sh(v, _MM_FROUND_TO_NEAREST_INT); }

// One row at a time: the factors first (a loop GCC vectorises, mode and metric as template
// parameters so the loop has no branches), then the blend over the row's RGBA interleaved channels.
template <int kMode, bool kDistance, bool kSkybox, bool kReversed, class Channel>
void run(const Channel* in, const float* depth, Channel* out, int w, int h, const CameraParams& cam,
         const detail::FogCoefficients<float>& k, const glm::vec3& fog, int threads) {
  using namespace formulas;
  const float zx = cam.zbuffer_params.x, zy = cam.zbuffer_params.y;
  const float near_plane = cam.near_plane(), far_plane = cam.far_plane();
  const auto& c = cam.frustum_corners;
  const float fr = fog.r, fg = fog.g, fb = fog.b;
  const int projection = int(cam.projection);
  const float inv_width = 1.0f / float(w);
#pragma omp parallel num_threads(threads)
  {
    std::vector<float> factor(static_cast<std::size_t>(w));
    float* f = factor.data();
#pragma omp for schedule(static)
    for (int y = 0; y < h; ++y) {
      const float vv = fog_pixel_v(float(y), float(h));
      const float* d = depth + std::size_t(y) * std::size_t(w);
#pragma omp simd
      for (int x = 0; x < w; ++x) {
        float ray = 0.0f;
        if constexpr (kDistance) {
          ray = fog_corner_ray_term(c, fog_pixel_u(float(x), inv_width), vv, FOG_SQUARED(kMode, kDistance));
        }
        f[x] = fog_factor(d[x], ray, FOG_DEPTH_RAW, kMode, kDistance, kSkybox, /*sky_infinite=*/0, kReversed,
                          projection, zx, zy, near_plane, far_plane, k.a, k.b);
      }
      const Channel* ci = in + 4 * std::size_t(y) * std::size_t(w);
      Channel* co = out + 4 * std::size_t(y) * std::size_t(w);
#pragma omp simd
      for (int x = 0; x < w; ++x) {
        store(co + 4 * x + 0, fog_blend(load(ci + 4 * x + 0), fr, f[x]));
        store(co + 4 * x + 1, fog_blend(load(ci + 4 * x + 1), fg, f[x]));
        store(co + 4 * x + 2, fog_blend(load(ci + 4 * x + 2), fb, f[x]));
        co[4 * x + 3] = ci[4 * x + 3];
      }
    }
  }
}

// Height fog (docs/DESIGN.md §6): the same formulas per pixel, kFeatures (fog_math.h FOG_HF_*) and,
// with kRawPerspective, the camera's kind (raw depth, conventional Z, perspective) compile-time
// constants as in the kernel, so that the row's loop has no branch on them (-1 / false: runtime
// values, for scenes the benchmark does not time); one loop over the row (the channels are not
// separable). GCC still keeps that loop scalar (docs/performance.md, height fog).
template <int kFeatures, bool kRawPerspective, class Channel>
void run_height(const Channel* in, const float* depth, Channel* out, int w, int h, const CameraParams& cam,
                const detail::HeightCoefficients<float>& k, int threads, int runtime_features = 0) {
  using namespace formulas;
  const int features = kFeatures >= 0 ? kFeatures : runtime_features;
  const float zx = cam.zbuffer_params.x, zy = cam.zbuffer_params.y;
  const float near_plane = cam.near_plane(), far_plane = cam.far_plane();
  const auto c = fog_ray_corners(cam);
  const int projection = kRawPerspective ? FOG_PROJECTION_PERSPECTIVE : int(cam.projection);
  const int reversed = kRawPerspective ? 0 : int(cam.reversed_z);
  const int kind = kRawPerspective ? FOG_DEPTH_RAW : int(cam.depth_kind);
  const float inv_width = 1.0f / float(w);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (int y = 0; y < h; ++y) {
    const float vv = fog_pixel_v(float(y), float(h));
    const float* d = depth + std::size_t(y) * std::size_t(w);
    const Channel* ci = in + 4 * std::size_t(y) * std::size_t(w);
    Channel* co = out + 4 * std::size_t(y) * std::size_t(w);
#pragma omp simd
    for (int x = 0; x < w; ++x) {
      const float u = fog_pixel_u(float(x), inv_width);
      float ray[3];
      for (int j = 0; j < 3; ++j)
        ray[j] = fog_bilerp(c[kBottomLeft][j], c[kBottomRight][j], c[kTopLeft][j], c[kTopRight][j], u, vv);
      int sky;
      float wy, d0, q;
      const float s_hit = fog_height_geometry(d[x], ray[0], ray[1], ray[2], kind, reversed, projection, zx, zy,
                                              near_plane, far_plane, k.up[0], k.up[1], k.up[2], k.light[0],
                                              k.light[1], k.light[2], (features & FOG_HF_SUN) != 0, k.d0, &sky, &wy,
                                              &d0, &q);
      float rgb[3] = {load(ci + 4 * x), load(ci + 4 * x + 1), load(ci + 4 * x + 2)};
      const bool fogged = fog_height_pixel(rgb, s_hit, sky, wy, d0, q, k.p, features);
      // Selects, not a branch (GCC vectorises no loop with control flow): a pixel not fogged keeps
      // its stored bits, as in the kernel.
      for (int j = 0; j < 3; ++j) co[4 * x + j] = fogged ? converted(rgb[j], ci[4 * x + j]) : ci[4 * x + j];
      co[4 * x + 3] = ci[4 * x + 3];
    }
  }
}

template <class Channel>
void dispatch_height(const Channel* in, const float* depth, Channel* out, int w, int h, const CameraParams& cam,
                     const Variant& v, const FogSettings& s, int threads) {
  const auto k = detail::height_coefficients<float>(s, cam);
  const int features = v.height_features | (v.fog_skybox ? FOG_HF_SKYBOX : 0);
  // The benchmark's two scenes as constants (fog_bench.cpp case_of, modes 3 and 4).
  // In-scattering equal to extinction in both (FOG_HF_SAME_IN, as select_variant finds).
  constexpr int kValley = FOG_HF_FALLOFF | FOG_HF_SAME_IN;
  constexpr int kHaze = FOG_HF_FALLOFF | FOG_HF_RGB | FOG_HF_SUN | FOG_HF_SKYBOX | FOG_HF_SAME_IN;
  const bool raw_perspective = cam.depth_kind == DepthKind::raw && !cam.reversed_z &&
                               cam.projection == Projection::perspective;
  if (raw_perspective && features == kValley) return run_height<kValley, true>(in, depth, out, w, h, cam, k, threads);
  if (raw_perspective && features == kHaze) return run_height<kHaze, true>(in, depth, out, w, h, cam, k, threads);
  run_height<-1, false>(in, depth, out, w, h, cam, k, threads, features);
}

template <class Channel>
void dispatch(const Channel* in, const float* depth, Channel* out, int w, int h, const CameraParams& cam,
              const Variant& v, const detail::FogCoefficients<float>& k, const glm::vec3& fog, int threads) {
  const auto with_mode = [&](auto mode) {
    const auto with_flags = [&](auto distance, auto skybox, auto reversed) {
      run<decltype(mode)::value, decltype(distance)::value, decltype(skybox)::value, decltype(reversed)::value>(
          in, depth, out, w, h, cam, k, fog, threads);
    };
    using T = std::true_type;
    using F = std::false_type;
    const auto with_reversed = [&](auto distance, auto skybox) {
      v.reversed_z ? with_flags(distance, skybox, T{}) : with_flags(distance, skybox, F{});
    };
    const auto with_skybox = [&](auto distance) {
      v.fog_skybox ? with_reversed(distance, T{}) : with_reversed(distance, F{});
    };
    v.distance ? with_skybox(T{}) : with_skybox(F{});
  };
  switch (v.mode) {
    case KernelMode::linear: return with_mode(std::integral_constant<int, 1>{});
    case KernelMode::linear_step: return with_mode(std::integral_constant<int, 2>{});
    case KernelMode::exp: return with_mode(std::integral_constant<int, 3>{});
    case KernelMode::exp2: return with_mode(std::integral_constant<int, 4>{});
    case KernelMode::height:  // dispatch_height
    case KernelMode::none: return;
  }
}

}  // namespace

void FOGCL_PEER_NAME(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                     const CameraParams& camera, const FogSettings& settings, int threads) {
  const Variant v = select_variant(settings, camera, in.format());
  if (v.mode == KernelMode::height) {
    if (in.format() == ColorFormat::rgba32f)
      dispatch_height(in.rgba32f(), depth.data(), out.rgba32f(), in.width(), in.height(), camera, v, settings, threads);
    else
      dispatch_height(in.rgba16f(), depth.data(), out.rgba16f(), in.width(), in.height(), camera, v, settings, threads);
    return;
  }
  const auto k = detail::fog_coefficients<float>(settings, v.mode);
  if (in.format() == ColorFormat::rgba32f)
    dispatch(in.rgba32f(), depth.data(), out.rgba32f(), in.width(), in.height(), camera, v, k, settings.color, threads);
  else
    dispatch(in.rgba16f(), depth.data(), out.rgba16f(), in.width(), in.height(), camera, v, k, settings.color, threads);
}

}  // namespace fogcl::bench
