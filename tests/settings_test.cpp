// Unit tests of the fog settings validation, variant selection and build options
// (docs/DESIGN.md §2, §3), and of the per-variant program cache of the pass.
#include <cmath>
#include <cstdio>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fogcl/fogcl.h"
#include "test_support.h"

namespace fogcl {
namespace {

using test::error_of;
using test::num;

const float kNaN = std::numeric_limits<float>::quiet_NaN();
const float kInf = std::numeric_limits<float>::infinity();



FogSettings mode(FogMode m) {
  FogSettings s;
  s.mode = m;
  return s;
}

// True when `options` holds the switch "-D name" as a whole token (not a prefix of another).
bool has_define(const std::string& options, const std::string& name) {
  std::istringstream in(options);
  std::vector<std::string> tokens;
  for (std::string t; in >> t;) tokens.push_back(t);
  for (std::size_t i = 0; i + 1 < tokens.size(); ++i)
    if (tokens[i] == "-D" && (tokens[i + 1] == name || tokens[i + 1].rfind(name + "=", 0) == 0)) return true;
  return false;
}

bool has_token(const std::string& options, const std::string& token) {
  std::istringstream in(options);
  for (std::string t; in >> t;)
    if (t == token) return true;
  return false;
}

// ---------------------------------------------------------------------------------------------
// validate(FogSettings)

TEST(SettingsTest, DefaultsAreValid) {
  EXPECT_NO_THROW(validate(FogSettings{}));
  for (FogMode m : {FogMode::off, FogMode::linear, FogMode::exp, FogMode::exp2}) EXPECT_NO_THROW(validate(mode(m)));
}

TEST(SettingsTest, RejectsBadDensity) {
  for (FogMode m : {FogMode::exp, FogMode::exp2}) {
    SCOPED_TRACE(to_string(m));
    for (float d : {-0.01f, -kInf, kNaN, kInf}) {
      FogSettings s = mode(m);
      s.density = d;
      const std::string msg = error_of([&] { validate(s); });
      EXPECT_MSG_HAS(msg, "density");
      EXPECT_MSG_HAS(msg, num(d));
    }
  }
}

TEST(SettingsTest, RejectsStartAfterEnd) {
  FogSettings s = mode(FogMode::linear);
  s.start = 20.0f;
  s.end = 10.5f;
  const std::string msg = error_of([&] { validate(s); });
  EXPECT_MSG_HAS(msg, "start");
  EXPECT_MSG_HAS(msg, "20");
  EXPECT_MSG_HAS(msg, "10.5");
}

TEST(SettingsTest, RejectsNonFiniteStartEnd) {
  for (float v : {kNaN, kInf, -kInf}) {
    FogSettings s = mode(FogMode::linear);
    s.start = v;
    s.end = 100.0f;
    std::string msg = error_of([&] { validate(s); });
    EXPECT_MSG_HAS(msg, "start");
    EXPECT_MSG_HAS(msg, num(v));

    s = mode(FogMode::linear);
    s.start = 0.0f;
    s.end = v;
    msg = error_of([&] { validate(s); });
    EXPECT_MSG_HAS(msg, "end");
    EXPECT_MSG_HAS(msg, num(v));
  }
}

TEST(SettingsTest, RejectsBadFogColor) {
  for (FogMode m : {FogMode::linear, FogMode::exp, FogMode::exp2}) {
    SCOPED_TRACE(to_string(m));
    for (int c = 0; c < 3; ++c) {
      for (float v : {kNaN, kInf, -kInf, 65505.0f, -70000.0f, 1e30f}) {
        FogSettings s = mode(m);
        s.color[c] = v;
        const std::string msg = error_of([&] { validate(s); });
        EXPECT_MSG_HAS(msg, "color");
        EXPECT_MSG_HAS(msg, num(v));
      }
    }
  }
}

TEST(SettingsTest, AcceptsEdgeValues) {
  FogSettings s = mode(FogMode::linear);
  s.start = s.end = 42.0f;
  EXPECT_NO_THROW(validate(s));
  s.start = s.end = 0.0f;
  EXPECT_NO_THROW(validate(s));
  s = mode(FogMode::linear);
  s.start = -5.0f;  // negative start is a legal linear fog (fog in front of the near plane)
  EXPECT_NO_THROW(validate(s));
  for (FogMode m : {FogMode::exp, FogMode::exp2}) {
    s = mode(m);
    s.density = 0.0f;
    EXPECT_NO_THROW(validate(s));
    s.density = 1e30f;
    EXPECT_NO_THROW(validate(s));
  }
  s = mode(FogMode::exp2);
  s.color = glm::vec3(65504.0f, -65504.0f, 0.0f);
  EXPECT_NO_THROW(validate(s));
}

TEST(SettingsTest, DoesNotCheckUnusedParameters) {
  FogSettings s = mode(FogMode::linear);
  s.density = -1.0f;
  EXPECT_NO_THROW(validate(s)) << "linear fog does not use density";
  s.density = kNaN;
  EXPECT_NO_THROW(validate(s)) << "linear fog does not use density";
  for (FogMode m : {FogMode::exp, FogMode::exp2}) {
    s = mode(m);
    s.start = 100.0f;
    s.end = 1.0f;
    EXPECT_NO_THROW(validate(s)) << to_string(m) << " fog does not use start/end";
    s.start = kNaN;
    s.end = kInf;
    EXPECT_NO_THROW(validate(s)) << to_string(m) << " fog does not use start/end";
  }
}

TEST(SettingsTest, FogOffAcceptsAnything) {
  FogSettings s = mode(FogMode::off);
  s.density = kNaN;
  s.start = 10.0f;
  s.end = -10.0f;
  s.color = glm::vec3(kNaN, kInf, 1e30f);
  EXPECT_NO_THROW(validate(s));
}

// ---------------------------------------------------------------------------------------------
// select_variant

const CameraParams& conventional_camera() {
  static const CameraParams p = make_camera_params(PerspectiveCamera{});
  return p;
}
const CameraParams& reversed_camera() {
  static const CameraParams p = [] {
    PerspectiveCamera c;
    c.reversed_z = true;
    return make_camera_params(c);
  }();
  return p;
}

TEST(VariantTest, FogOffNeedsNoPass) {
  const Variant v = select_variant(mode(FogMode::off), conventional_camera(), ColorFormat::rgba32f);
  EXPECT_EQ(v.mode, KernelMode::none);
  EXPECT_FALSE(v.needs_pass());
}

TEST(VariantTest, ZeroDensityNeedsNoPass) {
  for (FogMode m : {FogMode::exp, FogMode::exp2}) {
    FogSettings s = mode(m);
    s.density = 0.0f;
    const Variant v = select_variant(s, reversed_camera(), ColorFormat::rgba16f);
    EXPECT_EQ(v.mode, KernelMode::none) << to_string(m);
    EXPECT_FALSE(v.needs_pass());
  }
}

TEST(VariantTest, ModeMapping) {
  FogSettings s = mode(FogMode::linear);
  EXPECT_EQ(select_variant(s, conventional_camera(), ColorFormat::rgba32f).mode, KernelMode::linear);
  s.start = s.end = 10.0f;
  EXPECT_EQ(select_variant(s, conventional_camera(), ColorFormat::rgba32f).mode, KernelMode::linear_step);
  EXPECT_EQ(select_variant(mode(FogMode::exp), conventional_camera(), ColorFormat::rgba32f).mode, KernelMode::exp);
  EXPECT_EQ(select_variant(mode(FogMode::exp2), conventional_camera(), ColorFormat::rgba32f).mode, KernelMode::exp2);
  EXPECT_TRUE(select_variant(mode(FogMode::exp2), conventional_camera(), ColorFormat::rgba32f).needs_pass());
}

TEST(VariantTest, FieldsMapping) {
  FogSettings s = mode(FogMode::exp);
  Variant v = select_variant(s, conventional_camera(), ColorFormat::rgba32f);
  EXPECT_FALSE(v.distance);
  EXPECT_FALSE(v.fog_skybox);
  EXPECT_FALSE(v.reversed_z);
  EXPECT_EQ(v.storage, ColorFormat::rgba32f);
  EXPECT_EQ(v.precision, Precision::precise);

  s.metric = FogMetric::distance;
  s.fog_skybox = true;
  s.precision = Precision::fast;
  v = select_variant(s, reversed_camera(), ColorFormat::rgba16f);
  EXPECT_EQ(v.mode, KernelMode::exp);
  EXPECT_TRUE(v.distance);
  EXPECT_TRUE(v.fog_skybox);
  EXPECT_TRUE(v.reversed_z);
  EXPECT_EQ(v.storage, ColorFormat::rgba16f);
  EXPECT_EQ(v.precision, Precision::fast);

  // Each field alone.
  FogSettings d = mode(FogMode::exp2);
  d.metric = FogMetric::distance;
  v = select_variant(d, conventional_camera(), ColorFormat::rgba32f);
  EXPECT_TRUE(v.distance);
  EXPECT_FALSE(v.fog_skybox);
  FogSettings k = mode(FogMode::exp2);
  k.fog_skybox = true;
  v = select_variant(k, conventional_camera(), ColorFormat::rgba32f);
  EXPECT_FALSE(v.distance);
  EXPECT_TRUE(v.fog_skybox);
  v = select_variant(mode(FogMode::exp2), reversed_camera(), ColorFormat::rgba32f);
  EXPECT_TRUE(v.reversed_z);
  EXPECT_EQ(v.storage, ColorFormat::rgba32f);
}

TEST(VariantTest, InvalidSettingsThrow) {
  FogSettings s = mode(FogMode::exp);
  s.density = -1.0f;
  EXPECT_THROW(select_variant(s, conventional_camera(), ColorFormat::rgba32f), Error);
  s = mode(FogMode::linear);
  s.start = 2.0f;
  s.end = 1.0f;
  EXPECT_THROW(select_variant(s, conventional_camera(), ColorFormat::rgba32f), Error);
}

// ---------------------------------------------------------------------------------------------
// build_options

Variant variant(KernelMode m, bool distance = false, bool sky = false, bool reversed = false,
                ColorFormat storage = ColorFormat::rgba32f, Precision precision = Precision::precise) {
  Variant v;
  v.mode = m;
  v.distance = distance;
  v.fog_skybox = sky;
  v.reversed_z = reversed;
  v.storage = storage;
  v.precision = precision;
  return v;
}

DeviceTraits dev(const std::string& opencl_c_version) {
  DeviceTraits d;
  d.opencl_c_version = opencl_c_version;
  return d;
}

TEST(VariantTest, BuildOptionsExactStrings) {
  EXPECT_EQ(build_options(variant(KernelMode::exp2)),
            "-cl-std=CL1.2 -D FOG_MODE=4 -D FOG_VECTOR_WIDTH=16");
  EXPECT_EQ(build_options(variant(KernelMode::exp2, true)),
            "-cl-std=CL1.2 -D FOG_MODE=4 -D FOG_DISTANCE -D FOG_VECTOR_WIDTH=16");
  EXPECT_EQ(build_options(variant(KernelMode::linear, false, true)),
            "-cl-std=CL1.2 -D FOG_MODE=1 -D FOG_SKYBOX -D FOG_VECTOR_WIDTH=16");
  EXPECT_EQ(build_options(variant(KernelMode::linear_step, false, false, true, ColorFormat::rgba16f)),
            "-cl-std=CL1.2 -D FOG_MODE=2 -D REVERSED_Z -D FOG_COLOR_HALF -D FOG_VECTOR_WIDTH=16");
  EXPECT_EQ(build_options(variant(KernelMode::exp, true, true, true, ColorFormat::rgba16f, Precision::fast)),
            "-cl-std=CL1.2 -D FOG_MODE=3 -D FOG_DISTANCE -D FOG_SKYBOX -D REVERSED_Z -D FOG_COLOR_HALF "
            "-D FOG_NATIVE_MATH -cl-fast-relaxed-math -D FOG_VECTOR_WIDTH=16");
  // Non-CPU devices keep one pixel per work-item.
  DeviceTraits gpu;
  gpu.cpu = false;
  EXPECT_EQ(build_options(variant(KernelMode::exp2), gpu), "-cl-std=CL1.2 -D FOG_MODE=4 -D FOG_VECTOR_WIDTH=1");
}

// Streaming stores by frame size: from pass traffic (36 bytes a pixel) of half the device's
// last-level cache, counted up to 32 MiB (466033 pixels: 720p streams and the 512x256
// cache-resident frame does not, also where the cache reported is 300 MiB; 8 MiB: 116508), never
// for half storage, GPUs or an unknown cache size; forced on (0) or off by CpuCodegen.
TEST(VariantTest, BuildOptionsStreamingStoresByFrameSize) {
  DeviceTraits cpu;
  cpu.cache_bytes = 32ull << 20;
  EXPECT_EQ(streaming_min_pixels(cpu), 466033);
  EXPECT_GT(1280 * 720, streaming_min_pixels(cpu));
  EXPECT_LT(512 * 256, streaming_min_pixels(cpu));
  DeviceTraits large = cpu, small = cpu;
  large.cache_bytes = 300ull << 20;
  EXPECT_EQ(streaming_min_pixels(large), 466033);
  small.cache_bytes = 8ull << 20;
  EXPECT_EQ(streaming_min_pixels(small), 116508);
  EXPECT_EQ(build_options(variant(KernelMode::exp2), cpu),
            "-cl-std=CL1.2 -D FOG_MODE=4 -D FOG_VECTOR_WIDTH=16 -D FOG_STREAMING_MIN_PIXELS=466033");
  EXPECT_FALSE(has_define(build_options(variant(KernelMode::exp2, false, false, false, ColorFormat::rgba16f), cpu),
                          "FOG_STREAMING_MIN_PIXELS"));
  DeviceTraits unknown;  // cache_bytes 0
  EXPECT_EQ(streaming_min_pixels(unknown), -1);
  EXPECT_FALSE(has_define(build_options(variant(KernelMode::exp2), unknown), "FOG_STREAMING_MIN_PIXELS"));
  DeviceTraits gpu = cpu;
  gpu.cpu = false;
  EXPECT_EQ(streaming_min_pixels(gpu), -1);
  DeviceTraits always = cpu, never = cpu;
  always.codegen.streaming_stores = CpuCodegen::Streaming::always;
  never.codegen.streaming_stores = CpuCodegen::Streaming::never;
  EXPECT_TRUE(has_token(build_options(variant(KernelMode::exp2), always), "FOG_STREAMING_MIN_PIXELS=0"));
  EXPECT_FALSE(has_define(build_options(variant(KernelMode::exp2), never), "FOG_STREAMING_MIN_PIXELS"));
}

TEST(VariantTest, BuildOptionsModeNumbers) {
  const std::pair<KernelMode, const char*> modes[] = {{KernelMode::linear, "FOG_MODE=1"},
                                                      {KernelMode::linear_step, "FOG_MODE=2"},
                                                      {KernelMode::exp, "FOG_MODE=3"},
                                                      {KernelMode::exp2, "FOG_MODE=4"}};
  for (const auto& [m, want] : modes) EXPECT_TRUE(has_token(build_options(variant(m)), want)) << to_string(m);
}

TEST(VariantTest, BuildOptionsLeaveOutUnusedFeatures) {
  // Depth-based, sky test on, conventional Z, float storage, precise: no switch but the mode.
  FogSettings s = mode(FogMode::exp2);
  const std::string depth = build_options(select_variant(s, conventional_camera(), ColorFormat::rgba32f));
  EXPECT_FALSE(has_define(depth, "FOG_DISTANCE")) << depth;
  EXPECT_FALSE(has_define(depth, "FOG_SKYBOX")) << depth;
  EXPECT_FALSE(has_define(depth, "REVERSED_Z")) << depth;
  EXPECT_FALSE(has_define(depth, "FOG_COLOR_HALF")) << depth;
  EXPECT_FALSE(has_define(depth, "FOG_NATIVE_MATH")) << depth;
  EXPECT_FALSE(has_token(depth, "-cl-fast-relaxed-math")) << depth;
  EXPECT_TRUE(has_define(depth, "FOG_MODE")) << depth;

  s.metric = FogMetric::distance;
  const std::string dist = build_options(select_variant(s, conventional_camera(), ColorFormat::rgba32f));
  EXPECT_TRUE(has_define(dist, "FOG_DISTANCE")) << dist;

  s = mode(FogMode::exp2);
  s.fog_skybox = true;
  const std::string sky = build_options(select_variant(s, conventional_camera(), ColorFormat::rgba32f));
  EXPECT_TRUE(has_define(sky, "FOG_SKYBOX")) << sky;
  EXPECT_FALSE(has_define(sky, "FOG_DISTANCE")) << sky;

  const std::string rev = build_options(select_variant(mode(FogMode::exp2), reversed_camera(), ColorFormat::rgba32f));
  EXPECT_TRUE(has_define(rev, "REVERSED_Z")) << rev;

  const std::string half = build_options(select_variant(mode(FogMode::exp2), conventional_camera(), ColorFormat::rgba16f));
  EXPECT_TRUE(has_define(half, "FOG_COLOR_HALF")) << half;

  s = mode(FogMode::exp2);
  s.precision = Precision::fast;
  const std::string fast = build_options(select_variant(s, conventional_camera(), ColorFormat::rgba32f));
  EXPECT_TRUE(has_define(fast, "FOG_NATIVE_MATH")) << fast;
  EXPECT_TRUE(has_token(fast, "-cl-fast-relaxed-math")) << fast;
}

std::vector<Variant> all_pass_variants() {
  std::vector<Variant> out;
  for (KernelMode m : {KernelMode::linear, KernelMode::linear_step, KernelMode::exp, KernelMode::exp2})
    for (int bits = 0; bits < 32; ++bits)
      out.push_back(variant(m, bits & 1, bits & 2, bits & 4, (bits & 8) ? ColorFormat::rgba16f : ColorFormat::rgba32f,
                            (bits & 16) ? Precision::fast : Precision::precise));
  return out;
}

TEST(VariantTest, BuildOptionsAreAFaithfulCacheKey) {
  const std::vector<Variant> all = all_pass_variants();
  std::set<std::string> strings;
  for (const Variant& v : all) {
    const std::string o = build_options(v);
    strings.insert(o);
    EXPECT_EQ(o, build_options(Variant(v))) << "equal variants must give equal strings";
    // Each field appears exactly when set.
    EXPECT_EQ(has_define(o, "FOG_DISTANCE"), v.distance) << o;
    EXPECT_EQ(has_define(o, "FOG_SKYBOX"), v.fog_skybox) << o;
    EXPECT_EQ(has_define(o, "REVERSED_Z"), v.reversed_z) << o;
    EXPECT_EQ(has_define(o, "FOG_COLOR_HALF"), v.storage == ColorFormat::rgba16f) << o;
    EXPECT_EQ(has_define(o, "FOG_NATIVE_MATH"), v.precision == Precision::fast) << o;
  }
  EXPECT_EQ(strings.size(), all.size()) << "different variants must give different option strings";
  for (std::size_t i = 0; i < all.size(); ++i)
    for (std::size_t j = 0; j < all.size(); ++j) EXPECT_EQ(all[i] == all[j], i == j);
}

TEST(VariantTest, BuildOptionsLanguageVersion) {
  const Variant v = variant(KernelMode::exp);
  EXPECT_TRUE(has_token(build_options(v, dev("OpenCL C 1.1")), "-cl-std=CL1.1"));
  EXPECT_FALSE(has_token(build_options(v, dev("OpenCL C 1.1")), "-cl-std=CL1.2"));
  EXPECT_TRUE(has_token(build_options(v, dev("OpenCL C 1.2 pocl")), "-cl-std=CL1.2"));
  EXPECT_TRUE(has_token(build_options(v, dev("OpenCL C 2.0")), "-cl-std=CL1.2"));
  EXPECT_TRUE(has_token(build_options(v, dev("OpenCL C 3.0 PoCL")), "-cl-std=CL1.2"));
  EXPECT_EQ(build_options(v), build_options(v, dev("OpenCL C 1.2")));
}

TEST(VariantTest, BuildOptionsRejectsBadVersion) {
  const Variant v = variant(KernelMode::exp);
  for (const char* version : {"", "garbage", "OpenCL 1.2", "OpenCL C x.y"}) {
    const std::string msg = error_of([&] { build_options(v, dev(version)); });
    EXPECT_MSG_HAS(msg, std::string("'") + version + "'");
  }
  const std::string msg = error_of([&] { build_options(v, dev("OpenCL C 1.0")); });
  EXPECT_MSG_HAS(msg, "1.0");
}

TEST(VariantTest, BuildOptionsOfNoneVariantThrows) {
  EXPECT_THROW(build_options(Variant{}), Error);
  EXPECT_THROW(build_options(select_variant(mode(FogMode::off), conventional_camera(), ColorFormat::rgba32f)), Error);
}

TEST(VariantTest, BuildOptionsForTheRealDevice) {
  FOGCL_REQUIRE_DEVICE();
  const std::string version = device_opencl_c_version(test::runtime()->device());
  EXPECT_EQ(version.rfind("OpenCL C ", 0), 0u) << version;
  const std::string o = build_options(variant(KernelMode::exp2), dev(version));
  EXPECT_EQ(o.rfind("-cl-std=CL1.", 0), 0u) << o;
}

TEST(VariantTest, Describe) {
  EXPECT_EQ(describe(Variant{}), "none (no pass)");
  EXPECT_EQ(describe(variant(KernelMode::exp2)), "exp2 depth sky-test conventional-z rgba32f precise");
  EXPECT_EQ(describe(variant(KernelMode::linear_step, true, true, true, ColorFormat::rgba16f, Precision::fast)),
            "linear-step distance fog-skybox reversed-z rgba16f fast");
}

// ---------------------------------------------------------------------------------------------
// One program per distinct variant (docs/DESIGN.md §3), via the pass's program cache.

TEST(VariantTest, PrepareBuildsOncePerDistinctVariantOwnPass) {
  FOGCL_REQUIRE_DEVICE();
  // A pass of its own: its cache starts empty, so the counts are exact whatever ran before.
  FogPass pass(test::runtime()->context(), test::runtime()->device());
  EXPECT_EQ(pass.programs().builds(), 0u);
  const Variant depth = variant(KernelMode::exp2);
  const Variant dist = variant(KernelMode::exp2, true);
  pass.prepare(depth);
  EXPECT_EQ(pass.programs().builds(), 1u);
  pass.prepare(depth);
  EXPECT_EQ(pass.programs().builds(), 1u) << "the same variant again must not build";
  pass.prepare(Variant(depth));
  EXPECT_EQ(pass.programs().builds(), 1u);
  pass.prepare(dist);
  EXPECT_EQ(pass.programs().builds(), 2u) << "a new distinct variant builds once";
  pass.prepare(dist);
  pass.prepare(depth);
  EXPECT_EQ(pass.programs().builds(), 2u);
  pass.prepare(Variant{});  // mode none: no program at all
  EXPECT_EQ(pass.programs().builds(), 2u) << "a none variant must build nothing";
}

TEST(VariantTest, PrepareBuildsOncePerDistinctVariantSharedPass) {
  FOGCL_REQUIRE_DEVICE();
  FogPass& pass = test::shared_pass();
  // Other tests share this pass, so a variant may already be cached; pick two that no fog
  // scene of the other tests is likely to use, and measure relative to what is there.
  const Variant a = variant(KernelMode::linear_step, true, true, true, ColorFormat::rgba16f, Precision::fast);
  const Variant b = variant(KernelMode::linear_step, false, true, true, ColorFormat::rgba16f, Precision::fast);
  const std::size_t before = pass.programs().builds();
  pass.prepare(a);
  const std::size_t after_a = pass.programs().builds();
  EXPECT_LE(after_a - before, 1u);
  pass.prepare(b);
  const std::size_t after_b = pass.programs().builds();
  EXPECT_LE(after_b - after_a, 1u);
  std::printf("[ info ] shared pass: builds %zu -> %zu -> %zu\n", before, after_a, after_b);
  pass.prepare(a);
  pass.prepare(b);
  EXPECT_EQ(pass.programs().builds(), after_b) << "preparing cached variants again must not build";
  const Variant c = variant(KernelMode::linear_step, true, false, true, ColorFormat::rgba16f, Precision::fast);
  const std::size_t before_c = pass.programs().builds();
  pass.prepare(c);
  pass.prepare(c);
  EXPECT_LE(pass.programs().builds() - before_c, 1u);
}

}  // namespace
}  // namespace fogcl
