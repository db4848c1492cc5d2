// `fogcl report`: error against run time for every precision variant x color storage on the
// report's scenes (fogcl/report.h); writes report.csv, report.json and the Pareto plot report.png.
// `fogcl report --volumetric`: the same for the volumetric pass's variants (fogcl/volume_report.h);
// writes volume-report.csv, volume-report.json and volume-report.png.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>

#include "cli/cli.h"
#include "fogcl/error.h"
#include "fogcl/report.h"
#include "fogcl/volume_report.h"

namespace fogcl::cli {

int run_report(const ReportCliOptions& o) {
  namespace fs = std::filesystem;
  std::unique_ptr<Runtime> runtime;
  const std::string resolved = resolve_device_choice(o.device);
  try {
    if (resolved != "scalar") runtime = std::make_unique<Runtime>(resolved);
  } catch (const Error& e) {
    throw Error(device_choice_source(o.device) + e.what());
  }
  fs::create_directories(o.out_dir);  // once the device is there: a failed run leaves nothing

  ReportOptions options;
  options.width = o.width;
  options.height = o.height;
  options.runs = o.runs;
  std::printf("device: %s\nframes: %dx%d, median of %d runs (device time from profiling events; scalar: host time)\n\n",
              runtime ? runtime->description().c_str() : "scalar C++ (1 thread)", o.width, o.height, o.runs);
  std::fflush(stdout);
  const Report report = fogcl::run_report(runtime.get(), options);

  std::printf("| scene | variant | time ms | max err f | max err color | p99.9 err color | max ulp | %% 8-bit off | nonfinite |\n");
  std::printf("|---|---|--:|--:|--:|--:|--:|--:|--:|\n");
  for (const ReportRow& r : report.rows)
    std::printf("| %s | %s | %.3f | %.3g | %.3g | %.3g | %.3g | %.3g | %zu |\n", r.scene.c_str(), r.variant.c_str(),
                r.time_ms, r.max_abs_err_factor, r.max_abs_err_color, r.p999_abs_err_color, r.max_ulp, r.pct_8bit_off,
                r.nonfinite);
  std::printf("\neye depth from raw depth (float formulas), max relative error against the true eye depth:\n");
  for (const ReportRow& r : report.rows)
    if (r.eye_depth_rel_err >= 0 && r.variant == report.rows.front().variant)
      std::printf("  %-30s %.3g\n", r.scene.c_str(), r.eye_depth_rel_err);

  const std::string dir = o.out_dir;
  write_report_csv(report, (fs::path(dir) / "report.csv").string());
  write_report_json(report, (fs::path(dir) / "report.json").string());
  std::printf("\nwrote %s/report.csv and %s/report.json\n", dir.c_str(), dir.c_str());
  std::fflush(stdout);
  plot_report(dir);  // throws one line saying what to install when matplotlib is missing
  std::printf("wrote %s/report.png\n", dir.c_str());
  return 0;
}

VolumeReportOptions volume_report_options(const ReportCliOptions& o) {
  VolumeReportOptions options;
  options.width = o.width;
  options.height = o.height;
  options.runs = o.runs;
  if (!o.steps.empty()) options.steps = o.steps;
  options.scenes = o.scenes;  // the library names a scene it does not know
  if (!o.integrators.empty()) {
    options.integrators.clear();
    for (const std::string& name : o.integrators) {
      if (name == "stylized")
        options.integrators.push_back(VolumeIntegrator::stylized);
      else if (name == "physical")
        options.integrators.push_back(VolumeIntegrator::physical);
      else
        throw Error("--integrators: '" + name + "' is not one of stylized, physical");
    }
  }
  validate(options);
  return options;
}

int run_volume_report_cli(const ReportCliOptions& o) {
  namespace fs = std::filesystem;
  VolumeReportOptions options = volume_report_options(o);  // bad options are one line, before the device opens
  const std::string resolved = resolve_device_choice(o.device);
  if (resolved == "scalar")
    throw Error("fogcl report --volumetric measures OpenCL kernel variants; the scalar path (--device scalar) has none");
  const std::unique_ptr<Runtime> opened = [&] {
    try {
      return std::make_unique<Runtime>(resolved);
    } catch (const Error& e) {
      throw Error(device_choice_source(o.device) + e.what());
    }
  }();
  const Runtime& runtime = *opened;
  fs::create_directories(o.out_dir);  // once the device is there: a failed run leaves nothing
  std::size_t last_pct = 0;
  options.progress = [&](std::size_t done, std::size_t total) {
    const std::size_t pct = 100 * done / total;
    if (done == 0)
      std::fprintf(stderr, "%zu rows; the references first\n", total);
    else if (pct / 10 != last_pct / 10 || done == total)
      std::fprintf(stderr, "  %zu/%zu rows\n", done, total);
    last_pct = pct;
  };
  std::printf("device: %s\nframes: %dx%d, median of %d runs (device time from profiling events); reference: the "
              "scalar<double> march at %d steps, full resolution, no jitter; variants jittered (frame index 0)\n\n",
              runtime.description().c_str(), o.width, o.height, o.runs, options.reference_steps);
  std::fflush(stdout);
  const VolumeReport report = run_volume_report(runtime, options);
  std::printf("references: %.1f s\n\n", report.reference_seconds);

  std::printf("| scene | variant | time ms | max err | p99.9 err | %% 8-bit off | nonfinite |\n");
  std::printf("|---|---|--:|--:|--:|--:|--:|\n");
  for (const VolumeReportRow& r : report.rows)
    std::printf("| %s | %s | %.3f | %.3g | %.3g | %.3g | %zu |\n", r.scene.c_str(), r.variant.c_str(), r.time_ms,
                r.max_abs_err, r.p999_abs_err, r.pct_8bit_off, r.nonfinite);

  // The stiff case: the textbook sum against the exact segment weight, same steps.
  std::map<int, std::pair<double, double>> dense;  // steps -> (physical, riemann) max error
  for (const VolumeReportRow& r : report.rows)
    if (r.scene == "dense" && r.divisor == 1 && r.noise == NoiseSampling::buffer && r.storage == ColorFormat::rgba32f) {
      if (r.integrator == VolumeIntegrator::physical) dense[r.steps].first = r.max_abs_err;
      if (r.integrator == VolumeIntegrator::riemann) dense[r.steps].second = r.max_abs_err;
    }
  if (!dense.empty()) {
    std::printf("\ndense scene (sigma_t x diameter = 50), full resolution, rgba32f: max color error\n");
    std::printf("| steps | physical (exact segment weight) | riemann (textbook sum) |\n|--:|--:|--:|\n");
    for (const auto& [steps, e] : dense) std::printf("| %d | %.3g | %.3g |\n", steps, e.first, e.second);
  }

  const std::string dir = o.out_dir;
  write_volume_report_csv(report, (fs::path(dir) / "volume-report.csv").string());
  write_volume_report_json(report, (fs::path(dir) / "volume-report.json").string());
  std::printf("\nwrote %s/volume-report.csv and %s/volume-report.json\n", dir.c_str(), dir.c_str());
  std::fflush(stdout);
  plot_volume_report(dir);
  std::printf("wrote %s/volume-report.png\n", dir.c_str());
  return 0;
}

}  // namespace fogcl::cli
