// Error against run time (docs/DESIGN.md §4, docs/accuracy.md): every precision variant x color storage on a set
// of scenes, each measured against the float64 path; and the error budget that picks the fastest
// precision variant meeting a maximum error, measured once per device and library version.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "fogcl/fog_settings.h"
#include "fogcl/image.h"
#include "fogcl/runtime.h"
#include "fogcl/version.h"  // library_version()

namespace fogcl {


struct ReportOptions {
  int width = 640;    // frame size of every scene [pixels], >= 1
  int height = 360;   // >= 1
  int runs = 9;       // timed runs per (scene, variant); the median is reported; >= 7
  bool scalar = true; // also a row for the scalar float path (host time)
};

// One (scene, variant) measurement. Errors are against fog_scalar<double> on the same input
// (for half storage: the input rounded to half), over every pixel's R, G, B.
struct ReportRow {
  std::string scene;    // "demo", "wide-fov-120", ...
  std::string variant;  // "precise-rgba32f", "fast-rgba16f", "scalar-rgba32f"
  bool scalar = false;  // the scalar C++ path (its time is host time)
  Precision precision = Precision::precise;
  ColorFormat storage = ColorFormat::rgba32f;
  double time_ms = 0;             // median of `runs`: device time from CL profiling events of
                                  // FogPass::enqueue on zero-copy buffers; scalar: host time
  double max_abs_err_factor = 0;  // max |f - f64| from a probe run (color 1, fog color 0: out = f)
  double max_abs_err_color = 0;   // max |color - f64|
  double p999_abs_err_color = 0;  // 99.9th percentile of |color - f64|
  double max_ulp = 0;             // max |color - f64| in ulps of the storage type at the f64 value
  double pct_8bit_off = 0;        // % of pixels whose 8-bit sRGB code differs (>= 1) in any channel
  std::size_t nonfinite = 0;      // NaN/Inf values produced from finite input (color and probe)
  double eye_depth_rel_err = -1;  // far/near scenes only: max |eye depth - true| / true of the
                                  // float formulas over the depth range; -1 elsewhere
};

struct Report {
  std::string device;   // "scalar" or the OpenCL device's description
  std::string driver;   // CL_DRIVER_VERSION ("" for scalar)
  std::string version;  // library_version()
  int width = 0, height = 0, runs = 0;
  std::vector<ReportRow> rows;  // scene-major, in the order of report_scene_names()
};

// "demo", "wide-fov-120", "near0.01-far1e6-conventional", "near0.01-far1e6-reversed",
// "dense-exp", "thin-exp2", "height-valley", "height-haze-sun" (height fog: docs/DESIGN.md §6).
std::vector<std::string> report_scene_names();

// Runs every precision variant (precise, fast) x storage (rgba32f, rgba16f) on `runtime`'s device
// (none when runtime is null), plus the scalar float path when options.scalar, on every scene.
// Throws fogcl::Error for bad options, fogcl::ClError for OpenCL failures.
Report run_report(const Runtime* runtime, const ReportOptions& options = {});

// report.csv: a header row, then one row per (scene, variant) with the columns
// scene,variant,time_ms,max_abs_err_factor,max_abs_err_color,p999_abs_err_color,max_ulp,
// pct_8bit_off,nonfinite,eye_depth_rel_err (empty where it does not apply).
void write_report_csv(const Report& report, const std::string& path);
// report.json: {"device", "driver", "version", "width", "height", "runs", "rows": [{...}, ...]}.
void write_report_json(const Report& report, const std::string& path);

// Renders `dir`/report.png (a Pareto plot: log error against time, one panel per scene) from
// `dir`/report.csv with matplotlib, running `python` with the plotting script (embedded in the
// library) on its stdin. Throws fogcl::Error with one line saying what to install when python
// or matplotlib is missing, or what failed otherwise.
void plot_report(const std::string& dir, const std::string& python = "/usr/bin/python3");

// --- Error budget ------------------------------------------------------------------------------

// One precision variant for one storage format, over all report scenes.
struct VariantMeasurement {
  Precision precision = Precision::precise;
  ColorFormat storage = ColorFormat::rgba32f;
  double max_abs_err_color = 0;  // worst over the report's scenes
  double time_ms = 0;            // sum of the scenes' median device times
};

struct BudgetOptions {
  std::string cache_dir;    // "" = $XDG_CACHE_HOME/fogcl, else ~/.cache/fogcl
  ReportOptions measure{640, 360, 7, false};  // how a missing measurement is taken
};

struct PrecisionChoice {
  Precision precision = Precision::precise;
  double max_error = 0;                      // the budget asked for
  std::vector<VariantMeasurement> candidates; // of the storage asked for, fastest first
  bool from_cache = false;                    // true: read from cache_file, nothing was measured
  std::string cache_file;
  std::string measured_on;                    // "640x360, 7 runs" of the cached measurement
  std::string reason;                         // one line: why this variant
};

// The fastest precision variant whose measured worst color error (max_abs_err_color over the
// report's scenes, for `storage`) is <= max_error on the runtime's device. The measurement is
// cached in <cache_dir>/error-budget-<key>.csv keyed by device name, driver version and library
// version, so it runs once. Throws fogcl::Error naming max_error and the best achievable error
// when no variant meets it (and for a max_error that is NaN or < 0).
PrecisionChoice choose_precision_detailed(const Runtime& runtime, ColorFormat storage, double max_error,
                                          const BudgetOptions& options = {});
Precision choose_precision(const Runtime& runtime, ColorFormat storage, double max_error);

// Measurements taken (cache misses) in this process; a cache hit does not count.
std::size_t budget_measurements();

}  // namespace fogcl
