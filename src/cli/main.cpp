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
#include "cli/flag_values.h"
#include "cli/number_list.h"
#include "fogcl/volume_report.h"
#include "cli/sequence.h"
#include "cli/usage.h"
#include "cli/version_info.h"
#include "io/atomic_file.h"
#include "runtime/format.h"

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
    "device name (any case); default from the FOGCL_DEVICE environment variable";

CLI::Validator device_check(const std::string& flag) {
  return fogcl::cli::value_check([flag](const std::string& text) { fogcl::cli::check_device(flag, text); });
}

// A file name that may hold a frame placeholder (cli/sequence.h): not empty, one valid placeholder.
CLI::Validator path_check(const std::string& flag, const std::string& what) {
  return fogcl::cli::value_check([flag, what](const std::string& text) {
    fogcl::cli::require_text(flag, text, what);
    try {
      fogcl::cli::parse_frame_pattern(text);
    } catch (const fogcl::Error& e) {
      throw fogcl::Error(flag + " " + e.what());
    }
  });
}

// CLI11's parse errors as one line: a rule broken exit 1, anything else exit 2 ("(see --help)").
int parse_error(const CLI::App& app, const CLI::ParseError& e, int argc, char** argv) {
  std::string message = fogcl::detail::one_line(e.what());
  bool rule = false;
  if (dynamic_cast<const CLI::ValidationError*>(&e) != nullptr) {
    // "FLAG: BODY": the flag's own checks name it in BODY, CLI11's ("must be ...") do not.
    const std::size_t colon = message.find(": ");
    std::string flag = colon == std::string::npos ? std::string() : message.substr(0, colon);
    std::string body = colon == std::string::npos ? message : message.substr(colon + 2);
    rule = body.empty() || body[0] != fogcl::cli::kMalformedMark;
    if (!rule) body.erase(0, 1);
    message = body.rfind(flag, 0) == 0 ? body : flag + " " + body;
  }
  // "--mode: At Most 1 required but received 2": an option given twice.
  if (const std::size_t at = message.find(": At Most 1 required but received "); at != std::string::npos)
    message = message.substr(0, at) + " is given " + message.substr(at + 34) + " times (at most once)";
  // An unknown option is what to say first, before the required ones it may have stood for.
  for (const CLI::App* command : app.get_subcommands())
    for (const std::string& arg : command->remaining())
      if (arg.size() > 1 && arg[0] == '-') {
        message = "unknown option '" + arg + "' for fogcl " + command->get_name();
        rule = false;
        break;
      }
  if (app.get_subcommands().empty() && argc > 1 && argv[1][0] != '-')
    message = "unknown command '" + std::string(argv[1]) + "' (the commands are demo, apply, report and version)";
  std::fprintf(stderr, "fogcl: error: %s%s\n", message.c_str(), rule ? "" : " (see --help)");
  return rule ? fogcl::cli::kExitError : fogcl::cli::kExitUsage;
}

// "--near 0.3, --far 1000": the flags as typed, for messages about what they make together.
std::string typed(const CLI::App& app, std::initializer_list<const char*> flags) {
  std::string out;
  for (const char* flag : flags)
    if (app.count(flag) > 0) out += (out.empty() ? "" : ", ") + std::string(flag) + " " + fogcl::cli::flag_value(app, flag);
  return out;
}

// "--start 50" as typed, or "--start 0 (the default)".
std::string as_typed(const CLI::App& app, const char* flag, float value) {
  return std::string(flag) + " " +
         (app.count(flag) > 0 ? fogcl::cli::flag_value(app, flag) : fogcl::detail::str(value) + " (the default)");
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
  demo_cmd->add_option("--device", demo.device, kDeviceHelp)->check(device_check("--device"));
  demo_cmd->add_option("--max-memory", demo.max_memory,
                       "Refuse a scene whose size needs more memory than this (the frames and their float64 "
                       "references), e.g. 8G or 512M (binary units; default: half of the machine's memory)")
      ->check(fogcl::cli::value_check([](const std::string& text) { fogcl::cli::check_memory_size_text(text); }));

  fogcl::cli::ApplyOptions ap;
  std::string mode = "exp2", precision = "precise";
  std::string fog_color;
  CLI::App* apply_cmd = app.add_subcommand(
      "apply", "Fog OpenEXR renderer output (color + depth), one file or a frame sequence");
  apply_cmd->add_option("--color", ap.color_path,
                        "Input color EXR (RGBA or RGB, half or float; multi-part, layered or deep); "
                        "'shot.####.exr' or 'shot.%04d.exr' for a frame sequence ('%%' is a literal '%')")
      ->check(path_check("--color", "the color EXR"))
      ->required();
  apply_cmd->add_option("--layer", ap.layer, "Color layer: NAME reads NAME.R, NAME.G, NAME.B, NAME.A (default: R, G, B, A)")
      ->check(text_check("--layer", "a layer name; leave the flag out for R, G, B, A"));
  apply_cmd->add_option("--depth", ap.depth_path,
                        "Depth EXR (channel --depth-channel or the only channel); default: the depth "
                        "channel of the color file, in any part")
      ->check(path_check("--depth", "the depth EXR; leave the flag out for the color file's depth"));
  apply_cmd->add_option("--depth-channel", ap.depth_channel, "Name of the depth channel")
      ->check(text_check("--depth-channel", "a channel name"))
      ->capture_default_str();
  apply_cmd->add_option("--depth-kind", ap.depth_kind,
                        "raw: device depth in [0, 1]; eye: linear eye depth; distance: radial distance from "
                        "the eye (eye and distance: NaN, <= 0 and from 0.9999 x far on is background)")
      ->check(keyword_check("--depth-kind", {"raw", "eye", "distance"}))
      ->capture_default_str();
  apply_cmd->add_option("--out", ap.out_path,
                        "Output EXR: the input's parts, channels and attributes with the layer fogged "
                        "(RGBA float; windows kept)")
      ->check(path_check("--out", "the output EXR"))
      ->required();
  apply_cmd->add_flag("--rgba-only", ap.rgba_only, "Write only R, G, B, A (no other channels, parts or attributes)");
  apply_cmd->add_option("--png", ap.png_path, "Also write an 8-bit sRGB PNG preview here")
      ->check(path_check("--png", "a PNG file name; leave the flag out for no preview"));
  apply_cmd->add_option("--frames", ap.frames, "Sequences: FIRST-LAST (default: the frames found on disk)")
      ->check(fogcl::cli::value_check([](const std::string& text) { fogcl::cli::check_frame_range_text(text); }));
  apply_cmd->add_flag("--keep-going", ap.keep_going,
                      "Sequences: continue past a bad frame, list the failures at the end (exit code still 1)");
  apply_cmd->add_option("--max-memory", ap.max_memory,
                        "Refuse a frame whose header says it needs more memory than this (color, depth, output, "
                        "volume buffers), e.g. 8G or 512M (binary units; default: half of the machine's memory)")
      ->check(fogcl::cli::value_check([](const std::string& text) { fogcl::cli::check_memory_size_text(text); }));
  apply_cmd->add_option("--threads", ap.threads,
                        "Threads that compress and decompress EXR data (OpenEXR's pool) and run PoCL's "
                        "device, 1 to 4096 (default: every core this process may use)")
      ->check(integer_in(1, 4096, "between 1 and 4096"));
  apply_cmd->add_option("--pixel-type", ap.pixel_type,
                        "Output R, G, B, A as float (default) or half; half input written as half keeps "
                        "unfogged pixels bit for bit")
      ->check(keyword_check("--pixel-type", {"float", "half"}))
      ->capture_default_str();
  apply_cmd->add_option("--compression", ap.compression,
                        "Output compression: none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa or dwab (default: the "
                        "input's; other parts of a multi-part file are copied as stored)")
      ->check(keyword_check("--compression", {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"}));
  apply_cmd->add_option("--near", ap.near_plane, "Camera near plane [world units], > 0")
      ->check(real_check("--near", fogcl::cli::kPositive))
      ->required();
  apply_cmd->add_option("--far", ap.far_plane,
                        "Camera far plane [world units], > near; required unless --infinite-far (then it "
                        "may be given and is ignored)")
      ->check(real_check("--far", fogcl::cli::kPositive));
  apply_cmd->add_option("--fov", ap.fov,
                        "Vertical field of view [degrees], in (0, 180) (default: from the file's worldToNDC "
                        "and worldToCamera attributes); not with --ortho-size")
      ->check(real_check("--fov", RealRule{"in (0, 180) degrees", 0.0, true, 180.0, true}));
  apply_cmd->add_option("--ortho-size", ap.ortho_size,
                        "Orthographic camera: Unity's orthographicSize, half the vertical extent of the view "
                        "volume [world units], > 0; replaces --fov")
      ->check(real_check("--ortho-size", fogcl::cli::kPositive));
  apply_cmd->add_flag("--infinite-far", ap.infinite_far,
                      "Reversed Z with the far plane at infinity (raw depth = near / eye depth, 0 is sky); "
                      "implies --reversed-z; --far is ignored");
  apply_cmd->add_option("--aspect", ap.aspect,
                        "Width / height, > 0 (default: the file's camera, else the image's display window)")
      ->check(real_check("--aspect", fogcl::cli::kPositive));
  apply_cmd->add_flag("--reversed-z", ap.reversed_z, "Depth is reversed Z (1 at near, 0 at far)");
  apply_cmd->add_option("--mode", mode, "Fog mode: off, linear, exp, exp2 or height (required, except with --volumes: "
                                        "then off by default)")
      ->check(keyword_check("--mode", {"off", "linear", "exp", "exp2", "height"}));
  apply_cmd->add_option("--start", ap.settings.start, "Linear fog start [world units]")
      ->check(real_check("--start", fogcl::cli::kFinite))
      ->capture_default_str();
  apply_cmd->add_option("--end", ap.settings.end, "Linear fog end [world units], >= start")
      ->check(real_check("--end", fogcl::cli::kFinite))
      ->capture_default_str();
  apply_cmd->add_option("--density", ap.settings.density, "Exp/exp2 density [1/world unit], >= 0")
      ->check(real_check("--density", fogcl::cli::kNonNegative))
      ->capture_default_str();
  apply_cmd->add_option("--fog-color", fog_color, "Fog color, linear R,G,B, each |c| <= 65504 (default 0.5,0.5,0.5)")
      ->check(fogcl::cli::value_check([](const std::string& text) {
        const glm::dvec3 c = fogcl::cli::parse_triple("--fog-color", text, "R,G,B");
        for (int k = 0; k < 3; ++k)
          if (!(std::fabs(c[k]) <= 65504.0))  // half's range: the color may be stored as half
            throw fogcl::Error("--fog-color must be finite with each |component| <= 65504 (got '" + text + "')");
      }));
  apply_cmd->add_flag("--distance", "Distance-based fog (radial) instead of depth-based");
  apply_cmd->add_flag("--fog-skybox", ap.settings.fog_skybox, "Fog the skybox too");
  std::string sky = "far";
  apply_cmd->add_option("--sky", sky,
                        "Where the background is: far (Unity: at the far plane, fogged only with --fog-skybox) "
                        "or infinite (a renderer's mist: infinitely far, fully fogged in every mode and by the "
                        "volumes; implies --fog-skybox)")
      ->check(keyword_check("--sky", {"far", "infinite"}))
      ->capture_default_str();
  apply_cmd->add_option("--precision", precision, "Kernel maths: precise (default) or fast")
      ->check(keyword_check("--precision", {"precise", "fast"}));
  apply_cmd->add_option("--max-error", ap.max_error,
                        "Error budget, >= 0: use the fastest precision variant whose measured worst color error "
                        "(fogcl report's scenes, this device; measured once, cached under "
                        "$XDG_CACHE_HOME/fogcl) is <= E; not with --precision. With --volumes it also picks "
                        "the volumetric steps, resolution, upsampling and noise sampling the same way "
                        "(fogcl report --volumetric's scenes); not with those flags")
      ->check(real_check("--max-error", fogcl::cli::kNonNegative));
  apply_cmd->add_option("--device", ap.device, kDeviceHelp)->check(device_check("--device"));
  apply_cmd->add_option("--host-transfer", ap.host_transfer,
                        "How frames reach the device: auto (direct on a CPU device, staged on a GPU), direct "
                        "(the device uses the images' memory; a GPU driver copies from pageable memory) or staged "
                        "(pinned staging reused across frames; a sequence's uploads, kernels and downloads "
                        "overlap)")
      ->check(keyword_check("--host-transfer", {"auto", "direct", "staged"}))
      ->capture_default_str();
  apply_cmd->add_flag("--verbose", ap.verbose, "Print the device, the kernel variant chosen and why");
  fogcl::cli::add_volume_options(*apply_cmd, ap.volumes);
  fogcl::cli::add_camera_options(*apply_cmd, ap.camera);
  fogcl::cli::add_height_options(*apply_cmd, ap.height);

  fogcl::cli::ReportCliOptions report;
  std::string steps_text, scenes_text, integrators_text;
  const std::vector<std::string> kScenes = fogcl::volume_report_scene_names(), kIntegrators{"stylized", "physical"};
  CLI::App* report_cmd = app.add_subcommand(
      "report",
      "Error against run time: every precision variant x color storage (and the scalar path) on a set of "
      "scenes, against the float64 path; writes report.csv, report.json and the Pareto plot report.png");
  report_cmd->add_option("--out", report.out_dir, "Output folder")->check(text_check("--out", "a folder"))->capture_default_str();
  report_cmd->add_option("--device", report.device, kDeviceHelp)->check(device_check("--device"));
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
    if (apply_cmd->count("--far") == 0 && !ap.infinite_far)
      throw fogcl::cli::UsageError("--far is required (except with --infinite-far)");
    if (!ap.infinite_far && !(ap.far_plane > ap.near_plane))
      throw fogcl::Error("--far must be > --near (got " + typed(*apply_cmd, {"--far", "--near"}) + ")");
    if (apply_cmd->count("--fov") > 0 && apply_cmd->count("--ortho-size") > 0)
      throw fogcl::Error("give either --fov (perspective) or --ortho-size (orthographic), not both");
    if (ap.infinite_far) ap.reversed_z = true;  // an infinite far plane exists only in reversed Z
    ap.settings.mode = kModes.at(mode);
    if (ap.settings.mode == FogMode::linear && !(ap.settings.start <= ap.settings.end))
      throw fogcl::Error("--start must be <= --end (got " + as_typed(*apply_cmd, "--start", ap.settings.start) + ", " +
                         as_typed(*apply_cmd, "--end", ap.settings.end) + ")");
    ap.settings.precision = kPrecisions.at(precision);
    ap.settings.sky = kSkies.at(sky);
    ap.settings.metric = apply_cmd->count("--distance") > 0 ? FogMetric::distance : FogMetric::depth;
    if (!fog_color.empty()) ap.settings.color = fogcl::cli::parse_finite_vec3("--fog-color", fog_color);
    ap.camera_flags = typed(*apply_cmd, {"--near", "--far", "--fov", "--ortho-size", "--aspect", "--focal-length",
                                         "--sensor-width", "--sensor-height"}) +
                      (ap.infinite_far ? ", --infinite-far" : "");
    fogcl::cli::resolve_height_flags(*apply_cmd, ap);
    // --height-volumetric runs the volumetric pass without --volumes: the budget is its too.
    ap.volumes.max_error_given = ap.max_error_given && (!ap.volumes.volumes_path.empty() || ap.volumes.height_fog);
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
