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
    case KernelMode::none: return;
  }
}

}  // namespace

void FOGCL_PEER_NAME(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                     const CameraParams& camera, const FogSettings& settings, int threads) {
  const Variant v = select_variant(settings, camera, in.format());
  const auto k = detail::fog_coefficients<float>(settings, v.mode);
  if (in.format() == ColorFormat::rgba32f)
    dispatch(in.rgba32f(), depth.data(), out.rgba32f(), in.width(), in.height(), camera, v, k, settings.color, threads);
  else
    dispatch(in.rgba16f(), depth.data(), out.rgba16f(), in.width(), in.height(), camera, v, k, settings.color, threads);
}

}  // namespace fogcl::bench
