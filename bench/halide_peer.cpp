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

// The peer's schedule. The defaults are the fastest found on the 2-vCPU Xeon (see the figures at
// the end of this file); FOGCL_HALIDE_SCHEDULE overrides them for the exploration, a comma list of
//   vec=N        pixels a vector (8, 16, 32)
//   rows=N       rows a parallel task (1: parallel(y), each row a task)
//   factor=at|inline  the factors computed per vector (compute_at) or inline in the blend
//   target=host|avx512|skylake|avx2  host: the JIT host target less AVX512_SapphireRapids;
//                avx512: only the AVX512 base feature; skylake: AVX512 + AVX512_Skylake; avx2: no AVX-512
//   asserts=0    NoAsserts and NoBoundsQuery added to the target
//   fuse=1       channels and pixels fused into one vectorised dimension (interleaved RGBA as
//                loaded, the row's factors computed first and read at cx / 4)
//   inplace=1    (read by the bench) the output written over its input
struct Schedule {
  int vector = 16;
  int rows = 4;
  bool factor_at_vector = true;
  bool fused = false;
  Halide::Target target;
};

Halide::Target host_target() {
  // Halide 14 takes AVX512-BF16 + VNNI for Sapphire Rapids and then emits AVX512-FP16 for half
  // conversions: on a Zen 4 EPYC (BF16, no FP16) that is SIGILL. F16C does the conversions.
  return Halide::get_jit_target_from_environment().without_feature(Halide::Target::AVX512_SapphireRapids);
}

Schedule parse_schedule(const char* text) {
  using T = Halide::Target;
  Schedule s;
  s.target = host_target();
  std::string list = text != nullptr ? text : "";
  std::size_t at = 0;
  while (at < list.size()) {
    std::size_t end = list.find(',', at);
    if (end == std::string::npos) end = list.size();
    const std::string item = list.substr(at, end - at);
    at = end + 1;
    const std::size_t eq = item.find('=');
    const std::string key = item.substr(0, eq), value = eq == std::string::npos ? "" : item.substr(eq + 1);
    if (key == "vec") s.vector = std::stoi(value);
    else if (key == "rows") s.rows = std::stoi(value);
    else if (key == "factor") s.factor_at_vector = value != "inline";
    else if (key == "fuse") s.fused = value == "1";
    else if (key == "target") {
      const T base = s.target.without_feature(T::AVX512).without_feature(T::AVX512_Skylake)
                         .without_feature(T::AVX512_Cannonlake).without_feature(T::AVX512_SapphireRapids);
      if (value == "avx2") s.target = base;
      else if (value == "avx512") s.target = base.with_feature(T::AVX512);
      else if (value == "skylake") s.target = base.with_feature(T::AVX512).with_feature(T::AVX512_Skylake);
    } else if (key == "asserts" && value == "0") {
      s.target = s.target.with_feature(T::NoAsserts).with_feature(T::NoBoundsQuery);
    }
  }
  return s;
}

const Schedule& schedule() {
  static const Schedule s = parse_schedule(std::getenv("FOGCL_HALIDE_SCHEDULE"));
  return s;
}

// Halide's JIT runtime reads HL_NUM_THREADS when its thread pool starts (the first parallel
// realize); an explicit setting in the environment wins.
void size_pool(int threads) {
  static const bool sized = [&] {
    setenv("HL_NUM_THREADS", std::to_string(threads).c_str(), 0);
    return true;
  }();
  (void)sized;
}

// A copy of 32-bit words, rows x row_words, in the peer's target and parallel over rows (or on
// the calling thread alone): the Halide entry of the bench's copy ceiling.
struct CopyPipeline {
  Halide::ImageParam in{Halide::UInt(32), 2, "copy_in"};
  Halide::Func out{"copied"};
  Halide::Pipeline pipeline;
  Halide::Target target;

  explicit CopyPipeline(bool parallel) {
    Halide::Var x("x"), y("y"), xo("xo"), xi("xi");
    out(x, y) = in(x, y);
    out.split(x, xo, xi, 64).vectorize(xi, 16).unroll(xi);  // four 512-bit vectors a step
    if (parallel) out.parallel(y);
    target = schedule().target;
    pipeline = Halide::Pipeline(out);
    pipeline.compile_jit(target);
  }
};

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
  // Vectors of s.vector pixels over x, the four channels unrolled (Halide turns the four
  // stride-4 stores into one interleaved store), bands of s.rows rows in parallel (or each row);
  // the factors of a vector computed once per vector (or inline, CSE'd across the unrolled channels).
  const Schedule& s = schedule();
  Var yo("yo"), yi("yi");
  const Var row = s.rows > 1 ? yi : y;  // the loop of one row
  if (s.fused) {
    // Channels and pixels as one dimension, 4 * s.vector lanes of interleaved RGBA a vector, the
    // factors of a row computed first and read at cx / 4 (Halide still de-interleaves: slower).
    Var cx("cx"), cxo("cxo"), cxi("cxi");
    out.reorder(c, x, y).bound(c, 0, 4).fuse(c, x, cx).split(cx, cxo, cxi, 4 * s.vector).vectorize(cxi);
  } else {
    out.reorder(c, x, y).bound(c, 0, 4).unroll(c).split(x, xo, xi, s.vector).vectorize(xi);
  }
  if (s.rows > 1)
    out.split(y, yo, yi, s.rows).parallel(yo);
  else
    out.parallel(y);
  if (s.fused)
    factor.compute_at(out, row).vectorize(x, 16);
  else if (s.factor_at_vector)
    factor.compute_at(out, xo).vectorize(x, s.vector);
  target = s.target;
  pipeline = Halide::Pipeline(out);
  pipeline.compile_jit(target);
  // FOGCL_HALIDE_ASM=DIR: the pipeline's assembly, to compare with PoCL's kernel.
  if (const char* dir = std::getenv("FOGCL_HALIDE_ASM")) {
    const std::string name = "fog_mode" + std::to_string(mode) + (v.distance ? "_distance" : "_depth") +
                             (storage == ColorFormat::rgba16f ? "_f16" : "_f32");
    pipeline.compile_to_assembly(std::string(dir) + "/" + name + ".s", pipeline.infer_arguments(), name, target);
  }
}

using Key = std::tuple<int, bool, bool, bool, int, int>;

Pipeline& pipeline_for(const Variant& v, ColorFormat storage, int threads) {
  static std::map<Key, std::unique_ptr<Pipeline>> pipelines;
  size_pool(threads);
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

extern "C" void fogcl_halide_copy(const void* src, void* dst, std::size_t row_bytes, int rows, int threads) {
  using fogcl::bench::CopyPipeline;
  fogcl::bench::size_pool(threads);
  static CopyPipeline serial(false), parallel(true);
  CopyPipeline& p = threads > 1 ? parallel : serial;
  const int words = int(row_bytes / 4);
  halide_dimension_t shape[2] = {{0, words, 1}, {0, rows, words}};
  Halide::Buffer<> in(Halide::UInt(32), const_cast<void*>(src), 2, shape);
  Halide::Buffer<> out(Halide::UInt(32), dst, 2, shape);
  p.in.set(in);
  p.pipeline.realize(out, p.target);
}

// The schedule exploration behind Schedule's defaults (bench/halide_schedule_sweep.sh: each
// schedule its own process, the schedules in turn, 3 rounds, medians in ms; BM_Halide RGBA32F,
// Halide 14 JIT, HL_NUM_THREADS=2), on the 2-vCPU Xeon (skylake-avx512, 480 MiB L3, PoCL 3.1),
// 2026-11-25 20:13-20:21 UTC, load 0.9-1.7 (bench/results/xeon-2core-ceiling-2026-11-25/).
// 1080p, linear / exp2, depth / distance; "vs first" the median of the four ratios:
//   vec=16 rows=1 (the earlier peer)  1.54 1.60 1.59 1.69   1.00
//   vec=8                             1.59 1.71 1.84 1.97   1.12
//   vec=32                            1.64 1.64 1.60 1.63   1.02
//   rows=4                            1.42 1.43 1.52 1.57   0.93
//   rows=16                           1.43 1.48 1.54 1.57   0.93
//   factor=inline                     1.68 1.63 1.66 1.70   1.03
//   fuse=1 (Halide still splits the channels: the per-channel selects de-interleave them, and the
//          row of factors is a halide_malloc per row)
//                                     1.88 2.04 2.23 2.29   1.32
//   target=avx2                       2.49 2.69 2.73 2.88   1.70
//   target=skylake                    1.64 1.66 1.61 1.67   1.03
//   target=avx512                     1.55 1.73 1.64 1.70   1.02
//   asserts=0                         1.52 1.62 1.64 1.65   1.00
//   inplace=1 (output over its input) 1.53 1.61 1.72 1.84   1.05
// Bands of rows, 1080p and 4K (the same four cases at each size), vs rows=1:
//   rows=4 0.925, rows=8 0.960, rows=16 0.956, rows=32 0.944, rows=8 vec=32 0.941,
//   rows=8 asserts=0 0.942; at 4K rows=4 took 10.3-11.6 ms against rows=1's 10.9-11.3.
// Kept: 16 pixels a vector, bands of 4 rows a parallel task, the factors per vector, the host
// target less AVX512_SapphireRapids, asserts on (no measurable cost), out of place.
