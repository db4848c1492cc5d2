// The volumetric error budget: the fastest quality variant (steps, resolution,
// upsampling, noise sampling) whose measured worst color error on the volume report's scenes meets
// a maximum, measured once per (device, driver, library version + kernel digest, integrator, marched height
// fog or not, storage) and cached as
// a small CSV file under $XDG_CACHE_HOME/fogcl, like the deferred pass's (budget.cpp).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "fogcl/error.h"
#include "fogcl/volume_report.h"
#include "report/report_common.h"

namespace fogcl {

namespace {

namespace fs = std::filesystem;
using report_detail::one_line;
using report_detail::short_num;

std::atomic<std::size_t> g_measurements{0};

constexpr const char* kHeader = "steps,divisor,upsampling,noise,max_abs_err,time_ms";

struct Cached {
  std::string measured_on;
  std::vector<VolumeVariantMeasurement> all;
};

using report_detail::parse_named;
bool parse_number(const std::string& s, double* v) {
  char* end = nullptr;
  *v = std::strtod(s.c_str(), &end);
  return end != s.c_str() && *end == '\0';
}

// Metadata lines "key,value" the cache must match to be trusted.
// What the measurement covers: the integrator, and whether the pass marches the height fog (then
// the light-shaft scene is measured with the volume scenes).
std::string measured_kind(const VolumeSettings& base) {
  return std::string(to_string(base.integrator)) + (base.height_fog ? "+height-fog" : "");
}

std::map<std::string, std::string> cache_meta(const report_detail::DeviceKey& key, const VolumeSettings& base,
                                              ColorFormat storage) {
  return {{"device", one_line(key.device)},
          {"driver", one_line(key.driver)},
          {"version", key.version},
          {"integrator", measured_kind(base)},
          {"storage", to_string(storage)}};
}

// false when missing, unreadable, for another key or malformed (then it is measured again).
bool read_cache(const std::string& path, const std::map<std::string, std::string>& expect, Cached* out) {
  std::map<std::string, std::string> meta;
  std::vector<std::vector<std::string>> rows;
  if (!report_detail::read_cache_table(path, kHeader, &meta, &rows)) return false;
  for (const std::vector<std::string>& cells : rows) {
    if (cells.size() != 6) return false;
    VolumeVariantMeasurement m;
    double steps = 0, divisor = 0;
    if (!parse_number(cells[0], &steps) || !parse_number(cells[1], &divisor) ||
        !parse_named(cells[2], {VolumeUpsampling::depth_aware, VolumeUpsampling::bilinear}, &m.upsampling) ||
        !parse_named(cells[3], {NoiseSampling::buffer, NoiseSampling::image}, &m.noise) ||
        !parse_number(cells[4], &m.max_abs_err) || !parse_number(cells[5], &m.time_ms))
      return false;
    m.steps = int(steps);
    m.divisor = int(divisor);
    out->all.push_back(m);
  }
  for (const auto& [k, v] : expect)
    if (meta[k] != v) return false;
  out->measured_on = meta["measured"];
  return !out->all.empty();
}

void write_cache(const std::string& path, const std::map<std::string, std::string>& meta, const Cached& c) {
  std::ostringstream s;
  s << "# fogcl volumetric error-budget measurement (fogcl report --volumetric's scenes); delete this file to "
       "measure again\n";
  for (const auto& [k, v] : meta) s << k << ',' << v << '\n';
  s << "measured," << c.measured_on << '\n' << kHeader << '\n';
  char buf[64];
  for (const VolumeVariantMeasurement& m : c.all) {
    std::snprintf(buf, sizeof buf, "%.17g,%.17g", m.max_abs_err, m.time_ms);
    s << m.steps << ',' << m.divisor << ',' << to_string(m.upsampling) << ',' << to_string(m.noise) << ',' << buf
      << '\n';
  }
  report_detail::write_cache_file(path, s.str());
}

Cached measure(const Runtime& runtime, const VolumeSettings& base, ColorFormat storage,
               const VolumeReportOptions& options) {
  VolumeReportOptions o = options;
  o.integrators = {base.integrator};
  o.storages = {storage};
  o.riemann = false;
  o.scenes.clear();
  // Every scene when the pass marches the height fog (the worst of the volumes and the shafts);
  // without it, the volume scenes only.
  for (const std::string& scene : volume_report_scene_names())
    if (base.height_fog || !volume_report_scene_marches_height_fog(scene)) o.scenes.push_back(scene);
  const VolumeReport report = run_volume_report(runtime, o);
  ++g_measurements;
  Cached c;
  c.measured_on = std::to_string(o.width) + "x" + std::to_string(o.height) + ", median of " + std::to_string(o.runs) +
                  " runs, reference " + std::to_string(o.reference_steps) + " steps";
  std::map<std::string, std::size_t> index;  // quality name -> position in c.all
  for (const VolumeReportRow& row : report.rows) {
    const std::string name = volume_quality_name(row.steps, row.divisor, row.upsampling, row.noise);
    auto it = index.find(name);
    if (it == index.end()) {
      VolumeVariantMeasurement m;
      m.steps = row.steps;
      m.divisor = row.divisor;
      m.upsampling = row.upsampling;
      m.noise = row.noise;
      c.all.push_back(m);
      it = index.emplace(name, c.all.size() - 1).first;
    }
    VolumeVariantMeasurement& m = c.all[it->second];
    // NaN (a non-finite error) and a NaN/Inf output never pass a budget.
    const double e = std::isnan(row.max_abs_err) || row.nonfinite > 0 ? INFINITY : row.max_abs_err;
    m.max_abs_err = std::max(m.max_abs_err, e);
    m.time_ms += row.time_ms;
  }
  return c;
}

}  // namespace

std::size_t volume_budget_measurements() { return g_measurements.load(); }

VolumeQualityChoice choose_volume_quality(const Runtime& runtime, const VolumeSettings& base, ColorFormat storage,
                                          double max_error, const VolumeBudgetOptions& options) {
  if (!(max_error >= 0.0)) throw Error("max error must be a number >= 0 (got " + short_num(max_error) + ")");
  if (base.integrator == VolumeIntegrator::riemann)
    throw Error("the volumetric error budget measures the stylized and physical integrators, not riemann");
  const report_detail::DeviceKey key = report_detail::device_key(runtime);
  const auto meta = cache_meta(key, base, storage);
  VolumeQualityChoice choice;
  choice.max_error = max_error;
  const std::string dir = options.cache_dir.empty() ? report_detail::default_cache_dir() : options.cache_dir;
  choice.cache_file =
      (fs::path(dir) / report_detail::cache_file_name(
                           "volume-budget", key, measured_kind(base) + "/" + to_string(storage)))
          .string();
  Cached cached;
  if (read_cache(choice.cache_file, meta, &cached)) {
    choice.from_cache = true;
  } else {
    cached = measure(runtime, base, storage, options.measure);
    try {
      write_cache(choice.cache_file, meta, cached);
    } catch (const std::exception& e) {  // a read-only cache folder costs a re-measure, no more
      std::fprintf(stderr, "fogcl: warning: %s\n", e.what());
    }
  }
  choice.measured_on = cached.measured_on;
  choice.candidates = cached.all;
  std::stable_sort(
      choice.candidates.begin(), choice.candidates.end(),
      [](const VolumeVariantMeasurement& a, const VolumeVariantMeasurement& b) { return a.time_ms < b.time_ms; });
  const VolumeVariantMeasurement* best = nullptr;  // the most accurate, for the error message
  for (const VolumeVariantMeasurement& m : choice.candidates) {
    if (best == nullptr || m.max_abs_err < best->max_abs_err) best = &m;
    if (m.max_abs_err <= max_error) {
      choice.chosen = m;
      choice.settings = base;
      choice.settings.steps = m.steps;
      choice.settings.resolution_divisor = m.divisor;
      choice.settings.upsampling = m.upsampling;
      choice.settings.noise_sampling = m.noise;
      choice.reason = volume_quality_name(m.steps, m.divisor, m.upsampling, m.noise) + " is the fastest variant (" +
                      short_num(m.time_ms) + " ms over the report's scenes) whose worst color error " +
                      short_num(m.max_abs_err) + " is <= the budget " + short_num(max_error) + " (" +
                      to_string(base.integrator) + (base.height_fog ? " with the marched height fog" : "") + ", " +
                      to_string(storage) + ")";
      return choice;
    }
  }
  if (best == nullptr) throw Error("volumetric error budget: the measurement has no variant");
  throw Error("no volumetric variant meets the error budget (max error " + short_num(max_error) + ") with the " +
              to_string(base.integrator) + " integrator" + (base.height_fog ? ", the marched height fog" : "") +
              " and " + to_string(storage) + " storage on " + key.device +
              ": the best achievable worst color error is " + short_num(best->max_abs_err) + " (" +
              volume_quality_name(best->steps, best->divisor, best->upsampling, best->noise) + ")");
}

}  // namespace fogcl
