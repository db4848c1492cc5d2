// One grammar of errors on the fogcl command line (docs/cli.md#errors): every value flag of
// `apply`, `demo` and `report`, enumerated from their --help, given an empty, a non-numeric, a huge
// and a wrong-case value, exits 2 (malformed) or 1 (a rule broken) with one stderr line naming the
// flag, and leaves no file. Also the usage lines, '%%' in patterns and `fogcl --version`.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

#include "fogcl/version.h"
#include "test_support.h"

namespace fogcl::test {
namespace {

namespace fs = std::filesystem;

// What a flag takes, which decides the exit code of each test value.
enum class Kind { real, integer, vec3, matrix, keyword, keyword_list, integer_list, device, input, output, folder,
                  text, name, size, frames, none };

struct FlagSpec {
  Kind kind;
  std::string word = {};  // keywords: a valid one (its upper case is the wrong-case value)
};

// Every flag of the three commands. A flag that --help lists and this table lacks fails the test:
// a new flag must say here what it takes.
const std::map<std::string, std::map<std::string, FlagSpec>>& flag_table() {
  static const std::map<std::string, std::map<std::string, FlagSpec>> table{
      {"demo",
       {{"--out", {Kind::folder}}, {"--width", {Kind::integer}}, {"--height", {Kind::integer}},
        {"--device", {Kind::device}}, {"--max-memory", {Kind::size}}}},
      {"report",
       {{"--out", {Kind::folder}}, {"--device", {Kind::device}}, {"--width", {Kind::integer}},
        {"--height", {Kind::integer}}, {"--runs", {Kind::integer}}, {"--volumetric", {Kind::none}},
        {"--steps", {Kind::integer_list}}, {"--scenes", {Kind::keyword_list, "demo"}},
        {"--integrators", {Kind::keyword_list, "physical"}}}},
      {"apply",
       {{"--color", {Kind::input}}, {"--layer", {Kind::text}}, {"--depth", {Kind::input}},
        {"--depth-channel", {Kind::name}}, {"--depth-kind", {Kind::keyword, "eye"}}, {"--out", {Kind::output}},
        {"--rgba-only", {Kind::none}}, {"--png", {Kind::output}}, {"--frames", {Kind::frames}},
        {"--keep-going", {Kind::none}}, {"--max-memory", {Kind::size}}, {"--threads", {Kind::integer}},
        {"--pixel-type", {Kind::keyword, "half"}}, {"--compression", {Kind::keyword, "zip"}},
        {"--near", {Kind::real}}, {"--far", {Kind::real}}, {"--fov", {Kind::real}}, {"--ortho-size", {Kind::real}},
        {"--infinite-far", {Kind::none}}, {"--aspect", {Kind::real}}, {"--reversed-z", {Kind::none}},
        {"--mode", {Kind::keyword, "linear"}}, {"--start", {Kind::real}}, {"--end", {Kind::real}},
        {"--density", {Kind::real}}, {"--fog-color", {Kind::vec3}}, {"--distance", {Kind::none}},
        {"--fog-skybox", {Kind::none}}, {"--sky", {Kind::keyword, "infinite"}},
        {"--precision", {Kind::keyword, "fast"}}, {"--max-error", {Kind::real}}, {"--device", {Kind::device}},
        {"--host-transfer", {Kind::keyword, "direct"}}, {"--verbose", {Kind::none}},
        // the volumes
        {"--volumes", {Kind::input}}, {"--eye", {Kind::vec3}}, {"--forward", {Kind::vec3}}, {"--up", {Kind::vec3}},
        {"--light-dir", {Kind::vec3}}, {"--light-color", {Kind::vec3}}, {"--time", {Kind::real}},
        {"--frame", {Kind::integer}}, {"--fps", {Kind::real}}, {"--integrator", {Kind::keyword, "physical"}},
        {"--steps", {Kind::integer}}, {"--volume-resolution", {Kind::keyword, "full"}},
        {"--upsample", {Kind::keyword, "bilinear"}}, {"--noise-size", {Kind::integer}},
        {"--noise-seed", {Kind::integer}}, {"--noise-sampling", {Kind::keyword, "buffer"}},
        {"--shadow-map", {Kind::input}}, {"--light-view-proj", {Kind::matrix}}, {"--shadow-reversed-z", {Kind::none}},
        // the renderer's camera
        {"--camera-to-world", {Kind::matrix}}, {"--axes", {Kind::keyword, "blender"}},
        {"--focal-length", {Kind::real}}, {"--sensor-width", {Kind::real}}, {"--sensor-height", {Kind::real}},
        {"--sensor-fit", {Kind::keyword, "vertical"}},
        // height fog
        {"--extinction", {Kind::vec3}}, {"--inscattering", {Kind::vec3}}, {"--height-falloff", {Kind::real}},
        {"--base-height", {Kind::real}}, {"--cutoff", {Kind::real}}, {"--max-opacity", {Kind::real}},
        {"--sun-color", {Kind::vec3}}, {"--sun-exponent", {Kind::real}}, {"--sun-start", {Kind::real}},
        {"--height-volumetric", {Kind::none}}}},
  };
  return table;
}

std::string repeat(const std::string& part, int n) {
  std::string out;
  for (int i = 0; i < n; ++i) out += (i ? "," : "") + part;
  return out;
}

std::string upper(std::string s) {
  for (char& c : s) c = char(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// One test value and the exit code it must give: 2 malformed, 1 a rule broken.
struct Probe {
  const char* what;  // "empty", "non-numeric", "huge", "wrong case"
  std::string value;
  int exit_code;
};

std::vector<Probe> probes(const FlagSpec& f) {
  switch (f.kind) {
    case Kind::real:
      return {{"empty", "", 2}, {"non-numeric", "abc", 2}, {"huge", "1e39", 1}, {"wrong case", "NAN", 1}};
    case Kind::integer:
    case Kind::integer_list:
      return {{"empty", "", 2}, {"non-numeric", "abc", 2}, {"huge", "99999999999", 1}, {"wrong case", "1E3", 2}};
    case Kind::vec3:
      return {{"empty", "", 2}, {"non-numeric", "abc", 2}, {"huge", "1e39,1e39,1e39", 1}, {"wrong case", "NAN,1,1", 1}};
    case Kind::matrix:
      return {{"empty", "", 2}, {"non-numeric", repeat("abc", 16), 2}, {"huge", repeat("1e39", 16), 1},
              {"wrong case", "NAN," + repeat("1", 15), 1}};
    case Kind::keyword:
    case Kind::keyword_list:
      return {{"empty", "", 2}, {"non-numeric", "abc", 1}, {"huge", "99999999999", 1}, {"wrong case", upper(f.word), 1}};
    case Kind::device:
      return {{"empty", "", 2}, {"non-numeric", "abc", 1}, {"huge", "99999999999", 1}, {"wrong case", "CPU", 1}};
    case Kind::input:
      return {{"empty", "", 2}, {"non-numeric", "abc", 1}, {"huge", "99999999999", 1}, {"bad placeholder", "x%s.exr", 1}};
    case Kind::output:  // any other name is a name to write
      return {{"empty", "", 2}, {"bad placeholder", "x%s.exr", 1}};
    case Kind::folder:
    case Kind::name:  // a depth file's only channel is read whatever its name
      return {{"empty", "", 2}};
    case Kind::text:  // a layer or channel the file does not have
      return {{"empty", "", 2}, {"non-numeric", "abc", 1}, {"huge", "99999999999", 1}};
    case Kind::size:  // unit letters are read in any case ("8g" is 8G)
      return {{"empty", "", 2}, {"non-numeric", "abc", 2}, {"huge", "99999999999T", 1}};
    case Kind::frames:
      return {{"empty", "", 2}, {"non-numeric", "abc", 2}, {"huge", "99999999999", 1}};
    case Kind::none:
      return {};
  }
  return {};
}

// The value flags --help lists: lines "  --flag ..." (the check_docs.py reading).
std::set<std::string> help_flags(const std::string& help) {
  std::set<std::string> flags;
  std::istringstream lines(help);
  for (std::string line; std::getline(lines, line);) {
    const std::size_t at = line.find_first_not_of(' ');
    if (at == 0 || at == std::string::npos || line.compare(at, 2, "--") != 0) continue;
    const std::size_t end = line.find_first_of(" ,=", at);
    flags.insert(line.substr(at, end == std::string::npos ? std::string::npos : end - at));
  }
  flags.erase("--help");
  return flags;
}

// The CLI with `args` (a shell word list), stdout dropped: its exit code and stderr.
struct StderrRun {
  int exit_code;
  std::string err;
};
StderrRun run_stderr(const std::string& args) {
  const std::string cmd = cli_path() + " " + args + " 2>&1 >/dev/null";
  StderrRun r{-1, {}};
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), p) != nullptr) r.err += buf.data();
  const int status = pclose(p);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string quote(const std::string& s) { return "'" + s + "'"; }

class CliGrammar : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fresh_dir("cli-grammar");
    write_demo_scene(dir_, 16, 9);
  }
  static std::string path(const std::string& name) { return dir_ + "/" + name; }

  // The command's flags with a working value each; the flag under test replaces its own.
  static std::vector<std::pair<std::string, std::string>> base(const std::string& command) {
    if (command == "demo") return {{"--out", path("demo-out")}, {"--width", "8"}, {"--height", "8"}, {"--device", "scalar"}};
    if (command == "report")
      return {{"--out", path("report-out")}, {"--width", "8"}, {"--height", "8"}, {"--device", "scalar"}, {"--runs", "7"}};
    return {{"--color", path("scene.exr")}, {"--depth", path("scene-depth.exr")}, {"--out", path("out/o.exr")},
            {"--near", "0.3"}, {"--far", "1000"}, {"--fov", "60"}, {"--mode", "exp2"}, {"--device", "scalar"}};
  }
  static std::string command_line(const std::string& command, const std::string& flag, const std::string& value) {
    std::string line = command;
    bool replaced = false;
    for (const auto& [f, v] : base(command)) {
      replaced = replaced || f == flag;
      line += " " + f + " " + quote(f == flag ? value : v);
    }
    if (!replaced) line += " " + flag + " " + quote(value);
    return line;
  }
  // Nothing written: apply's output folder empty, demo's and report's folder not made.
  static std::string leftovers(const std::string& command) {
    const std::string out = command == "apply" ? path("out") : path(command + "-out");
    if (command != "apply") return fs::exists(out) ? out + " was made" : "";
    std::string found;
    for (const auto& e : fs::directory_iterator(out)) found += e.path().filename().string() + " ";
    return found;
  }
  static inline std::string dir_;
};

TEST_F(CliGrammar, TheTableListsEveryFlagOfTheHelp) {
  for (const auto& [command, flags] : flag_table()) {
    const CliRun help = run_cli(command + " --help");
    ASSERT_EQ(help.exit_code, 0) << help.output;
    const std::set<std::string> listed = help_flags(help.output);
    EXPECT_GT(listed.size(), 3u) << help.output;
    for (const std::string& flag : listed)
      EXPECT_EQ(flags.count(flag), 1u) << "fogcl " << command << " " << flag
                                       << " is not in the grammar test's table: say what it takes";
    for (const auto& [flag, spec] : flags)
      EXPECT_EQ(listed.count(flag), 1u) << "fogcl " << command << " --help does not list " << flag;
  }
}

TEST_F(CliGrammar, EveryFlagRefusesBadValuesInOneLineNamingIt) {
  fs::create_directories(path("out"));
  // The base lines work: each failure below is the flag's.
  for (const char* command : {"apply", "demo"}) {
    const StderrRun ok = run_stderr(command_line(command, "--device", "scalar"));
    ASSERT_EQ(ok.exit_code, 0) << command << ": " << ok.err;
    fs::remove_all(command == std::string("apply") ? path("out/o.exr") : path("demo-out"));
  }
  int runs = 0, failures = 0;
  for (const auto& [command, flags] : flag_table())
    for (const auto& [flag, spec] : flags)
      for (const Probe& probe : probes(spec)) {
        const std::string line = command_line(command, flag, probe.value);
        const StderrRun r = run_stderr(line);
        ++runs;
        const std::string where = "fogcl " + line + " (" + probe.what + ")";
        const std::size_t lines = std::count(r.err.begin(), r.err.end(), '\n');
        const bool named = r.err.find(flag) != std::string::npos ||
                           ((spec.kind == Kind::input || spec.kind == Kind::text) && r.err.find(probe.value) != std::string::npos);
        const bool usage_tail = r.err.find("(see --help)\n") != std::string::npos;
        const std::string left = leftovers(command);
        EXPECT_EQ(r.exit_code, probe.exit_code) << where << "\n" << r.err;
        EXPECT_EQ(lines, 1u) << where << "\n" << r.err;
        EXPECT_EQ(r.err.rfind("fogcl: error: ", 0), 0u) << where << "\n" << r.err;
        EXPECT_TRUE(named) << where << ": the line names neither the flag nor the file\n" << r.err;
        EXPECT_EQ(usage_tail, probe.exit_code == 2) << where << ": usage errors, and only they, end with (see --help)\n"
                                                    << r.err;
        EXPECT_EQ(left, "") << where << " left files";
        failures += r.exit_code != probe.exit_code || lines != 1 || !named || !left.empty();
        if (!left.empty()) fs::remove_all(command == std::string("apply") ? path("out/o.exr") : path(command + "-out"));
      }
  std::printf("[ measured ] %d runs over the flags of apply, demo and report, %d not as the grammar says\n", runs,
              failures);
  EXPECT_GT(runs, 250);
}

// Usage lines: what is missing or unknown, each exit 2, one line ending "(see --help)".
TEST_F(CliGrammar, UsageErrorsSayWhatAndPointToHelp) {
  const std::string in = " --color " + path("scene.exr") + " --depth " + path("scene-depth.exr");
  const struct {
    std::string args, says;
  } cases[] = {
      {"apply" + in + " -o " + path("c.exr") + " --near 1 --far 2", "unknown option '-o'"},
      {"apply" + in + " --out " + path("c.exr") + " --near 1 --far 2 --fov 60", "--mode is required"},
      {"apply" + in + " --out " + path("c.exr") + " --near 1 --mode exp --fov 60", "--far is required"},
      {"apply" + in + " --out " + path("c.exr") + " --near 1 --far 2 --mode exp --mode exp2", "--mode is given 2 times"},
      {"", "a command is required"},
      {"fog", "unknown command 'fog'"},
  };
  for (const auto& c : cases) {
    const StderrRun r = run_stderr(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("(see --help)\n"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(path("c.exr")));
  }
}

// Rules between flags and library checks name the flags, with the numbers as typed.
TEST_F(CliGrammar, RuleMessagesNameTheFlagsAsTyped) {
  const std::string in = "apply --color " + path("scene.exr") + " --depth " + path("scene-depth.exr") + " --out " +
                         path("r.exr") + " --device scalar";
  const struct {
    std::string args, says;
  } cases[] = {
      {" --near 1 --far 0.5 --fov 60 --mode exp", "--far must be > --near (got --far 0.5, --near 1)"},
      {" --near 0.3 --far 100 --fov 60 --mode linear --start 50 --end 1e1", "--start must be <= --end (got --start 50, --end 1e1)"},
      {" --near 0.3 --far 100 --fov 60 --mode exp --density -0.1", "--density must be finite and >= 0 (got -0.1)"},
      {" --near 0.3 --far 100 --ortho-size 0 --mode exp", "--ortho-size must be finite and > 0 (got 0)"},
      {" --near 0.3 --far 100 --fov 60 --mode exp --aspect 1e38", "--aspect 1e38"},
      {" --near 0.3 --far 100 --fov 60 --mode height --eye 0,1,0 --forward 0,-1e-45,1e-45 --up 0,1,0",
       "--forward is too short to normalise"},
      {" --near 0.3 --far 100 --fov 60 --mode EXP", "keywords are lowercase: exp"},
  };
  for (const auto& c : cases) {
    const StderrRun r = run_stderr(in + c.args);
    EXPECT_EQ(r.exit_code, 1) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(path("r.exr")));
  }
  // An explicitly chosen device that is not there fails the demo as it fails apply.
  const StderrRun demo = run_stderr("demo --device no-such-device-name --width 8 --height 8 --out " + path("demo-bad"));
  EXPECT_EQ(demo.exit_code, 1) << demo.err;
  EXPECT_NE(demo.err.find("--device"), std::string::npos) << demo.err;
  EXPECT_FALSE(fs::exists(path("demo-bad")));
}

// "%%" in a file name (a single file or a sequence's pattern) names one '%'.
TEST_F(CliGrammar, PercentPercentIsALiteralPercent) {
  const std::string fog = " --depth-kind raw --near 0.3 --far 1000 --fov 60 --mode exp --device scalar";
  const StderrRun single = run_stderr("apply --color " + path("scene.exr") + " --depth " + path("scene-depth.exr") +
                                      fog + " --out '" + path("fog%%.exr") + "' --png '" + path("fog%%.png") + "'");
  ASSERT_EQ(single.exit_code, 0) << single.err;
  EXPECT_TRUE(fs::exists(path("fog%.exr")));
  EXPECT_TRUE(fs::exists(path("fog%.png")));
  EXPECT_FALSE(fs::exists(path("fog%%.exr")));
  for (int f : {1, 2}) {
    fs::copy_file(path("scene.exr"), path("shot%." + std::to_string(f) + ".exr"), fs::copy_options::overwrite_existing);
    fs::copy_file(path("scene-depth.exr"), path("depth%." + std::to_string(f) + ".exr"),
                  fs::copy_options::overwrite_existing);
  }
  const StderrRun seq = run_stderr("apply --color '" + path("shot%%.#.exr") + "' --depth '" + path("depth%%.%d.exr") +
                                   "'" + fog + " --out '" + path("out%%.%04d.exr") + "'");
  ASSERT_EQ(seq.exit_code, 0) << seq.err;
  EXPECT_TRUE(fs::exists(path("out%.0001.exr")));
  EXPECT_TRUE(fs::exists(path("out%.0002.exr")));
}

// `fogcl --version` and `fogcl version`: the version, the commit, the OpenCL devices ("none"
// without a driver).
TEST_F(CliGrammar, VersionNamesTheBuildAndTheDevices) {
  for (const char* args : {"--version", "version"}) {
    const CliRun r = run_cli(args);
    std::printf("[ measured ] fogcl %s:\n%s", args, r.output.c_str());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.rfind(std::string("fogcl ") + FOGCL_VERSION_STRING + " ", 0), 0u) << r.output;
    EXPECT_NE(r.output.find("\ncommit: "), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("commit: \n"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("\nOpenCL platforms: "), std::string::npos) << r.output;
    if (runtime() != nullptr) {
      EXPECT_NE(r.output.find(device_name(runtime()->device())), std::string::npos) << r.output;
    }
  }
  const std::string empty = fresh_dir("cli-grammar-no-icd");
  const CliRun none = run_cli("--version", "env -u OCL_ICD_FILENAMES OCL_ICD_VENDORS=" + empty);
  EXPECT_EQ(none.exit_code, 0) << none.output;
  EXPECT_NE(none.output.find("OpenCL platforms: none"), std::string::npos) << none.output;
}

}  // namespace
}  // namespace fogcl::test
