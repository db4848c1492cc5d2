// The upsample + composite kernel (kernels/volume_composite.cl) on its own, against the C++ formulas
// it compiles from (volume_formulas: vol_inverse_eye_depth, vol_upsample, vol_composite), bit for bit on
// CPU devices: the 16-pixel path (with AVX-512 builtins and portable), its row tails, and the
// one-pixel path GPUs run. Synthetic targets give every case its share: A == 0 (the color's bits
// pass through, signalling NaNs included), A == 1 (P exactly, NaN/Inf colors hidden), partial A
// over NaN/Inf colors, sky pixels and sky taps in depth-aware mode, NaN depths, the target's
// edges (first and last blocks clamp), widths that are not a multiple of 16; and scenes of surfaces,
// where depth-aware pixels whose taps all lie on their own surface take the bilinear weights (the
// CPU lanes' bilinear blocks) beside blocks with silhouettes.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <array>
#include <algorithm>
#include <limits>
#include <random>
#include <vector>

#include "fogcl/depth_kinds.h"
#include "runtime/clhpp.h"
#include "test_support.h"
#include "volume/volume_formulas.h"
#include "volume/volume_params.h"
#include "volume_composite_cl.h"

namespace fogcl::test {
namespace {

enum class Path { lanes, lanes_portable, one_pixel };
// orthographic_near0: the near plane at 0, where a pixel on it has 1 / eye depth = inf and its block
// a key of 0: the depth difference's 1 - k rho is NaN (the CPU lanes' vrangeps must give 1 for it).
enum class View { conventional, reversed, infinite_far, orthographic, orthographic_near0 };
// random: raw depths at random (no pixel on its taps' surface); surfaces: a slanted plane, a box in
// front of it and sky above, so that most blocks are on one surface and some straddle a silhouette.
enum class Depth { random, surfaces };

struct CompositeCase {
  Path path;
  int scale;
  bool depth_aware;
  ColorFormat storage;
  View view;
  int width;
  int height = 0;  // 0: 8 s + 5 (odd: the last target row is a bottom tap, not clamped)
  Depth depth = Depth::random;
};

std::string name_of(const testing::TestParamInfo<CompositeCase>& info) {
  const CompositeCase& c = info.param;
  const char* paths[] = {"lanes", "lanes_portable", "one_pixel"};
  const char* views[] = {"conventional", "reversed", "infinite_far", "orthographic", "orthographic_near0"};
  return std::string(paths[int(c.path)]) + "_s" + std::to_string(c.scale) + (c.depth_aware ? "_aware" : "_bilinear") +
         (c.storage == ColorFormat::rgba16f ? "_f16_" : "_f32_") + views[int(c.view)] + "_w" + std::to_string(c.width) +
         (c.height ? "_h" + std::to_string(c.height) : "") + (c.depth == Depth::surfaces ? "_surfaces" : "");
}

std::vector<CompositeCase> all_cases() {
  std::vector<CompositeCase> cases;
  for (Path p : {Path::lanes, Path::lanes_portable, Path::one_pixel})
    for (int s : {1, 2, 4})
      for (bool aware : {true, false})
        for (ColorFormat f : {ColorFormat::rgba32f, ColorFormat::rgba16f}) cases.push_back({p, s, aware, f, View::conventional, 83});
  for (View v : {View::reversed, View::infinite_far, View::orthographic, View::orthographic_near0})
    for (Path p : {Path::lanes, Path::one_pixel}) cases.push_back({p, 2, true, ColorFormat::rgba32f, v, 83});
  for (int s : {2, 4}) cases.push_back({Path::lanes, s, true, ColorFormat::rgba16f, View::conventional, 64});
  cases.push_back({Path::lanes, 4, true, ColorFormat::rgba32f, View::conventional, 7});  // a tail only
  for (Path p : {Path::lanes, Path::lanes_portable, Path::one_pixel})
    for (int s : {2, 4})
      for (ColorFormat f : {ColorFormat::rgba32f, ColorFormat::rgba16f})
        cases.push_back({p, s, true, f, View::conventional, 83, 0, Depth::surfaces});
  for (View v : {View::reversed, View::orthographic})
    cases.push_back({Path::lanes, 2, true, ColorFormat::rgba16f, v, 83, 0, Depth::surfaces});
  // Heights whose last work-item's rows clamp their bottom tap to the target's last row (the lanes
  // take the s rows between two target rows per work-item).
  for (int s : {2, 4})
    for (ColorFormat f : {ColorFormat::rgba32f, ColorFormat::rgba16f})
      cases.push_back({Path::lanes, s, true, f, View::conventional, 83, 8 * s + 4});
  return cases;
}

CameraParams camera_of(View view, int width, int height) {
  if (view == View::orthographic || view == View::orthographic_near0) {
    OrthographicCamera o;
    o.aspect = float(width) / float(height);
    if (view == View::orthographic_near0) o.near_plane = 0.0f;
    return make_camera_params(o);
  }
  PerspectiveCamera p;
  p.aspect = float(width) / float(height);
  p.reversed_z = view != View::conventional;
  p.infinite_far = view == View::infinite_far;
  return make_camera_params(p);
}

// Whether vol_upsample gives frame pixel (x, y), of inverse eye depth rho, its bilinear weights as they
// are: every tap's depth difference within VOL_UPSAMPLE_EPS.
bool on_own_surface(int x, int y, float rho, const std::vector<float>& low_key, int low_width, int low_height,
                    int s) {
  using namespace volume_formulas;
  int x0, x1, y0, y1;
  vol_upsample_axis<float>(x, s, low_width, &x0, &x1);
  vol_upsample_axis<float>(y, s, low_height, &y0, &y1);
  for (int ty : {y0, y1})
    for (int tx : {x0, x1})
      if (!(vol_depth_difference(rho, low_key[std::size_t(ty) * low_width + tx]) <= VOL_UPSAMPLE_EPS)) return false;
  return true;
}

class VolumeCompositeKernel : public testing::TestWithParam<CompositeCase> {
 protected:
  void SetUp() override {
    FOGCL_REQUIRE_DEVICE();
    if (!runtime()->is_cpu())
      GTEST_SKIP() << "bit identity with the C++ path is the CPU device's (GPU divisions may round differently)";
  }
};

TEST_P(VolumeCompositeKernel, MatchesTheFormulasBitForBit) {
  using namespace volume_formulas;
  const CompositeCase& c = GetParam();
  const int width = c.width, height = c.height ? c.height : 8 * c.scale + 5, s = c.scale;
  const int low_width = (width + s - 1) / s, low_height = (height + s - 1) / s;
  const CameraParams cam = camera_of(c.view, width, height);
  const bool reversed = cam.reversed_z;
  std::mt19937 rng(11 + s);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);

  // Depth: random raw values, every 7th pixel sky, every 29th NaN, every 11th on the near plane; or
  // surfaces: sky in the top rows, a plane whose eye depth grows by 0.4 % a pixel (taps within
  // EPS = 1 % of the pixel or not, by their distance), and a box at half its depth.
  DepthImage depth(width, height);
  for (int i = 0; i < width * height; ++i) {
    const int x = i % width, y = i / width;
    if (c.depth == Depth::surfaces) {
      const bool box = x >= width / 3 && x < width / 3 + 21 && y >= height / 2;
      const double eye = (box ? 0.5 : 1.0) * 4.0 * (1.0 + 0.004 * x + 0.002 * y);
      depth.data()[i] = y < s + 1 ? (reversed ? 0.0f : 1.0f) : float(raw_from_eye_depth(eye, cam));
      continue;
    }
    depth.data()[i] = i % 29 == 3 ? std::numeric_limits<float>::quiet_NaN()
                      : i % 7 == 0 ? (reversed ? 0.0f : 1.0f)
                      : i % 11 == 5 ? (reversed ? 1.0f : 0.0f)
                                   : unit(rng);
  }
  // Color: random HDR, and NaN, Inf and signalling NaNs (alpha too) in a pattern.
  ColorImage color(width, height, c.storage);
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      glm::vec4 v(4.0f * unit(rng), 4.0f * unit(rng), 4.0f * unit(rng), unit(rng));
      const int k = (x * 5 + y * 3) % 11;
      if (k < 3) v[k] = (x + y) % 2 ? nan : ((x + y) % 4 ? inf : -inf);
      color.set_pixel(x, y, v);
      if (k == 4) {
        const std::size_t i = 4 * (std::size_t(y) * width + x);
        if (c.storage == ColorFormat::rgba16f) {
          color.rgba16f()[i + 1] = 0x7d01;
          color.rgba16f()[i + 3] = 0xfd02;
        } else {
          const std::uint32_t snan = 0x7fa00001u;
          std::memcpy(&color.rgba32f()[i + 1], &snan, 4);
          std::memcpy(&color.rgba32f()[i + 3], &snan, 4);
        }
      }
    }
  // Target: a band of A == 0 (whole blocks clear: the CPU lanes' copy), a band of A == 1, partial A elsewhere with a
  // sprinkle of 0 and 1; keys: the block's nearest eye depth (the march's), some sky.
  const int projection = int(cam.projection);
  const float zx = cam.zbuffer_params.x, zy = cam.zbuffer_params.y, near_plane = cam.near_plane(),
              far_plane = cam.far_plane();
  std::vector<float> low(4 * std::size_t(low_width) * low_height), low_key(std::size_t(low_width) * low_height);
  for (int ly = 0; ly < low_height; ++ly)
    for (int lx = 0; lx < low_width; ++lx) {
      const std::size_t i = std::size_t(ly) * low_width + lx;
      const int band = ly * 4 / low_height;  // 0..3 down the frame
      float a = unit(rng);
      if (band == 0) a = 0.0f;
      if ((lx + ly) % 9 == 0) a = lx % 2 ? -0.0f : 0.0f;  // -0 takes the CPU lanes' full path
      if (band == 1 || (lx + ly) % 9 == 4) a = 1.0f;
      for (int k = 0; k < 3; ++k) low[4 * i + k] = a * unit(rng);
      low[4 * i + 3] = a;
      low_key[i] = (lx * 3 + ly) % 13 == 0 && c.depth == Depth::random ? inf
                                           : vol_block_eye_depth<float>(depth.data(), lx, ly, s, width, height, projection,
                                                                        reversed, FOG_DEPTH_RAW, zx, zy, near_plane, far_plane);
    }
  std::array<float, VOL_F_COUNT> frame{};
  frame[VOL_F_WIDTH] = float(width);
  frame[VOL_F_HEIGHT] = float(height);
  frame[VOL_F_SCALE] = float(s);
  frame[VOL_F_LOW_WIDTH] = float(low_width);
  frame[VOL_F_LOW_HEIGHT] = float(low_height);
  detail::pack_depth_constants(frame.data(), cam);

  // The kernel, built with the options the pass would use for such a device.
  detail::VolumeVariant variant;
  variant.scale = s;
  variant.depth_aware = c.depth_aware;
  variant.projection = cam.projection;
  variant.reversed_z = reversed;
  variant.storage = c.storage;
  DeviceTraits traits;
  traits.opencl_c_version = device_opencl_c_version(runtime()->device());
  traits.cpu = c.path != Path::one_pixel;
  traits.codegen.target_intrinsics = c.path == Path::lanes;
  // The lanes path with non-temporal RGBA32F stores (by default they start at frames whose pass
  // traffic is half the last-level cache), the portable one with ordinary stores: 83-pixel rows give both aligned
  // and unaligned quads.
  traits.codegen.streaming_stores = c.path == Path::lanes ? CpuCodegen::Streaming::always : CpuCodegen::Streaming::never;
  const std::string options = detail::volume_composite_options(variant, traits);
  const cl::Context ctx = wrap(runtime()->context());
  const cl::Device device = wrap(runtime()->device());
  cl::Program program(ctx, std::string(volume_composite_cl));
  ASSERT_EQ(program.build({device}, options.c_str()), CL_SUCCESS)
      << options << "\n" << program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device);
  cl::Kernel kernel(program, "volume_composite");
  const auto buffer = [&](const void* p, std::size_t bytes) {
    return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes, const_cast<void*>(p));
  };
  const cl::Buffer in = buffer(color.data(), color.size_bytes()), d = buffer(depth.data(), depth.size_bytes());
  const cl::Buffer f = buffer(frame.data(), sizeof(frame)), l = buffer(low.data(), low.size() * 4),
                   k = buffer(low_key.data(), low_key.size() * 4);
  const cl::Buffer out(ctx, CL_MEM_WRITE_ONLY, color.size_bytes());
  int arg = 0;
  for (const cl::Buffer* b : {&in, &d, &out, &f, &l, &k}) kernel.setArg(arg++, *b);
  const cl::CommandQueue queue(ctx, device);
  const auto global = detail::volume_composite_global(variant, traits, width, height);
  ASSERT_EQ(queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(global[0], global[1])), CL_SUCCESS);
  ColorImage got(width, height, c.storage);
  queue.enqueueReadBuffer(out, CL_TRUE, 0, got.size_bytes(), got.data());

  // The formulas: A == 0 and alpha keep the input's bits; else vol_composite, rounded to the storage.
  ColorImage want = color;
  std::size_t clear = 0, opaque = 0, partial = 0, wrong = 0;
  std::vector<char> own(std::size_t(width) * height, 0);
  const std::size_t bpp = bytes_per_pixel(c.storage);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t i = std::size_t(y) * width + x;
      const float rho =
          c.depth_aware && s > 1 ? vol_inverse_eye_depth<float>(depth.data()[i], frame.data(), projection, reversed, FOG_DEPTH_RAW) : 0.0f;
      own[i] = c.depth_aware && s > 1 && on_own_surface(x, y, rho, low_key, low_width, low_height, s);
      const glm::vec4 fog = vol_upsample<float>(x, y, rho, low.data(), low_key.data(), low_width, low_height, s,
                                                c.depth_aware);
      if (fog.w == 0.0f) {
        ++clear;
      } else {
        fog.w == 1.0f ? ++opaque : ++partial;
        const glm::vec4 in_px = color.pixel(x, y);
        glm::vec4 o(0.0f);
        for (int ch = 0; ch < 3; ++ch) o[ch] = vol_composite<float>(in_px[ch], fog[ch], fog.w);
        want.set_pixel(x, y, o);
        auto* alpha = static_cast<unsigned char*>(want.data()) + i * bpp + 3 * (bpp / 4);
        std::memcpy(alpha, static_cast<const unsigned char*>(color.data()) + i * bpp + 3 * (bpp / 4), bpp / 4);
      }
      const bool same = std::memcmp(static_cast<const unsigned char*>(got.data()) + i * bpp,
                                    static_cast<const unsigned char*>(want.data()) + i * bpp, bpp) == 0;
      if (!same && wrong++ < 5) {
        const glm::vec4 g = got.pixel(x, y), w = want.pixel(x, y);
        std::printf("    (%d, %d) A %g: got (%g %g %g %g) want (%g %g %g %g)\n", x, y, fog.w, g.x, g.y, g.z, g.w, w.x,
                    w.y, w.z, w.w);
      }
    }
  // The CPU lanes' blocks (16 pixels of the s rows between two target rows) all of whose pixels
  // are on their own surface (bilinear, no products) and those with some off it.
  std::size_t own_pixels = 0, own_blocks = 0, mixed_blocks = 0;
  for (char o : own) own_pixels += o;
  for (int m = 0; s > 1 && m <= low_height; ++m)
    for (int x0 = 0; x0 + 16 <= width; x0 += 16) {
      int n = 0, total = 0;
      for (int y = std::max(s * m - s / 2, 0); y < std::min(s * m + s / 2, height); ++y)
        for (int x = x0; x < x0 + 16; ++x, ++total) n += own[std::size_t(y) * width + x];
      own_blocks += total > 0 && n == total;
      mixed_blocks += n > 0 && n < total;
    }
  std::printf("  %s: %zu clear, %zu opaque, %zu partial pixels, %zu differ; %zu on their own surface, blocks of "
              "16 x s: %zu all, %zu some (options: %s)\n",
              name_of({GetParam(), 0}).c_str(), clear, opaque, partial, wrong, own_pixels, own_blocks, mixed_blocks,
              options.c_str());
  if (c.depth == Depth::surfaces) {
    EXPECT_GT(own_blocks, 2u);
    EXPECT_GT(mixed_blocks, 2u);
  }
  EXPECT_GT(clear, std::size_t(width));
  EXPECT_GT(opaque, std::size_t(width));
  EXPECT_GT(partial, std::size_t(width));
  EXPECT_EQ(wrong, 0u);
}

INSTANTIATE_TEST_SUITE_P(Cases, VolumeCompositeKernel, testing::ValuesIn(all_cases()), name_of);

// The sky test on Linear01Depth's denominator q is DESIGN.md §2's on 1 / q: float 1 / q rounds
// monotonically, so the threshold and the float below it decide every q.
TEST(VolumeDepthSimilarity, SkyDenominatorIsTheSkyTest) {
  using namespace volume_formulas;
  const float t = VOL_SKY_DENOMINATOR, below = std::nextafter(t, 0.0f);
  std::printf("  threshold %a: 1/q %a (sky %d), below %a: 1/q %a (sky %d)\n", t, 1.0f / t, fog_is_sky(1.0f / t), below,
              1.0f / below, fog_is_sky(1.0f / below));
  EXPECT_FALSE(fog_is_sky(1.0f / t));
  EXPECT_TRUE(fog_is_sky(1.0f / below));
}

// A pixel's inverse eye depth against the key the march derives from the same depth (its eye
// depth): differences near 0 on surfaces (the two roundings), exactly 0 for sky against sky and 1
// for sky against a surface, in every projection and at stiff far / near ratios.
TEST(VolumeDepthSimilarity, OwnDepthIsSimilarAndSkyIsNot) {
  using namespace volume_formulas;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  float worst = 0.0f;
  for (View view : {View::conventional, View::reversed, View::infinite_far, View::orthographic})
    for (float far_plane : {100.0f, 1e6f, 1e9f}) {
      CameraParams cam = camera_of(view, 16, 9);
      if (view == View::orthographic) {
        OrthographicCamera o;
        o.far_plane = far_plane;
        cam = make_camera_params(o);
      } else if (view != View::infinite_far) {
        PerspectiveCamera p;
        p.near_plane = 0.01f;
        p.far_plane = far_plane;
        p.reversed_z = view == View::reversed;
        cam = make_camera_params(p);
      }
      std::array<float, VOL_F_COUNT> frame{};
      detail::pack_depth_constants(frame.data(), cam);
      const int projection = int(cam.projection);
      const auto eye = [&](float raw) {
        return vol_eye_depth<float>(raw, projection, cam.reversed_z, FOG_DEPTH_RAW, frame[VOL_F_ZX], frame[VOL_F_ZY],
                                    frame[VOL_F_NEAR], frame[VOL_F_FAR]);
      };
      const float sky_raw = cam.reversed_z ? 0.0f : 1.0f, sky_key = eye(sky_raw);
      const float sky_rho = vol_inverse_eye_depth<float>(sky_raw, frame.data(), projection, cam.reversed_z, FOG_DEPTH_RAW);
      ASSERT_EQ(sky_key, std::numeric_limits<float>::infinity());
      EXPECT_EQ(vol_depth_difference(sky_rho, sky_key), 0.0f);
      EXPECT_EQ(vol_depth_difference(sky_rho, std::numeric_limits<float>::quiet_NaN()), 0.0f);
      for (int n = 0; n < 2000; ++n) {
        const float raw = unit(rng), key = eye(raw);
        const float rho = vol_inverse_eye_depth<float>(raw, frame.data(), projection, cam.reversed_z, FOG_DEPTH_RAW);
        if (key == std::numeric_limits<float>::infinity()) {
          EXPECT_EQ(vol_depth_difference(rho, key), 0.0f) << raw;
          continue;
        }
        worst = std::max(worst, vol_depth_difference(rho, key));
        EXPECT_EQ(vol_depth_difference(rho, sky_key), 1.0f) << raw;
        EXPECT_EQ(vol_depth_difference(sky_rho, key), 1.0f) << raw;
        // Half and twice the depth: the difference is relative to the pixel's own depth.
        EXPECT_NEAR(vol_depth_difference(rho, 0.5f * key), 0.5f, 1e-5f) << raw;
        EXPECT_EQ(vol_depth_difference(rho, 2.5f * key), 1.0f) << raw;
      }
    }
  std::printf("  worst difference of a pixel's own depth: %.3g (relative; EPS is 0.01)\n", worst);
  EXPECT_LT(worst, 1e-5f);
}

// vol_upsample's depth-aware weights bilinear_k / max(difference_k, EPS): a pixel whose four taps are
// within EPS of its depth (one surface) gets the bilinear result bit for bit; just past EPS the
// result moves continuously from it; a tap across a silhouette (difference 1) keeps 1/100 of the
// weight it would have on the surface.
TEST(VolumeDepthSimilarity, OwnSurfaceTakesTheBilinearWeights) {
  using namespace volume_formulas;
  // A 2 x 2 target; frame pixel (1, 1) at s = 2 samples all four with fractions 1/4.
  const std::vector<float> low = {0.1f, 0.2f, 0.3f, 0.5f, 0.9f, 0.1f, 0.4f, 0.7f,
                                  0.3f, 0.6f, 0.2f, 0.25f, 0.8f, 0.8f, 0.1f, 0.9f};
  const float rho = 0.1f;  // eye depth 10
  const auto upsample = [&](std::array<double, 4> delta, bool aware) {
    std::vector<float> keys(4);
    for (int k = 0; k < 4; ++k) keys[k] = float(10.0 * (1.0 + delta[k]));
    return vol_upsample<float>(1, 1, rho, low.data(), keys.data(), 2, 2, 2, aware);
  };
  const glm::vec4 bilinear = upsample({0, 0, 0, 0}, false);
  const std::array<double, 4> within = {0.005, -0.009, 0.0, 0.0099};
  const glm::vec4 on_surface = upsample(within, true);
  EXPECT_EQ(std::memcmp(&on_surface, &bilinear, sizeof bilinear), 0);
  // Just past the tolerance: the normalised products differ from bilinear by about 1e-4 of a weight.
  const glm::vec4 past = upsample({0.005, -0.009, 0.0, 0.0100015}, true);
  float jump = 0;
  for (int c = 0; c < 4; ++c) jump = std::max(jump, std::fabs(past[c] - bilinear[c]));
  // Across a silhouette: tap 3 twice as far (difference 1), against the weights in double.
  const glm::vec4 across = upsample({0.005, -0.009, 0.0, 1.0}, true);
  const double b[4] = {0.5625, 0.1875, 0.1875, 0.0625}, e[4] = {0.01, 0.01, 0.01, 1.0};
  double sum = 0;
  for (int k = 0; k < 4; ++k) sum += b[k] / e[k];
  float worst = 0;
  for (int c = 0; c < 4; ++c) {
    double want = 0;
    for (int k = 0; k < 4; ++k) want += b[k] / e[k] / sum * double(low[4 * k + c]);
    worst = std::max(worst, float(std::fabs(double(across[c]) - want)));
  }
  std::printf("  one surface: bilinear bits; just past EPS: %.3g from bilinear; across a silhouette: %.3g from double\n",
              jump, worst);
  EXPECT_GT(jump, 0.0f);
  EXPECT_LT(jump, 1e-4f);
  EXPECT_LT(worst, 1e-6f);
}

}  // namespace
}  // namespace fogcl::test
