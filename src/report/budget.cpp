// The error budget (docs/accuracy.md): the fastest precision variant whose measured worst color error on
// the report's scenes meets a maximum, measured once per (device, driver, library version + kernel digest) and
// cached as a small CSV file under $XDG_CACHE_HOME/fogcl.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "fogcl/error.h"
#include "fogcl/report.h"
#include "report/report_common.h"

namespace fogcl {

namespace {

namespace fs = std::filesystem;

std::atomic<std::size_t> g_measurements{0};

using report_detail::one_line;
using CacheKey = report_detail::DeviceKey;

using report_detail::parse_named;

struct Cached {
  std::string measured_on;
  std::vector<VariantMeasurement> all;
};

// Reads a cache file; false when missing, unreadable, for another key or malformed (then the
// measurement is taken again and the file rewritten).
bool read_cache(const std::string& path, const CacheKey& key, Cached* out) {
  std::map<std::string, std::string> meta;
  std::vector<std::vector<std::string>> rows;
  if (!report_detail::read_cache_table(path, "precision,storage,max_abs_err_color,time_ms", &meta, &rows)) return false;
  for (const std::vector<std::string>& cells : rows) {
    VariantMeasurement m;
    if (cells.size() != 4 || !parse_named(cells[0], {Precision::precise, Precision::fast}, &m.precision) ||
        !parse_named(cells[1], {ColorFormat::rgba32f, ColorFormat::rgba16f}, &m.storage))
      return false;
    char* end = nullptr;
    m.max_abs_err_color = std::strtod(cells[2].c_str(), &end);
    if (end == cells[2].c_str()) return false;
    m.time_ms = std::strtod(cells[3].c_str(), &end);
    if (end == cells[3].c_str()) return false;
    out->all.push_back(m);
  }
  if (meta["device"] != one_line(key.device) || meta["driver"] != one_line(key.driver) ||
      meta["version"] != key.version)
    return false;
  out->measured_on = meta["measured"];
  return out->all.size() == 4;  // {precise, fast} x {rgba32f, rgba16f}
}

void write_cache(const std::string& path, const CacheKey& key, const Cached& c) {
  std::ostringstream s;
  s << "# fogcl error-budget measurement (fogcl report's scenes); delete this file to measure again\n"
    << "device," << one_line(key.device) << "\ndriver," << one_line(key.driver) << "\nversion," << key.version
    << "\nmeasured," << c.measured_on << "\nprecision,storage,max_abs_err_color,time_ms\n";
  char buf[64];
  for (const VariantMeasurement& m : c.all) {
    std::snprintf(buf, sizeof buf, "%.17g,%.17g", m.max_abs_err_color, m.time_ms);
    s << to_string(m.precision) << ',' << to_string(m.storage) << ',' << buf << '\n';
  }
  report_detail::write_cache_file(path, s.str());
}

Cached measure(const Runtime& runtime, const ReportOptions& options) {
  ReportOptions o = options;
  o.scalar = false;
  const Report report = run_report(&runtime, o);
  ++g_measurements;
  Cached c;
  c.measured_on = std::to_string(o.width) + "x" + std::to_string(o.height) + ", median of " +
                  std::to_string(o.runs) + " runs";
  for (ColorFormat storage : {ColorFormat::rgba32f, ColorFormat::rgba16f})
    for (Precision p : {Precision::precise, Precision::fast}) {
      VariantMeasurement m;
      m.precision = p;
      m.storage = storage;
      for (const ReportRow& row : report.rows)
        if (!row.scalar && row.precision == p && row.storage == storage) {
          // NaN (a non-finite error) must never pass a budget.
          const double e = std::isnan(row.max_abs_err_color) ? INFINITY : row.max_abs_err_color;
          m.max_abs_err_color = std::max(m.max_abs_err_color, e);
          m.time_ms += row.time_ms;
        }
      c.all.push_back(m);
    }
  return c;
}

std::string num(double v) { return report_detail::short_num(v); }

}  // namespace

std::size_t budget_measurements() { return g_measurements.load(); }

PrecisionChoice choose_precision_detailed(const Runtime& runtime, ColorFormat storage, double max_error,
                                          const BudgetOptions& options) {
  if (!(max_error >= 0.0))
    throw Error("max error must be a number >= 0 (got " + num(max_error) + ")");
  const CacheKey key = report_detail::device_key(runtime);
  PrecisionChoice choice;
  choice.max_error = max_error;
  const std::string dir = options.cache_dir.empty() ? report_detail::default_cache_dir() : options.cache_dir;
  choice.cache_file = (fs::path(dir) / report_detail::cache_file_name("error-budget", key)).string();

  Cached cached;
  if (read_cache(choice.cache_file, key, &cached)) {
    choice.from_cache = true;
  } else {
    cached = measure(runtime, options.measure);
    try {
      write_cache(choice.cache_file, key, cached);
    } catch (const std::exception& e) {  // a read-only cache folder costs a re-measure, no more
      std::fprintf(stderr, "fogcl: warning: %s\n", e.what());
    }
  }
  choice.measured_on = cached.measured_on;
  for (const VariantMeasurement& m : cached.all)
    if (m.storage == storage) choice.candidates.push_back(m);
  std::sort(choice.candidates.begin(), choice.candidates.end(),
            [](const VariantMeasurement& a, const VariantMeasurement& b) { return a.time_ms < b.time_ms; });

  const VariantMeasurement* best = nullptr;  // the most accurate, for the error message
  for (const VariantMeasurement& m : choice.candidates) {
    if (best == nullptr || m.max_abs_err_color < best->max_abs_err_color) best = &m;
    if (m.max_abs_err_color <= max_error) {
      choice.precision = m.precision;
      choice.reason = std::string(to_string(m.precision)) + " is the fastest variant (" + num(m.time_ms) +
                      " ms over the report's scenes) whose worst color error " + num(m.max_abs_err_color) +
                      " is <= the budget " + num(max_error) + " with " + to_string(storage) + " storage";
      return choice;
    }
  }
  if (best == nullptr) throw Error("error budget: no measurement for " + std::string(to_string(storage)));
  throw Error("no precision variant meets the error budget (max error " + num(max_error) + ") with " +
              to_string(storage) + " storage on " + key.device + ": the best achievable worst color error is " +
              num(best->max_abs_err_color) + " (" + to_string(best->precision) + ")");
}

Precision choose_precision(const Runtime& runtime, ColorFormat storage, double max_error) {
  return choose_precision_detailed(runtime, storage, max_error).precision;
}

}  // namespace fogcl
