// fogcl: the command-line tool. `fogcl demo` renders and fogs the built-in scene; `fogcl apply`
// fogs an EXR color + depth pair; `fogcl report` measures error against run time per variant.
#include <cmath>
#include <cstdio>
#include <exception>
#include <new>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/apply_flags.h"
#include "cli/cli.h"
#include "cli/frame_memory.h"
#include "cli/flag_values.h"
#include "cli/number_list.h"
#include "fogcl/volume_report.h"
#include "cli/sequence.h"
#include "cli/usage.h"
#include "cli/version_info.h"
#include "io/atomic_file.h"
#include "runtime/format.h"

namespace {

// CLI11's parse errors as one line: a rule broken exit 1, anything else exit 2 ("(see --help)").
int parse_error(const CLI::App& app, const CLI::ParseError& e, int argc, char** argv) {
  bool rule = false;
  const std::vector<CLI::App*> commands = app.get_subcommands();
  std::string message =
      fogcl::cli::parse_error_text(e, std::vector<const CLI::App*>(commands.begin(), commands.end()), &rule);
  if (app.get_subcommands().empty() && argc > 1 && argv[1][0] != '-')
    message = "unknown command '" + std::string(argv[1]) + "' (the commands are demo, apply, report and version)";
  std::fprintf(stderr, "fogcl: error: %s%s\n", message.c_str(), rule ? "" : " (see --help)");
  return rule ? fogcl::cli::kExitError : fogcl::cli::kExitUsage;
}


}  // namespace

int main(int argc, char** argv) {
  using fogcl::cli::integer_in;
  using fogcl::cli::keyword_check;
  using fogcl::cli::real_check;
  using fogcl::cli::RealRule;
  using fogcl::cli::text_check;
  fogcl::detail::remove_temporaries_on_signals();  // a killed run leaves no temporary file
  CLI::App app{"fogcl: deferred fog (Unity linear/exp/exp2) and volumetric fog volumes, on OpenCL devices and in C++"};
  app.require_subcommand(0, 1);  // none only with --version
  app.footer(fogcl::cli::exit_codes_help());
  bool version_flag = false;
  app.add_flag("--version", version_flag,
               "Print the version, the git commit it was built from and the OpenCL platforms and devices found");

  const CLI::Validator kPixels = integer_in(1, 16384, "in [1, 16384]");
  fogcl::cli::DemoOptions demo;
  CLI::App* demo_cmd = app.add_subcommand(
      "demo", "Render the built-in scene, fog it in several settings on OpenCL and in C++, write EXR + PNG, print timings and errors");
  demo_cmd->add_option("--out", demo.out_dir, "Output folder")->check(text_check("--out", "a folder"))->capture_default_str();
  demo_cmd->add_option("--width", demo.width, "Image width [pixels]")->check(kPixels)->capture_default_str();
  demo_cmd->add_option("--height", demo.height, "Image height [pixels]")->check(kPixels)->capture_default_str();
  demo_cmd->add_option("--device", demo.device, fogcl::cli::kDeviceHelp)->check(fogcl::cli::device_check("--device"));
  demo_cmd->add_option("--max-memory", demo.max_memory,
                       "Refuse a scene whose size needs more memory than this (the frames and their float64 "
                       "references), e.g. 8G or 512M (binary units; default: half of the machine's memory)")
      ->check(fogcl::cli::value_check([](const std::string& text) { fogcl::cli::check_memory_size_text(text); }));

  fogcl::cli::ApplyFlags apply_flags;
  fogcl::cli::ApplyOptions& ap = apply_flags.options;
  CLI::App* apply_cmd = app.add_subcommand(
      "apply", "Fog OpenEXR renderer output (color + depth), one file or a frame sequence");
  fogcl::cli::add_apply_flags(*apply_cmd, apply_flags);

  fogcl::cli::ReportCliOptions report;
  std::string steps_text, scenes_text, integrators_text;
  const std::vector<std::string> kScenes = fogcl::volume_report_scene_names(), kIntegrators{"stylized", "physical"};
  CLI::App* report_cmd = app.add_subcommand(
      "report",
      "Error against run time: every precision variant x color storage (and the scalar path) on a set of "
      "scenes, against the float64 path; writes report.csv, report.json and the Pareto plot report.png");
  report_cmd->add_option("--out", report.out_dir, "Output folder")->check(text_check("--out", "a folder"))->capture_default_str();
  report_cmd->add_option("--device", report.device, fogcl::cli::kDeviceHelp)->check(fogcl::cli::device_check("--device"));
  report_cmd->add_option("--width", report.width, "Frame width [pixels]")->check(kPixels)->capture_default_str();
  report_cmd->add_option("--height", report.height, "Frame height [pixels]")->check(kPixels)->capture_default_str();
  report_cmd->add_option("--runs", report.runs,
                         "Timed runs per row (the median is reported), >= 7 (default 9); --volumetric: >= 3 "
                         "(default 5)")
      ->check(integer_in(1, 1000, "in [1, 1000] (>= 7 for the deferred report, >= 3 with --volumetric)"));
  report_cmd->add_flag("--volumetric", report.volumetric,
                       "The volumetric pass instead: steps x resolution x upsampling x noise sampling x integrator x "
                       "storage on four volume scenes, a light-shaft and a street-lamp scene against the scalar<double> march at 4096 "
                       "steps (default frame "
                       "160x90); writes volume-report.csv, .json and .png");
  report_cmd->add_option("--steps", steps_text, "--volumetric: only these step counts, each in [1, 4096], e.g. 16,32 "
                                                "(default all six)")
      ->check(fogcl::cli::value_check([](const std::string& text) { fogcl::cli::parse_step_list("--steps", text); }));
  report_cmd->add_option("--scenes", scenes_text, "--volumetric: only these of demo,dense,thin,inside,shafts,lamps")
      ->check(fogcl::cli::value_check(
          [&kScenes](const std::string& text) { fogcl::cli::keyword_list_value("--scenes", text, kScenes); }));
  report_cmd->add_option("--integrators", integrators_text, "--volumetric: only these of stylized,physical")
      ->check(fogcl::cli::value_check([&kIntegrators](const std::string& text) {
        fogcl::cli::keyword_list_value("--integrators", text, kIntegrators);
      }));

  CLI::App* version_cmd = app.add_subcommand("version", "Print the version, the git commit it was built from and the OpenCL platforms and devices found (as --version)");
  for (CLI::App* command : {demo_cmd, apply_cmd, report_cmd, version_cmd})
    command->footer(fogcl::cli::exit_codes_help());

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help prints the help (exit 0). Anything else is one line like every other error.
    if (e.get_exit_code() == 0) return app.exit(e);
    return parse_error(app, e, argc, argv);
  }

  try {
    if (version_flag || *version_cmd) return fogcl::cli::print_version();
    if (app.get_subcommands().empty())
      throw fogcl::cli::UsageError("a command is required: demo, apply, report or version");
    // FOGCL_DEVICE is --device's default: the same rule.
    const char* env_device = std::getenv("FOGCL_DEVICE");
    if (env_device != nullptr && *env_device != '\0' && app.get_subcommands().front()->count("--device") == 0)
      fogcl::cli::check_device("FOGCL_DEVICE", env_device);
    if (*demo_cmd) return fogcl::cli::run_demo(demo);
    if (*report_cmd) {
      fogcl::cli::set_memory_stage("measuring the report");
      if (!steps_text.empty()) report.steps = fogcl::cli::parse_step_list("--steps", steps_text);
      if (!scenes_text.empty()) report.scenes = fogcl::cli::keyword_list_value("--scenes", scenes_text, kScenes);
      if (!integrators_text.empty())
        report.integrators = fogcl::cli::keyword_list_value("--integrators", integrators_text, kIntegrators);
      if (report.volumetric) {  // its own defaults: the 4096-step references must take seconds
        if (report_cmd->count("--width") == 0) report.width = 160;
        if (report_cmd->count("--height") == 0) report.height = 90;
        if (report_cmd->count("--runs") == 0) report.runs = 5;
        if (report.runs < 3)
          throw fogcl::Error("--runs must be >= 3 with --volumetric (got " + fogcl::cli::flag_value(*report_cmd, "--runs") + ")");
        return fogcl::cli::run_volume_report_cli(report);
      }
      for (const char* flag : {"--steps", "--scenes", "--integrators"})
        if (report_cmd->count(flag) > 0)
          throw fogcl::Error(std::string(flag) + " selects volumetric variants; it needs --volumetric");
      if (report.runs < 7)
        throw fogcl::Error("--runs must be >= 7 for the deferred report (got " +
                           fogcl::cli::flag_value(*report_cmd, "--runs") + ")");
      return fogcl::cli::run_report(report);
    }
    fogcl::cli::resolve_apply_flags(*apply_cmd, apply_flags);

    return fogcl::cli::run_apply(ap);
  } catch (const fogcl::cli::UsageError& e) {
    std::fprintf(stderr, "fogcl: error: %s (see --help)\n", e.what());
    return fogcl::cli::kExitUsage;
  } catch (const std::bad_alloc&) {  // the last resort: the places that allocate frames name them
    std::fprintf(stderr, "fogcl: error: out of memory while %s\n", fogcl::cli::memory_stage());
    return fogcl::cli::kExitError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fogcl: error: %s\n", e.what());
    return fogcl::cli::kExitError;
  }
}
