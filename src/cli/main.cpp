// fogcl: the command-line tool. `fogcl demo` renders and fogs the built-in scene; `fogcl apply`
// fogs an EXR color + depth pair; `fogcl report` measures error against run time per variant.
#include <cmath>
#include <cstdio>
#include <exception>
#include <new>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/cli.h"
#include "cli/frame_memory.h"
#include "cli/usage.h"
#include "io/atomic_file.h"

namespace {

using fogcl::FogMetric;
using fogcl::FogMode;
using fogcl::Precision;
using fogcl::SkyDistance;

const std::map<std::string, FogMode> kModes{
    {"off", FogMode::off}, {"linear", FogMode::linear}, {"exp", FogMode::exp}, {"exp2", FogMode::exp2}, {"height", FogMode::height}};
const std::map<std::string, Precision> kPrecisions{{"precise", Precision::precise}, {"fast", Precision::fast}};
const std::map<std::string, SkyDistance> kSkies{{"far", SkyDistance::far_plane}, {"infinite", SkyDistance::infinite}};

const char* kDeviceHelp =
    "cpu (default: PoCL's CPU device), gpu, scalar (one-thread C++ path) or part of an OpenCL "
    "device name; default from the FOGCL_DEVICE environment variable";

}  // namespace

int main(int argc, char** argv) {
  fogcl::detail::remove_temporaries_on_signals();  // a killed run leaves no temporary file
  CLI::App app{"fogcl: deferred fog (Unity linear/exp/exp2) and volumetric fog volumes, on OpenCL devices and in C++"};
  app.require_subcommand(1);
  app.footer(fogcl::cli::exit_codes_help());

  const CLI::Validator kPixels = fogcl::cli::integer_in(1, 16384, "in [1, 16384]");
  fogcl::cli::DemoOptions demo;
  CLI::App* demo_cmd = app.add_subcommand(
      "demo", "Render the built-in scene, fog it in several settings on OpenCL and in C++, write EXR + PNG, print timings and errors");
  demo_cmd->add_option("--out", demo.out_dir, "Output folder")->capture_default_str();
  demo_cmd->add_option("--width", demo.width, "Image width [pixels]")->check(kPixels)->capture_default_str();
  demo_cmd->add_option("--height", demo.height, "Image height [pixels]")->check(kPixels)->capture_default_str();
  demo_cmd->add_option("--device", demo.device, kDeviceHelp);
  demo_cmd->add_option("--max-memory", demo.max_memory,
                       "Refuse a scene whose size needs more memory than this (the frames and their float64 "
                       "references), e.g. 8G or 512M (binary units; default: half of the machine's memory)");

  fogcl::cli::ApplyOptions ap;
  std::string mode = "exp2", precision = "precise";
  std::vector<float> fog_color;
  CLI::App* apply_cmd = app.add_subcommand(
      "apply", "Fog OpenEXR renderer output (color + depth), one file or a frame sequence");
  apply_cmd->add_option("--color", ap.color_path,
                        "Input color EXR (RGBA or RGB, half or float; multi-part, layered or deep); "
                        "'shot.####.exr' or 'shot.%04d.exr' for a frame sequence")
      ->required();
  apply_cmd->add_option("--layer", ap.layer, "Color layer: NAME reads NAME.R, NAME.G, NAME.B, NAME.A (default: R, G, B, A)");
  apply_cmd->add_option("--depth", ap.depth_path,
                        "Depth EXR (channel --depth-channel or the only channel); default: the depth "
                        "channel of the color file, in any part");
  apply_cmd->add_option("--depth-channel", ap.depth_channel, "Name of the depth channel")->capture_default_str();
  apply_cmd->add_option("--depth-kind", ap.depth_kind,
                        "raw: device depth in [0, 1]; eye: linear eye depth; distance: radial distance from "
                        "the eye (non-finite, <= 0 or >= far is background)")
      ->capture_default_str();
  apply_cmd->add_option("--out", ap.out_path,
                        "Output EXR: the input's parts, channels and attributes with the layer fogged "
                        "(RGBA float; windows kept)")
      ->required();
  apply_cmd->add_flag("--rgba-only", ap.rgba_only, "Write only R, G, B, A (no other channels, parts or attributes)");
  apply_cmd->add_option("--png", ap.png_path, "Also write an 8-bit sRGB PNG preview here");
  apply_cmd->add_option("--frames", ap.frames, "Sequences: FIRST-LAST (default: the frames found on disk)");
  apply_cmd->add_flag("--keep-going", ap.keep_going,
                      "Sequences: continue past a bad frame, list the failures at the end (exit code still 1)");
  apply_cmd->add_option("--max-memory", ap.max_memory,
                        "Refuse a frame whose header says it needs more memory than this (color, depth, output, "
                        "volume buffers), e.g. 8G or 512M (binary units; default: half of the machine's memory)");
  apply_cmd->add_option("--threads", ap.threads,
                        "Threads that compress and decompress EXR data (OpenEXR's pool) and run PoCL's "
                        "device, 1 to 4096 (default: every core this process may use)")
      ->check(fogcl::cli::integer_in(1, 4096, "between 1 and 4096"));
  apply_cmd->add_option("--pixel-type", ap.pixel_type,
                        "Output R, G, B, A as float (default) or half; half input written as half keeps "
                        "unfogged pixels bit for bit")
      ->capture_default_str();
  apply_cmd->add_option("--compression", ap.compression,
                        "Output compression: none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa or dwab (default: the "
                        "input's; other parts of a multi-part file are copied as stored)");
  apply_cmd->add_option("--near", ap.near_plane, "Camera near plane [world units], > 0")->required();
  apply_cmd->add_option("--far", ap.far_plane,
                        "Camera far plane [world units], > near; required unless --infinite-far (then it "
                        "may be given and is ignored)");
  apply_cmd->add_option("--fov", ap.fov,
                        "Vertical field of view [degrees], in (0, 180) (default: from the file's worldToNDC "
                        "and worldToCamera attributes); not with --ortho-size");
  apply_cmd->add_option("--ortho-size", ap.ortho_size,
                        "Orthographic camera: Unity's orthographicSize, half the vertical extent of the view "
                        "volume [world units], > 0; replaces --fov");
  apply_cmd->add_flag("--infinite-far", ap.infinite_far,
                      "Reversed Z with the far plane at infinity (raw depth = near / eye depth, 0 is sky); "
                      "implies --reversed-z; --far is ignored");
  apply_cmd->add_option("--aspect", ap.aspect,
                        "Width / height (default: the file's camera, else the image's display window)");
  apply_cmd->add_flag("--reversed-z", ap.reversed_z, "Depth is reversed Z (1 at near, 0 at far)");
  apply_cmd->add_option("--mode", mode, "Fog mode (required, except with --volumes: then off by default)")
      ->transform(CLI::IsMember(kModes, CLI::ignore_case));
  apply_cmd->add_option("--start", ap.settings.start, "Linear fog start [world units]")->capture_default_str();
  apply_cmd->add_option("--end", ap.settings.end, "Linear fog end [world units], >= start")->capture_default_str();
  apply_cmd->add_option("--density", ap.settings.density, "Exp/exp2 density [1/world unit], >= 0")->capture_default_str();
  apply_cmd->add_option("--fog-color", fog_color, "Fog color, linear R,G,B (default 0.5,0.5,0.5)")
      ->delimiter(',')
      ->expected(3);
  apply_cmd->add_flag("--distance", "Distance-based fog (radial) instead of depth-based");
  apply_cmd->add_flag("--fog-skybox", ap.settings.fog_skybox, "Fog the skybox too");
  std::string sky = "far";
  apply_cmd->add_option("--sky", sky,
                        "Where the background is: far (Unity: at the far plane, fogged only with --fog-skybox) "
                        "or infinite (a renderer's mist: infinitely far, fully fogged in every mode and by the "
                        "volumes; implies --fog-skybox)")
      ->transform(CLI::IsMember(kSkies, CLI::ignore_case))
      ->capture_default_str();
  apply_cmd->add_option("--precision", precision, "Kernel maths: precise (default) or fast")
      ->transform(CLI::IsMember(kPrecisions, CLI::ignore_case));
  apply_cmd->add_option("--max-error", ap.max_error,
                        "Error budget: use the fastest precision variant whose measured worst color error "
                        "(fogcl report's scenes, this device; measured once, cached under "
                        "$XDG_CACHE_HOME/fogcl) is <= E; not with --precision. With --volumes it also picks "
                        "the volumetric steps, resolution, upsampling and noise sampling the same way "
                        "(fogcl report --volumetric's scenes); not with those flags");
  apply_cmd->add_option("--device", ap.device, kDeviceHelp);
  apply_cmd->add_option("--host-transfer", ap.host_transfer,
                        "How frames reach the device: auto (direct on a CPU device, staged on a GPU), direct "
                        "(the device uses the images' memory; a GPU driver copies from pageable memory) or staged "
                        "(pinned staging reused across frames; a sequence's uploads, kernels and downloads "
                        "overlap)")
      ->check(CLI::IsMember({"auto", "direct", "staged"}))
      ->capture_default_str();
  apply_cmd->add_flag("--verbose", ap.verbose, "Print the device, the kernel variant chosen and why");
  fogcl::cli::add_volume_options(*apply_cmd, ap.volumes);
  fogcl::cli::add_camera_options(*apply_cmd, ap.camera);
  fogcl::cli::add_height_options(*apply_cmd, ap.height);

  fogcl::cli::ReportCliOptions report;
  CLI::App* report_cmd = app.add_subcommand(
      "report",
      "Error against run time: every precision variant x color storage (and the scalar path) on a set of "
      "scenes, against the float64 path; writes report.csv, report.json and the Pareto plot report.png");
  report_cmd->add_option("--out", report.out_dir, "Output folder")->capture_default_str();
  report_cmd->add_option("--device", report.device, kDeviceHelp);
  report_cmd->add_option("--width", report.width, "Frame width [pixels]")->check(kPixels)->capture_default_str();
  report_cmd->add_option("--height", report.height, "Frame height [pixels]")->check(kPixels)->capture_default_str();
  report_cmd->add_option("--runs", report.runs,
                         "Timed runs per row (the median is reported), >= 7 (default 9); --volumetric: >= 3 "
                         "(default 5)")
      ->check(fogcl::cli::integer_in(1, 1000, "in [1, 1000] (>= 7 for the deferred report, >= 3 with --volumetric)"));
  report_cmd->add_flag("--volumetric", report.volumetric,
                       "The volumetric pass instead: steps x resolution x upsampling x noise sampling x integrator x "
                       "storage on four volume scenes against the scalar<double> march at 4096 steps (default frame "
                       "160x90); writes volume-report.csv, .json and .png");
  report_cmd->add_option("--steps", report.steps, "--volumetric: only these step counts, e.g. 16,32 (default all six)")
      ->delimiter(',')
      ->check(fogcl::cli::integer_in(1, 4096, "in [1, 4096]"));
  report_cmd->add_option("--scenes", report.scenes, "--volumetric: only these of demo,dense,thin,inside")
      ->delimiter(',');
  report_cmd->add_option("--integrators", report.integrators, "--volumetric: only these of stylized,physical")
      ->delimiter(',');

  for (CLI::App* command : {demo_cmd, apply_cmd, report_cmd}) command->footer(fogcl::cli::exit_codes_help());

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help prints the help (exit 0). Anything else is one line like every other error: a value
    // that breaks a flag's rule (a range, a list of names) exit 1, a malformed command line exit 2.
    if (e.get_exit_code() == 0) return app.exit(e);
    const bool rule = dynamic_cast<const CLI::ValidationError*>(&e) != nullptr;
    std::string message = fogcl::detail::one_line(e.what());
    // CLI11 writes "--steps: must be ..."; fogcl's own rule messages read "--steps must be ...".
    if (const std::size_t at = message.find(": must be "); rule && at != std::string::npos) message.erase(at, 1);
    if (app.get_subcommands().empty() && argc > 1 && argv[1][0] != '-')
      message = "unknown command '" + std::string(argv[1]) + "' (the commands are demo, apply and report)";
    std::fprintf(stderr, "fogcl: error: %s%s\n", message.c_str(), rule ? "" : " (see --help)");
    return rule ? fogcl::cli::kExitError : fogcl::cli::kExitUsage;
  }

  try {
    if (*demo_cmd) return fogcl::cli::run_demo(demo);
    if (*report_cmd) {
      fogcl::cli::set_memory_stage("measuring the report");
      if (report.runs > 1000) throw fogcl::Error("--runs must be <= 1000 (got " + std::to_string(report.runs) + ")");
      if (report.volumetric) {  // its own defaults: the 4096-step references must take seconds
        if (report_cmd->count("--width") == 0) report.width = 160;
        if (report_cmd->count("--height") == 0) report.height = 90;
        if (report_cmd->count("--runs") == 0) report.runs = 5;
        return fogcl::cli::run_volume_report_cli(report);
      }
      for (const char* flag : {"--steps", "--scenes", "--integrators"})
        if (report_cmd->count(flag) > 0)
          throw fogcl::Error(std::string(flag) + " selects volumetric variants; it needs --volumetric");
      if (report.runs < 7) throw fogcl::Error("--runs must be >= 7 for the deferred report (got " +
                                              std::to_string(report.runs) + ")");
      return fogcl::cli::run_report(report);
    }
    fogcl::cli::note_given_volume_flags(*apply_cmd, ap.volumes);
    fogcl::cli::resolve_camera_flags(*apply_cmd, ap);
    // With volumes the deferred fog is optional: no --mode runs only the volumetric pass.
    if (apply_cmd->count("--mode") == 0) {
      if (ap.volumes.volumes_path.empty()) throw fogcl::cli::UsageError("--mode is required (off, linear, exp, exp2 or height)");
      mode = "off";
    }
    ap.precision_given = apply_cmd->count("--precision") > 0;
    ap.max_error_given = apply_cmd->count("--max-error") > 0;
    ap.volumes.max_error_given = ap.max_error_given && !ap.volumes.volumes_path.empty();
    ap.volumes.max_error = ap.max_error;
    ap.volumes.max_memory = ap.max_memory;
    if (apply_cmd->count("--threads") > 0 && ap.threads < 1)
      throw fogcl::Error("--threads must be between 1 and 4096 (got " + std::to_string(ap.threads) + ")");
    if (apply_cmd->count("--far") == 0 && !ap.infinite_far)
      throw fogcl::cli::UsageError("--far is required (except with --infinite-far)");
    if (apply_cmd->count("--ortho-size") > 0 && !(ap.ortho_size > 0.0f && std::isfinite(ap.ortho_size)))
      throw fogcl::Error("--ortho-size must be finite and > 0 (got " + std::to_string(ap.ortho_size) + ")");
    // Not given is 0 in ApplyOptions: a given 0 must not read as "no --fov given".
    if (apply_cmd->count("--fov") > 0 && !(ap.fov > 0.0f && ap.fov < 180.0f))
      throw fogcl::Error("--fov must be in (0, 180) degrees (got " + fogcl::cli::flag_value(*apply_cmd, "--fov") + ")");
    if (apply_cmd->count("--aspect") > 0 && !(ap.aspect > 0.0f && std::isfinite(ap.aspect)))
      throw fogcl::Error("--aspect must be finite and > 0 (got " + fogcl::cli::flag_value(*apply_cmd, "--aspect") + ")");
    if (apply_cmd->count("--fov") > 0 && apply_cmd->count("--ortho-size") > 0)
      throw fogcl::Error("give either --fov (perspective) or --ortho-size (orthographic), not both");
    if (ap.infinite_far) ap.reversed_z = true;  // an infinite far plane exists only in reversed Z
    ap.settings.mode = kModes.at(mode);
    ap.settings.precision = kPrecisions.at(precision);
    ap.settings.sky = kSkies.at(sky);
    ap.settings.metric = apply_cmd->count("--distance") > 0 ? FogMetric::distance : FogMetric::depth;
    if (!fog_color.empty()) ap.settings.color = glm::vec3(fog_color[0], fog_color[1], fog_color[2]);
    fogcl::cli::resolve_height_flags(*apply_cmd, ap);
    return fogcl::cli::run_apply(ap);
  } catch (const fogcl::cli::UsageError& e) {
    std::fprintf(stderr, "fogcl: error: %s\n", e.what());
    return fogcl::cli::kExitUsage;
  } catch (const std::bad_alloc&) {  // the last resort: the places that allocate frames name them
    std::fprintf(stderr, "fogcl: error: out of memory while %s\n", fogcl::cli::memory_stage());
    return fogcl::cli::kExitError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fogcl: error: %s\n", e.what());
    return fogcl::cli::kExitError;
  }
}
