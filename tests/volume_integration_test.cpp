// The volumetric pass's integration API (the caller's queue and buffers, wait list in, event out),
// the host-side culling, and nothing visible = no dispatch and the input bit for bit.
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "runtime/host_staging.h"
#include "volume/volume_formulas.h"
#include "volume/volume_params.h"
#include "volume_support.h"

namespace fogcl::test {
namespace {

class VolumeIntegration : public ::testing::Test {
 protected:
  void SetUp() override {
    FOGCL_REQUIRE_DEVICE();
    ctx = wrap(runtime()->context());
    queue = cl::CommandQueue(ctx, wrap(runtime()->device()));
    t = volume_test_scene(80, 45);
    settings.steps = 16;
  }
  // Buffers the test keeps alive; FrameBuffers borrows their handles.
  FrameBuffers buffers(bool in_place) {
    color_in = cl::Buffer(ctx, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, t.frame.color.size_bytes(),
                          const_cast<void*>(t.frame.color.data()));
    depth = cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, t.frame.depth.size_bytes(),
                       const_cast<float*>(t.frame.depth.data()));
    color_out = in_place ? color_in : cl::Buffer(ctx, CL_MEM_READ_WRITE, t.frame.color.size_bytes());
    FrameBuffers fb;
    fb.width = t.frame.color.width();
    fb.height = t.frame.color.height();
    fb.color_in = color_in();
    fb.depth = depth();
    fb.color_out = color_out();
    return fb;
  }
  ColorImage read(cl_mem b) {
    ColorImage out(t.frame.color.width(), t.frame.color.height());
    queue.enqueueReadBuffer(wrap(b), CL_TRUE, 0, out.size_bytes(), out.data());
    return out;
  }
  cl::Buffer color_in, depth, color_out;
  cl::Context ctx;
  cl::CommandQueue queue;
  VolumeTestScene t;
  VolumeSettings settings;
};

TEST_F(VolumeIntegration, WaitsOnCallerEventsNeverBlocksAndMatchesTheConvenienceApi) {
  VolumePass pass(ctx(), runtime()->device());
  const FrameBuffers fb = buffers(false);
  // enqueue never builds: an unprepared variant is an error that says what to call.
  EXPECT_MSG_HAS(error_of([&] { pass.enqueue(queue(), fb, t.frame.params, t.scene, settings); }),
                 "is not prepared: call VolumePass::prepare");
  pass.prepare(t.frame.params, t.scene, settings, ColorFormat::rgba32f);
  cl::UserEvent gate(ctx);
  // A hidden finish inside enqueue would hang here: the gate opens only below.
  const cl::Event done = adopt(pass.enqueue(queue(), fb, t.frame.params, t.scene, settings, nullptr, {gate()}));
  EXPECT_NE(done.getInfo<CL_EVENT_COMMAND_EXECUTION_STATUS>(), CL_COMPLETE);
  EXPECT_EQ(pass.stats().march_dispatches, 1u);
  EXPECT_EQ(pass.stats().composite_dispatches, 1u);
  gate.setStatus(CL_COMPLETE);
  done.wait();
  const ColorImage got = read(fb.color_out);
  ColorImage expected;
  VolumePass(*runtime()).apply(t.frame.color, t.frame.depth, expected, t.frame.params, t.scene, settings);
  EXPECT_EQ(std::memcmp(got.data(), expected.data(), got.size_bytes()), 0);
  // In place gives the same bytes.
  const FrameBuffers in_place = buffers(true);
  adopt(pass.enqueue(queue(), in_place, t.frame.params, t.scene, settings)).wait();
  const ColorImage got_in_place = read(in_place.color_out);
  EXPECT_EQ(std::memcmp(got_in_place.data(), expected.data(), got.size_bytes()), 0);
  EXPECT_EQ(pass.stats().noise_uploads, 1u) << "the noise texture is uploaded once and reused";
}

// The pass keeps its per-frame device scratch (constants, low-resolution march output) across
// frames: frames in flight at once (more than the pool's sets, at two resolutions, with
// different volumes) each get their own, and every output is what a fresh convenience call gives.
TEST_F(VolumeIntegration, FramesInFlightKeepTheirOwnScratch) {
  VolumePass pass(ctx(), runtime()->device());
  constexpr int kFrames = 7;
  std::vector<VolumeScene> scenes;
  std::vector<VolumeSettings> frame_settings;
  for (int i = 0; i < kFrames; ++i) {
    VolumeScene sc = t.scene;
    for (FogVolume& v : sc.volumes) {
      v.center += glm::vec3(0.3f * float(i), 0.0f, 0.0f);
      v.density *= 1.0f + 0.25f * float(i);
    }
    if (i % 3 == 2) sc.volumes.pop_back();  // fewer constants
    VolumeSettings st = settings;
    st.resolution_divisor = i % 2 == 0 ? 2 : 1;
    pass.prepare(t.frame.params, sc, st, ColorFormat::rgba32f);
    scenes.push_back(sc);
    frame_settings.push_back(st);
  }
  const FrameBuffers fb = buffers(false);
  VolumePass reference(*runtime());  // convenience calls, one frame at a time
  std::vector<cl::Buffer> outs;
  std::vector<cl::Event> done;
  for (int round = 0; round < 2; ++round) {  // all in flight behind a gate, then one at a time
    outs.clear();
    done.clear();
    cl::UserEvent gate(ctx);
    for (int i = 0; i < kFrames; ++i) {
      outs.emplace_back(ctx, CL_MEM_READ_WRITE, t.frame.color.size_bytes());
      FrameBuffers f = fb;
      f.color_out = outs.back()();
      const std::vector<cl_event> waits = round == 0 ? std::vector<cl_event>{gate()} : std::vector<cl_event>{};
      done.push_back(adopt(pass.enqueue(queue(), f, t.frame.params, scenes[std::size_t(i)],
                                        frame_settings[std::size_t(i)], nullptr, waits)));
      if (round == 1) done.back().wait();
    }
    gate.setStatus(CL_COMPLETE);
    for (int i = 0; i < kFrames; ++i) {
      done[std::size_t(i)].wait();
      ColorImage expected;
      reference.apply(t.frame.color, t.frame.depth, expected, t.frame.params, scenes[std::size_t(i)],
                      frame_settings[std::size_t(i)]);
      const ColorImage got = read(outs[std::size_t(i)]());
      EXPECT_EQ(std::memcmp(got.data(), expected.data(), got.size_bytes()), 0) << "round " << round << ", frame " << i;
    }
  }
  EXPECT_EQ(pass.stats().march_dispatches, 2u * kFrames);
}

TEST_F(VolumeIntegration, NothingVisibleMeansNoDispatchAndTheInputBitForBit) {
  // One volume behind the camera, one far off to the side: the frustum culls both.
  FogVolume behind = t.scene.volumes[0];
  behind.center = t.scene.pose.eye - 20.0f * glm::normalize(t.scene.pose.forward);
  behind.radius = 2.0f;
  FogVolume aside = behind;
  aside.center = t.scene.pose.eye + glm::vec3(300.0f, 0.0f, 50.0f);
  t.scene.volumes = {behind, aside};
  // Some sky and NaN colors: the bits must survive.
  float* c = t.frame.color.rgba32f();
  c[0] = std::numeric_limits<float>::quiet_NaN();
  c[5] = INFINITY;
  VolumePass pass(ctx(), runtime()->device());
  const FrameBuffers fb = buffers(false);
  adopt(pass.enqueue(queue(), fb, t.frame.params, t.scene, settings)).wait();
  EXPECT_EQ(pass.stats().march_dispatches, 0u);
  EXPECT_EQ(pass.stats().frames_without_volumes, 1u);
  EXPECT_EQ(pass.stats().volumes_culled, 2u);
  const ColorImage got = read(fb.color_out);
  EXPECT_EQ(std::memcmp(got.data(), t.frame.color.data(), got.size_bytes()), 0);
  ColorImage out;
  VolumePass convenience(*runtime());
  convenience.apply(t.frame.color, t.frame.depth, out, t.frame.params, t.scene, settings);
  EXPECT_EQ(convenience.stats().march_dispatches, 0u);
  EXPECT_EQ(std::memcmp(out.data(), t.frame.color.data(), out.size_bytes()), 0);
  ColorImage scalar_out;
  apply_volumes_scalar(t.frame.color, t.frame.depth, scalar_out, t.frame.params, t.scene, settings);
  EXPECT_EQ(std::memcmp(scalar_out.data(), t.frame.color.data(), out.size_bytes()), 0);
}

TEST(VolumeCulling, FrustumAndDepthRange) {
  const VolumeTestScene t = volume_test_scene(64, 36);
  VolumeScene s = t.scene;
  FogVolume v;
  v.radius = 1.0f;
  const glm::vec3 eye = s.pose.eye, f = glm::normalize(s.pose.forward);
  const auto visible = [&](glm::vec3 center, float max_eye) {
    v.center = center;
    s.volumes = {v};
    return !visible_volumes(s, t.frame.params, max_eye).empty();
  };
  EXPECT_TRUE(visible(eye + 10.0f * f, INFINITY));
  EXPECT_FALSE(visible(eye - 10.0f * f, INFINITY)) << "behind the camera";
  EXPECT_TRUE(visible(eye + 0.5f * f, INFINITY)) << "the camera inside";
  EXPECT_FALSE(visible(eye + 10.0f * f + glm::vec3(30.0f, 0.0f, 0.0f), INFINITY)) << "off to the right";
  EXPECT_TRUE(visible(eye + 10.0f * f + glm::vec3(6.0f, 0.0f, 0.0f), INFINITY)) << "partly on screen";
  EXPECT_FALSE(visible(eye + 10.0f * f, 5.0f)) << "wholly behind the farthest surface";
  EXPECT_TRUE(visible(eye + 10.0f * f, 9.5f)) << "its front is nearer than the farthest surface";
  EXPECT_TRUE(visible(eye + 500.0f * f, INFINITY)) << "beyond the far plane, against the sky";
  // max_eye_depth: +inf with sky, finite without.
  EXPECT_TRUE(std::isinf(max_eye_depth(t.frame.depth, t.frame.params)));
  DepthImage ground(4, 4, 0.5f);
  EXPECT_LT(max_eye_depth(ground, t.frame.params), t.frame.params.far_plane());
}

// max_eye_depth finds the farthest pixel from the smallest and largest stored values (and NaN):
// the same float as the largest per-pixel eye depth, for every depth kind and projection, on
// values inside and outside the range, sky, nothing written, NaN and +-inf.
TEST(VolumeCulling, MaxEyeDepthIsTheLargestPixelEyeDepth) {
  const float specials[] = {0.0f, -0.0f, 1.0f, -3.0f, 2.0f, 1000.0f, 0.99995f, INFINITY, -INFINITY,
                            std::numeric_limits<float>::quiet_NaN()};
  int cases = 0;
  detail::CopyWorkers workers(4);
  for (int projection = 0; projection < 3; ++projection)
    for (int kind = 0; kind < 3; ++kind)
      for (bool reversed : {false, true}) {
        PerspectiveCamera p;
        p.reversed_z = reversed || projection == 1;
        p.infinite_far = projection == 1;
        OrthographicCamera o;
        o.reversed_z = reversed;
        CameraParams camera = projection == 2 ? make_camera_params(o) : make_camera_params(p);
        if (kind == 2 && projection == 2) continue;  // radial distance is perspective only
        camera.depth_kind = DepthKind(kind);
        for (unsigned seed = 0; seed < 24; ++seed) {
          // Ordinary values of the kind's range, then up to two specials in some frames.
          // The last three frames span four of max_eye_depth's 64K-pixel chunks, a special in the last.
          const bool large = seed >= 21;
          DepthImage depth(large ? 500 : 37, large ? 400 : 5);
          unsigned x = seed * 2654435761u + 1u;
          const float scale = kind == 0 ? 1.0f : 900.0f;
          for (std::size_t i = 0; i < depth.pixel_count(); ++i) {
            x = x * 1664525u + 1013904223u;
            depth.data()[i] = 0.001f + scale * float(x >> 8) / float(1u << 24);
          }
          if (seed % 3 != 0) depth.data()[x % depth.pixel_count()] = specials[seed % 10];
          if (seed % 4 == 1) depth.data()[(x >> 5) % depth.pixel_count()] = specials[(seed / 4) % 10];
          if (large) depth.data()[depth.pixel_count() - 1 - x % 97] = specials[(projection * 3 + kind) % 10];
          float expected = 0.0f;
          for (std::size_t i = 0; i < depth.pixel_count() && expected < INFINITY; ++i) {
            const float e = volume_formulas::vol_eye_depth(
                depth.data()[i], int(camera.projection), camera.reversed_z, int(camera.depth_kind),
                camera.zbuffer_params.x, camera.zbuffer_params.y, camera.near_plane(), camera.far_plane());
            expected = e < INFINITY ? std::fmax(expected, e) : INFINITY;
          }
          const float got = max_eye_depth(depth, camera);
          EXPECT_EQ(std::memcmp(&got, &expected, sizeof got), 0)
              << "projection " << projection << " kind " << kind << " reversed " << reversed << " seed " << seed
              << ": " << got << " against " << expected;
          // The chunks spread over threads (a staged call's scan): the same float.
          const float spread = detail::max_eye_depth(depth, camera, &workers);
          EXPECT_EQ(std::memcmp(&spread, &expected, sizeof spread), 0)
              << "on 4 threads, projection " << projection << " kind " << kind << " reversed " << reversed << " seed "
              << seed << ": " << spread << " against " << expected;
          ++cases;
        }
      }
  std::printf("[ worst    ] max_eye_depth against the per-pixel maximum: %d frames, on one thread and on 4, "
              "every one the same float\n",
              cases);
}

TEST(VolumeValidation, BadInputNamesTheValueAndTheRule) {
  VolumeScene s;
  s.volumes.resize(2);
  s.volumes[1].radius = -1.0f;
  EXPECT_MSG_HAS(error_of([&] { validate(s); }), "volume 1: radius must be finite and > 0 (got -1)");
  s.volumes[1].radius = 1.0f;
  s.volumes[0].density = std::numeric_limits<float>::quiet_NaN();
  EXPECT_MSG_HAS(error_of([&] { validate(s); }), "volume 0: density");
  s.volumes[0].density = 1e20f;  // stiff, but valid
  validate(s);
  s.pose.forward = glm::vec3(0.0f);
  EXPECT_MSG_HAS(error_of([&] { validate(s); }), "camera forward must be a finite non-zero vector");
  s.pose.forward = glm::vec3(0.0f, 2.0f, 0.0f);
  EXPECT_MSG_HAS(error_of([&] { validate(s); }), "must not be parallel to forward");
  ShadowMapParams m;
  m.world_to_light_clip[1][1] = 0.0f;
  EXPECT_MSG_HAS(error_of([&] { validate(m); }), "singular");
  m.world_to_light_clip[1][1] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_MSG_HAS(error_of([&] { validate(m); }), "row 1, column 1) is not finite");
  VolumeSettings settings;
  settings.steps = 0;
  EXPECT_MSG_HAS(error_of([&] { validate(settings); }), "volume steps must be in [1, 4096] (got 0)");
  settings.steps = 50;
  settings.resolution_divisor = 3;
  EXPECT_MSG_HAS(error_of([&] { validate(settings); }), "resolution divisor must be 1 (full), 2 (half) or 4");
}

}  // namespace
}  // namespace fogcl::test
