// Error against run time (fogcl report), the error budget that picks the precision variant, and
// the camera and budget CLI flags (--ortho-size, --infinite-far, --max-error) end to end on the demo's
// EXR files, compared against the library's double path. Tiny frames keep it fast.
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include "fogcl/exr_io.h"
#include "fogcl/report.h"
#include "test_support.h"

namespace fogcl::test {
namespace {

namespace fs = std::filesystem;

constexpr double kFactorBudget = 2e-6;     // the library's budgets (tests/extreme_cases_test.cpp)
constexpr double kColorRelBudget = 1e-5;
constexpr double kSmallestScale = 0.62;    // the report's fog color's smallest channel

TEST(Report, WritesCsvJsonAndPlotWithSaneValues) {
  FOGCL_REQUIRE_DEVICE();
  ReportOptions o;
  o.width = 48;
  o.height = 27;
  o.runs = 7;
  const Report r = run_report(runtime(), o);
  const std::size_t scenes = report_scene_names().size();
  ASSERT_EQ(r.rows.size(), scenes * 5) << "4 device variants + the scalar row per scene";

  for (const ReportRow& row : r.rows) {
    std::printf("[ report   ] %-30s %-16s %8.4f ms  f %.2e  color %.2e  p999 %.2e  ulp %.3g  8bit %.3g%%  nonfinite %zu\n",
                row.scene.c_str(), row.variant.c_str(), row.time_ms, row.max_abs_err_factor, row.max_abs_err_color,
                row.p999_abs_err_color, row.max_ulp, row.pct_8bit_off, row.nonfinite);
    EXPECT_GT(row.time_ms, 0.0) << row.scene << " " << row.variant;
    EXPECT_EQ(row.nonfinite, 0u) << row.scene << " " << row.variant;
    EXPECT_LE(row.p999_abs_err_color, row.max_abs_err_color) << row.scene << " " << row.variant;
    EXPECT_GE(row.pct_8bit_off, 0.0);
    EXPECT_LE(row.pct_8bit_off, 100.0);
    if (row.precision == Precision::precise || row.scalar) {
      if (row.storage == ColorFormat::rgba32f) {
        EXPECT_LE(row.max_abs_err_factor, kFactorBudget) << row.scene << " " << row.variant;
        EXPECT_LE(row.max_abs_err_color, kColorRelBudget * kSmallestScale) << row.scene << " " << row.variant;
      }
    }
    // Half storage: the only error left is the final rounding to half (<= 0.5 ulp + float noise).
    if (row.storage == ColorFormat::rgba16f) {
      EXPECT_LE(row.max_ulp, 1.0) << row.scene << " " << row.variant;
    }
    if (row.scene == "near0.01-far1e6-reversed") {
      EXPECT_LE(row.eye_depth_rel_err, 1e-6);
    }
    if (row.scene == "near0.01-far1e6-conventional") {
      EXPECT_GT(row.eye_depth_rel_err, 1e-3) << "float raw depth at far/near 1e8";
    }
    if (row.scene.rfind("near0.01", 0) != 0) {
      EXPECT_EQ(row.eye_depth_rel_err, -1.0);
    }
  }

  const std::string dir = fresh_dir("report");
  write_report_csv(r, dir + "/report.csv");
  write_report_json(r, dir + "/report.json");
  const auto csv = read_csv(dir + "/report.csv");
  ASSERT_EQ(csv.size(), r.rows.size() + 1);
  const std::vector<std::string> required = {"scene",     "variant",           "time_ms",
                                             "max_abs_err_factor", "max_abs_err_color", "p999_abs_err_color",
                                             "max_ulp",   "pct_8bit_off",      "nonfinite"};
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < csv[0].size(); ++i) col[csv[0][i]] = i;
  for (const std::string& name : required) ASSERT_TRUE(col.count(name)) << "column " << name;
  for (std::size_t i = 1; i < csv.size(); ++i) {
    ASSERT_EQ(csv[i].size(), csv[0].size()) << "row " << i;
    EXPECT_EQ(csv[i][col["scene"]], r.rows[i - 1].scene);
    EXPECT_EQ(csv[i][col["variant"]], r.rows[i - 1].variant);
    for (const char* numeric : {"time_ms", "max_abs_err_factor", "max_abs_err_color", "p999_abs_err_color",
                                "max_ulp", "pct_8bit_off", "nonfinite"}) {
      const std::string& text = csv[i][col[numeric]];
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      EXPECT_TRUE(!text.empty() && *end == '\0') << numeric << " '" << text << "'";
      EXPECT_TRUE(std::isfinite(v) && v >= 0) << numeric << " " << v;
    }
  }
  std::ifstream json(dir + "/report.json");
  const std::string js((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  EXPECT_NE(js.find("\"rows\": ["), std::string::npos);
  EXPECT_NE(js.find("\"p999_abs_err_color\""), std::string::npos);

  // A missing interpreter is one clear line saying what to install.
  try {
    plot_report(dir, "/nonexistent/python3");
    ADD_FAILURE() << "plot_report with a missing python did not throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("python3-matplotlib"), std::string::npos) << e.what();
  }
  if (!require_matplotlib()) return;
  plot_report(dir);
  ASSERT_TRUE(fs::exists(dir + "/report.png"));
  // src/report/plot_report.py: one 5.2 x 4.0 inch panel per scene, 110 dpi.
  expect_plot(dir + "/report.png", int(scenes), 5.2, 4.0, 110);
}

TEST(ErrorBudget, PicksTheFastestCachesAndRefusesTheImpossible) {
  FOGCL_REQUIRE_DEVICE();
  BudgetOptions o;
  o.cache_dir = fresh_dir("budget-cache");
  o.measure = ReportOptions{24, 14, 7, false};
  const std::size_t before = budget_measurements();

  const PrecisionChoice first = choose_precision_detailed(*runtime(), ColorFormat::rgba32f, 1e9, o);
  EXPECT_FALSE(first.from_cache);
  EXPECT_EQ(budget_measurements(), before + 1);
  ASSERT_TRUE(fs::exists(first.cache_file)) << first.cache_file;
  ASSERT_EQ(first.candidates.size(), 2u);
  for (const VariantMeasurement& m : first.candidates)
    std::printf("[ budget   ] %-8s %s: worst color error %.3g, %.4f ms\n", to_string(m.precision),
                to_string(m.storage), m.max_abs_err_color, m.time_ms);
  EXPECT_LE(first.candidates[0].time_ms, first.candidates[1].time_ms);
  EXPECT_EQ(first.precision, first.candidates[0].precision) << "a huge budget picks the fastest";
  EXPECT_FALSE(first.reason.empty());

  // Second call: read from the cache, not measured again.
  const PrecisionChoice second = choose_precision_detailed(*runtime(), ColorFormat::rgba16f, 1e9, o);
  EXPECT_TRUE(second.from_cache);
  EXPECT_EQ(budget_measurements(), before + 1);
  EXPECT_EQ(second.cache_file, first.cache_file);

  // A budget the most accurate variant meets, but not the other, picks the accurate one.
  const VariantMeasurement& a = first.candidates[0];
  const VariantMeasurement& b = first.candidates[1];
  if (a.max_abs_err_color != b.max_abs_err_color) {
    const VariantMeasurement& best = a.max_abs_err_color < b.max_abs_err_color ? a : b;
    const double between = 0.5 * (a.max_abs_err_color + b.max_abs_err_color);
    EXPECT_EQ(choose_precision_detailed(*runtime(), ColorFormat::rgba32f, between, o).precision, best.precision);
  }

  // Below every variant: a clear error naming the budget and the best achievable error.
  try {
    choose_precision_detailed(*runtime(), ColorFormat::rgba32f, 1e-12, o);
    ADD_FAILURE() << "a 1e-12 budget was met";
  } catch (const Error& e) {
    const std::string m = e.what();
    std::printf("[ message  ] %s\n", m.c_str());
    EXPECT_NE(m.find("1e-12"), std::string::npos) << m;
    EXPECT_NE(m.find("best achievable"), std::string::npos) << m;
  }
  EXPECT_THROW(choose_precision_detailed(*runtime(), ColorFormat::rgba32f, -1.0, o), Error);
  EXPECT_EQ(budget_measurements(), before + 1);

  // A cache from another library version is not trusted: it is measured again.
  {
    std::ifstream in(first.cache_file);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t at = text.find(std::string("version,") + library_version());
    ASSERT_NE(at, std::string::npos) << text;
    // ... with the kernels' digest: a kernel changed within one version is measured again too.
    EXPECT_NE(text.find("+kernels.", at), std::string::npos) << text;
    text.replace(at, 8 + std::string(library_version()).size(), "version,0.0.0-other");
    std::ofstream(first.cache_file, std::ios::trunc) << text;
  }
  EXPECT_FALSE(choose_precision_detailed(*runtime(), ColorFormat::rgba32f, 1e9, o).from_cache);
  EXPECT_EQ(budget_measurements(), before + 2);
}

// A cache that cannot be written (its name taken by a directory) costs a warning and a measurement
// next time, and leaves no temporary behind (it was left as NAME.csv.tmpPID).
TEST(ErrorBudget, ACacheThatCannotBeWrittenLeavesNoTemporary) {
  FOGCL_REQUIRE_DEVICE();
  BudgetOptions o;
  o.cache_dir = fresh_dir("budget-cache-blocked");
  o.measure = ReportOptions{24, 14, 7, false};
  const PrecisionChoice first = choose_precision_detailed(*runtime(), ColorFormat::rgba32f, 1e9, o);
  ASSERT_TRUE(fs::exists(first.cache_file));
  fs::remove(first.cache_file);
  fs::create_directories(first.cache_file + "/in-the-way");
  for (int run = 0; run < 2; ++run) {
    const PrecisionChoice c = choose_precision_detailed(*runtime(), ColorFormat::rgba32f, 1e9, o);
    EXPECT_FALSE(c.from_cache) << "nothing could have been cached";
  }
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(o.cache_dir)) left.push_back(e.path().filename().string());
  std::printf("[ blocked  ] the cache folder holds: %s\n", left.empty() ? "nothing" : left.front().c_str());
  EXPECT_EQ(left, std::vector<std::string>{fs::path(first.cache_file).filename().string()})
      << "a temporary was left next to the cache";
  EXPECT_TRUE(fs::is_directory(first.cache_file + "/in-the-way"));
}

// --- CLI ---------------------------------------------------------------------------------------


class CliCameraAndBudgetFlags : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fresh_dir("cli5");
    const CliRun demo = run_cli("demo --out " + dir_ + " --width 48 --height 27 --device " +
                                cli_device());
    demo_ok_ = demo.exit_code == 0;
    demo_output_ = demo.output;
  }
  void SetUp() override { ASSERT_TRUE(demo_ok_) << demo_output_; }
  static std::string in(const std::string& name) { return dir_ + "/" + name; }
  static std::string device() { return cli_device(); }

  // Runs apply, then compares its output with fog_scalar<double> for `params`.
  static void check_apply(const std::string& args, const std::string& color_file, const std::string& depth_file,
                          const CameraParams& params, const FogSettings& s, const std::string& expect_in_output) {
    const std::string out = in("out-" + std::to_string(std::hash<std::string>{}(args)) + ".exr");
    const CliRun r = run_cli("apply --color " + in(color_file) + " --depth " + in(depth_file) + " --out " + out +
                             " --device " + device() + " --verbose " + args);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find(expect_in_output), std::string::npos) << r.output;
    const ColorImage got = read_exr_color(out);
    const ColorImage color = read_exr_color(in(color_file));
    const DepthImage depth = read_exr_depth(in(depth_file));
    const FogResult<double> ref = fog_scalar<double>(color, depth, params, s);
    const ErrorStats e = compare_color(got, ref, color, s.color);
    std::printf("[ worst    ] fogcl apply %s: rel %.2e\n", args.c_str(), e.max_rel);
    EXPECT_LE(e.max_rel, kColorRelBudget) << args;
    EXPECT_EQ(e.nonfinite_from_finite, 0u);
    EXPECT_EQ(e.alpha_changed, 0u) << args;
  }

  static inline std::string dir_, demo_output_;
  static inline bool demo_ok_ = false;
};

FogSettings exp_fog() {
  FogSettings s;
  s.mode = FogMode::exp;
  s.density = 0.02f;
  s.metric = FogMetric::distance;
  s.color = glm::vec3(0.6f, 0.7f, 0.8f);
  return s;
}
const char* kExpFog = " --mode exp --density 0.02 --distance --fog-color 0.6,0.7,0.8";

TEST_F(CliCameraAndBudgetFlags, OrthoSizeReplacesFov) {
  OrthographicCamera cam;
  cam.ortho_size = 5.0f;
  cam.aspect = 48.0f / 27.0f;
  cam.near_plane = 0.3f;
  cam.far_plane = 1000.0f;
  check_apply("--near 0.3 --far 1000 --ortho-size 5" + std::string(kExpFog), "scene.exr", "scene-depth.exr",
              make_camera_params(cam), exp_fog(), "orthographic (--ortho-size)");
  cam.reversed_z = true;
  check_apply("--near 0.3 --far 1000 --ortho-size 5 --reversed-z" + std::string(kExpFog), "scene-revz.exr",
              "scene-revz-depth.exr", make_camera_params(cam), exp_fog(), "orthographic, size 5");
}

TEST_F(CliCameraAndBudgetFlags, InfiniteFarImpliesReversedZAndIgnoresFar) {
  PerspectiveCamera cam;
  cam.aspect = 48.0f / 27.0f;
  cam.reversed_z = cam.infinite_far = true;
  // No --far and no --reversed-z: both follow from --infinite-far.
  check_apply("--near 0.3 --fov 60 --infinite-far" + std::string(kExpFog), "scene-revz.exr", "scene-revz-depth.exr",
              make_camera_params(cam), exp_fog(), "implied by --infinite-far");
  // --far may still be given; it is ignored.
  check_apply("--near 0.3 --far 5 --fov 60 --infinite-far --reversed-z" + std::string(kExpFog), "scene-revz.exr",
              "scene-revz-depth.exr", make_camera_params(cam), exp_fog(), "far infinite");
}

TEST_F(CliCameraAndBudgetFlags, CameraFlagConflictsAreClearErrors) {
  const std::string base = "apply --color " + in("scene.exr") + " --depth " + in("scene-depth.exr") +
                           " --device scalar --mode exp --out " + in("bad.exr");
  const struct {
    std::string args, expect;
    int code = 1;  // 2: a required flag left out (a usage error)
  } cases[] = {
      {" --near 0.3 --far 1000 --fov 60 --ortho-size 5", "not both"},
      {" --near 0.3 --fov 60", "--far is required", 2},
      {" --near 0.3 --far 1000 --ortho-size 0", "--ortho-size must be"},
      {" --near 0.3 --far 1000 --ortho-size 5 --infinite-far", "--infinite-far"},
      {" --near 0.3 --far 1000 --fov 60 --precision fast --max-error 1", "not both"},
      {" --near 0.3 --far 1000 --fov 60 --max-error 1", "scalar"},
      {" --near 0.3 --far 1000 --ortho-size 5 --depth-kind distance", "needs a perspective camera"},
  };
  for (const auto& c : cases) {
    const CliRun r = run_cli(base + c.args);
    std::printf("[ message  ] %s", r.output.c_str());
    EXPECT_EQ(r.exit_code, c.code) << c.args << ": " << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.args << ": " << r.output;
    EXPECT_FALSE(fs::exists(in("bad.exr"))) << c.args;
  }
}

TEST_F(CliCameraAndBudgetFlags, MaxErrorPicksTheVariantFromTheCache) {
  FOGCL_REQUIRE_DEVICE();
  // Measure once through the API into the cache the CLI will read ($XDG_CACHE_HOME/fogcl).
  const std::string xdg = fresh_dir("xdg");
  BudgetOptions o;
  o.cache_dir = xdg + "/fogcl";
  o.measure = ReportOptions{24, 14, 7, false};
  const PrecisionChoice fastest = choose_precision_detailed(*runtime(), ColorFormat::rgba32f, 1e9, o);
  const std::string env = "XDG_CACHE_HOME='" + xdg + "'";

  PerspectiveCamera cam;
  cam.aspect = 48.0f / 27.0f;
  const std::string common = "apply --color " + in("scene.exr") + " --depth " + in("scene-depth.exr") +
                             " --near 0.3 --far 1000 --fov 60 --device " + cli_device() + " --verbose" + kExpFog;
  const std::string out = in("budget.exr");
  const CliRun r = run_cli(common + " --max-error 1 --out " + out, env);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::printf("%s", r.output.c_str());
  EXPECT_NE(r.output.find("read from the cache"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(std::string("precision: ") + to_string(fastest.precision) + " is the fastest"),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("candidate precise"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("candidate fast"), std::string::npos) << r.output;
  const ColorImage color = read_exr_color(in("scene.exr"));
  const FogResult<double> ref = fog_scalar<double>(color, read_exr_depth(in("scene-depth.exr")),
                                                   make_camera_params(cam), exp_fog());
  const ErrorStats e = compare_color(read_exr_color(out), ref, color, exp_fog().color);
  std::printf("[ worst    ] --max-error 1 (%s): rel %.2e\n", to_string(fastest.precision), e.max_rel);
  EXPECT_LE(e.max_rel, kColorRelBudget);
  EXPECT_EQ(e.alpha_changed, 0u);

  // Without a budget: precise, and said so.
  const CliRun plain = run_cli(common + " --out " + in("plain.exr"), env);
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_NE(plain.output.find("precision: precise (the default"), std::string::npos) << plain.output;

  // Below every variant: exit 1, one line naming the budget and the best achievable error.
  const CliRun tiny = run_cli(common + " --max-error 1e-12 --out " + in("tiny.exr"), env);
  EXPECT_EQ(tiny.exit_code, 1) << tiny.output;
  EXPECT_NE(tiny.output.find("fogcl: error: no precision variant meets the error budget (max error 1e-12)"),
            std::string::npos)
      << tiny.output;
  EXPECT_NE(tiny.output.find("best achievable"), std::string::npos) << tiny.output;
  EXPECT_FALSE(fs::exists(in("tiny.exr")));
}

}  // namespace
}  // namespace fogcl::test
