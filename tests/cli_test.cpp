// The fogcl CLI on real files: `demo` writes a scene, `apply` fogs the generated EXR pair and is
// compared against the library's double path; bad input exits non-zero with one line and no file.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sys/wait.h>
#include <unistd.h>

#include "fogcl/demo_scene.h"
#include "fogcl/exr_io.h"
#include "test_support.h"

namespace fogcl::test {
namespace {

namespace fs = std::filesystem;


class Cli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // One folder per process: ctest runs each test in its own process, in parallel.
    dir_ = temp_dir() + "/cli-" + std::to_string(::getpid());
    fs::remove_all(dir_);
    const CliRun demo = run_cli("demo --out " + dir_ + " --width 96 --height 54 --device " +
                             cli_device());
    demo_output_ = demo.output;
    demo_ok_ = demo.exit_code == 0;
  }
  void SetUp() override { ASSERT_TRUE(demo_ok_) << demo_output_; }
  static std::string in(const std::string& name) { return dir_ + "/" + name; }
  static inline std::string dir_, demo_output_;
  static inline bool demo_ok_ = false;
};

TEST_F(Cli, DemoWritesImagesAndATable) {
  for (const char* f : {"scene.exr", "scene-depth.exr", "scene.png", "exp2-distance-scalar.exr",
                        "exp2-distance-scalar.png"})
    EXPECT_TRUE(fs::exists(in(f))) << f;
  EXPECT_NE(demo_output_.find("median ms"), std::string::npos) << demo_output_;
  if (runtime() != nullptr) {
    EXPECT_TRUE(fs::exists(in("exp2-distance-opencl.exr")));
  }
}

// The demo's volumetric rows and their inputs; the `fogcl apply` line it prints reproduces its
// volumes-stylized-shadow row bit for bit (same inputs, same pass).
TEST_F(Cli, DemoVolumeRowsAreReproducedByApply) {
  for (const char* f : {"volumes.json", "volumes-physical.json", "light-shadow.exr", "light-view-proj.txt",
                        "volumes-stylized-scalar.png", "volumes-physical-shadow-scalar.exr", "volumes-shadow+exp2-scalar.png"})
    EXPECT_TRUE(fs::exists(in(f))) << f;
  for (const char* row : {"volumes-stylized ", "volumes-stylized-shadow ", "volumes-physical ", "volumes-physical-shadow ",
                          "volumes-shadow+exp2 "})
    EXPECT_NE(demo_output_.find(row), std::string::npos) << row << " in " << demo_output_;
  const std::size_t at = demo_output_.find("  fogcl apply ");
  ASSERT_NE(at, std::string::npos) << demo_output_;
  std::string line = demo_output_.substr(at + 8, demo_output_.find('\n', at) - at - 8);
  const std::string kind = runtime() ? "opencl" : "scalar";
  line.replace(line.find("OUT.exr"), 7, in("apply-volumes.exr"));
  const CliRun r = run_cli(line + " --device " + cli_device());
  ASSERT_EQ(r.exit_code, 0) << line << "\n" << r.output;
  const ColorImage got = read_exr_color(in("apply-volumes.exr"));
  const ColorImage want = read_exr_color(in("volumes-stylized-shadow-" + kind + ".exr"));
  ASSERT_EQ(got.size_bytes(), want.size_bytes());
  const std::size_t differing = std::memcmp(got.data(), want.data(), got.size_bytes()) == 0 ? 0 : 1;
  std::printf("[ measured ] demo's fogcl apply line vs its %s row: %s\n", kind.c_str(),
              differing ? "differs" : "bit-identical");
  EXPECT_EQ(differing, 0u);
}

// The light-shaft rows: the shadow map only takes the sun's light away (never adds), and it cuts
// shafts: along some image row, shadowed runs of fog alternate with lit ones.
TEST_F(Cli, DemoShaftRowHasShafts) {
  const std::string kind = runtime() ? "opencl" : "scalar";
  for (const char* row : {"height-shafts ", "height-shafts-lit "})
    EXPECT_NE(demo_output_.find(row), std::string::npos) << row << " in " << demo_output_;
  const ColorImage shafts = read_exr_color(in("height-shafts-" + kind + ".exr"));
  const ColorImage lit = read_exr_color(in("height-shafts-lit-" + kind + ".exr"));
  const ColorImage scene = read_exr_color(in("scene-low-sun.exr"));
  ASSERT_EQ(shafts.size_bytes(), lit.size_bytes());
  const auto luminance = [](const glm::vec4& c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; };
  double brighter = 0.0, darkest = 0.0, fog_gain = 0.0;
  std::size_t shadowed = 0, most_runs = 0;
  for (int y = 0; y < shafts.height(); ++y) {
    std::size_t runs = 0;
    bool in_run = false;
    for (int x = 0; x < shafts.width(); ++x) {
      const double d = luminance(lit.pixel(x, y)) - luminance(shafts.pixel(x, y));
      for (int c = 0; c < 3; ++c)
        brighter = std::max(brighter, double(shafts.pixel(x, y)[c]) - double(lit.pixel(x, y)[c]));
      darkest = std::max(darkest, d);
      fog_gain = std::max(fog_gain, luminance(lit.pixel(x, y)) - luminance(scene.pixel(x, y)));
      const bool dark = d > 0.02;  // a shadowed stretch of the ray: the sun's glow is missing
      shadowed += dark ? 1 : 0;
      if (dark && !in_run) ++runs;
      in_run = dark;
    }
    most_runs = std::max(most_runs, runs);
  }
  const double pct = 100.0 * double(shadowed) / double(shafts.pixel_count());
  std::printf("[ measured ] height-shafts vs its lit row: up to %.3g darker (lit fog adds up to %.3g), %.3g brighter; "
              "%.1f%% of pixels shadowed; up to %zu separate shadowed runs in one image row\n",
              darkest, fog_gain, brighter, pct, most_runs);
  EXPECT_LE(brighter, 1e-5) << "a shadow never adds light";
  EXPECT_GT(darkest, 0.1) << "the spheres' shadows are visible in the fog";
  EXPECT_GT(pct, 2.0);
  EXPECT_LT(pct, 90.0) << "shafts, not a shadow over everything";
  EXPECT_GE(most_runs, 2u) << "lit and shadowed columns alternate";
}

// The street-lamp row: the lamps only add light to the night mist, and most of it near them: the
// mean added luminance in a square around each lamp's image (a spot's: 1.5 units into its cone) is
// several times the frame's mean.
TEST_F(Cli, DemoLampRowIsBrighterNearTheLamps) {
  const std::string kind = runtime() ? "opencl" : "scalar";
  for (const char* row : {"street-lamps ", "street-lamps-off "})
    EXPECT_NE(demo_output_.find(row), std::string::npos) << row << " in " << demo_output_;
  const ColorImage on = read_exr_color(in("street-lamps-" + kind + ".exr"));
  const ColorImage off = read_exr_color(in("street-lamps-off-" + kind + ".exr"));
  ASSERT_EQ(on.size_bytes(), off.size_bytes());
  const auto luminance = [](const glm::vec4& c) { return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b; };
  double darker = 0.0, mean = 0.0;
  for (int y = 0; y < on.height(); ++y)
    for (int x = 0; x < on.width(); ++x) {
      const double d = luminance(on.pixel(x, y)) - luminance(off.pixel(x, y));
      for (int c = 0; c < 3; ++c) darker = std::max(darker, double(off.pixel(x, y)[c]) - double(on.pixel(x, y)[c]));
      mean += d / double(on.pixel_count());
    }
  // Each lamp's image position: the demo camera (fogcl's left-handed world, 60 degrees vertical).
  const DemoView view;
  const glm::vec3 forward = glm::normalize(view.target - view.eye);
  const glm::vec3 right = glm::normalize(glm::cross(glm::vec3(0.0f, 1.0f, 0.0f), forward));
  const glm::vec3 up = glm::cross(forward, right);
  const double tan_half = std::tan(30.0 * 3.14159265358979 / 180.0), aspect = double(on.width()) / on.height();
  const int r = std::max(2, on.height() / 20);
  std::size_t lamps_in_view = 0;
  for (const LocalLight& l : demo_street_lamps()) {
    // A spot's glow is its cone: look 1.5 units down its axis; a point light's is around it.
    const glm::vec3 at = l.kind == LightKind::spot ? l.position + 1.5f * glm::normalize(l.direction) : l.position;
    const glm::vec3 p = at - view.eye;
    const double z = glm::dot(p, forward);
    const double u = (1.0 + glm::dot(p, right) / (z * tan_half * aspect)) * 0.5 * on.width();
    const double v = (1.0 - glm::dot(p, up) / (z * tan_half)) * 0.5 * on.height();
    if (!(z > 0.0 && u >= r && u < on.width() - r && v >= r && v < on.height() - r)) continue;
    ++lamps_in_view;
    double near = 0.0;
    int n = 0;
    for (int y = int(v) - r; y <= int(v) + r; ++y)
      for (int x = int(u) - r; x <= int(u) + r; ++x) {
        near += luminance(on.pixel(x, y)) - luminance(off.pixel(x, y));
        ++n;
      }
    near /= n;
    std::printf("[ measured ] lamp at (%g, %g, %g), pixel (%.0f, %.0f): %.3g added near it, %.3g on the frame's mean\n",
                double(l.position.x), double(l.position.y), double(l.position.z), u, v, near, mean);
    EXPECT_GT(near, 3.0 * mean) << "lamp at pixel " << u << "," << v;
  }
  std::printf("[ measured ] street-lamps vs off: %zu lamps in view, up to %.3g darker\n", lamps_in_view, darker);
  EXPECT_GE(lamps_in_view, 4u);
  EXPECT_GT(mean, 0.0);
  EXPECT_LE(darker, 1e-5) << "a lamp never takes light away";
}

TEST_F(Cli, ApplyMatchesTheDoublePath) {
  const std::string common = "--color " + in("scene.exr") + " --depth " + in("scene-depth.exr") +
                             " --near 0.3 --far 1000 --fov 60 --mode exp2 --density 0.03 --distance"
                             " --fog-color 0.6,0.7,0.8";
  for (const char* device : {"cpu", "scalar"}) {
    if (std::string(device) == "cpu" && runtime() == nullptr) continue;
    const std::string out = in(std::string("apply-") + device + ".exr");
    const CliRun r = run_cli("apply " + common + " --out " + out + " --device " + device + " --verbose");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const ColorImage got = read_exr_color(out);
    const ColorImage color = read_exr_color(in("scene.exr"));
    const DepthImage depth = read_exr_depth(in("scene-depth.exr"));
    PerspectiveCamera cam;
    cam.aspect = float(color.width()) / float(color.height());
    FogSettings s;
    s.mode = FogMode::exp2;
    s.density = 0.03f;
    s.metric = FogMetric::distance;
    s.color = glm::vec3(0.6f, 0.7f, 0.8f);
    const FogResult<double> ref = fog_scalar<double>(color, depth, make_camera_params(cam), s);
    const ErrorStats e = compare_color(got, ref, color, s.color);
    std::printf("[ worst    ] fogcl apply --device %s: rel %.2e\n", device, e.max_rel);
    EXPECT_LE(e.max_rel, 1e-5);
    EXPECT_EQ(e.alpha_changed, 0u);
    EXPECT_NE(r.output.find("variant: exp2 distance"), std::string::npos) << r.output;
  }
}

TEST_F(Cli, BadInputExitsNonZeroWithOneLineAndNoFile) {
  const std::string base = "apply --color " + in("scene.exr") + " --depth " + in("scene-depth.exr") +
                           " --fov 60 --device scalar";
  const std::string out = in("bad.exr");
  const struct {
    std::string args, expect;
  } cases[] = {
      {" --near -1 --far 1000 --mode exp", "near"},
      {" --near 1 --far 0.5 --mode exp", "far"},
      {" --near 0.3 --far 1000 --mode linear --start 50 --end 10", "start"},
      {" --near 0.3 --far 1000 --mode exp --density -0.1", "density"},
      {" --near 0.3 --far 1000 --mode exp --density nan", "density"},
      {" --near 0.3 --far 1000 --mode fog", "mode"},
      {" --near 0.3 --far 1000 --mode exp --fov 180", "fov"},
  };
  for (const auto& c : cases) {
    const CliRun r = run_cli(base + c.args + " --out " + out);
    EXPECT_NE(r.exit_code, 0) << c.args;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.args << ": " << r.output;
    // One line: "fogcl: error: ..." and nothing else.
    EXPECT_EQ(r.output.rfind("fogcl: error: ", 0), 0u) << c.args << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << c.args << ": " << r.output;
    EXPECT_FALSE(fs::exists(out)) << c.args;
  }
  const CliRun missing = run_cli("apply --color " + in("nope.exr") + " --depth " + in("scene-depth.exr") +
                              " --near 0.3 --far 1000 --fov 60 --mode exp --out " + out);
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("nope.exr"), std::string::npos) << missing.output;
  EXPECT_EQ(missing.output.rfind("fogcl: error: ", 0), 0u) << missing.output;
  EXPECT_EQ(std::count(missing.output.begin(), missing.output.end(), '\n'), 1) << missing.output;
  EXPECT_FALSE(fs::exists(out));
}

// Whether `help` lists `flag` as an option: a line "  --flag ..." or "  -x,--flag ...", so that
// "--up" is not found in "--upsample" or in another option's description.
bool lists_option(const std::string& help, const std::string& flag) {
  std::size_t line = 0;
  while (line < help.size()) {
    std::size_t end = help.find('\n', line);
    if (end == std::string::npos) end = help.size();
    std::size_t i = help.find_first_not_of(' ', line);
    if (i < end && help[i] == '-' && i + 1 < end && help[i + 1] != '-') {  // "-h,--help"
      const std::size_t comma = help.find(',', i);
      i = comma < end ? comma + 1 : end;
    }
    if (i < end && help.compare(i, flag.size(), flag) == 0 &&
        (i + flag.size() == end || help[i + flag.size()] == ' '))
      return true;
    line = end + 1;
  }
  return false;
}

TEST_F(Cli, HelpDocumentsEveryFlag) {
  const CliRun r = run_cli("apply --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_FALSE(lists_option(r.output, "--upsam")) << "lists_option must match whole flags only (--upsample)";
  for (const char* flag : {"--color", "--depth", "--out", "--near", "--far", "--fov", "--aspect", "--reversed-z",
                           "--mode", "--start", "--end", "--density", "--fog-color", "--distance",
                           "--fog-skybox", "--device", "--layer", "--depth-channel", "--depth-kind", "--rgba-only",
                           "--png", "--frames", "--keep-going", "--threads", "--pixel-type", "--compression",
                           "--ortho-size", "--infinite-far", "--sky", "--precision", "--max-error", "--verbose",
                           "--max-memory", "--camera-to-world", "--axes", "--focal-length", "--sensor-width",
                           "--sensor-height", "--sensor-fit", "--volumes", "--eye", "--forward", "--up",
                           "--light-dir", "--light-color", "--time", "--frame", "--fps", "--integrator", "--steps",
                           "--volume-resolution", "--upsample", "--noise-size", "--noise-seed", "--noise-sampling",
                           "--shadow-map", "--light-view-proj", "--shadow-reversed-z", "--help"})
    EXPECT_TRUE(lists_option(r.output, flag)) << flag << " is not an option line of fogcl apply --help";
  const CliRun d = run_cli("demo --help");
  for (const char* flag : {"--out", "--width", "--height", "--device"})
    EXPECT_TRUE(lists_option(d.output, flag)) << flag << " is not an option line of fogcl demo --help";
}

}  // namespace
}  // namespace fogcl::test
