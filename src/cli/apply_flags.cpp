// `fogcl apply`'s flags (cli/apply_flags.h).
#include "cli/apply_flags.h"

#include <cmath>
#include <map>

#include <CLI/CLI.hpp>

#include "cli/flag_values.h"
#include "cli/usage.h"
#include "io/atomic_file.h"
#include "runtime/format.h"

namespace fogcl::cli {

namespace {

const std::map<std::string, FogMode> kModes{
    {"off", FogMode::off}, {"linear", FogMode::linear}, {"exp", FogMode::exp}, {"exp2", FogMode::exp2}, {"height", FogMode::height}};
const std::map<std::string, Precision> kPrecisions{{"precise", Precision::precise}, {"fast", Precision::fast}};
const std::map<std::string, SkyDistance> kSkies{{"far", SkyDistance::far_plane}, {"infinite", SkyDistance::infinite}};

// "--near 0.3, --far 1000": the flags as typed, for messages about what they make together.
std::string typed(const CLI::App& app, std::initializer_list<const char*> flags) {
  std::string out;
  for (const char* flag : flags)
    if (app.count(flag) > 0) out += (out.empty() ? "" : ", ") + std::string(flag) + " " + flag_value(app, flag);
  return out;
}

// "--start 50" as typed, or "--start 0 (the default)".
std::string as_typed(const CLI::App& app, const char* flag, float value) {
  return std::string(flag) + " " +
         (app.count(flag) > 0 ? flag_value(app, flag) : detail::str(value) + " (the default)");
}
}  // namespace

void add_apply_flags(CLI::App& apply, ApplyFlags& flags, bool files) {
  ApplyOptions& ap = flags.options;
  std::string& mode = flags.mode;
  std::string& precision = flags.precision;
  std::string& fog_color = flags.fog_color;
  std::string& sky = flags.sky;
  if (files) {
    apply.add_option("--color", ap.color_path,
                          "Input color EXR (RGBA or RGB, half or float; multi-part, layered or deep); "
                          "'shot.####.exr' or 'shot.%04d.exr' for a frame sequence ('%%' is a literal '%')")
        ->check(path_check("--color", "the color EXR"))
        ->required();
    apply.add_option("--layer", ap.layer, "Color layer: NAME reads NAME.R, NAME.G, NAME.B, NAME.A (default: R, G, B, A)")
        ->check(text_check("--layer", "a layer name; leave the flag out for R, G, B, A"));
    apply.add_option("--depth", ap.depth_path,
                          "Depth EXR (channel --depth-channel or the only channel); default: the depth "
                          "channel of the color file, in any part")
        ->check(path_check("--depth", "the depth EXR; leave the flag out for the color file's depth"));
    apply.add_option("--depth-channel", ap.depth_channel, "Name of the depth channel")
        ->check(text_check("--depth-channel", "a channel name"))
        ->capture_default_str();
  }
  apply.add_option("--depth-kind", ap.depth_kind,
                        "raw: device depth in [0, 1]; eye: linear eye depth; distance: radial distance from "
                        "the eye (eye and distance: NaN, <= 0 and from 0.9999 x far on is background)")
      ->check(keyword_check("--depth-kind", {"raw", "eye", "distance"}))
      ->capture_default_str();
  if (files) {
    apply.add_option("--out", ap.out_path,
                          "Output EXR: the input's parts, channels and attributes with the layer fogged "
                          "(RGBA float; windows kept)")
        ->check(path_check("--out", "the output EXR"))
        ->required();
    apply.add_flag("--rgba-only", ap.rgba_only, "Write only R, G, B, A (no other channels, parts or attributes)");
    apply.add_option("--png", ap.png_path, "Also write an 8-bit sRGB PNG preview here")
        ->check(path_check("--png", "a PNG file name; leave the flag out for no preview"));
    apply.add_option("--frames", ap.frames, "Sequences: FIRST-LAST (default: the frames found on disk)")
        ->check(value_check([](const std::string& text) { check_frame_range_text(text); }));
    apply.add_flag("--keep-going", ap.keep_going,
                        "Sequences: continue past a bad frame, list the failures at the end (exit code still 1)");
  }
  apply.add_option("--max-memory", ap.max_memory,
                        "Refuse a frame whose header says it needs more memory than this (color, depth, output, "
                        "volume buffers), e.g. 8G or 512M (binary units; default: half of the machine's memory)")
      ->check(value_check([](const std::string& text) { check_memory_size_text(text); }));
  if (files) {
    apply.add_option("--threads", ap.threads,
                          "Threads that compress and decompress EXR data (OpenEXR's pool) and run PoCL's "
                          "device, 1 to 4096 (default: every core this process may use)")
        ->check(integer_in(1, 4096, "between 1 and 4096"));
    apply.add_option("--pixel-type", ap.pixel_type,
                          "Output R, G, B, A as float (default) or half; half input written as half keeps "
                          "unfogged pixels bit for bit")
        ->check(keyword_check("--pixel-type", {"float", "half"}))
        ->capture_default_str();
    apply.add_option("--compression", ap.compression,
                          "Output compression: none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa or dwab (default: the "
                          "input's; other parts of a multi-part file are copied as stored)")
        ->check(keyword_check("--compression", {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"}));
  }
  apply.add_option("--near", ap.near_plane, "Camera near plane [world units], > 0")
      ->check(real_check("--near", kPositive))
      ->required();
  apply.add_option("--far", ap.far_plane,
                        "Camera far plane [world units], > near; required unless --infinite-far (then it "
                        "may be given and is ignored)")
      ->check(real_check("--far", kPositive));
  apply.add_option("--fov", ap.fov,
                        "Vertical field of view [degrees], in (0, 180) (default: from the file's worldToNDC "
                        "and worldToCamera attributes); not with --ortho-size")
      ->check(real_check("--fov", RealRule{"in (0, 180) degrees", 0.0, true, 180.0, true}));
  apply.add_option("--ortho-size", ap.ortho_size,
                        "Orthographic camera: Unity's orthographicSize, half the vertical extent of the view "
                        "volume [world units], > 0; replaces --fov")
      ->check(real_check("--ortho-size", kPositive));
  apply.add_flag("--infinite-far", ap.infinite_far,
                      "Reversed Z with the far plane at infinity (raw depth = near / eye depth, 0 is sky); "
                      "implies --reversed-z; --far is ignored");
  apply.add_option("--aspect", ap.aspect,
                        "Width / height, > 0 (default: the file's camera, else the image's display window)")
      ->check(real_check("--aspect", kPositive));
  apply.add_flag("--reversed-z", ap.reversed_z, "Depth is reversed Z (1 at near, 0 at far)");
  apply.add_option("--mode", mode, "Fog mode: off, linear, exp, exp2 or height (required, except with --volumes: "
                                        "then off by default)")
      ->check(keyword_check("--mode", {"off", "linear", "exp", "exp2", "height"}));
  apply.add_option("--start", ap.settings.start, "Linear fog start [world units]")
      ->check(real_check("--start", kFinite))
      ->capture_default_str();
  apply.add_option("--end", ap.settings.end, "Linear fog end [world units], >= start")
      ->check(real_check("--end", kFinite))
      ->capture_default_str();
  apply.add_option("--density", ap.settings.density, "Exp/exp2 density [1/world unit], >= 0")
      ->check(real_check("--density", kNonNegative))
      ->capture_default_str();
  apply.add_option("--fog-color", fog_color, "Fog color, linear R,G,B, each |c| <= 65504 (default 0.5,0.5,0.5)")
      ->check(value_check([](const std::string& text) {
        const glm::dvec3 c = parse_triple("--fog-color", text, "R,G,B");
        for (int k = 0; k < 3; ++k)
          if (!(std::fabs(c[k]) <= 65504.0))  // half's range: the color may be stored as half
            throw Error("--fog-color must be finite with each |component| <= 65504 (got '" + text + "')");
      }));
  apply.add_flag("--distance", "Distance-based fog (radial) instead of depth-based");
  apply.add_flag("--fog-skybox", ap.settings.fog_skybox, "Fog the skybox too");
  apply.add_option("--sky", sky,
                        "Where the background is: far (Unity: at the far plane, fogged only with --fog-skybox) "
                        "or infinite (a renderer's mist: infinitely far, fully fogged in every mode and by the "
                        "volumes; implies --fog-skybox)")
      ->check(keyword_check("--sky", {"far", "infinite"}))
      ->capture_default_str();
  apply.add_option("--precision", precision, "Kernel maths: precise (default) or fast")
      ->check(keyword_check("--precision", {"precise", "fast"}));
  apply.add_option("--max-error", ap.max_error,
                        "Error budget, >= 0: use the fastest precision variant whose measured worst color error "
                        "(fogcl report's scenes, this device; measured once, cached under "
                        "$XDG_CACHE_HOME/fogcl) is <= E; not with --precision. With --volumes it also picks "
                        "the volumetric steps, resolution, upsampling and noise sampling the same way "
                        "(fogcl report --volumetric's scenes); not with those flags")
      ->check(real_check("--max-error", kNonNegative));
  apply.add_option("--device", ap.device, kDeviceHelp)->check(device_check("--device"));
  apply.add_option("--host-transfer", ap.host_transfer,
                        "How frames reach the device: auto (direct on a CPU device, staged on a GPU), direct "
                        "(the device uses the images' memory; a GPU driver copies from pageable memory) or staged "
                        "(pinned staging reused across frames; a sequence's uploads, kernels and downloads "
                        "overlap)")
      ->check(keyword_check("--host-transfer", {"auto", "direct", "staged"}))
      ->capture_default_str();
  if (files) apply.add_flag("--verbose", ap.verbose, "Print the device, the kernel variant chosen and why");
  add_volume_options(apply, ap.volumes);
  add_camera_options(apply, ap.camera);
  add_height_options(apply, ap.height);
}

void resolve_apply_flags(const CLI::App& apply, ApplyFlags& flags) {
  ApplyOptions& ap = flags.options;
  std::string& mode = flags.mode;
  const std::string& precision = flags.precision;
  const std::string& fog_color = flags.fog_color;
  const std::string& sky = flags.sky;
  note_given_volume_flags(apply, ap.volumes);
  resolve_camera_flags(apply, ap);
  // With volumes the deferred fog is optional: no --mode runs only the volumetric pass.
  if (apply.count("--mode") == 0) {
    if (ap.volumes.volumes_path.empty()) throw UsageError("--mode is required (off, linear, exp, exp2 or height)");
    mode = "off";
  }
  ap.precision_given = apply.count("--precision") > 0;
  ap.max_error_given = apply.count("--max-error") > 0;
  ap.volumes.max_error_given = ap.max_error_given && !ap.volumes.volumes_path.empty();
  ap.volumes.max_error = ap.max_error;
  ap.volumes.max_memory = ap.max_memory;
  if (apply.count("--far") == 0 && !ap.infinite_far)
    throw UsageError("--far is required (except with --infinite-far)");
  if (!ap.infinite_far && !(ap.far_plane > ap.near_plane))
    throw Error("--far must be > --near (got " + typed(apply, {"--far", "--near"}) + ")");
  if (apply.count("--fov") > 0 && apply.count("--ortho-size") > 0)
    throw Error("give either --fov (perspective) or --ortho-size (orthographic), not both");
  if (ap.infinite_far) ap.reversed_z = true;  // an infinite far plane exists only in reversed Z
  ap.settings.mode = kModes.at(mode);
  if (ap.settings.mode == FogMode::linear && !(ap.settings.start <= ap.settings.end))
    throw Error("--start must be <= --end (got " + as_typed(apply, "--start", ap.settings.start) + ", " +
                       as_typed(apply, "--end", ap.settings.end) + ")");
  ap.settings.precision = kPrecisions.at(precision);
  ap.settings.sky = kSkies.at(sky);
  ap.settings.metric = apply.count("--distance") > 0 ? FogMetric::distance : FogMetric::depth;
  if (!fog_color.empty()) ap.settings.color = parse_finite_vec3("--fog-color", fog_color);
  ap.camera_flags = typed(apply, {"--near", "--far", "--fov", "--ortho-size", "--aspect", "--focal-length",
                                       "--sensor-width", "--sensor-height"}) +
                    (ap.infinite_far ? ", --infinite-far" : "");
  resolve_height_flags(apply, ap);
  // --height-volumetric runs the volumetric pass without --volumes: the budget is its too.
  ap.volumes.max_error_given = ap.max_error_given && (!ap.volumes.volumes_path.empty() || ap.volumes.height_fog);
}

std::string parse_error_text(const CLI::ParseError& e, const std::vector<const CLI::App*>& commands, bool* rule) {
  std::string message = detail::one_line(e.what());
  *rule = false;
  if (dynamic_cast<const CLI::ValidationError*>(&e) != nullptr) {
    // "FLAG: BODY": the flag's own checks name it in BODY, CLI11's ("must be ...") do not.
    const std::size_t colon = message.find(": ");
    std::string flag = colon == std::string::npos ? std::string() : message.substr(0, colon);
    std::string body = colon == std::string::npos ? message : message.substr(colon + 2);
    *rule = body.empty() || body[0] != kMalformedMark;
    if (!*rule) body.erase(0, 1);
    message = body.rfind(flag, 0) == 0 ? body : flag + " " + body;
  }
  // "--mode: At Most 1 required but received 2": an option given twice.
  if (const std::size_t at = message.find(": At Most 1 required but received "); at != std::string::npos)
    message = message.substr(0, at) + " is given " + message.substr(at + 34) + " times (at most once)";
  // An unknown option is what to say first, before the required ones it may have stood for.
  for (const CLI::App* command : commands)
    for (const std::string& arg : command->remaining())
      if (arg.size() > 1 && arg[0] == '-') {
        message = "unknown option '" + arg + "' for fogcl " + command->get_name();
        *rule = false;
        return message;
      }
  return message;
}

ApplyOptions parse_memory_apply_args(const std::vector<std::string>& args) {
  CLI::App apply("fogcl apply, for a frame in memory", "apply");
  ApplyFlags flags;
  add_apply_flags(apply, flags, false);
  // CLI11 takes the arguments last first.
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    apply.parse(reversed);
  } catch (const CLI::ParseError& e) {
    bool rule = false;
    const std::string message = parse_error_text(e, {&apply}, &rule);
    if (rule) throw Error(message);
    throw UsageError(message);
  }
  resolve_apply_flags(apply, flags);
  return flags.options;
}

}  // namespace fogcl::cli
