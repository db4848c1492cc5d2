// `fogcl report`: error against run time for every precision variant x color storage on the
// report's scenes (fogcl/report.h); writes report.csv, report.json and the Pareto plot report.png.
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli/cli.h"
#include "fogcl/report.h"

namespace fogcl::cli {

int run_report(const ReportCliOptions& o) {
  namespace fs = std::filesystem;
  fs::create_directories(o.out_dir);
  std::unique_ptr<Runtime> runtime;
  const std::string resolved = resolve_device_choice(o.device);
  if (resolved != "scalar") runtime = std::make_unique<Runtime>(resolved);

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

}  // namespace fogcl::cli
