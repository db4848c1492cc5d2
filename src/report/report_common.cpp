// Shared by the deferred and the volumetric reports and their error budgets (report_common.h).
#include "report/report_common.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include "fogcl/error.h"
#include "fogcl/version.h"
#include "runtime/clhpp.h"

#include "deferred_fog_cl.h"      // the kernels' text, headers included (generated)
#include "plot_common_py.h"  // generated from report/plot_common.py
#include "volume_composite_cl.h"
#include "volume_march_cl.h"

namespace fogcl::report_detail {

namespace fs = std::filesystem;

int srgb8(double linear) {
  const double l = std::isnan(linear) ? 0.0 : std::clamp(linear, 0.0, 1.0);
  return int(std::lround(srgb_encode(l) * 255.0));
}

std::size_t nonfinite_from_finite(const ColorImage& out, const ColorImage& in) {
  std::size_t n = 0;
  for (int y = 0; y < in.height(); ++y)
    for (int x = 0; x < in.width(); ++x) {
      const glm::vec4 o = out.pixel(x, y), i = in.pixel(x, y);
      for (int c = 0; c < 4; ++c) n += std::isfinite(i[c]) && !std::isfinite(o[c]);
    }
  return n;
}

ColorErrorStats color_error_stats(const ColorImage& out, const ColorImage& in, const std::vector<double>& ref_rgba,
                                  ColorFormat storage) {
  if (out.width() != in.width() || out.height() != in.height() || ref_rgba.size() != 4 * in.pixel_count())
    throw Error("color_error_stats: the output, the input and the reference differ in size");
  ColorErrorStats s;
  std::vector<double> errs;
  errs.reserve(3 * in.pixel_count());
  std::size_t off = 0;
  for (int y = 0; y < in.height(); ++y)
    for (int x = 0; x < in.width(); ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(in.width()) + std::size_t(x);
      const glm::vec4 g = out.pixel(x, y);
      bool differs = false;
      for (int c = 0; c < 3; ++c) {
        const double r = ref_rgba[4 * i + std::size_t(c)];
        const double e = std::fabs(double(g[c]) - r);
        errs.push_back(std::isnan(e) ? std::numeric_limits<double>::infinity() : e);
        s.max_ulp = std::max(s.max_ulp, errs.back() / ulp_of(r, storage));
        differs = differs || srgb8(double(g[c])) != srgb8(r);
      }
      off += differs;
    }
  s.max_abs = *std::max_element(errs.begin(), errs.end());
  const std::size_t k = std::min(errs.size() - 1, std::size_t(std::ceil(0.999 * double(errs.size()))) - 1);
  std::nth_element(errs.begin(), errs.begin() + std::ptrdiff_t(k), errs.end());
  s.p999_abs = errs[k];
  s.pct_8bit_off = 100.0 * double(off) / double(in.pixel_count());
  s.nonfinite = nonfinite_from_finite(out, in);
  return s;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string num(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}
std::string json_num(double v) { return std::isfinite(v) ? num(v) : "null"; }

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

void write_file(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw Error("cannot write " + path);
    f << text;
    if (!f.flush()) throw Error("cannot write " + path);
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw Error("cannot write " + path);
}

void run_plot_script(const std::string& dir, const std::string& python, const char* script, std::size_t n,
                     const std::string& png) {
  const std::string install =
      "install python3-matplotlib (apt-get install python3-matplotlib, or scripts/setup.sh --bench)";
  if (::access(python.c_str(), X_OK) != 0)
    throw Error("cannot draw " + png + ": " + python + " is missing; " + install);
  // The script reads the folder from argv[1]; exit code 3 means "matplotlib missing".
  std::string quoted = "'";
  for (char c : dir) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  quoted += "'";
  const std::string cmd = python + " - " + quoted;
  FILE* p = ::popen(cmd.c_str(), "w");
  if (p == nullptr) throw Error("cannot draw " + png + ": cannot run " + python);
  const std::size_t common = sizeof(plot_common_py) - 1;
  const bool sent = std::fwrite(plot_common_py, 1, common, p) == common && std::fwrite(script, 1, n, p) == n;
  const int status = ::pclose(p);
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 3) throw Error("cannot draw " + png + ": matplotlib is missing for " + python + "; " + install);
  if (!sent || code != 0)
    throw Error("cannot draw " + png + ": the plotting script failed (" + python + " exit code " +
                std::to_string(code) + ")");
}

std::string default_cache_dir() {
  const char* xdg = std::getenv("XDG_CACHE_HOME");
  if (xdg != nullptr && *xdg == '/') return (fs::path(xdg) / "fogcl").string();
  const char* home = std::getenv("HOME");
  if (home != nullptr && *home != '\0') return (fs::path(home) / ".cache" / "fogcl").string();
  return (fs::temp_directory_path() / "fogcl-cache").string();
}

namespace {

// FNV-1a 64 of the parts, each followed by a separator byte, as 16 hex digits.
std::string fnv1a_hex(const std::vector<const char*>& parts) {
  std::uint64_t h = 1469598103934665603ull;
  for (const char* s : parts) {
    for (; *s != '\0'; ++s) h = (h ^ static_cast<unsigned char>(*s)) * 1099511628211ull;
    h = (h ^ 0xff) * 1099511628211ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

}  // namespace

DeviceKey device_key(const Runtime& runtime) {
  // The kernels' text is part of the version: measured errors and times belong to the kernels
  // that were measured, and a development build changes them without a new version number.
  static const std::string version =
      std::string(library_version()) + "+kernels." + fnv1a_hex({deferred_fog_cl, volume_march_cl, volume_composite_cl});
  return with_cl_errors([&] {
    const cl::Device d = wrap(runtime.device());
    const cl::Platform platform(d.getInfo<CL_DEVICE_PLATFORM>());
    return DeviceKey{d.getInfo<CL_DEVICE_NAME>() + " (" + platform.getInfo<CL_PLATFORM_NAME>() + ")",
                     d.getInfo<CL_DRIVER_VERSION>(), version};
  });
}

std::string cache_file_name(const std::string& prefix, const DeviceKey& k, const std::string& extra) {
  std::vector<const char*> parts{k.device.c_str(), k.driver.c_str(), k.version.c_str()};
  if (!extra.empty()) parts.push_back(extra.c_str());  // the deferred budget's names stay as they were
  return prefix + "-" + fnv1a_hex(parts) + ".csv";
}

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\r', ' ');
  return s;
}

void write_cache_file(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  bool created = false;  // only a temporary this call made is removed
  const auto fail = [&](const std::string& why) {
    std::error_code ignored;
    if (created) fs::remove(tmp, ignored);  // no failure leaves the temporary behind
    return Error("cannot write the error-budget cache " + path + ": " + why);
  };
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  if (ec) throw fail("cannot create its folder: " + ec.message());
  {
    std::ofstream f(tmp, std::ios::trunc);
    if (!f) throw fail("cannot create " + tmp);
    created = true;
    f << text;
    if (!f.flush()) throw fail("writing " + tmp + " failed");
  }
  fs::rename(tmp, path, ec);  // atomic: a concurrent reader sees the old file or the new one
  std::error_code ignored;
  if (ec) throw fail(fs::is_directory(path, ignored) ? std::string("it is a directory") : ec.message());
}

std::string short_num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

bool read_cache_table(const std::string& path, const std::string& header, std::map<std::string, std::string>* meta,
                      std::vector<std::vector<std::string>>* rows) {
  std::ifstream f(path);
  if (!f) return false;
  std::string line;
  bool table = false;
  while (std::getline(f, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (!table) {
      if (line == header) {
        table = true;
        continue;
      }
      const std::size_t comma = line.find(',');
      if (comma == std::string::npos) return false;
      (*meta)[line.substr(0, comma)] = line.substr(comma + 1);
      continue;
    }
    std::vector<std::string> cells;
    std::istringstream row(line);
    std::string cell;
    while (std::getline(row, cell, ',')) cells.push_back(cell);
    rows->push_back(cells);
  }
  return true;
}

}  // namespace fogcl::report_detail
