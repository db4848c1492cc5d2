// Shared helpers for the test suite: the OpenCL device (or a skip), synthetic frames and error
// measurement against the double reference.
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fogcl/demo_scene.h"
#include "fogcl/fogcl.h"
#include "runtime/clhpp.h"  // the tests drive OpenCL through fogcl's private CLHPP settings

namespace fogcl::test {

// The runtime for FOGCL_DEVICE (default PoCL CPU), created once; nullptr when no OpenCL device
// exists (kernel tests then GTEST_SKIP with the reason in runtime_error()).
Runtime* runtime();
const std::string& runtime_error();
// One FogPass shared by the tests (its program cache makes each variant build once).
FogPass& shared_pass();
// The passes whose kernels a kernel test checks: shared_pass(), and on CPU devices also one that
// builds the GPUs' one-pixel kernel (CpuCodegen::one_pixel_per_work_item), so that PoCL covers
// the kernel text GPUs run. Each entry names its path ("blocks", "one pixel" or "device").
struct KernelPath {
  const char* name;
  FogPass* pass;
  bool is_cpu_blocks;  // PoCL's 16-pixel blocks: scalar<float>'s bits
};
std::vector<KernelPath> kernel_paths();

#define FOGCL_REQUIRE_DEVICE()                                                        \
  do {                                                                                \
    if (::fogcl::test::runtime() == nullptr)                                          \
      GTEST_SKIP() << "no OpenCL device: " << ::fogcl::test::runtime_error();         \
  } while (0)

struct TestFrame {
  ColorImage color;
  DepthImage depth;
  PerspectiveCamera camera;
  CameraParams params;
};

// A frame with random HDR colors (0..4, alpha 0..1) and depths spread log-uniformly between the
// near and the far plane, ~10% sky pixels. Depths whose Linear01Depth lies within 1e-3 of the sky
// threshold, or whose distance (depth- or distance-based) lies within 1e-3 relative of
// `avoid_distance`, are redrawn, so that discontinuities of the spec (sky test, hard step) do not
// turn last-ulp differences into full-scale errors.
TestFrame make_test_frame(int width, int height, bool reversed_z, ColorFormat format,
                          std::uint32_t seed = 1, float avoid_distance = -1.0f);

struct ErrorStats {
  double max_abs = 0;   // max |got - ref|
  double max_rel = 0;   // max |got - ref| / scale, scale = max(|color in|, |fog color|, 1e-30)
  double max_ulps = 0;  // max |got - ref| in half ulps at ref
  // Half storage budget: ulps at ref beyond what the fog-factor budget already allows
  // (2e-6 * |color - fog color|). Where half is subnormal, one ulp (2^-24) is finer than the
  // factor budget, so plain ulps would hold half to a stricter standard than float.
  double max_half_ulps_beyond_factor = 0;
  std::size_t nonfinite_from_finite = 0;
  // Pixels whose alpha is not the input's bits (a NaN alpha of half storage may come out quieted,
  // docs/accuracy.md): alpha passes through the blend, so every caller expects 0.
  std::size_t alpha_changed = 0;
  std::size_t pixels = 0;
};

// Compares the RGB of `got` against the double reference, and counts in alpha_changed the pixels
// whose alpha is not `in`'s.
ErrorStats compare_color(const ColorImage& got, const FogResult<double>& ref, const ColorImage& in,
                         const glm::vec3& fog_color);

// Max |got - ref| of the fog factor, where `probe` is the output of a run with color (1,1,1,1)
// and fog color 0, which makes each channel equal to f exactly.
double factor_error(const ColorImage& probe, const FogResult<double>& ref);

// A frame with every color (1, 1, 1, 1), same size and format as `like`.
ColorImage white_like(const ColorImage& like);

// Size of one half-precision ulp at |x|.
double half_ulp(double x);

// An empty folder `name`-PID under temp_dir() (made anew).
std::string fresh_dir(const std::string& name);
// A CSV file's cells, row by row (a trailing comma is a last, empty cell).
std::vector<std::vector<std::string>> read_csv(const std::string& path);
std::string temp_dir();  // a per-run scratch folder: FOGCL_TEST_DIR, else the build tree's tests/tmp
// The fogcl CLI under test: FOGCL_TEST_CLI, else the one this build made. Both variables exist
// for runs outside the build tree (scripts/gpu-run.sh on the GPU machine).
const std::string& cli_path();
// The CLI's --device value for the device the tests run on: FOGCL_DEVICE's choice (cpu unless
// set), or scalar where no OpenCL device exists. CLI-vs-library tests compare like with like.
std::string cli_device();
// Gives the calling (child) process the OpenCL loader environment the test process started with.
// PoCL 5.0 sets OCL_ICD_FILENAMES=libpocl.so.2 in the process that loads it (seen on Ubuntu 24.04
// with NVIDIA's driver registered beside it): a CLI started after that would see PoCL alone.
void restore_start_opencl_env();

// Runs fn, expects fogcl::Error, returns its message ("" and a test failure otherwise).
template <class Fn>
std::string error_of(Fn&& fn) {
  try {
    fn();
  } catch (const Error& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected fogcl::Error, got another exception: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected fogcl::Error, nothing was thrown";
  return {};
}

#define EXPECT_MSG_HAS(msg, part) \
  EXPECT_NE((msg).find(part), std::string::npos) << "message: '" << (msg) << "' lacks '" << (part) << "'"

// A float as the library formats it in messages (9 significant digits).
std::string num(float v);
// "x,y,z" with num's digits: a vector as the CLI's flags take it.
std::string vec3_text(const glm::vec3& v);

// `text` as the whole content of the file `path`.
void write_text(const std::string& path, const std::string& text);
// The whole content of the file `path`, byte for byte ("" / empty where it cannot be read).
std::string read_text(const std::string& path);
std::vector<char> file_bytes(const std::string& path);
// The number of 4-byte words (the RGBA floats) that differ between a and b; SIZE_MAX where their
// sizes differ.
std::size_t differing_floats(const ColorImage& a, const ColorImage& b);
// The demo scene at width x height (render_demo_scene's defaults) written into `dir` as
// scene.exr (RGBA) and scene-depth.exr.
DemoFrame write_demo_scene(const std::string& dir, int width, int height);

// Checks a plot the report tools drew with matplotlib (src/report/plot_*.py): the PNG decodes, is
// the size of `panels` panels of panel_w x panel_h inches at `dpi` in rows of at most 3 (±1 px),
// and is not blank: at least 2 % of its pixels differ from the most common one and the gray
// levels' standard deviation is at least 5 (of 255). Prints what it measured.
void expect_plot(const std::string& png, int panels, double panel_w, double panel_h, int dpi);
// Whether /usr/bin/python3 imports matplotlib (scripts/setup.sh installs python3-matplotlib); a
// test failure saying so where it does not.
bool require_matplotlib();

// The fogcl CLI run with `args` (and `env` assignments before it), stdout + stderr captured.
struct CliRun {
  int exit_code;
  std::string output;
};
CliRun run_cli(const std::string& args, const std::string& env = "");
// The fogcl CLI started in the background with `args` (split at spaces, no shell), stdout and
// stderr into the file `log`, FOGCL_TEMP_FILES=named when named_temporaries, and held at one call
// by tests/support/call_gate.c, preloaded: the first of `calls` (comma-separated function names,
// e.g. kNamingCalls) on a path ending in `suffix` waits until fogcl's signal handlers have returned
// `release` times (0: until the process is killed). The gate says what it does in lines that
// next_line() reads: "held CALL PATH" once it holds, "handled SIGNO" after each handler. No
// sampling: each step waits for the line before it.
class GatedCli {
 public:
  GatedCli(const std::string& args, const std::string& log, bool named_temporaries, const std::string& calls,
           const std::string& suffix, int release);
  ~GatedCli();  // kills a run not waited for
  GatedCli(const GatedCli&) = delete;
  GatedCli& operator=(const GatedCli&) = delete;
  // The gate's next line; "" once the process has ended, or after a minute (a hang guard only: the
  // line always comes in a run that behaves).
  std::string next_line();
  void signal(int signo) const;
  int wait();  // waitpid's status
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
  int lines_ = -1;  // the read end of the gate's pipe
  std::string pending_;
};
// The calls that give a finished output its name (src/io/atomic_file.cpp): renaming a named
// temporary, linking an unnamed one.
inline const std::string kNamingCalls = "rename,renameat,renameat2,linkat";
// How a run ended, from waitpid's status: "exit N" or "signal N".
std::string ending(int status);
// Whether process `pid` has a file open in `dir` for writing an output: a named temporary
// ("DIR/NAME.tmp-..."), and with unnamed_too an O_TMPFILE inode (shown as "DIR/#INODE (deleted)").
bool writing_in(pid_t pid, const std::string& dir, bool unnamed_too);

}  // namespace fogcl::test

namespace fogcl {
// Readable parameter names in gtest output.
inline void PrintTo(KernelMode m, std::ostream* os) { *os << to_string(m); }
inline void PrintTo(ColorFormat f, std::ostream* os) { *os << to_string(f); }
}  // namespace fogcl
