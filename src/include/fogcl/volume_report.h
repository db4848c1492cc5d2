// Error against run time of the volumetric pass (docs/volumetric.md §Error against run
// time): every variant of steps x resolution x upsampling x noise sampling x integrator x color
// storage on four scenes, each measured against the scalar<double> march at 4096 steps, full
// resolution, no jitter; and the error budget that picks the fastest variant meeting a maximum
// error, measured once per device, library version, integrator and storage.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "fogcl/image.h"
#include "fogcl/runtime.h"
#include "fogcl/volumes.h"

namespace fogcl {

struct VolumeReportOptions {
  int width = 160;                                  // frame size of every scene [pixels], >= 1
  int height = 90;                                  // >= 1
  int runs = 5;                                     // timed runs per row; the median is reported; >= 3
  std::vector<int> steps{8, 16, 32, 64, 128, 256};  // each in [1, 4096]
  std::vector<int> divisors{1, 2, 4};               // resolution: 1 full, 2 half, 4 quarter
  bool bilinear = true;                             // below full resolution: bilinear rows beside depth-aware ones
  std::vector<NoiseSampling> noise{NoiseSampling::buffer, NoiseSampling::image};  // image: devices with images
  std::vector<VolumeIntegrator> integrators{VolumeIntegrator::stylized, VolumeIntegrator::physical};
  std::vector<ColorFormat> storages{ColorFormat::rgba32f, ColorFormat::rgba16f};
  bool riemann = true;              // rows of the textbook Riemann sum on the dense scene (full
                                    // resolution, buffer noise, rgba32f), against the physical reference
  int reference_steps = 4096;       // the reference march's steps, in [1, 4096]
  std::vector<std::string> scenes;  // names from volume_report_scene_names(); empty = all
  // When set: called with done = 0 before the references, then after each row.
  std::function<void(std::size_t done, std::size_t total)> progress;
};

// One (scene, variant) measurement; errors against the reference over every pixel's R, G, B.
struct VolumeReportRow {
  std::string scene;    // "demo", "dense", "thin", "inside", "shafts", "lamps"
  std::string variant;  // "physical-s64-half-depth-buffer-rgba32f", ...
  VolumeIntegrator integrator = VolumeIntegrator::stylized;
  int steps = 0;
  int divisor = 1;
  VolumeUpsampling upsampling = VolumeUpsampling::depth_aware;  // depth-aware at full resolution
  NoiseSampling noise = NoiseSampling::buffer;
  ColorFormat storage = ColorFormat::rgba32f;
  double time_ms = 0;         // median of `runs`: device time from CL profiling events, from a
                              // marker enqueued just before the march to the composite's end
  double max_abs_err = 0;     // max |color - f64| (NaN counts as +inf)
  double p999_abs_err = 0;    // 99.9th percentile of |color - f64|
  double pct_8bit_off = 0;    // % of pixels whose 8-bit sRGB code differs (>= 1) in any channel
  std::size_t nonfinite = 0;  // NaN/Inf values in the output
};

struct VolumeReport {
  std::string device, driver, version;
  int width = 0, height = 0, runs = 0, reference_steps = 0;
  double reference_seconds = 0;       // wall time of the references (threads over scenes)
  std::vector<VolumeReportRow> rows;  // scene-major, in the order of volume_report_scene_names()
};

// "demo" (demo_fog_volumes(), the camera inside one of them), "dense" (one sphere, no noise,
// sigma_t * diameter = 50), "thin" (one noisy sphere, sigma_t * diameter = 1e-4 at full noise),
// "inside" (the camera inside one noisy volume): the demo scene's frame, camera and light.
// "shafts": no volumes, the height fog marched (VolumeSettings::height_fog = demo_shaft_fog())
// under demo_low_sun() with the scene's shadow map for that sun (1024x1024): light shafts; its
// rows are the physical integrator's only (the marched fog's). "lamps": no volumes, the night
// frame (demo_night_frame()) in a marched mist (demo_night_fog()) lit by demo_street_lamps()'s
// spot and point lights; physical only too.
std::vector<std::string> volume_report_scene_names();
// true for the scenes whose rows march the height fog ("shafts", "lamps").
bool volume_report_scene_marches_height_fog(const std::string& scene);

// Throws fogcl::Error naming the value and the rule for bad options (all but what depends on the
// device: image noise sampling needs image support).
void validate(const VolumeReportOptions& options);

// Runs every variant of `options` on the runtime's device. Throws fogcl::Error for bad options
// (naming the value and the rule), fogcl::ClError for OpenCL failures.
VolumeReport run_volume_report(const Runtime& runtime, const VolumeReportOptions& options = {});

// volume-report.csv: a header row, then one row per (scene, variant) with the columns
// scene,variant,integrator,steps,resolution,upsampling,noise,storage,time_ms,max_abs_err,
// p999_abs_err,pct_8bit_off,nonfinite.
void write_volume_report_csv(const VolumeReport& report, const std::string& path);
// volume-report.json: {"device", "driver", "version", "width", "height", "runs", "reference_steps",
// "rows": [{...}, ...]}.
void write_volume_report_json(const VolumeReport& report, const std::string& path);
// `dir`/volume-report.png from `dir`/volume-report.csv (matplotlib; see plot_report).
void plot_volume_report(const std::string& dir, const std::string& python = "/usr/bin/python3");

// "s64 half depth-aware buffer": the quality part of a variant.
std::string volume_quality_name(int steps, int divisor, VolumeUpsampling upsampling, NoiseSampling noise);

// --- Error budget ------------------------------------------------------------------------------

// One quality variant (steps, resolution, upsampling, noise sampling) over the report's scenes.
struct VolumeVariantMeasurement {
  int steps = 0;
  int divisor = 1;
  VolumeUpsampling upsampling = VolumeUpsampling::depth_aware;
  NoiseSampling noise = NoiseSampling::buffer;
  double max_abs_err = 0;  // worst max |color - f64| over the scenes
  double time_ms = 0;      // sum of the scenes' median device times
};

struct VolumeBudgetOptions {
  std::string cache_dir;        // "" = $XDG_CACHE_HOME/fogcl, else ~/.cache/fogcl
  VolumeReportOptions measure;  // how a missing measurement is taken (integrator, storage and
                                // riemann are set by the budget)
};

struct VolumeQualityChoice {
  VolumeSettings settings;  // `base` with steps, resolution, upsampling and noise sampling chosen
  double max_error = 0;     // the budget asked for
  VolumeVariantMeasurement chosen;
  std::vector<VolumeVariantMeasurement> candidates;  // fastest first
  bool from_cache = false;                           // true: read from cache_file, nothing was measured
  std::string cache_file;
  std::string measured_on;  // "160x90, median of 5 runs, reference 4096 steps"
  std::string reason;       // one line: why this variant
};

// The fastest quality variant whose measured worst color error over the report's scenes, with
// base.integrator and `storage`, is <= max_error on the runtime's device. The measurement is cached
// in <cache_dir>/volume-budget-<key>.csv keyed by device name, driver version, library version,
// integrator and storage, so it runs once. Throws fogcl::Error naming max_error and the best
// achievable error when no variant meets it (and for a max_error that is NaN or < 0).
VolumeQualityChoice choose_volume_quality(const Runtime& runtime, const VolumeSettings& base, ColorFormat storage,
                                          double max_error, const VolumeBudgetOptions& options = {});

// Volumetric measurements taken (cache misses) in this process; a cache hit does not count.
std::size_t volume_budget_measurements();

}  // namespace fogcl
