// An integrator's mistakes are fogcl::Error naming the value and the rule, never a silently
// wrong image, a crash or another exception type: a camera whose aspect is not the frame's
// (width and height swapped among them), a pass used after a move, a pixel out of range, a null
// event in a wait list, an image too large for host memory.
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "fogcl/volume_pass.h"
#include "fogcl/volume_scalar.h"
#include "test_support.h"
#include "volume_support.h"

namespace fogcl::test {
namespace {

template <class Fn>
std::string error_of(Fn&& fn) {
  try {
    fn();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("not a fogcl::Error: ") + e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Random frame sizes and camera aspects: accepted exactly when the aspects agree within the
// documented tolerance, and the message names both.
TEST(Misuse, CameraAspectMustMatchTheFrame) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> side(1, 4000);
  std::uniform_real_distribution<double> log_aspect(-1.5, 1.5);
  int accepted = 0, rejected = 0;
  double closest_rejected = INFINITY;
  for (int i = 0; i < 2000; ++i) {
    const int w = side(rng), h = side(rng);
    PerspectiveCamera cam;
    // Half the cases near the frame's aspect, half anywhere.
    cam.aspect = i % 2 ? float(double(w) / h * (1.0 + 0.004 * log_aspect(rng))) : float(std::exp(log_aspect(rng)));
    const CameraParams p = make_camera_params(cam);
    const double rel = std::fabs(frustum_aspect(p) / (double(w) / h) - 1.0);
    const double tolerance = std::max(1e-3, 0.5 / w + 0.5 / h);
    const std::string e = error_of([&] { validate(p, w, h); });
    if (rel <= tolerance * 0.999) {
      EXPECT_EQ(e, "") << w << "x" << h << " aspect " << cam.aspect;
      ++accepted;
    } else if (rel > tolerance * 1.001) {
      EXPECT_TRUE(contains(e, "camera aspect") && contains(e, std::to_string(w) + "x" + std::to_string(h))) << e;
      closest_rejected = std::min(closest_rejected, rel / tolerance);
      ++rejected;
      CameraParams opted = p;
      opted.non_square_pixels = true;
      EXPECT_EQ(error_of([&] { validate(opted, w, h); }), "");
    }
  }
  std::printf("aspect check: %d accepted, %d rejected; closest rejection at %.4f x the tolerance\n", accepted,
              rejected, closest_rejected);
  EXPECT_GT(accepted, 100);
  EXPECT_GT(rejected, 100);
}

TEST(Misuse, EveryPassRejectsAMismatchedOrSwappedFrame) {
  FOGCL_REQUIRE_DEVICE();
  const TestFrame t = make_test_frame(64, 36, false, ColorFormat::rgba32f, 3);
  PerspectiveCamera wide;  // 16:9 (the default) on a square frame
  const CameraParams wide_params = make_camera_params(wide);
  const ColorImage square(64, 64);
  const DepthImage square_depth(64, 64, 0.5f);
  FogSettings fog;
  ColorImage out(3, 3);
  const std::string e1 = error_of([&] { shared_pass().apply(square, square_depth, out, wide_params, fog); });
  EXPECT_TRUE(contains(e1, "camera aspect 1.77") && contains(e1, "64x64")) << e1;
  EXPECT_EQ(out.width(), 3) << "a rejected call must leave its output as it was";
  // The frame transposed (36x64) for the camera of a 64x36 one.
  const ColorImage swapped(36, 64);
  const DepthImage swapped_depth(36, 64, 0.5f);
  const std::string e2 = error_of([&] { shared_pass().apply(swapped, swapped_depth, out, t.params, fog); });
  EXPECT_TRUE(contains(e2, "width and height swapped")) << e2;
  std::string e3 = error_of([&] { apply_fog_scalar(swapped, swapped_depth, out, t.params, fog); });
  EXPECT_TRUE(contains(e3, "width and height swapped")) << e3;
  VolumePass volumes(*runtime(), shared_pass().program_cache());
  const VolumeTestScene s = volume_test_scene(48, 27);
  const std::string e4 =
      error_of([&] { volumes.apply(square, square_depth, out, s.frame.params, s.scene, VolumeSettings{}); });
  EXPECT_TRUE(contains(e4, "camera aspect")) << e4;
  const std::string e5 = error_of(
      [&] { apply_volumes_scalar(square, square_depth, out, s.frame.params, s.scene, VolumeSettings{}); });
  EXPECT_TRUE(contains(e5, "camera aspect")) << e5;
  // Stated on purpose, the same call runs.
  CameraParams opted = wide_params;
  opted.non_square_pixels = true;
  EXPECT_EQ(error_of([&] { shared_pass().apply(square, square_depth, out, opted, fog); }), "");
  std::printf("%s\n%s\n", e1.c_str(), e2.c_str());
}

TEST(Misuse, AMovedFromPassIsAnError) {
  FOGCL_REQUIRE_DEVICE();
  const TestFrame t = make_test_frame(16, 9, false, ColorFormat::rgba32f, 4);
  FogPass a(*runtime(), {}, shared_pass().program_cache());
  FogPass b = std::move(a);
  ColorImage out;
  const std::string e = error_of([&] { a.apply(t.color, t.depth, out, t.params, FogSettings{}); });  // NOLINT
  EXPECT_TRUE(contains(e, "FogPass used after move")) << e;
  EXPECT_TRUE(contains(error_of([&] { a.stats(); }), "FogPass used after move"));                       // NOLINT
  EXPECT_TRUE(contains(error_of([&] { a.prepare(Variant{}); }), "FogPass used after move"));            // NOLINT
  EXPECT_EQ(error_of([&] { b.apply(t.color, t.depth, out, t.params, FogSettings{}); }), "");
  a = std::move(b);  // assigned again, it works
  EXPECT_EQ(error_of([&] { a.apply(t.color, t.depth, out, t.params, FogSettings{}); }), "");  // NOLINT
  VolumePass v(*runtime(), shared_pass().program_cache());
  VolumePass w = std::move(v);
  const VolumeTestScene s = volume_test_scene(16, 9);
  const std::string ev = error_of([&] { v.apply(s.frame.color, s.frame.depth, out, s.frame.params, s.scene, {}); });  // NOLINT
  EXPECT_TRUE(contains(ev, "VolumePass used after move")) << ev;
  std::printf("%s\n%s\n", e.c_str(), ev.c_str());
}

TEST(Misuse, PixelAccessOutOfRangeIsAnError) {
  ColorImage c(5, 3, ColorFormat::rgba16f);
  DepthImage d(5, 3);
  const DepthImage& cd = d;
  for (const auto& xy : std::initializer_list<std::pair<int, int>>{{5, 0}, {0, 3}, {-1, 0}, {0, -1}, {1000000, 2}}) {
    const int x = xy.first, y = xy.second;  // not a structured binding: the lambdas capture them
    EXPECT_TRUE(contains(error_of([&] { c.pixel(x, y); }), "outside the 5x3 image"));
    EXPECT_TRUE(contains(error_of([&] { c.set_pixel(x, y, glm::vec4(1.0f)); }), "outside the 5x3 image"));
    EXPECT_TRUE(contains(error_of([&] { d.at(x, y) = 1.0f; }), "outside the 5x3 image"));
    EXPECT_TRUE(contains(error_of([&] { (void)cd.at(x, y); }), "outside the 5x3 image"));
  }
  c.set_pixel(4, 2, glm::vec4(0.5f));
  EXPECT_EQ(c.pixel(4, 2), glm::vec4(0.5f));
  std::printf("%s\n", error_of([&] { c.pixel(5, 0); }).c_str());
}

TEST(Misuse, ANullEventInAWaitListIsAnError) {
  FOGCL_REQUIRE_DEVICE();
  const TestFrame t = make_test_frame(16, 9, false, ColorFormat::rgba32f, 5);
  const cl::Context ctx(runtime()->context(), true);
  cl::Buffer color(ctx, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, t.color.size_bytes(), const_cast<void*>(t.color.data()));
  cl::Buffer depth(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, t.depth.size_bytes(), const_cast<float*>(t.depth.data()));
  FrameBuffers fb{color(), depth(), color(), 16, 9, ColorFormat::rgba32f};
  FogSettings fog;
  shared_pass().prepare(fog, t.params, ColorFormat::rgba32f);
  cl::UserEvent ready(ctx);
  const std::string e = error_of([&] { shared_pass().enqueue(runtime()->queue(), fb, t.params, fog, {ready(), nullptr}); });
  EXPECT_TRUE(contains(e, "wait_list[1] is a null event")) << e;
  VolumePass volumes(*runtime(), shared_pass().program_cache());
  const VolumeTestScene s = volume_test_scene(16, 9);
  const std::string ev = error_of(
      [&] { volumes.enqueue(runtime()->queue(), fb, s.frame.params, s.scene, VolumeSettings{}, nullptr, {nullptr}); });
  EXPECT_TRUE(contains(ev, "wait_list[0] is a null event")) << ev;
  ready.setStatus(CL_COMPLETE);
  std::printf("%s\n", e.c_str());
}

TEST(Misuse, AnImageTooLargeForHostMemoryIsAnError) {
  // 2^21 x 2^21 RGBA32F: 64 TiB, more than any host here; the message names the image and its
  // bytes. It is refused before it is allocated: where Linux overcommits, the allocation would
  // succeed and the process be killed when its pages are touched.
  const std::string e = error_of([] { ColorImage huge(1 << 21, 1 << 21); });
  EXPECT_TRUE(contains(e, "color image 2097152x2097152 rgba32f: cannot allocate 70368744177664 bytes")) << e;
#if defined(__linux__)
  EXPECT_TRUE(contains(e, "bytes of memory and swap")) << e;
#endif
  const std::string ed = error_of([] { DepthImage huge(1 << 21, 1 << 21); });
  EXPECT_TRUE(contains(ed, "depth image 2097152x2097152: cannot allocate")) << ed;
  const std::string eo = error_of([] { ColorImage huge(std::numeric_limits<int>::max(), std::numeric_limits<int>::max()); });
  EXPECT_TRUE(contains(eo, "2147483647x2147483647")) << eo;
  std::printf("%s\n%s\n", e.c_str(), eo.c_str());
}

TEST(Misuse, ExternalStorageWithoutAnOwnerIsNotFreed) {
  // Memory from elsewhere with no owner to keep alive: the storage must not free it.
  alignas(64) static std::byte memory[64 * 16];
  {
    const ColorImage image(8, 8, ColorFormat::rgba32f,
                           detail::AlignedBytes(memory, sizeof memory, std::shared_ptr<void>()));
    EXPECT_EQ(image.data(), memory);
  }
  memory[0] = std::byte{1};  // still ours
  EXPECT_EQ(memory[0], std::byte{1});
}

}  // namespace
}  // namespace fogcl::test
