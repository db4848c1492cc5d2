#include "halide_peer.h"

#include <Halide.h>

#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <tuple>

#include "fogcl/variant.h"
#include "settings/fog_coefficients.h"

namespace fogcl::bench {

namespace {

using Halide::Expr;
using Halide::select;

// fog_math.h's constants (FOG_MODE_*, FOG_PROJECTION_*): the Halide pipeline bakes the variant in,
// as the OpenCL kernel does with -D switches.
enum Mode { kLinear = 1, kStep = 2, kExp = 3, kExp2 = 4 };

Expr f32(float v) { return Expr(v); }

// fog_exp2_poly: 2^min(x, 0), n = ceil(x - 1/2) by truncation, 2^r by the degree-6 fit, results
// below 2^-126 flushed to 0. Halide 14 has no fma(): each step is a multiply and an add, which
// LLVM may contract (the error column shows what that costs).
Expr fog_exp2(const Expr& x) {
  Expr xc = select(f32(0) < x, f32(0), x);
  xc = select(f32(-126) > xc, f32(-126), xc);
  const Expr n = Halide::cast<int>(xc - 0.5f);
  const Expr r = xc - Halide::cast<float>(n);
  Expr p = f32(0x1.444p-13f);
  p = p * r + 0x1.5f48cp-10f;
  p = p * r + 0x1.3b2a1cp-7f;
  p = p * r + 0x1.c6aeccp-5f;
  p = p * r + 0x1.ebfbep-3f;
  p = p * r + 0x1.62e43p-1f;
  p = p * r + 1.0f;
  const Expr scale = Halide::reinterpret<float>((n + 127) << 23);
  return select(x < -126.0f, f32(0), p * scale);
}

// One JIT-compiled pipeline: a variant and a storage format, any frame size.
struct Pipeline {
  Halide::ImageParam color, depth;
  Halide::Param<float> zx{"zx"}, zy{"zy"}, near_plane{"near_plane"}, far_plane{"far_plane"};
  Halide::Param<float> k_a{"k_a"}, k_b{"k_b"}, fog_r{"fog_r"}, fog_g{"fog_g"}, fog_b{"fog_b"};
  Halide::Param<float> inv_width{"inv_width"}, height{"height"};
  Halide::Param<float> corner[4][3];  // Corner order (kBottomLeft ...), xyz
  Halide::Func factor{"factor"}, out{"fogged"};
  Halide::Pipeline pipeline;
  Halide::Target target;

  Pipeline(const Variant& v, ColorFormat storage);
};

Pipeline::Pipeline(const Variant& v, ColorFormat storage)
    : color(storage == ColorFormat::rgba16f ? Halide::Float(16) : Halide::Float(32), 3, "color"),
      depth(Halide::Float(32), 2, "depth") {
  using Halide::Var;
  Var c("c"), x("x"), y("y"), xo("xo"), xi("xi");
  const int mode = v.mode == KernelMode::linear        ? kLinear
                   : v.mode == KernelMode::linear_step ? kStep
                   : v.mode == KernelMode::exp         ? kExp
                                                       : kExp2;
  const bool squared = mode == kExp2 && v.distance;  // FOG_SQUARED

  // fog_view_distance: sanitised raw depth, Linear01Depth (or its projection's equivalent), the
  // sky test, and q = d (depth-based) or scale * |ray| (distance-based; its square for exp2).
  const Expr raw = depth(x, y);
  Expr t;
  if (v.reversed_z) {
    t = select(raw > 0.0f, raw, f32(0));
    t = select(t < 1.0f, t, f32(1));
  } else {
    t = select(raw < 1.0f, raw, f32(1));
    t = select(t > 0.0f, t, f32(0));
  }
  Expr scale, d, sky;
  if (v.projection == Projection::perspective_infinite_far) {
    sky = t == 0.0f;
    scale = near_plane / t;
    d = scale - near_plane;
  } else {
    if (v.projection == Projection::orthographic)
      scale = zx * t + zy;
    else
      scale = 1.0f / (v.reversed_z ? zx * t + zy : zy * (1.0f - t) + t);
    sky = scale > 0.9999f;
    d = scale * far_plane - near_plane;
  }
  Expr q = d;
  if (v.distance) {
    const Expr u = (Halide::cast<float>(x) + 0.5f) * inv_width;
    const Expr vv = 1.0f - (Halide::cast<float>(y) + 0.5f) / height;
    Expr ray[3];
    for (int k = 0; k < 3; ++k) {
      const Expr left = (corner[kTopLeft][k] - corner[kBottomLeft][k]) * vv + corner[kBottomLeft][k];
      const Expr right = (corner[kTopRight][k] - corner[kBottomRight][k]) * vv + corner[kBottomRight][k];
      ray[k] = (right - left) * u + left;
    }
    const Expr length2 = ray[0] * ray[0] + (ray[1] * ray[1] + ray[2] * ray[2]);
    q = squared ? (scale * scale) * length2 : scale * Halide::sqrt(length2);
  }
  // fog_factor_at.
  Expr f;
  switch (mode) {
    case kLinear:
      f = Halide::clamp((k_a - q) * k_b, 0.0f, 1.0f);
      break;
    case kStep:
      f = select(q < k_a, f32(1), f32(0));
      break;
    case kExp:
      f = fog_exp2(q * -k_a);
      break;
    default:
      if (squared) {
        f = fog_exp2((q * k_a) * -k_a);
      } else {
        const Expr tk = q * k_a;
        f = fog_exp2(-(tk * tk));
      }
  }
  factor(x, y) = v.fog_skybox ? f : select(sky, f32(1), f);

  // fog_blend per channel, alpha passed through (its bits, as fogcl keeps them).
  const Expr in = color(c, x, y);
  const Expr cf = Halide::cast<float>(in);
  const Expr fog = select(c == 0, fog_r, c == 1, fog_g, fog_b);
  const Expr fx = factor(x, y);
  const Expr blended = select(fx == 1.0f, cf, select(fx == 0.0f, fog, fx * (cf - fog) + fog));
  out(c, x, y) = select(c == 3, in, Halide::cast(color.type(), blended));

  // Interleaved RGBA: c is the innermost dimension, 4 wide, stride 1.
  color.dim(0).set_bounds(0, 4).set_stride(1);
  color.dim(1).set_stride(4);
  out.output_buffer().dim(0).set_bounds(0, 4).set_stride(1);
  out.output_buffer().dim(1).set_stride(4);
  // Rows in parallel, 16 pixels a vector, the four channels unrolled (Halide turns the four
  // stride-4 stores into one interleaved store); the factors of 16 pixels computed per vector.
  out.reorder(c, x, y).bound(c, 0, 4).unroll(c).split(x, xo, xi, 16).vectorize(xi).parallel(y);
  factor.compute_at(out, xo).vectorize(x, 16);

  // Halide 14 takes AVX512-BF16 + VNNI for Sapphire Rapids and then emits AVX512-FP16 for half
  // conversions: on a Zen 4 EPYC (BF16, no FP16) that is SIGILL. F16C does the conversions.
  target = Halide::get_jit_target_from_environment().without_feature(Halide::Target::AVX512_SapphireRapids);
  pipeline = Halide::Pipeline(out);
  pipeline.compile_jit(target);
}

using Key = std::tuple<int, bool, bool, bool, int, int>;

Pipeline& pipeline_for(const Variant& v, ColorFormat storage, int threads) {
  static std::map<Key, std::unique_ptr<Pipeline>> pipelines;
  static const bool pool_sized = [&] {
    // Halide's JIT runtime reads HL_NUM_THREADS when its thread pool starts (the first parallel
    // realize); an explicit setting in the environment wins.
    setenv("HL_NUM_THREADS", std::to_string(threads).c_str(), 0);
    return true;
  }();
  (void)pool_sized;
  const Key key{int(v.mode), v.distance, v.fog_skybox, v.reversed_z, int(v.projection), int(storage)};
  auto& p = pipelines[key];
  if (!p) p = std::make_unique<Pipeline>(v, storage);
  return *p;
}

}  // namespace

}  // namespace fogcl::bench

using namespace fogcl;
using fogcl::bench::Pipeline;
using fogcl::bench::pipeline_for;

extern "C" void fogcl_halide_prepare(const CameraParams& camera, const FogSettings& settings, ColorFormat storage,
                                     int threads) {
  const Variant v = select_variant(settings, camera, storage);
  if (v.needs_pass()) pipeline_for(v, storage, threads);
}

extern "C" void fogcl_halide_fog(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                                 const CameraParams& camera, const FogSettings& settings, int threads) {
  const Variant v = select_variant(settings, camera, in.format());
  if (!v.needs_pass()) {
    out = in;
    return;
  }
  Pipeline& p = pipeline_for(v, in.format(), threads);
  const auto k = detail::fog_coefficients<float>(settings, v.mode);
  const int w = in.width(), h = in.height();
  p.zx.set(camera.zbuffer_params.x);
  p.zy.set(camera.zbuffer_params.y);
  p.near_plane.set(camera.near_plane());
  p.far_plane.set(camera.far_plane());
  p.k_a.set(k.a);
  p.k_b.set(k.b);
  p.fog_r.set(settings.color.r);
  p.fog_g.set(settings.color.g);
  p.fog_b.set(settings.color.b);
  p.inv_width.set(1.0f / float(w));
  p.height.set(float(h));
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 3; ++j) p.corner[i][j].set(camera.frustum_corners[i][j]);
  const Halide::Type type = p.color.type();
  halide_dimension_t color_shape[3] = {{0, 4, 1}, {0, w, 4}, {0, h, 4 * w}};
  halide_dimension_t depth_shape[2] = {{0, w, 1}, {0, h, w}};
  Halide::Buffer<> color_in(type, const_cast<void*>(in.data()), 3, color_shape);
  Halide::Buffer<> color_out(type, out.data(), 3, color_shape);
  Halide::Buffer<> depth_in(Halide::Float(32), const_cast<float*>(depth.data()), 2, depth_shape);
  p.color.set(color_in);
  p.depth.set(depth_in);
  p.pipeline.realize(color_out, p.target);
}
