#include "test_support.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <random>

#include <Imath/half.h>
#include <png.h>

#include "fogcl/exr_io.h"

namespace fogcl::test {

namespace {
struct RuntimeHolder {
  std::unique_ptr<Runtime> runtime;
  std::unique_ptr<FogPass> pass;
  std::unique_ptr<FogPass> one_pixel_pass;  // CPU devices only
  std::string error;
  RuntimeHolder() {
    try {
      runtime = std::make_unique<Runtime>();
      pass = std::make_unique<FogPass>(*runtime);
      if (runtime->is_cpu()) {
        CpuCodegen one_pixel;
        one_pixel.one_pixel_per_work_item = true;
        one_pixel_pass = std::make_unique<FogPass>(*runtime, one_pixel);
      }
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
};
RuntimeHolder& holder() {
  static RuntimeHolder h;
  return h;
}
}  // namespace

Runtime* runtime() { return holder().runtime.get(); }
const std::string& runtime_error() { return holder().error; }
FogPass& shared_pass() { return *holder().pass; }
std::vector<KernelPath> kernel_paths() {
  RuntimeHolder& h = holder();
  if (!h.one_pixel_pass) return {{"device", h.pass.get(), false}};
  return {{"blocks", h.pass.get(), true}, {"one pixel", h.one_pixel_pass.get(), false}};
}

TestFrame make_test_frame(int width, int height, bool reversed_z, ColorFormat format,
                          std::uint32_t seed, float avoid_distance) {
  TestFrame t;
  t.camera.aspect = float(width) / float(height);
  t.camera.reversed_z = reversed_z;
  t.params = make_camera_params(t.camera);
  t.color = ColorImage(width, height, format);
  t.depth = DepthImage(width, height);
  std::mt19937 rng(seed * 7919u + unsigned(width) * 31u + unsigned(height));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double n = t.camera.near_plane, f = t.camera.far_plane;
  const double zx = t.params.zbuffer_params.x, zy = t.params.zbuffer_params.y;
  const double sky_raw = reversed_z ? 0.0 : 1.0;
  const auto& c = t.params.frustum_corners;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      t.color.set_pixel(x, y, glm::vec4(4 * unit(rng), 4 * unit(rng), 4 * unit(rng), unit(rng)));
      if (unit(rng) < 0.1) {
        t.depth.at(x, y) = float(sky_raw);
        continue;
      }
      // Independent of fog_math.h: the ray length of the pixel from the corners, in double.
      const double u = (x + 0.5) / width, v = 1.0 - (y + 0.5) / height;
      double len2 = 0;
      for (int k = 0; k < 3; ++k) {
        const double b = c[0][k] + (c[1][k] - c[0][k]) * u, tp = c[2][k] + (c[3][k] - c[2][k]) * u;
        const double r = b + (tp - b) * v;
        len2 += r * r;
      }
      for (;;) {
        const double eye = n * std::pow(f / n, unit(rng));  // log-uniform eye depth in [n, f]
        const double raw = double(float((f / eye - zy) / zx));
        const double l01 = 1.0 / (zx * raw + zy);
        if (std::fabs(l01 - 0.9999) < 1e-3 || raw < 0.0 || raw > 1.0) continue;
        const double d_depth = l01 * f - n, d_dist = l01 * std::sqrt(len2);
        if (avoid_distance > 0 && (std::fabs(d_depth - avoid_distance) < 1e-3 * avoid_distance ||
                                   std::fabs(d_dist - avoid_distance) < 1e-3 * avoid_distance))
          continue;
        t.depth.at(x, y) = float(raw);
        break;
      }
    }
  }
  return t;
}

void expect_plot(const std::string& path, int panels, double panel_w, double panel_h, int dpi) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&image, path.c_str())) << path << ": " << image.message;
  image.format = PNG_FORMAT_GRAY;
  std::vector<std::uint8_t> gray(PNG_IMAGE_SIZE(image));
  ASSERT_TRUE(png_image_finish_read(&image, nullptr, gray.data(), 0, nullptr)) << path << ": " << image.message;
  const int cols = std::min(3, panels), rows = (panels + cols - 1) / cols;
  const double want_w = panel_w * cols * dpi, want_h = panel_h * rows * dpi;
  std::array<std::size_t, 256> histogram{};
  double sum = 0, sum2 = 0;
  for (std::uint8_t g : gray) {
    ++histogram[g];
    sum += g;
    sum2 += double(g) * g;
  }
  const double n = double(gray.size()), mean = sum / n, sd = std::sqrt(std::max(0.0, sum2 / n - mean * mean));
  const double other = 1.0 - double(*std::max_element(histogram.begin(), histogram.end())) / n;
  std::printf("[ plot     ] %s: %ux%u (want %.0fx%.0f), %.1f %% of pixels not the background, gray sd %.1f\n",
              path.c_str(), image.width, image.height, want_w, want_h, 100 * other, sd);
  EXPECT_NEAR(double(image.width), want_w, 1.0) << path;
  EXPECT_NEAR(double(image.height), want_h, 1.0) << path;
  EXPECT_GE(other, 0.02) << path << " is blank";
  EXPECT_GE(sd, 5.0) << path << " is blank";
}

bool require_matplotlib() {
  const bool ok = std::system("/usr/bin/python3 -c 'import matplotlib' >/dev/null 2>&1") == 0;
  if (ok) return true;
  // A machine where nothing can be installed (the GPU machine: scripts/gpu-run.sh) skips instead.
  if (std::getenv("FOGCL_TEST_PLOTS_OPTIONAL") != nullptr)
    [] { GTEST_SKIP() << "/usr/bin/python3 has no matplotlib (FOGCL_TEST_PLOTS_OPTIONAL is set)"; }();
  else
    ADD_FAILURE() << "/usr/bin/python3 has no matplotlib: scripts/setup.sh installs python3-matplotlib";
  return false;
}

double half_ulp(double x) { return ulp_of(x, ColorFormat::rgba16f); }

ErrorStats compare_color(const ColorImage& got, const FogResult<double>& ref, const ColorImage& in,
                         const glm::vec3& fog_color) {
  ErrorStats s;
  s.pixels = in.pixel_count();
  for (int y = 0; y < in.height(); ++y) {
    for (int x = 0; x < in.width(); ++x) {
      const std::size_t i = std::size_t(y) * in.width() + x;
      const glm::vec4 g = got.pixel(x, y), c = in.pixel(x, y);
      for (int ch = 0; ch < 3; ++ch) {
        const double r = ref.rgba[4 * i + ch];
        if (std::isfinite(c[ch]) && !std::isfinite(g[ch])) ++s.nonfinite_from_finite;
        if (std::isnan(r) && std::isnan(g[ch])) continue;
        if (std::isinf(r) && double(g[ch]) == r) continue;
        const double err = std::fabs(double(g[ch]) - r);
        const double scale = std::max({std::fabs(double(c[ch])), std::fabs(double(fog_color[ch])), 1e-30});
        s.max_abs = std::max(s.max_abs, err);
        s.max_rel = std::max(s.max_rel, err / scale);
        s.max_ulps = std::max(s.max_ulps, err / half_ulp(r));
        const double factor_allowance = 2e-6 * std::fabs(double(c[ch]) - double(fog_color[ch]));
        s.max_half_ulps_beyond_factor =
            std::max(s.max_half_ulps_beyond_factor, std::max(0.0, err - factor_allowance) / half_ulp(r));
      }
      // Alpha passes through untouched: bit-compare.
      bool alpha_same;
      if (in.format() == ColorFormat::rgba32f)
        alpha_same = std::memcmp(&in.rgba32f()[4 * i + 3], &got.rgba32f()[4 * i + 3], 4) == 0;
      else
        alpha_same = in.rgba16f()[4 * i + 3] == got.rgba16f()[4 * i + 3] || (std::isnan(c.w) && std::isnan(g.w));
      if (!alpha_same) ++s.alpha_changed;
    }
  }
  return s;
}

double factor_error(const ColorImage& probe, const FogResult<double>& ref) {
  return max_abs_factor_error(probe, ref);
}

ColorImage white_like(const ColorImage& like) {
  return uniform_image(like.width(), like.height(), like.format(), glm::vec4(1.0f));
}

std::string temp_dir() {
  static const std::string dir = [] {
    const char* env = std::getenv("FOGCL_TEST_DIR");
    std::filesystem::path p = env != nullptr && *env != '\0' ? env : FOGCL_TEST_TMP;
    std::filesystem::create_directories(p);
    return p.string();
  }();
  return dir;
}

std::string fresh_dir(const std::string& name) {
  const std::string d = temp_dir() + "/" + name + "-" + std::to_string(::getpid());
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

std::vector<std::vector<std::string>> read_csv(const std::string& path) {
  std::ifstream f(path);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  while (std::getline(f, line)) {
    std::vector<std::string> cells;
    std::string cell;
    std::istringstream s(line);
    while (std::getline(s, cell, ',')) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.push_back("");
    rows.push_back(cells);
  }
  return rows;
}

std::string num(float v) {
  std::ostringstream s;
  s.precision(9);
  s << v;
  return s.str();
}

std::string vec3_text(const glm::vec3& v) { return num(v.x) + "," + num(v.y) + "," + num(v.z); }

void write_text(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
}

std::string read_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

std::vector<char> file_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

std::size_t differing_floats(const ColorImage& a, const ColorImage& b) {
  if (a.width() != b.width() || a.height() != b.height() || a.size_bytes() != b.size_bytes()) return SIZE_MAX;
  const auto* pa = static_cast<const unsigned char*>(a.data());
  const auto* pb = static_cast<const unsigned char*>(b.data());
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size_bytes(); i += 4) n += std::memcmp(pa + i, pb + i, 4) != 0;
  return n;
}

DemoFrame write_demo_scene(const std::string& dir, int width, int height) {
  DemoFrame frame = render_demo_scene(width, height);
  write_exr_rgba(dir + "/scene.exr", frame.color);
  write_exr_depth(dir + "/scene-depth.exr", frame.depth);
  return frame;
}

const std::string& cli_path() {
  static const std::string path = [] {
    const char* env = std::getenv("FOGCL_TEST_CLI");
    return std::string(env != nullptr && *env != '\0' ? env : FOGCL_CLI_PATH);
  }();
  return path;
}

namespace {
// Read during static initialisation, before any OpenCL call of the test process.
const std::optional<std::string> kIcdFilenamesAtStart = []() -> std::optional<std::string> {
  const char* v = std::getenv("OCL_ICD_FILENAMES");
  return v != nullptr ? std::optional<std::string>(v) : std::nullopt;
}();
}  // namespace

void restore_start_opencl_env() {
  if (kIcdFilenamesAtStart)
    setenv("OCL_ICD_FILENAMES", kIcdFilenamesAtStart->c_str(), 1);
  else
    unsetenv("OCL_ICD_FILENAMES");
}

std::string cli_device() { return runtime() != nullptr ? resolve_device_choice() : std::string("scalar"); }

CliRun run_cli(const std::string& args, const std::string& env) {
  // The child gets the OpenCL loader environment the tests started with (restore_start_opencl_env).
  const std::string loader_env =
      kIcdFilenamesAtStart ? "OCL_ICD_FILENAMES='" + *kIcdFilenamesAtStart + "'" : "env -u OCL_ICD_FILENAMES";
  const std::string cmd = loader_env + " " + env + " " + cli_path() + " " + args + " 2>&1";
  CliRun r{-1, {}};
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), p) != nullptr) r.output += buf.data();
  const int status = pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

namespace {
// The CLI started in the background (GatedCli) with `env` ("NAME=value") set in the child and
// descriptor `keep_fd` left open there.
pid_t spawn_cli(const std::string& args, const std::string& log, bool named_temporaries,
                     const std::vector<std::string>& env, int keep_fd) {
  std::vector<std::string> words{cli_path()};
  for (std::size_t at = 0; at < args.size();) {
    const std::size_t end = std::min(args.find(' ', at), args.size());
    if (end > at) words.push_back(args.substr(at, end - at));
    at = end + 1;
  }
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    if (named_temporaries) ::setenv("FOGCL_TEMP_FILES", "named", 1);
    for (const std::string& e : env) ::putenv(const_cast<char*>(e.c_str()));
    if (keep_fd >= 0) ::fcntl(keep_fd, F_SETFD, 0);
    restore_start_opencl_env();
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return pid;
}

const std::string& call_gate_path() {
  static const std::string path = [] {
    const char* env = std::getenv("FOGCL_TEST_CALL_GATE");  // scripts/gpu-run.sh's bundle
    return std::string(env != nullptr && *env != '\0' ? env : FOGCL_CALL_GATE_PATH);
  }();
  return path;
}
}  // namespace

GatedCli::GatedCli(const std::string& args, const std::string& log, bool named_temporaries, const std::string& calls,
                   const std::string& suffix, int release) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("GatedCli: pipe2 failed");
  pid_ = spawn_cli(args, log, named_temporaries,
                   {"LD_PRELOAD=" + call_gate_path(), "FOGCL_GATE_CALLS=" + calls, "FOGCL_GATE_SUFFIX=" + suffix,
                    "FOGCL_GATE_RELEASE=" + std::to_string(release), "FOGCL_GATE_FD=" + std::to_string(fds[1])},
                   fds[1]);
  ::close(fds[1]);  // the child's copy is the only writer: its end is the pipe's end of file
  lines_ = fds[0];
}

GatedCli::~GatedCli() {
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
  }
  if (lines_ >= 0) ::close(lines_);
}

std::string GatedCli::next_line() {
  for (;;) {
    const std::size_t end = pending_.find('\n');
    if (end != std::string::npos) {
      const std::string line = pending_.substr(0, end);
      pending_.erase(0, end + 1);
      return line;
    }
    pollfd p{lines_, POLLIN, 0};
    if (::poll(&p, 1, 60 * 1000) <= 0) return "";
    char buf[512];
    const ssize_t n = ::read(lines_, buf, sizeof buf);
    if (n <= 0) return "";
    pending_.append(buf, std::size_t(n));
  }
}

void GatedCli::signal(int signo) const { ::kill(pid_, signo); }

int GatedCli::wait() {
  int status = 0;
  ::waitpid(pid_, &status, 0);
  pid_ = -1;
  return status;
}

std::string ending(int status) {
  return WIFEXITED(status) ? "exit " + std::to_string(WEXITSTATUS(status))
                           : WIFSIGNALED(status) ? "signal " + std::to_string(WTERMSIG(status)) : "?";
}

bool writing_in(pid_t pid, const std::string& dir, bool unnamed_too) {
  namespace fs = std::filesystem;
  std::error_code ec;
  for (fs::directory_iterator it("/proc/" + std::to_string(pid) + "/fd", ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code link_ec;
    const std::string target = fs::read_symlink(it->path(), link_ec).string();
    if (!link_ec && target.compare(0, dir.size() + 1, dir + "/") == 0 &&
        (target.find(".tmp-") != std::string::npos || (unnamed_too && target.find("(deleted)") != std::string::npos)))
      return true;
  }
  return false;
}

}  // namespace fogcl::test
