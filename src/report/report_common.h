// What the deferred report (report.cpp), the volumetric report (volume_report.cpp) and their error
// budgets (budget.cpp, volume_budget.cpp) share: the error measures, the median, CSV/JSON text,
// the plotting-script runner and the budget cache's file naming. Written once, used by all four.
#pragma once

#include <cstddef>
#include <initializer_list>
#include <map>
#include <string>
#include <vector>

#include "fogcl/image.h"
#include "fogcl/runtime.h"

namespace fogcl::report_detail {

// A budget cache file: "key,value" lines, then the line `header`, then CSV rows; blank lines and
// '#' comments are skipped. false when the file is missing or a meta line has no comma.
bool read_cache_table(const std::string& path, const std::string& header, std::map<std::string, std::string>* meta,
                      std::vector<std::vector<std::string>>* rows);

// The one of `values` whose to_string() is `s` (a cache file's cell); false if none.
template <class E>
bool parse_named(const std::string& s, std::initializer_list<E> values, E* out) {
  for (E v : values)
    if (s == to_string(v)) return *out = v, true;
  return false;
}

// 8-bit sRGB code: NaN -> 0, clamp to [0, 1], IEC 61966-2-1 encode, round; no dither.
int srgb8(double linear);

// The color error columns of a run's output `out` (made from `in`) against a float64 reference
// (4 values per pixel, RGBA; only R, G, B are compared).
struct ColorErrorStats {
  double max_abs = 0;         // max |color - f64| (a NaN difference counts as +inf)
  double p999_abs = 0;        // 99.9th percentile of |color - f64| over every pixel's R, G, B
  double max_ulp = 0;         // max |color - f64| in ulps of `storage` at the f64 value
  double pct_8bit_off = 0;    // % of pixels whose 8-bit sRGB code differs (>= 1) in any channel
  std::size_t nonfinite = 0;  // NaN/Inf values in `out` where `in` was finite
};
ColorErrorStats color_error_stats(const ColorImage& out, const ColorImage& in, const std::vector<double>& ref_rgba,
                                  ColorFormat storage);

std::size_t nonfinite_from_finite(const ColorImage& out, const ColorImage& in);

double median(std::vector<double> v);

// Numbers as text: %.6g, "inf"/"nan" spelled for CSV; JSON gets null for non-finite values.
std::string num(double v);
std::string json_num(double v);
std::string json_string(const std::string& s);
// Writes `text` to `path` through a temporary file and a rename. Throws fogcl::Error.
void write_file(const std::string& path, const std::string& text);

// Runs `python` with plot_common.py's text and then `script` on its stdin, `dir` as argv[1];
// `png` names the picture for the messages. Exit code 3 of the script means "matplotlib is missing". Throws fogcl::Error
// with one line saying what to install, or what failed.
void run_plot_script(const std::string& dir, const std::string& python, const char* script, std::size_t script_size,
                     const std::string& png);

// --- Error-budget caches ------------------------------------------------------------------------

// $XDG_CACHE_HOME/fogcl, else ~/.cache/fogcl, else <tmp>/fogcl-cache.
std::string default_cache_dir();
// The device's identity for a cache: "name (platform)", driver version, library version with the
// kernels' digest ("0.1.0+kernels.<FNV-1a 64 of their text>").
struct DeviceKey {
  std::string device, driver, version;
};
DeviceKey device_key(const Runtime& runtime);
// `prefix`-<FNV-1a 64 of the key's parts and `extra`>.csv: a stable file name per key.
std::string cache_file_name(const std::string& prefix, const DeviceKey& key, const std::string& extra = "");
// Newlines replaced by spaces (a cache file's metadata is one line per key).
std::string one_line(std::string s);
// Writes a cache file atomically (temporary file + rename): a concurrent reader sees the old file
// or the new one. Throws fogcl::Error when the folder or the file cannot be written.
void write_cache_file(const std::string& path, const std::string& text);
// "%.3g" for messages.
std::string short_num(double v);

}  // namespace fogcl::report_detail
