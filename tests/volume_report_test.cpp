// Error against run time of the volumetric pass (fogcl report --volumetric), the volumetric error
// budget (--max-error with --volumes) and its cache, on small frames and few variants so the
// whole file runs in seconds.
#include "fogcl/volume_report.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "fogcl/demo_scene.h"
#include "fogcl/exr_io.h"
#include "fogcl/volume_pass.h"
#include "test_support.h"

namespace fogcl::test {
namespace {

namespace fs = std::filesystem;

// Few variants: 2 step counts x (full, half depth-aware, half bilinear) x 2 integrators, buffer
// noise, rgba32f, plus the Riemann rows on the dense scene.
VolumeReportOptions small_report() {
  VolumeReportOptions o;
  o.width = 32;
  o.height = 18;
  o.runs = 3;
  o.steps = {8, 64};
  o.divisors = {1, 2};
  o.noise = {NoiseSampling::buffer};
  o.storages = {ColorFormat::rgba32f};
  return o;
}

const VolumeReportRow* find(const VolumeReport& r, const std::string& scene, VolumeIntegrator integrator, int steps,
                            int divisor) {
  for (const VolumeReportRow& row : r.rows)
    if (row.scene == scene && row.integrator == integrator && row.steps == steps && row.divisor == divisor &&
        row.upsampling == VolumeUpsampling::depth_aware)
      return &row;
  return nullptr;
}

// ctest runs each test in a process of its own: each runs only the rows it checks.
TEST(VolumeReport, RowsAreSaneAndFilesAreWritten) {
  FOGCL_REQUIRE_DEVICE();
  const VolumeReport r = run_volume_report(*runtime(), small_report());
  // 4 volume scenes x 2 integrators x 2 steps x 3 resolutions/upsamplings, the light-shaft and the
  // street-lamp scenes' physical rows, + 2 Riemann rows.
  ASSERT_EQ(r.rows.size(), 4u * 2 * 2 * 3 + 2 * 2 * 3 + 2);
  EXPECT_EQ(r.reference_steps, 4096);
  for (const VolumeReportRow& row : r.rows) {
    std::printf("[ vreport ] %-7s %-44s %8.3f ms  max %.3g  p999 %.3g  8bit %.3g%%  nonfinite %zu\n", row.scene.c_str(),
                row.variant.c_str(), row.time_ms, row.max_abs_err, row.p999_abs_err, row.pct_8bit_off, row.nonfinite);
    EXPECT_GT(row.time_ms, 0.0) << row.variant;
    EXPECT_EQ(row.nonfinite, 0u) << row.scene << " " << row.variant;
    EXPECT_TRUE(std::isfinite(row.max_abs_err)) << row.scene << " " << row.variant;
    EXPECT_LE(row.p999_abs_err, row.max_abs_err) << row.scene << " " << row.variant;
    EXPECT_GE(row.pct_8bit_off, 0.0);
    EXPECT_LE(row.pct_8bit_off, 100.0);
    // Thin media keep their digits: sigma_t * diameter = 1e-4 changes colors by ~1e-4 at most; at full
    // resolution the error is float rounding (measured 1.0e-6 at most), at half resolution it is the
    // resolution's, a fraction of that change (measured 1.0e-5 on this 32 x 18 frame).
    if (row.scene == "thin") {
      EXPECT_LE(row.max_abs_err, row.divisor == 1 ? 2e-6 : 2e-5) << row.variant;
    }
  }

  const std::string dir = fresh_dir("volume-report");
  write_volume_report_csv(r, dir + "/volume-report.csv");
  write_volume_report_json(r, dir + "/volume-report.json");
  const auto csv = read_csv(dir + "/volume-report.csv");
  ASSERT_EQ(csv.size(), r.rows.size() + 1);
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < csv[0].size(); ++i) col[csv[0][i]] = i;
  for (const char* name : {"scene", "variant", "integrator", "steps", "resolution", "upsampling", "noise", "storage",
                           "time_ms", "max_abs_err", "p999_abs_err", "pct_8bit_off", "nonfinite"})
    ASSERT_TRUE(col.count(name)) << "column " << name;
  for (std::size_t i = 1; i < csv.size(); ++i) {
    ASSERT_EQ(csv[i].size(), csv[0].size()) << "row " << i;
    EXPECT_EQ(csv[i][col["variant"]], r.rows[i - 1].variant);
    EXPECT_EQ(std::stoi(csv[i][col["steps"]]), r.rows[i - 1].steps);
    for (const char* numeric : {"time_ms", "max_abs_err", "p999_abs_err", "pct_8bit_off", "nonfinite"}) {
      const std::string& text = csv[i][col[numeric]];
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      EXPECT_TRUE(!text.empty() && *end == '\0') << numeric << " '" << text << "'";
      EXPECT_TRUE(std::isfinite(v) && v >= 0) << numeric << " " << v;
    }
  }
  std::ifstream json(dir + "/volume-report.json");
  const std::string js((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  EXPECT_NE(js.find("\"reference_steps\": 4096"), std::string::npos) << js.substr(0, 400);
  EXPECT_NE(js.find("\"variant\": \"riemann-s8-full-buffer-rgba32f\""), std::string::npos);
  EXPECT_EQ(std::count(js.begin(), js.end(), '{'), std::ptrdiff_t(r.rows.size() + 1));

  if (!require_matplotlib()) return;
  plot_volume_report(dir);
  ASSERT_TRUE(fs::exists(dir + "/volume-report.png"));
  // src/report/plot_volume_report.py: a 5.4 x 4.3 inch panel per scene and one for the Riemann
  // rows, 100 dpi.
  expect_plot(dir + "/volume-report.png", 6 + 1, 5.4, 4.3, 100);
}

// The marched height fog's rows: physical only (its integrator), and at full resolution the shafts'
// error (the sun's visibility taken once per segment) shrinks as the steps grow, about as 1 / steps.
TEST(VolumeReport, ShaftErrorShrinksWithSteps) {
  FOGCL_REQUIRE_DEVICE();
  VolumeReportOptions o = small_report();
  o.width = 48;
  o.height = 27;
  o.scenes = {"shafts"};
  o.steps = {4, 16, 64};
  o.divisors = {1, 2};
  const VolumeReport r = run_volume_report(*runtime(), o);
  ASSERT_EQ(r.rows.size(), 3u * 3) << "3 steps x (full, half depth-aware, half bilinear), physical only";
  for (const VolumeReportRow& row : r.rows) {
    std::printf("[ vreport ] %-7s %-44s %8.3f ms  max %.3g  p999 %.3g  8bit %.3g%%\n", row.scene.c_str(),
                row.variant.c_str(), row.time_ms, row.max_abs_err, row.p999_abs_err, row.pct_8bit_off);
    EXPECT_EQ(row.integrator, VolumeIntegrator::physical) << row.variant;
    EXPECT_EQ(row.nonfinite, 0u) << row.variant;
  }
  const VolumeReportRow* prev = nullptr;
  for (int steps : o.steps) {
    const VolumeReportRow* row = find(r, "shafts", VolumeIntegrator::physical, steps, 1);
    ASSERT_TRUE(row) << steps;
    EXPECT_GT(row->max_abs_err, 0.0) << "the shafts are there: a coarse march misses part of them";
    if (prev != nullptr) {
      std::printf("  shafts, full resolution: max error %.3g (%d steps) -> %.3g (%d steps)\n", prev->max_abs_err,
                  prev->steps, row->max_abs_err, steps);
      // 4x the steps: the error falls about 4x; half of that is the property.
      EXPECT_LT(row->max_abs_err, 0.5 * prev->max_abs_err) << steps;
      EXPECT_LT(row->p999_abs_err, 0.5 * prev->p999_abs_err) << steps;
    }
    prev = row;
  }
}

// The street lamps in the marched mist: physical rows only; at full resolution the error (the
// per-piece transmittance, mist density, cone and phase) shrinks with the steps.
TEST(VolumeReport, LampErrorShrinksWithSteps) {
  FOGCL_REQUIRE_DEVICE();
  VolumeReportOptions o = small_report();
  o.scenes = {"lamps"};
  o.divisors = {1};
  const VolumeReport r = run_volume_report(*runtime(), o);
  ASSERT_EQ(r.rows.size(), 2u) << "8 and 64 steps, full resolution, physical only";
  const VolumeReportRow* coarse = find(r, "lamps", VolumeIntegrator::physical, 8, 1);
  const VolumeReportRow* fine = find(r, "lamps", VolumeIntegrator::physical, 64, 1);
  ASSERT_TRUE(coarse && fine);
  std::printf("  lamps, full resolution: max error %.3g (8 steps) -> %.3g (64 steps), p99.9 %.3g -> %.3g\n",
              coarse->max_abs_err, fine->max_abs_err, coarse->p999_abs_err, fine->p999_abs_err);
  EXPECT_EQ(coarse->nonfinite + fine->nonfinite, 0u);
  EXPECT_GT(coarse->max_abs_err, 0.0);
  EXPECT_LT(fine->max_abs_err, 0.5 * coarse->max_abs_err);
  EXPECT_LT(fine->p999_abs_err, 0.5 * coarse->p999_abs_err);
  // A report of one scene is one panel, drawn 8.6 inches wide so that its title and legend fit.
  if (!require_matplotlib()) return;
  const std::string dir = fresh_dir("volume-report-lamps");
  write_volume_report_csv(r, dir + "/volume-report.csv");
  plot_volume_report(dir);
  expect_plot(dir + "/volume-report.png", 1, 8.6, 4.3, 100);
}

TEST(VolumeReport, PhysicalErrorShrinksWithStepsOnTheDemo) {
  FOGCL_REQUIRE_DEVICE();
  VolumeReportOptions o = small_report();
  o.scenes = {"demo"};
  o.divisors = {1};
  const VolumeReport r = run_volume_report(*runtime(), o);
  // Full resolution: no upsampling error, the march's own. (The stylized march's adaptive
  // stepping moves its samples discontinuously with the step count: not monotone, printed only.)
  for (VolumeIntegrator i : {VolumeIntegrator::physical, VolumeIntegrator::stylized}) {
    const VolumeReportRow* coarse = find(r, "demo", i, 8, 1);
    const VolumeReportRow* fine = find(r, "demo", i, 64, 1);
    ASSERT_TRUE(coarse && fine);
    std::printf("  demo, %s, full resolution: max error %.3g (8 steps) -> %.3g (64 steps)\n", to_string(i),
                coarse->max_abs_err, fine->max_abs_err);
    if (i == VolumeIntegrator::physical) {
      EXPECT_LT(fine->max_abs_err, 0.5 * coarse->max_abs_err);
      EXPECT_LT(fine->p999_abs_err, 0.5 * coarse->p999_abs_err);
    }
  }
}

TEST(VolumeReport, PhysicalIsFarBelowTheRiemannSumOnTheDenseScene) {
  FOGCL_REQUIRE_DEVICE();
  VolumeReportOptions o = small_report();
  o.scenes = {"dense"};
  o.divisors = {1};
  o.integrators = {VolumeIntegrator::physical};
  const VolumeReport r = run_volume_report(*runtime(), o);
  ASSERT_EQ(r.rows.size(), 2u * 2) << "physical and riemann at 8 and 64 steps";
  for (int steps : {8, 64}) {
    const VolumeReportRow* physical = find(r, "dense", VolumeIntegrator::physical, steps, 1);
    const VolumeReportRow* riemann = find(r, "dense", VolumeIntegrator::riemann, steps, 1);
    ASSERT_TRUE(physical && riemann) << steps;
    std::printf("  dense, %d steps: physical %.3g, riemann %.3g\n", steps, physical->max_abs_err, riemann->max_abs_err);
    // Constant extinction: the exact segment weight leaves float rounding only.
    EXPECT_LE(physical->max_abs_err, 1e-4);
    EXPECT_GT(riemann->max_abs_err, 1000.0 * physical->max_abs_err);
  }
  EXPECT_LT(find(r, "dense", VolumeIntegrator::riemann, 64, 1)->max_abs_err,
            find(r, "dense", VolumeIntegrator::riemann, 8, 1)->max_abs_err)
      << "the Riemann sum converges, slowly";
}

TEST(VolumeReportOptionsCheck, BadOptionsNameTheValueAndTheRule) {
  FOGCL_REQUIRE_DEVICE();
  const struct {
    std::function<void(VolumeReportOptions&)> change;
    std::string expect;
  } cases[] = {
      {[](VolumeReportOptions& o) { o.runs = 2; }, "runs must be >= 3 for a median (got 2)"},
      {[](VolumeReportOptions& o) { o.steps = {0}; }, "steps must be in [1, 4096] (got 0)"},
      {[](VolumeReportOptions& o) { o.divisors = {3}; }, "divisor must be 1, 2 or 4 (got 3)"},
      {[](VolumeReportOptions& o) { o.scenes = {"fog"}; }, "scene 'fog' is not one of"},
      {[](VolumeReportOptions& o) {
         o.scenes = {"shafts"};
         o.integrators = {VolumeIntegrator::stylized};
       },
       "scene 'shafts' marches the height fog, which needs the physical integrator"},
      {[](VolumeReportOptions& o) { o.width = 0; }, "frame size must be >= 1x1 (got 0x90)"},
      {[](VolumeReportOptions& o) { o.noise = {NoiseSampling::automatic}; },
       "noise sampling must be buffer or image (got auto)"},
  };
  for (const auto& c : cases) {
    VolumeReportOptions o;
    c.change(o);
    try {
      run_volume_report(*runtime(), o);
      ADD_FAILURE() << "accepted: " << c.expect;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(c.expect), std::string::npos) << e.what();
    }
  }
}

// The budget's measurement: small frames, two step counts, full and half resolution.
VolumeBudgetOptions small_budget(const std::string& cache_dir) {
  VolumeBudgetOptions o;
  o.cache_dir = cache_dir;
  o.measure.width = 24;
  o.measure.height = 14;
  o.measure.runs = 3;
  o.measure.steps = {8, 64};  // the report test's: PoCL's program cache serves both
  o.measure.divisors = {1, 2};
  o.measure.noise = {NoiseSampling::buffer};
  o.measure.reference_steps = 1024;
  return o;
}

TEST(VolumeErrorBudget, PicksTheFastestMeetingTheBudgetAndReadsItsCache) {
  FOGCL_REQUIRE_DEVICE();
  const VolumeBudgetOptions o = small_budget(fresh_dir("volume-budget"));
  VolumeSettings base;
  base.integrator = VolumeIntegrator::physical;
  const std::size_t before = volume_budget_measurements();

  const VolumeQualityChoice first = choose_volume_quality(*runtime(), base, ColorFormat::rgba32f, 1e9, o);
  EXPECT_FALSE(first.from_cache);
  EXPECT_EQ(volume_budget_measurements(), before + 1);
  ASSERT_TRUE(fs::exists(first.cache_file)) << first.cache_file;
  ASSERT_EQ(first.candidates.size(), 2u * 3) << "2 steps x (full, half depth-aware, half bilinear)";
  for (const VolumeVariantMeasurement& m : first.candidates)
    std::printf("[ vbudget  ] %-28s worst error %.3g, %.3f ms\n",
                volume_quality_name(m.steps, m.divisor, m.upsampling, m.noise).c_str(), m.max_abs_err, m.time_ms);
  for (std::size_t i = 1; i < first.candidates.size(); ++i)
    EXPECT_LE(first.candidates[i - 1].time_ms, first.candidates[i].time_ms) << "fastest first";
  EXPECT_EQ(first.chosen.time_ms, first.candidates[0].time_ms) << "a huge budget picks the fastest";
  EXPECT_EQ(first.settings.integrator, VolumeIntegrator::physical) << "the integrator is the caller's";
  EXPECT_FALSE(first.reason.empty());

  // A budget between the most and the least accurate: the fastest variant meeting it, read from
  // the cache this time.
  double lo = INFINITY, hi = 0;
  for (const VolumeVariantMeasurement& m : first.candidates)
    lo = std::min(lo, m.max_abs_err), hi = std::max(hi, m.max_abs_err);
  ASSERT_LT(lo, hi);
  const double budget = std::sqrt(lo * hi);
  const VolumeQualityChoice second = choose_volume_quality(*runtime(), base, ColorFormat::rgba32f, budget, o);
  EXPECT_TRUE(second.from_cache);
  EXPECT_EQ(volume_budget_measurements(), before + 1) << "the second call reads the cache";
  std::printf("[ vbudget  ] budget %.3g: %s\n", budget, second.reason.c_str());
  EXPECT_LE(second.chosen.max_abs_err, budget);
  for (const VolumeVariantMeasurement& m : second.candidates)
    if (m.time_ms < second.chosen.time_ms) {
      EXPECT_GT(m.max_abs_err, budget) << "a faster variant met the budget";
    }
  EXPECT_EQ(second.settings.steps, second.chosen.steps);
  EXPECT_EQ(second.settings.resolution_divisor, second.chosen.divisor);
  EXPECT_EQ(second.settings.upsampling, second.chosen.upsampling);

  // Below every variant: a clear error naming the budget and the best achievable error.
  try {
    choose_volume_quality(*runtime(), base, ColorFormat::rgba32f, 1e-12, o);
    ADD_FAILURE() << "a 1e-12 budget was met";
  } catch (const Error& e) {
    const std::string m = e.what();
    std::printf("[ message  ] %s\n", m.c_str());
    EXPECT_NE(m.find("max error 1e-12"), std::string::npos) << m;
    EXPECT_NE(m.find("best achievable"), std::string::npos) << m;
  }
  EXPECT_THROW(choose_volume_quality(*runtime(), base, ColorFormat::rgba32f, -1.0, o), Error);
  EXPECT_EQ(volume_budget_measurements(), before + 1);
}

// With the marched height fog the budget is measured apart (its own cache), over the light-shaft
// scene too: its worst error is at least the volume scenes' own.
TEST(VolumeErrorBudget, TheMarchedHeightFogIsMeasuredWithTheShaftScene) {
  FOGCL_REQUIRE_DEVICE();
  const VolumeBudgetOptions o = small_budget(fresh_dir("volume-budget-height"));
  VolumeSettings volumes_only;
  volumes_only.integrator = VolumeIntegrator::physical;
  VolumeSettings height = volumes_only;
  height.height_fog = demo_shaft_fog();
  const std::size_t before = volume_budget_measurements();
  const VolumeQualityChoice a = choose_volume_quality(*runtime(), volumes_only, ColorFormat::rgba32f, 1e9, o);
  const VolumeQualityChoice b = choose_volume_quality(*runtime(), height, ColorFormat::rgba32f, 1e9, o);
  EXPECT_EQ(volume_budget_measurements(), before + 2) << "two measurements: the height fog's is its own";
  EXPECT_NE(a.cache_file, b.cache_file);
  EXPECT_TRUE(b.settings.height_fog.has_value()) << "the caller's settings come back with the choice";
  std::ifstream cache(b.cache_file);
  const std::string text((std::istreambuf_iterator<char>(cache)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("integrator,physical+height-fog"), std::string::npos) << text;
  ASSERT_EQ(a.candidates.size(), b.candidates.size());
  for (const VolumeVariantMeasurement& m : b.candidates)
    for (const VolumeVariantMeasurement& n : a.candidates)
      if (m.steps == n.steps && m.divisor == n.divisor && m.upsampling == n.upsampling) {
        std::printf("[ vbudget  ] %-28s worst error %.3g with the marched fog, %.3g without\n",
                    volume_quality_name(m.steps, m.divisor, m.upsampling, m.noise).c_str(), m.max_abs_err,
                    n.max_abs_err);
        EXPECT_GE(m.max_abs_err, n.max_abs_err) << "the worst over more scenes";
      }
  EXPECT_NE(b.reason.find("with the marched height fog"), std::string::npos) << b.reason;
}

// fogcl apply's camera flags for the demo's view (DemoView), exact to float.
std::string demo_pose_flags() {
  const DemoView view;
  const glm::vec3 fwd = view.target - view.eye;
  char pose[256];
  std::snprintf(pose, sizeof pose, " --eye %.9g,%.9g,%.9g --forward %.9g,%.9g,%.9g --up 0,1,0", view.eye.x, view.eye.y,
                view.eye.z, fwd.x, fwd.y, fwd.z);
  return pose;
}

// fogcl apply --volumes --max-error: reads the cache the API wrote, prints the choice, runs it.
TEST(VolumeErrorBudgetCli, MaxErrorPicksTheVariantAndExplicitFlagsConflict) {
  FOGCL_REQUIRE_DEVICE();
  const std::string dir = fresh_dir("volume-budget-cli");
  const DemoFrame frame = render_demo_scene(48, 27);
  write_exr_rgba(dir + "/scene.exr", frame.color);
  write_exr_depth(dir + "/scene-depth.exr", frame.depth);
  std::ofstream(dir + "/volumes.json") << R"({"volumes": [{"center": [0.5, 1.5, 4], "radius": 2.5, "density": 0.6,
      "fade_edge": 1, "proximity_fade": 0.5, "tiling": [0.2, 0.2, 0.2], "detail_tiling": [0.6, 0.6, 0.6]}]})";
  const ColorFormat storage = read_exr_color(dir + "/scene.exr").format();
  VolumeSettings base;  // stylized, as the CLI's default
  const VolumeQualityChoice measured =
      choose_volume_quality(*runtime(), base, storage, 1e9, small_budget(dir + "/xdg/fogcl"));
  const std::string pose = demo_pose_flags();
  const std::string common = "apply --color " + dir + "/scene.exr --depth " + dir +
                             "/scene-depth.exr --near 0.3 --far 1000 --fov 60 --volumes " + dir + "/volumes.json" +
                             pose + " --device " + cli_device();
  const std::string env = "XDG_CACHE_HOME='" + dir + "/xdg'";

  const CliRun r = run_cli(common + " --verbose --max-error 1e9 --out " + dir + "/out.exr", env);
  std::printf("%s", r.output.c_str());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("measurement read from the cache"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("CHOSEN"), std::string::npos) << r.output;
  const std::string chosen = volume_quality_name(measured.chosen.steps, measured.chosen.divisor,
                                                 measured.chosen.upsampling, measured.chosen.noise);
  EXPECT_NE(r.output.find("volumes: " + chosen + " is the fastest variant"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("precision: not chosen (--mode off"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(std::to_string(measured.chosen.steps) + " steps"), std::string::npos) << r.output;

  // The explicit flags the budget picks are a contradiction with it: exit 1, one line, no file.
  for (const std::string flag :
       {"--steps 32", "--volume-resolution full", "--upsample bilinear", "--noise-sampling buffer"}) {
    const CliRun bad = run_cli(common + " --max-error 1 " + flag + " --out " + dir + "/bad.exr", env);
    std::printf("[ message  ] %s", bad.output.c_str());
    EXPECT_EQ(bad.exit_code, 1) << flag << ": " << bad.output;
    EXPECT_NE(bad.output.find("give either " + flag.substr(0, flag.find(' ')) + " or --max-error"), std::string::npos)
        << bad.output;
    EXPECT_FALSE(fs::exists(dir + "/bad.exr"));
  }
  const CliRun tiny = run_cli(common + " --max-error 1e-12 --out " + dir + "/tiny.exr", env);
  EXPECT_EQ(tiny.exit_code, 1) << tiny.output;
  EXPECT_NE(tiny.output.find("no volumetric variant meets the error budget (max error 1e-12)"), std::string::npos)
      << tiny.output;
  EXPECT_FALSE(fs::exists(dir + "/tiny.exr"));
}

// fogcl apply --mode height --height-volumetric --max-error, without --volumes: the budget picks the
// march's variant from the marched fog's own measurement (here the cache the API wrote).
TEST(VolumeErrorBudgetCli, MaxErrorPicksTheMarchedHeightFogsVariant) {
  FOGCL_REQUIRE_DEVICE();
  const std::string dir = fresh_dir("volume-budget-height-cli");
  const DemoFrame frame = render_demo_scene(48, 27);
  write_exr_rgba(dir + "/scene.exr", frame.color);
  write_exr_depth(dir + "/scene-depth.exr", frame.depth);
  VolumeSettings base;
  base.integrator = VolumeIntegrator::physical;
  base.height_fog = demo_shaft_fog();
  const ColorFormat storage = read_exr_color(dir + "/scene.exr").format();
  const VolumeQualityChoice measured =
      choose_volume_quality(*runtime(), base, storage, 1e9, small_budget(dir + "/xdg/fogcl"));
  const std::string pose = demo_pose_flags();
  const std::string cmd = "apply --color " + dir + "/scene.exr --depth " + dir +
                          "/scene-depth.exr --near 0.3 --far 1000 --fov 60 --mode height --density 0.05 "
                          "--height-falloff 0.3 --height-volumetric --verbose --max-error 1e9" +
                          pose + " --device " + cli_device() + " --out " + dir + "/out.exr";
  const CliRun r = run_cli(cmd, "XDG_CACHE_HOME='" + dir + "/xdg'");
  std::printf("%s", r.output.c_str());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("measurement read from the cache"), std::string::npos) << r.output;
  const std::string chosen = volume_quality_name(measured.chosen.steps, measured.chosen.divisor,
                                                 measured.chosen.upsampling, measured.chosen.noise);
  EXPECT_NE(r.output.find("volumes: " + chosen + " is the fastest variant"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("with the marched height fog"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(dir + "/out.exr"));
}

// fogcl report's volumetric flags: bad values and misplaced flags are one line, exit 1, before
// any measurement.
TEST(VolumeReportCli, BadFlagsAreOneLineErrors) {
  const std::string out = fresh_dir("volume-report-cli");
  const struct {
    std::string args, expect;
  } cases[] = {
      {"--volumetric --device scalar", "the scalar path (--device scalar) has none"},
      {"--volumetric --integrators riemann", "--integrators must be one of stylized or physical (got 'riemann')"},
      {"--volumetric --runs 2 --device " + cli_device(), "--runs must be >= 3 with --volumetric (got 2)"},
      {"--volumetric --scenes fog,dense --device " + cli_device(),
       "--scenes must be one of demo, dense, thin, inside, shafts or lamps (got 'fog') in 'fog,dense'"},
      {"--steps 8", "--steps selects volumetric variants; it needs --volumetric"},
      {"--runs 5", "--runs must be >= 7 for the deferred report (got 5)"},
  };
  for (const auto& c : cases) {
    const CliRun r = run_cli("report --out " + out + " " + c.args);
    std::printf("[ message  ] %s", r.output.c_str());
    EXPECT_EQ(r.exit_code, 1) << c.args << ": " << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.args << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << c.args << ": " << r.output;
    EXPECT_FALSE(fs::exists(out + "/volume-report.csv")) << c.args;
  }
}

}  // namespace
}  // namespace fogcl::test
