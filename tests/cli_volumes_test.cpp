// `fogcl apply --volumes` on real files: the CLI's output against the library's VolumePass (and
// scalar path) on the same inputs, and bad volume input: one line naming the value, exit 1, no file.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "fogcl/demo_scene.h"
#include "fogcl/exr_io.h"
#include "fogcl/volume_pass.h"
#include "fogcl/volume_scalar.h"
#include "fogcl/volumes_json.h"
#include "test_support.h"

namespace fogcl::test {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 64, kHeight = 36;

// The volumes of the test scene, as FogVolume and as the JSON text the CLI reads (written by hand
// from the same numbers, so the parser is checked, not a writer's round trip).
std::vector<FogVolume> test_volumes() {
  FogVolume around;  // the camera is inside
  around.center = glm::vec3(0.5f, 1.5f, -4.0f);
  around.radius = 5.0f;
  around.density = 0.6f;
  around.fade_edge = 2.0f;
  around.proximity_fade = 1.0f;
  around.tiling = glm::vec3(0.2f);
  around.detail_tiling = glm::vec3(0.5f);
  FogVolume behind = around;  // behind the (2.2, 1, -0.5) sphere
  behind.center = glm::vec3(3.0f, 1.5f, 3.0f);
  behind.radius = 3.0f;
  behind.density = 1.0f;
  behind.fog_color = glm::vec4(0.9f, 0.8f, 0.7f, 1.0f);
  FogVolume ground = around;  // crossing the ground, no noise, with physical-only keys
  ground.center = glm::vec3(-5.0f, 0.0f, 12.0f);
  ground.radius = 6.0f;
  ground.max_y = 3.0f;
  ground.fade_y = 1.0f;
  ground.density = 0.8f;
  ground.noise = false;
  ground.fog_color = glm::vec4(0.7f, 0.8f, 1.0f, 0.5f);
  ground.albedo = glm::vec3(0.9f, 0.9f, 0.95f);
  ground.anisotropy = 0.3f;
  ground.ambient = glm::vec3(0.05f, 0.06f, 0.08f);
  return {around, behind, ground};
}

const char* kVolumesJson = R"({
  "volumes": [
    {"center": [0.5, 1.5, -4], "radius": 5, "density": 0.6, "fade_edge": 2, "proximity_fade": 1,
     "tiling": [0.2, 0.2, 0.2], "detail_tiling": [0.5, 0.5, 0.5]},
    {"center": [3, 1.5, 3], "radius": 3, "density": 1.0, "fade_edge": 2, "proximity_fade": 1,
     "tiling": [0.2, 0.2, 0.2], "detail_tiling": [0.5, 0.5, 0.5], "fog_color": [0.9, 0.8, 0.7]},
    {"center": [-5, 0, 12], "radius": 6, "density": 0.8, "fade_edge": 2, "proximity_fade": 1,
     "tiling": [0.2, 0.2, 0.2], "detail_tiling": [0.5, 0.5, 0.5], "max_y": 3, "fade_y": 1,
     "noise": false, "fog_color": [0.7, 0.8, 1.0, 0.5], "albedo": [0.9, 0.9, 0.95], "anisotropy": 0.3,
     "ambient": [0.05, 0.06, 0.08]}
  ]
})";

class CliVolumes : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // One folder per process: ctest runs each test in its own process, in parallel.
    dir_ = fresh_dir("cli-volumes");
    frame_ = new DemoFrame(write_demo_scene(dir_, kWidth, kHeight));
    write_text(in("volumes.json"), kVolumesJson);
    shadow_ = new ShadowMap(render_demo_shadow_map(128, 128));
    write_exr_depth(in("shadow.exr"), shadow_->depth);
    std::ostringstream m;
    m.precision(9);
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) m << (r + c > 0 ? "," : "") << shadow_->params.world_to_light_clip[c][r];
    matrix_ = m.str();
  }
  static void TearDownTestSuite() {
    delete frame_;
    delete shadow_;
  }
  static std::string in(const std::string& name) { return dir_ + "/" + name; }

  // The library's view of the same run.
  static VolumeScene scene() {
    VolumeScene s;
    s.volumes = test_volumes();
    const DemoView view;
    s.pose.eye = view.eye;
    s.pose.forward = view.target - view.eye;
    s.pose.up = glm::vec3(0.0f, 1.0f, 0.0f);
    s.light = demo_light();
    return s;
  }
  // The CLI arguments of scene(): the files, the camera (as render_demo_scene's), pose and light;
  // `change` replaces a flag's value ("" leaves the flag out).
  static std::string base_args(const std::map<std::string, std::string>& change = {}) {
    const VolumeScene s = scene();
    std::map<std::string, std::string> flags{{"--color", in("scene.exr")},
                                             {"--depth", in("scene-depth.exr")},
                                             {"--near", "0.3"},
                                             {"--far", "1000"},
                                             {"--fov", "60"},
                                             {"--volumes", in("volumes.json")},
                                             {"--eye", vec3_text(s.pose.eye)},
                                             {"--forward", vec3_text(s.pose.forward)},
                                             {"--up", vec3_text(s.pose.up)},
                                             {"--light-dir", vec3_text(s.light.direction)},
                                             {"--light-color", vec3_text(s.light.color)}};
    for (const auto& [flag, value] : change) flags[flag] = value;
    std::string args = "apply";
    for (const auto& [flag, value] : flags)
      if (!value.empty()) args += " " + flag + " " + value;
    return args;
  }
  // The CLI run must succeed; returns its output image.
  static ColorImage run_ok(const std::string& args, const std::string& out_name, std::string* output = nullptr) {
    const std::string out = in(out_name);
    fs::remove(out);
    const CliRun r = run_cli(args + " --out " + out);
    EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.output;
    if (output) *output = r.output;
    if (r.exit_code != 0) return ColorImage();
    return read_exr_color(out);
  }

  static inline std::string dir_, matrix_;
  static inline DemoFrame* frame_ = nullptr;
  static inline ShadowMap* shadow_ = nullptr;
};

TEST_F(CliVolumes, ScalarPathEqualsTheLibraryBitForBit) {
  const ColorImage got = run_ok(base_args() + " --device scalar", "scalar.exr");
  ASSERT_GT(got.width(), 0);
  const VolumeScene s = scene();
  ColorImage want;
  apply_volumes_scalar(frame_->color, frame_->depth, want, frame_->params, s, VolumeSettings{});
  const VolumeResult<double> ref =
      volumes_scalar<double>(frame_->color, frame_->depth, frame_->params, s, VolumeSettings{});
  const std::size_t diff = differing_floats(got, want);
  std::printf(
      "[ measured ] CLI --device scalar vs apply_volumes_scalar: %zu differing floats; vs double: max %.3g "
      "(%zu volumes visible)\n",
      diff, max_abs_rgb_error(got, ref), ref.visible);
  EXPECT_EQ(diff, 0u);
  EXPECT_EQ(ref.visible, 3u);
  EXPECT_LE(max_abs_rgb_error(got, ref), 1e-4);
}

// VOLUMES.json's "lights" reach the pass: the CLI's image is the library's with the same lights,
// bit for bit, and differs from the one without them; the stylized integrator refuses them.
TEST_F(CliVolumes, LightsInTheFileReachThePass) {
  LocalLight lamp;
  lamp.position = {2.0f, 1.5f, 2.0f};
  lamp.color = {1.0f, 0.7f, 0.4f};
  lamp.intensity = 30.0f;
  lamp.range = 6.0f;
  LocalLight spot = lamp;
  spot.kind = LightKind::spot;
  spot.position = {-4.0f, 5.0f, 11.0f};
  spot.direction = {0.0f, -1.0f, 0.1f};
  spot.inner_angle = 10.0f;
  spot.outer_angle = 30.0f;
  write_text(in("lights.json"), volumes_to_json(test_volumes(), {lamp, spot}));
  const std::string args = base_args({{"--volumes", in("lights.json")}}) + " --device scalar --integrator physical";
  const ColorImage got = run_ok(args, "lights.exr");
  ASSERT_GT(got.width(), 0);
  VolumeScene s = scene();
  s.lights = {lamp, spot};
  VolumeSettings physical;
  physical.integrator = VolumeIntegrator::physical;
  ColorImage want, dark;
  apply_volumes_scalar(frame_->color, frame_->depth, want, frame_->params, s, physical);
  s.lights.clear();
  apply_volumes_scalar(frame_->color, frame_->depth, dark, frame_->params, s, physical);
  const std::size_t diff = differing_floats(got, want), lit = differing_floats(got, dark);
  std::printf("[ measured ] CLI with 2 lights vs the library: %zu differing floats; %zu floats lit by them\n", diff, lit);
  EXPECT_EQ(diff, 0u);
  EXPECT_GT(lit, 0u);
  const CliRun r = run_cli(base_args({{"--volumes", in("lights.json")}}) + " --device scalar --out " + in("no.exr"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_MSG_HAS(r.output, "fogcl: error: ");
  EXPECT_MSG_HAS(r.output, "local lights need the physical integrator (got stylized, with 2 lights)");
}

TEST_F(CliVolumes, OpenCLPathEqualsVolumePassBitForBit) {
  FOGCL_REQUIRE_DEVICE();
  std::string output;
  const ColorImage got = run_ok(base_args() + " --device " + cli_device() + " --verbose", "opencl.exr", &output);
  ASSERT_GT(got.width(), 0);
  const VolumeScene s = scene();
  VolumePass pass(*runtime());
  ColorImage want;
  pass.apply(frame_->color, frame_->depth, want, frame_->params, s, VolumeSettings{});
  const VolumeResult<double> ref =
      volumes_scalar<double>(frame_->color, frame_->depth, frame_->params, s, VolumeSettings{});
  const std::size_t diff = differing_floats(got, want);
  std::printf("[ measured ] CLI --device (the tests' device) vs VolumePass::apply: %zu differing floats; vs double: max %.3g\n", diff,
              max_abs_rgb_error(got, ref));
  EXPECT_EQ(diff, 0u);
  EXPECT_LE(max_abs_rgb_error(got, ref), 1e-4);
  // --verbose names the variant.
  for (const char* part :
       {"volumes: 3 of 3 visible", "stylized integrator", "50 steps", "half resolution (32x18 target)",
        "depth-aware upsampling", "march build options: ", "composite build options: "})
    EXPECT_MSG_HAS(output, part);
  // The default --noise-sampling auto, as the device resolves it.
  EXPECT_MSG_HAS(output, std::string(to_string(pass.noise_sampling())) + " sampling");
  EXPECT_MSG_HAS(output, pass.last_march_options());

  // --noise-sampling image: the noise as an OpenCL 3D image with the sampler's filtering.
  const ColorImage image = run_ok(base_args() + " --device " + cli_device() + " --noise-sampling image --verbose", "image.exr", &output);
  VolumeSettings st;
  st.noise_sampling = NoiseSampling::image;
  pass.apply(frame_->color, frame_->depth, want, frame_->params, s, st);
  const std::size_t image_diff = differing_floats(image, want);
  std::printf(
      "[ measured ] CLI --noise-sampling image vs VolumePass::apply: %zu differing floats; vs double: max %.3g\n",
      image_diff, max_abs_rgb_error(image, ref));
  EXPECT_EQ(image_diff, 0u);
  EXPECT_MSG_HAS(output, "image sampling");
  EXPECT_MSG_HAS(output, pass.last_march_options());
}

// Every quality flag reaches the pass: the CLI equals the library with the same settings, and
// those settings change the picture (so an ignored flag would fail the first check).
TEST_F(CliVolumes, EveryFlagReachesThePass) {
  const bool cl = runtime() != nullptr;
  const std::string args = base_args() + " --device " + (cl ? cli_device() : std::string("scalar")) +
                           " --integrator physical --steps 12 --volume-resolution quarter --upsample bilinear"
                           " --noise-size 32 --noise-seed 7 --time 1.5 --frame 3 --shadow-map " +
                           in("shadow.exr") + " --light-view-proj " + matrix_;
  const ColorImage got = run_ok(args, "flags.exr");
  ASSERT_GT(got.width(), 0);
  VolumeScene s = scene();
  s.time = 1.5f;
  s.frame_index = 3;
  VolumeSettings st;
  st.integrator = VolumeIntegrator::physical;
  st.steps = 12;
  st.resolution_divisor = 4;
  st.upsampling = VolumeUpsampling::bilinear;
  st.noise_size = 32;
  st.noise_seed = 7;
  ShadowMap sm = *shadow_;
  sm.depth = read_exr_depth(in("shadow.exr"));
  ColorImage want, plain;
  if (cl) {
    VolumePass pass(*runtime());
    pass.apply(frame_->color, frame_->depth, want, frame_->params, s, st, &sm);
  } else {
    apply_volumes_scalar(frame_->color, frame_->depth, want, frame_->params, s, st, &sm);
  }
  apply_volumes_scalar(frame_->color, frame_->depth, plain, frame_->params, scene(), VolumeSettings{});
  const std::size_t diff = differing_floats(got, want), from_default = differing_floats(got, plain);
  std::printf(
      "[ measured ] CLI with every volume flag vs the library: %zu differing floats; vs default settings: %zu\n", diff,
      from_default);
  EXPECT_EQ(diff, 0u);
  EXPECT_GT(from_default, 100u);
  // Each setting alone changes the picture (with the others at the CLI's values).
  const VolumeResult<float> all = volumes_scalar<float>(frame_->color, frame_->depth, frame_->params, s, st, &sm);
  const auto changed = [&](VolumeScene s2, VolumeSettings st2, const ShadowMap* sm2) {
    const VolumeResult<float> r = volumes_scalar<float>(frame_->color, frame_->depth, frame_->params, s2, st2, sm2);
    return r.rgba != all.rgba;
  };
  VolumeScene s2 = s;
  s2.time = 0;
  EXPECT_TRUE(changed(s2, st, &sm)) << "--time";
  s2 = s;
  s2.frame_index = 0;
  EXPECT_TRUE(changed(s2, st, &sm)) << "--frame";
  VolumeSettings st2 = st;
  st2.steps = 50;
  EXPECT_TRUE(changed(s, st2, &sm)) << "--steps";
  st2 = st, st2.noise_seed = 1;
  EXPECT_TRUE(changed(s, st2, &sm)) << "--noise-seed";
  st2 = st, st2.noise_size = 64;
  EXPECT_TRUE(changed(s, st2, &sm)) << "--noise-size";
  st2 = st, st2.upsampling = VolumeUpsampling::depth_aware;
  EXPECT_TRUE(changed(s, st2, &sm)) << "--upsample";
  EXPECT_TRUE(changed(s, st, nullptr)) << "--shadow-map";
}

TEST_F(CliVolumes, ModeOffLeavesUnfoggedPixelsBitIdentical) {
  // The volumes behind the sphere and on the ground: the camera is outside both.
  const std::string json = kVolumesJson;
  write_text(in("outside.json"), "{\"volumes\": [" + json.substr(json.find("{\"center\": [3,")));
  std::string output;
  const ColorImage got = run_ok(base_args({{"--volumes", in("outside.json")}}) + " --mode off --device scalar --verbose",
                                "off.exr", &output);
  ASSERT_GT(got.width(), 0);
  EXPECT_NE(output.find("no deferred fog pass (fog off or density 0): the output is the volumes' result"),
            std::string::npos) << output;
  EXPECT_EQ(output.find("no pass runs"), std::string::npos) << output;
  VolumeScene s = scene();
  s.volumes.erase(s.volumes.begin());
  const VolumeResult<double> ref =
      volumes_scalar<double>(frame_->color, frame_->depth, frame_->params, s, VolumeSettings{});
  std::size_t untouched = 0, same = 0, changed = 0;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const bool equal = std::memcmp(&got.rgba32f()[4 * (y * kWidth + x)],
                                     &frame_->color.rgba32f()[4 * (y * kWidth + x)], 4 * sizeof(float)) == 0;
      if (ref.coverage[std::size_t(y) * kWidth + x] == 0) {
        ++untouched;
        same += equal;
      } else {
        changed += !equal;
      }
    }
  std::printf(
      "[ measured ] --mode off --volumes: %zu of %zu pixels the fog does not reach, %zu of them bit-identical; "
      "%zu fogged pixels changed\n",
      untouched, std::size_t(kWidth * kHeight), same, changed);
  EXPECT_GT(untouched, 0u);
  EXPECT_EQ(same, untouched);
  EXPECT_GT(changed, 100u);
}

TEST_F(CliVolumes, VolumesThenDeferredFogEqualsTheLibrary) {
  const std::string fog = " --mode exp2 --density 0.03 --distance --fog-color 0.6,0.7,0.8";
  const ColorImage got = run_ok(base_args() + fog + " --device scalar", "both.exr");
  ASSERT_GT(got.width(), 0);
  ColorImage want;
  apply_volumes_scalar(frame_->color, frame_->depth, want, frame_->params, scene(), VolumeSettings{});
  FogSettings f;
  f.mode = FogMode::exp2;
  f.density = 0.03f;
  f.metric = FogMetric::distance;
  f.color = glm::vec3(0.6f, 0.7f, 0.8f);
  apply_fog_scalar(want, frame_->depth, want, frame_->params, f);
  const std::size_t diff = differing_floats(got, want);
  std::printf("[ measured ] CLI volumes + exp2 vs the library's volumes then deferred fog: %zu differing floats\n",
              diff);
  EXPECT_EQ(diff, 0u);
  // Without --mode the deferred fog stays off: the volumes alone.
  const ColorImage alone = run_ok(base_args() + " --device scalar", "alone.exr");
  ColorImage volumes_only;
  apply_volumes_scalar(frame_->color, frame_->depth, volumes_only, frame_->params, scene(), VolumeSettings{});
  EXPECT_EQ(differing_floats(alone, volumes_only), 0u);
  EXPECT_GT(differing_floats(got, volumes_only), 100u);
}

// Sequences: --frame defaults to the frame number and --time to frame / --fps; explicit values win.
TEST_F(CliVolumes, SequencesScrollTheNoiseAndChangeTheJitter) {
  for (int f : {1, 2}) {
    fs::copy_file(in("scene.exr"), in("seq." + std::to_string(f) + ".exr"), fs::copy_options::overwrite_existing);
    fs::copy_file(in("scene-depth.exr"), in("seqz." + std::to_string(f) + ".exr"),
                  fs::copy_options::overwrite_existing);
  }
  const std::string args =
      base_args({{"--color", in("seq.#.exr")}, {"--depth", in("seqz.#.exr")}}) + " --device scalar --fps 10";
  const CliRun r = run_cli(args + " --out " + in("seqout.#.exr"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const CliRun fixed = run_cli(args + " --frame 5 --time 0.25 --out " + in("seqfix.#.exr"));
  ASSERT_EQ(fixed.exit_code, 0) << fixed.output;
  for (int f : {1, 2}) {
    VolumeScene s = scene();
    s.frame_index = std::uint32_t(f);
    s.time = float(f / 10.0);
    ColorImage want;
    apply_volumes_scalar(frame_->color, frame_->depth, want, frame_->params, s, VolumeSettings{});
    const std::size_t diff = differing_floats(read_exr_color(in("seqout." + std::to_string(f) + ".exr")), want);
    s.frame_index = 5;
    s.time = 0.25f;
    apply_volumes_scalar(frame_->color, frame_->depth, want, frame_->params, s, VolumeSettings{});
    const std::size_t diff_fixed = differing_floats(read_exr_color(in("seqfix." + std::to_string(f) + ".exr")), want);
    std::printf(
        "[ measured ] sequence frame %d: %zu differing floats (frame %d, time %g); with --frame 5 --time 0.25: %zu\n",
        f, diff, f, f / 10.0, diff_fixed);
    EXPECT_EQ(diff, 0u);
    EXPECT_EQ(diff_fixed, 0u);
  }
  const std::size_t between = differing_floats(read_exr_color(in("seqout.1.exr")), read_exr_color(in("seqout.2.exr")));
  std::printf("[ measured ] frames 1 and 2 differ in %zu floats\n", between);
  EXPECT_GT(between, 100u);
}

// ---- Bad input: one line naming the value, exit 1, no file ------------------------------------

struct BadCase {
  std::string what;                 // the case, for failure messages
  std::string args;                 // appended to the base arguments (or replacing them, see below)
  std::vector<std::string> expect;  // parts the message must contain
  int code = 1;                     // 1 for a value that breaks a rule, 2 for a malformed value or a required flag left out
};

void expect_rejected(const std::string& args, const std::string& out, const BadCase& c) {
  fs::remove(out);
  const CliRun r = run_cli(args + " --out " + out);
  std::printf("[ message  ] %-28s %s", c.what.c_str(), r.output.c_str());
  EXPECT_EQ(r.exit_code, c.code) << c.what << ": " << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << c.what << ": " << r.output;
  for (const std::string& part : c.expect)
    EXPECT_NE(r.output.find(part), std::string::npos) << c.what << ": lacks '" << part << "' in " << r.output;
  EXPECT_FALSE(fs::exists(out)) << c.what;
}

TEST_F(CliVolumes, BadVolumesJsonIsOneLineNamingVolumeKeyAndRule) {
  const std::string ok = R"({"center": [0, 1, 0], "radius": 2})";
  const struct {
    std::string what, json;
    std::vector<std::string> expect;
  } cases[] = {
      {"unknown key",
       R"({"volumes": [)" + ok + R"(, {"center": [0, 1, 0], "radius": 2, "desnity": 0.5}]})",
       {"volume 1", "unknown key 'desnity'", "did you mean 'density'"}},
      {"wrong type",
       R"({"volumes": [{"center": [0, 1, 0], "radius": 2, "density": "thick"}]})",
       {"volume 0", "'density'", "must be a number", "\"thick\""}},
      {"wrong bool type",
       R"({"volumes": [{"center": [0, 1, 0], "radius": 2, "noise": 1}]})",
       {"volume 0", "'noise'", "true or false"}},
      {"short vector",
       R"({"volumes": [{"center": [0, 1], "radius": 2}]})",
       {"volume 0", "'center'", "array of 3 numbers"}},
      {"vector not an array", R"({"volumes": [{"center": 3, "radius": 2}]})", {"volume 0", "'center'", "array of 3"}},
      {"string in a vector",
       R"({"volumes": [{"center": [0, "a", 0], "radius": 2}]})",
       {"volume 0", "'center[1]'", "must be a number"}},
      {"color length",
       R"({"volumes": [{"center": [0, 1, 0], "radius": 2, "fog_color": [1, 1]}]})",
       {"volume 0", "'fog_color'", "3 or 4 numbers"}},
      {"negative radius",
       R"({"volumes": [)" + ok + R"(, {"center": [0, 1, 0], "radius": -2}]})",
       {"volume 1", "'radius'", "must be > 0", "-2"}},
      {"negative density",
       R"({"volumes": [{"center": [0, 1, 0], "radius": 2, "density": -0.1}]})",
       {"volume 0", "'density'", ">= 0", "-0.1"}},
      {"library range",
       R"({"volumes": [{"center": [0, 1, 0], "radius": 2, "fog_cutoff": 1.5}]})",
       {"volume 0", "fog_cutoff", "[0, 1)", "1.5"}},
      {"anisotropy range",
       R"({"volumes": [{"center": [0, 1, 0], "radius": 2, "anisotropy": 1}]})",
       {"volume 0", "anisotropy", "(-1, 1)"}},
      {"inf (overflowing double)",
       R"({"volumes": [)" + ok + R"(, {"center": [0, 1, 0], "radius": 2, "density": 1e999}]})",
       {"volume 1", "'density'", "finite", "1e999"}},
      {"inf in a vector",
       R"({"volumes": [{"center": [0, -1e999, 0], "radius": 2}]})",
       {"volume 0", "'center'", "finite"}},
      {"overflowing float",
       R"({"volumes": [{"center": [0, 1, 0], "radius": 1e39}]})",
       {"volume 0", "'radius'", "finite", "1e+39"}},
      {"NaN literal",
       R"({"volumes": [{"center": [0, 1, 0], "radius": 2, "density": NaN}]})",
       {"malformed JSON", "line 1, column", "invalid literal"}},
      {"missing volumes", R"({})", {"'volumes' is missing"}},
      {"volumes not an array", R"({"volumes": {"center": [0, 1, 0]}})", {"'volumes' must be an array"}},
      {"misspelt volumes", R"({"volume": []})", {"unknown key 'volume'"}},
      {"volume not an object", R"({"volumes": [3]})", {"volume 0", "must be an object"}},
      {"missing center", R"({"volumes": [{"radius": 2}]})", {"volume 0", "'center' is missing"}},
      {"missing radius", R"({"volumes": [{"center": [0, 1, 0]}]})", {"volume 0", "'radius' is missing"}},
      {"duplicate key",
       R"({"volumes": [)" + ok + R"(, {"center": [0, 1, 0], "radius": 2, "radius": 3}]})",
       {"volume 1", "duplicate key 'radius'"}},
      {"malformed JSON",
       "{\"volumes\": [\n  {\"center\": [0, 1, 0], \"radius\": 2,}\n]}",
       {"malformed JSON", "line 2, column"}},
      {"not JSON at all", "volumes = 3", {"malformed JSON", "line 1, column 1"}},
      {"light without a type", R"({"volumes": [], "lights": [{"position": [0, 1, 0]}]})", {"light 0", "'type' is missing"}},
      {"light of an unknown type",
       R"({"volumes": [], "lights": [{"type": "area", "position": [0, 1, 0]}]})",
       {"light 0", "'type'", "\"point\" or \"spot\"", "\"area\""}},
      {"light without a position", R"({"volumes": [], "lights": [{"type": "point"}]})", {"light 0", "'position' is missing"}},
      {"misspelt light key",
       R"({"volumes": [], "lights": [{"type": "point", "position": [0, 1, 0], "intensty": 2}]})",
       {"light 0", "unknown key 'intensty'", "did you mean 'intensity'"}},
      {"cone on a point light",
       R"({"volumes": [], "lights": [{"type": "point", "position": [0, 1, 0], "outer_angle": 30}]})",
       {"light 0", "'outer_angle'", "spot lights only"}},
      {"light's wrong type",
       R"({"volumes": [], "lights": [{"type": "point", "position": [0, 1, 0]}, {"type": "point", "position": [0, 1, 0], "range": "far"}]})",
       {"light 1", "'range'", "must be a number"}},
      {"light range",
       R"({"volumes": [], "lights": [{"type": "point", "position": [0, 1, 0], "range": 0}]})",
       {"light 0", "range", "(0, 1e15]", "got 0"}},
      {"spot cone order",
       R"({"volumes": [], "lights": [{"type": "spot", "position": [0, 1, 0], "inner_angle": 50, "outer_angle": 40}]})",
       {"light 0", "inner_angle", "[0, outer_angle]", "50"}},
      {"light too bright for its radius",
       R"({"volumes": [], "lights": [{"type": "point", "position": [0, 1, 0], "intensity": 1e30, "radius": 1e-3}]})",
       {"light 0", "intensity", "<= 1e30"}},
      {"lights not an array", R"({"volumes": [], "lights": {"type": "point"}})", {"'lights' must be an array"}},
      {"duplicate light key",
       R"({"volumes": [], "lights": [{"type": "point", "position": [0, 1, 0], "position": [0, 2, 0]}]})",
       {"light 0", "duplicate key 'position'"}},
  };
  for (const auto& c : cases) {
    const std::string path = in("bad-volumes.json");
    write_text(path, c.json);
    std::vector<std::string> expect = c.expect;
    expect.push_back(path);  // every message names the file
    expect_rejected(base_args({{"--volumes", path}}) + " --device scalar", in("bad.exr"), {c.what, "", expect});
  }
  const std::string args = base_args({{"--volumes", in("no-such.json")}}) + " --device scalar";
  expect_rejected(args, in("bad.exr"), {"missing file", "", {"no-such.json", "cannot open"}});
}

// The library reads VOLUMES.json as the command line does (fogcl/volumes_json.h): random volumes
// and lights written by volumes_to_json read back as the same floats, and for files made bad by random byte
// changes the CLI's line is "fogcl: error: " and the library's message, word for word.
TEST_F(CliVolumes, TheLibraryReadsVolumesJsonAsTheCommandLineDoes) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const auto unit3 = [&] { return glm::vec3(u(rng), u(rng), u(rng)); };
  int round_trips = 0;
  for (int i = 0; i < 200; ++i) {
    std::vector<FogVolume> volumes = demo_fog_volumes(i % 2 == 0 ? VolumeIntegrator::stylized : VolumeIntegrator::physical);
    for (FogVolume& v : volumes) {
      v.center = 100.0f * unit3() - glm::vec3(50.0f);
      v.radius = 0.01f + 40.0f * u(rng);
      v.density = 8.0f * u(rng);
      v.fog_color = glm::vec4(unit3(), u(rng));
      v.tiling = 0.01f + unit3();
      if (u(rng) < 0.5f) v.albedo = unit3();
    }
    std::vector<LocalLight> lights(std::size_t(i % 4));
    for (LocalLight& l : lights) {
      l.kind = u(rng) < 0.5f ? LightKind::point : LightKind::spot;
      l.position = 100.0f * unit3() - glm::vec3(50.0f);
      l.color = unit3();
      l.intensity = 1000.0f * u(rng);
      l.range = 0.5f + 100.0f * u(rng);
      l.radius = l.range * (0.001f + 0.5f * u(rng));
      l.direction = unit3() - glm::vec3(0.5f, 1.0f, 0.5f);
      l.outer_angle = 1.0f + 89.0f * u(rng);
      l.inner_angle = l.outer_angle * u(rng);
      if (l.kind == LightKind::point) l.direction = LocalLight{}.direction;  // a point light writes no cone
      if (l.kind == LightKind::point) l.inner_angle = LocalLight{}.inner_angle, l.outer_angle = LocalLight{}.outer_angle;
    }
    const std::string path = in("random.json");
    write_text(path, volumes_to_json(volumes, lights));
    const VolumesFile file = read_volumes_file(path);
    const std::vector<FogVolume>& back = file.volumes;
    ASSERT_EQ(file.lights.size(), lights.size());
    for (std::size_t k = 0; k < lights.size(); ++k) {
      const LocalLight &a = file.lights[k], &b = lights[k];
      EXPECT_TRUE(a.kind == b.kind && a.position == b.position && a.color == b.color && a.intensity == b.intensity &&
                  a.range == b.range && a.radius == b.radius && a.direction == b.direction &&
                  a.inner_angle == b.inner_angle && a.outer_angle == b.outer_angle)
          << i << " light " << k;
    }
    if (lights.empty()) EXPECT_EQ(read_volumes_json(path).size(), volumes.size());
    else EXPECT_THROW(read_volumes_json(path), Error) << "the volumes-only reader would drop the lights";
    ASSERT_EQ(back.size(), volumes.size());
    for (std::size_t k = 0; k < back.size(); ++k) {
      EXPECT_EQ(std::memcmp(&back[k].center, &volumes[k].center, sizeof(glm::vec3)), 0) << i;
      EXPECT_EQ(back[k].radius, volumes[k].radius) << i;
      EXPECT_EQ(back[k].density, volumes[k].density) << i;
      EXPECT_EQ(back[k].albedo.has_value(), volumes[k].albedo.has_value()) << i;
    }
    EXPECT_EQ(volumes_to_json(file), volumes_to_json(volumes, lights)) << i;
    ++round_trips;
  }
  int compared = 0;
  const std::string good = volumes_to_json(test_volumes());
  for (int i = 0; compared < 25 && i < 400; ++i) {
    std::string bad = good;
    std::uniform_int_distribution<std::size_t> at(0, bad.size() - 1);
    for (int k = 0; k < 1 + i % 3; ++k) bad[at(rng)] = "{}[],:\"0-e.x\" "[at(rng) % 13];
    const std::string path = in("mutated.json");
    write_text(path, bad);
    std::string library;
    try {
      read_volumes_json(path);
      continue;  // still valid volumes
    } catch (const Error& e) {
      library = e.what();
    }
    const CliRun r = run_cli(base_args({{"--volumes", path}}) + " --device scalar --out " + in("mutated.exr"));
    EXPECT_EQ(r.output, "fogcl: error: " + library + "\n") << bad;
    EXPECT_EQ(r.exit_code, 1);
    ++compared;
  }
  std::printf("[ library  ] %d round trips bit for bit; %d bad files, the CLI's line is the library's message\n",
              round_trips, compared);
  EXPECT_GE(compared, 10);
}

TEST_F(CliVolumes, BadCameraLightAndShadowInputIsOneLineNamingTheValue) {
  // A file that is not an EXR, and an EXR without a depth channel (R, G, B, A).
  write_text(in("not-an-exr.exr"), "this is not an OpenEXR file\n");
  const std::string shadow = " --shadow-map " + in("shadow.exr") + " --light-view-proj ";
  std::string nan_matrix = matrix_, singular;
  nan_matrix.replace(0, nan_matrix.find(','), "nan");                                        // row 0, column 0
  for (int i = 0; i < 16; ++i) singular += std::string(i ? "," : "") + (i < 8 ? "1" : "0");  // rank 1 rows
  // Flags of base_args() given another value.
  const struct {
    std::string what;
    std::map<std::string, std::string> change;
    std::vector<std::string> expect;
    int code = 1;
  } changed[] = {
      {"zero forward", {{"--forward", "0,0,0"}}, {"--forward", "non-zero", "0,0,0"}},
      {"up parallel to forward", {{"--forward", "0,0,1"}, {"--up", "0,0,-2"}}, {"parallel", "(0, 0, -2)", "(0, 0, 1)"}},
      {"zero up", {{"--up", "0,0,0"}}, {"--up", "non-zero"}},
      {"NaN eye", {{"--eye", "0,nan,0"}}, {"--eye", "finite", "0,nan,0"}},
      {"two numbers", {{"--forward", "0,1"}}, {"--forward", "three comma-separated numbers", "0,1"}, 2},
      {"zero light", {{"--light-dir", "0,0,0"}}, {"--light-dir", "non-zero"}},
      {"negative light", {{"--light-color", "1,-1,1"}}, {"--light-color", ">= 0"}},
      {"missing --eye", {{"--eye", ""}}, {"--eye is required with --volumes"}, 2},
      {"missing --forward", {{"--forward", ""}}, {"--forward is required with --volumes"}, 2},
      {"missing --up", {{"--up", ""}}, {"--up is required with --volumes"}, 2},
      {"no mode, no volumes",
       {{"--volumes", ""}, {"--eye", ""}, {"--forward", ""}, {"--up", ""}, {"--light-dir", ""}, {"--light-color", ""}},
       {"--mode is required"},
       2},
      {"volume flag without --volumes", {{"--volumes", ""}, {"--mode", "exp"}}, {"--eye needs --volumes"}},
  };
  for (const auto& c : changed)
    expect_rejected(base_args(c.change) + " --device scalar", in("bad.exr"), {c.what, "", c.expect, c.code});

  const std::string base = base_args() + " --device scalar";
  const BadCase cases[] = {
      {"steps", " --steps 0", {"--steps", "[1, 4096]", "0"}},
      {"noise size", " --noise-size 48", {"--noise-size", "32, 64 or 128", "48"}},
      {"frame", " --frame -1", {"--frame", "-1"}},
      {"fps", " --fps 0", {"--fps", "> 0"}},
      {"time", " --time inf", {"--time", "finite"}},
      {"light matrix NaN", shadow + nan_matrix, {"--light-view-proj", "row 0, column 0", "finite", "nan"}},
      {"light matrix singular", shadow + singular, {"--light-view-proj", "singular", "determinant"}},
      {"light matrix 15 numbers",
       shadow + matrix_.substr(0, matrix_.rfind(',')),
       {"--light-view-proj", "16", "got 15"},
       2},
      {"light matrix word",
       shadow + "a" + matrix_.substr(matrix_.find(',')),
       {"--light-view-proj", "element 0", "'a'"},
       2},
      {"shadow map unreadable",
       " --shadow-map " + in("not-an-exr.exr") + " --light-view-proj " + matrix_,
       {"--shadow-map", "not-an-exr.exr"}},
      {"shadow map missing",
       " --shadow-map " + in("none.exr") + " --light-view-proj " + matrix_,
       {"--shadow-map", "none.exr"}},
      {"shadow map without depth",
       " --shadow-map " + in("scene.exr") + " --light-view-proj " + matrix_,
       {"--shadow-map", "scene.exr", "Z"}},
      {"shadow map without matrix", " --shadow-map " + in("shadow.exr"), {"--shadow-map needs --light-view-proj"}},
      {"matrix without shadow map", " --light-view-proj " + matrix_, {"--light-view-proj needs --shadow-map"}},
  };
  for (const BadCase& c : cases) expect_rejected(base + c.args, in("bad.exr"), c);
}

TEST_F(CliVolumes, HelpDocumentsEveryVolumeFlag) {
  const CliRun r = run_cli("apply --help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* flag :
       {"--volumes", "--eye", "--forward", "--up", "--light-dir", "--light-color", "--time", "--frame", "--fps",
        "--integrator", "--steps", "--volume-resolution", "--upsample", "--noise-size", "--noise-seed",
        "--noise-sampling", "--shadow-map", "--light-view-proj", "--shadow-reversed-z"})
    EXPECT_NE(r.output.find(flag), std::string::npos) << flag;
}

}  // namespace
}  // namespace fogcl::test
