// `fogcl apply --mode height` on real files: the CLI's output against the library (FogPass and the
// scalar path) bit for bit, the volumes first, and bad input: one line naming the flag and the rule,
// exit 1, no file left.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "fogcl/demo_scene.h"
#include "fogcl/exr_io.h"
#include "fogcl/volume_scalar.h"
#include "test_support.h"

namespace fogcl::test {
namespace {

namespace fs = std::filesystem;

class CliHeight : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fresh_dir("cli-height");
    frame_ = new DemoFrame(write_demo_scene(dir_, 64, 36));
  }
  static void TearDownTestSuite() { delete frame_; }
  static std::string in(const std::string& name) { return dir_ + "/" + name; }

  static CameraPose pose() {
    const DemoView view;
    return CameraPose{view.eye, view.target - view.eye, glm::vec3(0.0f, 1.0f, 0.0f)};
  }
  static std::string files() {
    return "apply --color " + in("scene.exr") + " --depth " + in("scene-depth.exr") + " --near 0.3 --far 1000 --fov 60";
  }
  static std::string pose_flags() {
    const CameraPose p = pose();
    return " --eye " + vec3_text(p.eye) + " --forward " + vec3_text(p.forward) + " --up " + vec3_text(p.up);
  }
  // Every part of the mode at once, as flags and as settings.
  static constexpr const char* kFlags =
      " --mode height --extinction 0.02,0.03,0.05 --inscattering 0.01,0.02,0.04 --height-falloff 0.4 "
      "--base-height 0.5 --start 1 --cutoff 400 --max-opacity 0.9 --fog-color 0.6,0.7,0.8 --fog-skybox "
      "--light-dir 0.3,0.4,1 --sun-color 1.5,1.2,0.9 --sun-exponent 20 --sun-start 2";
  static FogSettings settings() {
    FogSettings s;
    s.mode = FogMode::height;
    s.color = glm::vec3(0.6f, 0.7f, 0.8f);
    s.fog_skybox = true;
    HeightFogSettings& h = s.height;
    h.extinction = glm::vec3(0.02f, 0.03f, 0.05f);
    h.inscattering = glm::vec3(0.01f, 0.02f, 0.04f);
    h.falloff = 0.4f;
    h.base_height = 0.5f;
    h.start = 1.0f;
    h.cutoff = 400.0f;
    h.max_opacity = 0.9f;
    SunLobe sun;
    sun.direction = glm::vec3(0.3f, 0.4f, 1.0f);
    sun.color = glm::vec3(1.5f, 1.2f, 0.9f);
    sun.exponent = 20.0f;
    sun.start = 2.0f;
    h.sun = sun;
    return s;
  }
  static CameraParams camera() {
    CameraParams c = frame_->params;
    c.pose = pose();
    return c;
  }
  static ColorImage run_ok(const std::string& args, const std::string& name) {
    const std::string out = in(name);
    fs::remove(out);
    const CliRun r = run_cli(args + " --out " + out);
    EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.output;
    if (r.exit_code != 0) return ColorImage();
    return read_exr_color(out);
  }

  static inline std::string dir_;
  static inline DemoFrame* frame_ = nullptr;
};

TEST_F(CliHeight, EveryFlagReachesThePassBitForBit) {
  const ColorImage scalar = run_ok(files() + pose_flags() + kFlags + " --device scalar", "scalar.exr");
  ColorImage want;
  apply_fog_scalar(frame_->color, frame_->depth, want, camera(), settings());
  const std::size_t diff = differing_floats(scalar, want);
  std::printf("[ measured ] CLI --mode height (every flag) vs apply_fog_scalar: %zu differing floats\n", diff);
  EXPECT_EQ(diff, 0u);
  // --distance changes nothing: height fog is along the ray.
  EXPECT_EQ(differing_floats(run_ok(files() + pose_flags() + kFlags + " --distance --device scalar", "d.exr"), want), 0u);
  if (runtime() != nullptr && cli_device() != "scalar") {
    const ColorImage device = run_ok(files() + pose_flags() + kFlags + " --device " + cli_device(), "device.exr");
    ColorImage lib;
    shared_pass().apply(frame_->color, frame_->depth, lib, camera(), settings());
    const std::size_t d = differing_floats(device, lib);
    std::printf("[ measured ] CLI --mode height on --device %s vs FogPass::apply: %zu differing floats\n",
                cli_device().c_str(), d);
    EXPECT_EQ(d, 0u);
  }
  // The fog did something: the default density alone differs.
  EXPECT_GT(differing_floats(run_ok(files() + pose_flags() + " --mode height --device scalar", "plain.exr"), want),
            1000u);
  // Each flag changes the picture: with its value changed (the boolean --fog-skybox left out) the
  // output is not the one above.
  const struct {
    const char* flag;
    const char* other;  // nullptr: leave the flag out
  } changes[] = {
      {"--extinction", "0.03,0.03,0.05"}, {"--inscattering", "0.02,0.02,0.04"}, {"--height-falloff", "0.3"},
      {"--base-height", "0.6"},           {"--start", "1.5"},                   {"--cutoff", "300"},
      {"--max-opacity", "0.5"},           {"--fog-color", "0.6,0.7,0.9"},       {"--fog-skybox", nullptr},
      {"--light-dir", "0.3,0.5,1"},       {"--sun-color", "1.5,1.2,1"},         {"--sun-exponent", "10"},
      {"--sun-start", "3"},
  };
  const std::string all = kFlags;
  for (const auto& c : changes) {
    const std::string flag = std::string(" ") + c.flag;
    const std::size_t at = all.find(flag + " ");
    ASSERT_NE(at, std::string::npos) << c.flag;
    const std::size_t value = at + flag.size() + 1;
    const std::size_t end = c.other ? all.find(' ', value) : value - 1;
    const std::string changed =
        all.substr(0, at) + (c.other ? flag + " " + c.other : "") + (end == std::string::npos ? "" : all.substr(end));
    const std::size_t d = differing_floats(run_ok(files() + pose_flags() + changed + " --device scalar", "flag.exr"), want);
    std::printf("[ measured ] %s %s: %zu floats change\n", c.flag, c.other ? c.other : "(left out)", d);
    EXPECT_GT(d, 0u) << c.flag << " changed nothing: " << changed;
  }
}

TEST_F(CliHeight, VolumesFirstThenHeightFog) {
  const std::string json = in("volumes.json");
  std::ofstream(json) << "{\"volumes\": [{\"center\": [0, 1, 2], \"radius\": 2.5, \"density\": 0.5}]}\n";
  const std::string fog = " --mode height --density 0.05 --height-falloff 0.5 --light-dir 0.3,0.8,-0.5";
  const ColorImage got = run_ok(files() + pose_flags() + fog + " --volumes " + json + " --device scalar", "both.exr");
  VolumeScene scene;
  FogVolume v;
  v.center = glm::vec3(0, 1, 2);
  v.radius = 2.5f;
  v.density = 0.5f;
  scene.volumes = {v};
  scene.pose = pose();
  scene.light.direction = glm::vec3(0.3f, 0.8f, -0.5f);
  ColorImage want;
  apply_volumes_scalar(frame_->color, frame_->depth, want, frame_->params, scene, VolumeSettings{});
  FogSettings s;
  s.mode = FogMode::height;
  s.density = 0.05f;
  s.height.falloff = 0.5f;
  apply_fog_scalar(want, frame_->depth, want, camera(), s);
  EXPECT_EQ(differing_floats(got, want), 0u);
}

// --height-volumetric (docs/DESIGN.md §6.5): the volumetric pass marches the fog and the deferred
// pass runs none. Lit (no shadow map) the picture is the closed form's within 1e-5; it is the
// library's march bit for bit; the demo's shadow map darkens the sun's fog where it shadows it.
TEST_F(CliHeight, HeightVolumetricIsTheClosedFormLitAndShaftsInShadow) {
  const std::string fog = " --mode height --density 0.05 --inscattering 0.02,0.04,0.06 --height-falloff 0.3 "
                          "--fog-color 0.6,0.7,0.8 --fog-skybox --light-dir 0.3,0.4,1 --sun-color 1.5,1.2,0.9";
  const std::string march = " --height-volumetric --volume-resolution full --steps 8 --device scalar";
  const ColorImage closed = run_ok(files() + pose_flags() + fog + " --device scalar", "closed.exr");
  const ColorImage marched = run_ok(files() + pose_flags() + fog + march, "marched.exr");
  FogSettings s;
  s.mode = FogMode::height;
  s.density = 0.05f;
  s.color = glm::vec3(0.6f, 0.7f, 0.8f);
  s.fog_skybox = true;
  s.height.inscattering = glm::vec3(0.02f, 0.04f, 0.06f);
  s.height.falloff = 0.3f;
  SunLobe sun;
  sun.direction = glm::vec3(0.3f, 0.4f, 1.0f);
  sun.color = glm::vec3(1.5f, 1.2f, 0.9f);
  s.height.sun = sun;
  VolumeScene scene;
  scene.pose = pose();
  scene.light.direction = sun.direction;
  VolumeSettings vs;
  vs.integrator = VolumeIntegrator::physical;
  vs.resolution_divisor = 1;
  vs.steps = 8;
  vs.height_fog = s;
  ColorImage lib;
  apply_volumes_scalar(frame_->color, frame_->depth, lib, frame_->params, scene, vs);
  const auto worst = [](const ColorImage& a, const ColorImage& b) {
    double w = 0.0;
    for (int y = 0; y < a.height(); ++y)
      for (int x = 0; x < a.width(); ++x)
        for (int c = 0; c < 3; ++c) {
          const double d = std::fabs(double(a.pixel(x, y)[c]) - double(b.pixel(x, y)[c]));
          w = d == d ? std::max(w, d) : INFINITY;
        }
    return w;
  };
  const double lit = worst(marched, closed);
  const std::size_t vs_lib = differing_floats(marched, lib);
  std::printf("[ measured ] --height-volumetric lit vs the closed form: worst %.3g; vs apply_volumes_scalar: %zu "
              "differing floats\n", lit, vs_lib);
  EXPECT_LE(lit, 1e-5);
  EXPECT_EQ(vs_lib, 0u);
  // The demo light's shadow map as the sun's: the spheres' shadows take the sun's fog away, never add.
  const ShadowMap shadow = render_demo_shadow_map(96, 96);
  write_exr_depth(in("shadow.exr"), shadow.depth);
  std::string matrix;
  for (int row = 0; row < 4; ++row)
    for (int c = 0; c < 4; ++c) {
      char v[32];
      std::snprintf(v, sizeof v, "%.9g", double(shadow.params.world_to_light_clip[c][row]));
      matrix += (row + c ? "," : "") + std::string(v);
    }
  const ColorImage shafts =
      run_ok(files() + pose_flags() + fog + march + " --shadow-map " + in("shadow.exr") + " --light-view-proj " + matrix,
             "shafts.exr");
  double darker = 0.0, brighter = 0.0;
  for (int y = 0; y < shafts.height(); ++y)
    for (int x = 0; x < shafts.width(); ++x)
      for (int c = 0; c < 3; ++c) {
        const double d = double(shafts.pixel(x, y)[c]) - double(marched.pixel(x, y)[c]);
        darker = std::max(darker, -d);
        brighter = std::max(brighter, d);
      }
  std::printf("[ measured ] --height-volumetric with the shadow map: up to %.3g darker, %.3g brighter\n", darker,
              brighter);
  EXPECT_GT(darker, 1e-3);
  EXPECT_LE(brighter, 1e-6);
  EXPECT_NE(run_cli(files() + pose_flags() + fog + march + " --integrator stylized --out " + in("x.exr")).exit_code, 0);
}

// The demo scene's far plane is at 1000; with no falloff a fogged sky is still an infinite ray
// (docs/DESIGN.md §6.2), whatever start or sun start lies past the far plane: every sky pixel is
// exactly the fog color, or the fog color plus the lobe (the float64 path's value within §6.3's
// budget), no pixel is non-finite, and the CLI gives the library's bits. With --sky infinite,
// --reversed-z, --precision fast and --pixel-type half, on the device and the scalar path.
TEST_F(CliHeight, ZeroFalloffSkyPastTheStartIsTheFogColor) {
  PerspectiveCamera rc;
  rc.reversed_z = true;
  const DemoFrame rev = render_demo_scene(64, 36, rc);
  write_exr_rgba(in("scene-revz.exr"), rev.color);
  write_exr_depth(in("scene-revz-depth.exr"), rev.depth);
  struct Case {
    std::string flags;
    bool reversed = false, sky_infinite = false, fast = false, half = false;
    float sun_start = -1;  // -1: no lobe
  };
  const Case cases[] = {
      {""},
      {" --sky infinite", false, true},
      {" --reversed-z", true},
      {" --precision fast", false, false, true},
      {" --pixel-type half", false, false, false, true},
      {" --light-dir 0.2,1,0.4 --sun-color 1,1,1 --sun-start 1e38", false, false, false, false, 1e38f},
      {" --light-dir 0.2,1,0.4 --sun-color 1,1,1 --sun-start 2000 --reversed-z", true, false, false, false, 2000},
  };
  std::vector<std::string> devices = {"scalar"};
  if (runtime() != nullptr && cli_device() != "scalar") devices.push_back(cli_device());
  double worst_lobe = 0;
  for (const Case& c : cases) {
    const DemoFrame& frame = c.reversed ? rev : *frame_;
    const std::string inputs = c.reversed ? "apply --color " + in("scene-revz.exr") + " --depth " + in("scene-revz-depth.exr") +
                                                " --near 0.3 --far 1000 --fov 60"
                                          : files();
    FogSettings s;
    s.mode = FogMode::height;
    s.density = 0.5f;
    s.height.start = 2000.0f;
    s.fog_skybox = true;
    s.sky = c.sky_infinite ? SkyDistance::infinite : SkyDistance::far_plane;
    s.precision = c.fast ? Precision::fast : Precision::precise;
    if (c.sun_start >= 0) {
      SunLobe sun;
      sun.direction = glm::vec3(0.2f, 1.0f, 0.4f);
      sun.color = glm::vec3(1.0f);
      sun.start = c.sun_start;
      s.height.sun = sun;
    }
    CameraParams cam = frame.params;
    cam.pose = pose();
    const FogResult<double> ref = fog_scalar<double>(frame.color, frame.depth, cam, s);
    for (const std::string& device : devices) {
      const std::string args = inputs + pose_flags() + " --mode height --density 0.5 --start 2000 --fog-skybox" + c.flags +
                               " --device " + device;
      const ColorImage got = run_ok(args, "zero-falloff.exr");
      ASSERT_EQ(got.width(), 64) << args;
      std::size_t sky = 0, nonfinite = 0, sky_off = 0;
      for (int y = 0; y < got.height(); ++y)
        for (int x = 0; x < got.width(); ++x) {
          const bool is_sky = frame.depth.at(x, y) == (c.reversed ? 0.0f : 1.0f);
          sky += is_sky;
          for (int k = 0; k < 3; ++k) {
            const float g = got.pixel(x, y)[k];
            nonfinite += !std::isfinite(g);
            if (!is_sky) continue;
            if (c.sun_start < 0) {
              sky_off += g != 0.5f;
            } else {
              const double err = std::fabs(double(g) - ref.rgba[4 * (std::size_t(y) * 64 + x) + k]);
              const double scale = 1 + std::fabs(frame.color.pixel(x, y)[k]) + 0.5 + 1;
              worst_lobe = std::max(worst_lobe, std::isnan(err) ? INFINITY : err / scale);
            }
          }
        }
      std::printf("[ measured ] k = 0, start 2000, fogged sky%s on %s: %zu sky pixels, %zu sky channels not 0.5, %zu non-finite\n",
                  c.flags.c_str(), device.c_str(), sky, sky_off, nonfinite);
      EXPECT_GT(sky, 100u);
      EXPECT_EQ(sky_off, 0u) << args;
      EXPECT_EQ(nonfinite, 0u) << args;
      if (c.half) continue;  // the library's bits in float storage
      ColorImage want;
      if (device == "scalar")
        apply_fog_scalar(frame.color, frame.depth, want, cam, s);
      else
        shared_pass().apply(frame.color, frame.depth, want, cam, s);
      EXPECT_EQ(differing_floats(got, want), 0u) << args;
    }
  }
  std::printf("[ worst    ] the lobe's sky past a sun start of 1e38 and 2000: err %.2e of 1 + |c| + |F| + |S|\n", worst_lobe);
  EXPECT_LE(worst_lobe, 4e-6);
}

TEST_F(CliHeight, BadInputIsOneLineNamingTheFlagAndTheRule) {
  const std::string p = pose_flags();
  struct Case {
    std::string args, part;
  };
  const Case cases[] = {
      {" --mode height", "--eye is required with --mode height"},
      {" --mode height --eye 0,1,0 --up 0,1,0", "--forward is required"},
      {" --mode height --eye 0,1,0 --forward 0,0,0 --up 0,1,0", "--forward must be a non-zero vector"},
      {" --mode height --eye 0,1,0 --forward 0,2,0 --up 0,1,0", "--up must not be parallel to --forward"},
      {" --mode height --eye 0,nan,0 --forward 0,0,1 --up 0,1,0", "--eye must be finite"},
      {p + " --mode height --density -0.1", "--density must be finite and >= 0"},
      {p + " --mode height --density inf", "--density must be finite and >= 0"},
      {p + " --mode height --extinction 0.1,-1,0", "--extinction must be finite and >= 0"},
      {p + " --mode height --extinction 0.1,nan,0", "--extinction must be finite and >= 0"},
      {p + " --mode height --inscattering inf,0,0", "--inscattering must be finite and >= 0"},
      {p + " --mode height --height-falloff nan", "--height-falloff must be finite"},
      {p + " --mode height --height-falloff -inf", "--height-falloff must be finite"},
      {p + " --mode height --base-height nan", "--base-height must be finite"},
      {p + " --mode height --max-opacity 1.01", "--max-opacity must be in [0, 1]"},
      {p + " --mode height --max-opacity -0.5", "--max-opacity must be in [0, 1]"},
      {p + " --mode height --start 5 --cutoff 5", "--cutoff must be > --start"},
      {p + " --mode height --cutoff 0", "--cutoff must be > --start"},
      {p + " --mode height --start -1", "--start must be finite and >= 0"},
      {p + " --mode height --light-dir 0,1,0 --sun-color 1,1,1 --sun-exponent 0", "--sun-exponent must be finite and > 0"},
      {p + " --mode height --light-dir 0,1,0 --sun-color 1,-1,1", "--sun-color must be finite and >= 0"},
      {p + " --mode height --sun-color 1,1,1", "--sun-color needs --light-dir"},
      {p + " --mode height --sun-start 3", "--sun-start needs --sun-color"},
      {p + " --mode height --density 0.1 --extinction 1,1,1", "give either --density or --extinction"},
      {" --mode exp --height-falloff 0.1", "--height-falloff needs --mode height"},
      {" --mode linear --cutoff 10", "--cutoff needs --mode height"},
      {" --mode exp2 --max-opacity 0.5", "--max-opacity needs --mode height"},
      {" --mode off --sun-color 1,1,1", "--sun-color needs --mode height"},
      {" --mode exp --extinction 1,1,1", "--extinction needs --mode height"},
  };
  const std::string out = in("bad.exr");
  for (const Case& c : cases) {
    fs::remove(out);
    const CliRun r = run_cli(files() + c.args + " --device scalar --out " + out);
    std::printf("[ message  ] %s", r.output.c_str());
    EXPECT_EQ(r.exit_code, 1) << c.args << "\n" << r.output;
    EXPECT_EQ(r.output.rfind("fogcl: error: ", 0), 0u) << r.output;
    EXPECT_NE(r.output.find(c.part), std::string::npos) << c.args << "\n" << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(fs::exists(out)) << c.args;
  }
}

// --height-volumetric's light and shadow flags walked with empty, huge and wrong values: each is one
// line naming the flag (exit 1, or 2 for malformed text), no file; flags that would change nothing in
// the marched fog's image (no volumes) are refused; the largest accepted values give a finite image.
TEST_F(CliHeight, HeightVolumetricLightAndShadowFlagsWalk) {
  const ShadowMap shadow = render_demo_shadow_map(64, 64);
  write_exr_depth(in("walk-shadow.exr"), shadow.depth);
  std::ofstream(in("not-an-exr.exr")) << "{}";
  std::string m;
  for (int row = 0; row < 4; ++row)
    for (int c = 0; c < 4; ++c) {
      char v[32];
      std::snprintf(v, sizeof v, "%.9g", double(shadow.params.world_to_light_clip[c][row]));
      m += (row + c ? "," : "") + std::string(v);
    }
  const std::string base = files() + pose_flags() +
                           " --mode height --density 0.05 --height-falloff 0.3 --height-volumetric --steps 4 "
                           "--volume-resolution quarter --device scalar";
  const std::string sm = " --shadow-map " + in("walk-shadow.exr") + " --light-view-proj " + m;
  struct Case {
    std::string args, part;
    int exit_code;
  };
  const Case cases[] = {
      {" --light-dir ''", "--light-dir must be three comma-separated numbers", 2},
      {" --light-dir 1,2", "--light-dir must be three comma-separated numbers", 2},
      {" --light-dir a,b,c", "--light-dir must be three comma-separated numbers", 2},
      {" --light-dir 0,0,0", "--light-dir must be a non-zero vector", 1},
      {" --light-dir nan,1,0", "--light-dir must be finite", 1},
      {" --light-dir 1e39,0,1", "--light-dir must be finite", 1},
      {" --light-dir 3e38,3e38,3e38", "--light-dir is too long to normalise", 1},
      {" --light-color ''", "--light-color must be three comma-separated numbers", 2},
      {" --light-color inf,1,1", "--light-color must be finite", 1},
      {" --light-color -1,0,0", "--light-color must be >= 0", 1},
      {" --light-color 1,1,1", "--light-color colors the fog volumes' light (--volumes)", 1},
      {" --shadow-map ''", "--shadow-map must not be empty", 2},
      {" --shadow-map " + in("none.exr") + " --light-view-proj " + m + " --light-dir 0,1,0 --sun-color 1,1,1",
       "--shadow-map: " + in("none.exr"), 1},
      {" --shadow-map " + in("not-an-exr.exr") + " --light-view-proj " + m + " --light-dir 0,1,0 --sun-color 1,1,1",
       "cannot read EXR", 1},
      {" --shadow-map " + dir_ + " --light-view-proj " + m, "is a directory", 1},
      {" --shadow-map " + in("walk-shadow.exr"), "--shadow-map needs --light-view-proj", 1},
      {" --light-view-proj " + m, "--light-view-proj needs --shadow-map", 1},
      {" --shadow-reversed-z", "--shadow-reversed-z needs --shadow-map", 1},
      {" --shadow-map " + in("walk-shadow.exr") + " --light-view-proj 1,2,3", "--light-view-proj must be 16", 2},
      {" --shadow-map " + in("walk-shadow.exr") + " --light-view-proj ''", "--light-view-proj element 0", 2},
      {" --shadow-map " + in("walk-shadow.exr") + " --light-view-proj 0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0",
       "--light-view-proj: light view-projection matrix is singular", 1},
      {" --shadow-map " + in("walk-shadow.exr") + " --light-view-proj 1e39,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1",
       "--light-view-proj element (row 0, column 0) must be a finite float", 1},
      {sm, "--shadow-map with --height-volumetric needs --sun-color", 1},
      {sm + " --light-dir 0,1,0 --sun-color 1,1,1 --integrator stylized", "--height-volumetric needs --integrator physical",
       1},
  };
  const std::string out = in("walk.exr");
  for (const Case& c : cases) {
    fs::remove(out);
    const CliRun r = run_cli(base + c.args + " --out " + out);
    std::printf("[ message  ] %s", r.output.c_str());
    EXPECT_EQ(r.exit_code, c.exit_code) << c.args << "\n" << r.output;
    EXPECT_EQ(r.output.rfind("fogcl: error: ", 0), 0u) << r.output;
    EXPECT_NE(r.output.find(c.part), std::string::npos) << c.args << "\n" << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(fs::exists(out)) << c.args;
  }
  // The largest values each flag takes: a finite image.
  for (const std::string& ok : {sm + " --light-dir 1e18,1e18,1e18 --sun-color 3e38,3e38,3e38",
                                sm + " --light-dir 0.3,0.8,-0.5 --sun-color 1,1,1 --sun-exponent 3e38",
                                sm + " --light-dir 1e-30,1,0 --sun-color 1,1,1 --shadow-reversed-z"}) {
    const ColorImage img = run_ok(base + ok, "walk-ok.exr");
    std::size_t nonfinite = 0;
    for (int y = 0; y < img.height(); ++y)
      for (int x = 0; x < img.width(); ++x)
        for (int c = 0; c < 4; ++c) nonfinite += std::isfinite(img.pixel(x, y)[c]) ? 0 : 1;
    std::printf("[ measured ] %s: %zu non-finite values\n", ok.substr(ok.find("--light-dir")).c_str(), nonfinite);
    EXPECT_GT(img.width(), 0) << ok;
    EXPECT_EQ(nonfinite, 0u) << ok;
  }
}

TEST_F(CliHeight, HelpDocumentsEveryHeightFlag) {
  const CliRun r = run_cli("apply --help");
  for (const char* flag : {"--extinction", "--inscattering", "--height-falloff", "--base-height", "--cutoff",
                           "--max-opacity", "--sun-color", "--sun-exponent", "--sun-start", "height"})
    EXPECT_NE(r.output.find(flag), std::string::npos) << flag;
}

}  // namespace
}  // namespace fogcl::test
