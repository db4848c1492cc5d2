// `fogcl apply`: fogs renderer EXR output, one file or a frame sequence, with one device setup
// and one program build for the whole sequence.
#include <unistd.h>

#include <cstdio>
#include <exception>
#include <limits>
#include <string>
#include <vector>

#include "cli/cli.h"
#include "cli/sequence.h"
#include "fogcl/depth_kinds.h"
#include "fogcl/exr_io.h"
#include "fogcl/report.h"

namespace fogcl::cli {

namespace {

struct FramePaths {
  std::string color, depth, out, png;
};

// The camera of one frame: flags win over the color file's worldToNDC / worldToCamera.
PerspectiveCamera frame_camera(const ApplyOptions& o, const ExrInput& color, std::string* from) {
  PerspectiveCamera camera;
  camera.near_plane = o.near_plane;
  camera.far_plane = o.far_plane;
  camera.reversed_z = o.reversed_z;
  camera.infinite_far = o.infinite_far;
  if (o.fov != 0.0f) {
    camera.fov_y_deg = o.fov;
    *from = "flags";
  } else if (color.camera.present) {
    camera.fov_y_deg = color.camera.fov_y_deg;
    *from = "worldToNDC";
  } else {
    throw Error(color.path + ": no --fov given (nor --ortho-size) and the file has no usable camera (" +
                (color.camera.note.empty() ? std::string("no worldToNDC and worldToCamera attributes")
                                           : color.camera.note) +
                ")");
  }
  if (o.aspect != 0.0f)
    camera.aspect = o.aspect;
  else if (o.fov == 0.0f && color.camera.present)
    camera.aspect = color.camera.aspect;
  else
    camera.aspect = float(color.color.width()) / float(color.color.height());
  return camera;
}

// The camera constants of one frame: orthographic with --ortho-size, else perspective (finite or
// infinite far). *text describes it for --verbose.
CameraParams frame_params(const ApplyOptions& o, const ExrInput& color, std::string* text) {
  char buf[256];
  const char* z = o.infinite_far ? "reversed Z (implied by --infinite-far)" : o.reversed_z ? "reversed Z" : "conventional Z";
  if (o.ortho_size > 0.0f) {
    OrthographicCamera camera;
    camera.ortho_size = o.ortho_size;
    camera.aspect = o.aspect != 0.0f ? o.aspect : float(color.color.width()) / float(color.color.height());
    camera.near_plane = o.near_plane;
    camera.far_plane = o.far_plane;
    camera.reversed_z = o.reversed_z;
    std::snprintf(buf, sizeof buf, "orthographic, size %g (half height), aspect %g, near %g, far %g, %s",
                  camera.ortho_size, camera.aspect, camera.near_plane, camera.far_plane, z);
    *text = buf;
    return make_camera_params(camera);
  }
  std::string from;
  const PerspectiveCamera camera = frame_camera(o, color, &from);
  if (camera.infinite_far)
    std::snprintf(buf, sizeof buf, "perspective, fov %g deg, aspect %g (from %s), near %g, far infinite, %s",
                  camera.fov_y_deg, camera.aspect, from.c_str(), camera.near_plane, z);
  else
    std::snprintf(buf, sizeof buf, "perspective, fov %g deg, aspect %g (from %s), near %g, far %g, %s",
                  camera.fov_y_deg, camera.aspect, from.c_str(), camera.near_plane, camera.far_plane, z);
  *text = buf;
  return make_camera_params(camera);
}

// The settings of the pass: the precision from --precision, the error budget (--max-error) or
// the default (precise). *why says which, for --verbose.
FogSettings pass_settings(const ApplyOptions& o, Backend& backend, ColorFormat storage, std::string* why) {
  FogSettings s = o.settings;
  if (!o.max_error_given) {
    *why = o.precision_given ? "precision: " + std::string(to_string(s.precision)) + " (--precision)\n"
                             : "precision: precise (the default; no --max-error budget given)\n";
    return s;
  }
  if (backend.is_scalar())
    throw Error("--max-error picks an OpenCL kernel variant; the scalar path (--device scalar) has none");
  const PrecisionChoice c = choose_precision_detailed(*backend.runtime(), storage, o.max_error);
  s.precision = c.precision;
  char buf[256];
  std::snprintf(buf, sizeof buf, "error budget: --max-error %g, %s storage; measurement %s (%s)\n", o.max_error,
                to_string(storage), c.from_cache ? "read from the cache" : "taken now and cached", c.measured_on.c_str());
  *why = buf;
  *why += "  cache: " + c.cache_file + "\n";
  for (const VariantMeasurement& m : c.candidates) {
    std::snprintf(buf, sizeof buf, "  candidate %-8s worst color error %.3g, time %.3f ms over the scenes: %s\n",
                  to_string(m.precision), m.max_abs_err_color, m.time_ms,
                  m.max_abs_err_color <= o.max_error ? "meets the budget" : "over the budget");
    *why += buf;
  }
  *why += "precision: " + c.reason + "\n";
  return s;
}

// volumes: null without --volumes; sequence_frame: the frame number, -1 for a single file.
void apply_frame(const ApplyOptions& o, const FramePaths& paths, Backend& backend, bool print_setup,
                 VolumeStage* volumes, int sequence_frame) {
  const DepthKind kind = parse_depth_kind(o.depth_kind);
  // Outside the depth's data window (and in empty deep pixels) there is nothing: background.
  // Raw depth gets the sky value; eye / distance depth gets +inf, which converts to it.
  const float outside = kind == DepthKind::raw ? (o.reversed_z ? 0.0f : 1.0f) : std::numeric_limits<float>::infinity();

  ExrReadRequest request;
  request.layer = o.layer;
  request.depth_outside = outside;
  if (paths.depth.empty()) request.depth_channel = o.depth_channel;
  ExrInput color = read_exr(paths.color, request);

  std::string camera_text;
  const CameraParams params = frame_params(o, color, &camera_text);
  validate(o.settings);
  if (kind != DepthKind::raw && params.projection != Projection::perspective)
    throw Error(std::string("--depth-kind ") + to_string(kind) + " needs a perspective camera with a finite far "
                "plane (give raw depth with --ortho-size or --infinite-far)");

  DepthImage depth;
  if (paths.depth.empty()) {
    depth = std::move(color.depth);
  } else {
    ExrReadRequest depth_request;
    depth_request.read_color = false;
    depth_request.depth_channel = o.depth_channel;
    depth_request.depth_single_channel_fallback = true;
    depth_request.depth_outside = outside;
    ExrInput d = read_exr(paths.depth, depth_request);
    if (!(d.windows == color.windows))
      throw Error(paths.depth + ": data/display window differs from " + paths.color +
                  "'s: depth and color must cover the same pixels");
    depth = std::move(d.depth);
  }
  to_raw_depth(depth, kind, params);

  std::string precision_why;
  const FogSettings settings = pass_settings(o, backend, color.color.format(), &precision_why);
  if (print_setup) {
    const Variant variant = select_variant(settings, params, color.color.format());
    std::fprintf(stderr, "device: %s\n", backend.name().c_str());
    std::fprintf(stderr, "camera: %s\n", camera_text.c_str());
    std::fprintf(stderr, "depth: %s, channel %s%s\n", to_string(kind), o.depth_channel.c_str(),
                 color.deep ? " (deep color, flattened)" : "");
    std::fprintf(stderr, "%s", precision_why.c_str());
    if (backend.is_scalar()) std::fprintf(stderr, "(the scalar path computes in float; it has no precision variants)\n");
    std::fprintf(stderr, "variant: %s\n", describe(variant).c_str());
    if (variant.needs_pass())
      std::fprintf(stderr,
                   "  why: %s fog (--mode), %s, %s, %s projection, %s storage (the input's); what the scene "
                   "does not use is not compiled\n",
                   to_string(variant.mode), variant.distance ? "distance-based (--distance)" : "depth-based (no sqrt)",
                   variant.fog_skybox ? "no sky test (--fog-skybox)" : "sky test (sky stays unfogged)",
                   params.projection == Projection::orthographic                ? "orthographic (--ortho-size)"
                   : params.projection == Projection::perspective_infinite_far ? "infinite-far (--infinite-far)"
                                                                                : "perspective",
                   to_string(variant.storage));
    else
      std::fprintf(stderr, "  why: no pass runs (fog off or density 0): the output is the input\n");
    if (!backend.is_scalar() && variant.needs_pass())
      std::fprintf(stderr, "build options: %s\n", backend.pass()->build_options_for(variant).c_str());
  }
  ColorImage out;
  const ColorImage* fog_in = &color.color;
  ColorImage with_volumes;
  if (volumes != nullptr) {  // DESIGN §5: the volumes first, the deferred fog on their result
    volumes->apply(color.color, depth, with_volumes, params, sequence_frame, print_setup);
    fog_in = &with_volumes;
  }
  backend.apply(*fog_in, depth, out, params, settings);
  write_exr_output(paths.out, out, color, o.rgba_only);
  if (!paths.png.empty()) write_png_preview(paths.png, out);
}

}  // namespace

int run_apply(const ApplyOptions& o) {
  parse_depth_kind(o.depth_kind);  // a bad kind fails before any file is touched
  if (o.fov != 0.0f && o.ortho_size != 0.0f)
    throw Error("give either --fov (perspective) or --ortho-size (orthographic), not both");
  if (o.ortho_size != 0.0f && o.infinite_far)
    throw Error("--infinite-far is a perspective projection; it does not go with --ortho-size");
  if (o.max_error_given && o.precision_given)
    throw Error("give either --precision or --max-error (which picks the precision), not both");
  const FramePattern color = parse_frame_pattern(o.color_path);
  const FramePattern depth = parse_frame_pattern(o.depth_path);
  const FramePattern out = parse_frame_pattern(o.out_path);
  const FramePattern png = parse_frame_pattern(o.png_path);
  if (!color.is_sequence) {
    for (const FramePattern* p : {&depth, &out, &png})
      if (p->is_sequence)
        throw Error("'" + p->text + "' has a frame placeholder but --color '" + o.color_path + "' has none");
    if (!o.frames.empty()) throw Error("--frames needs a frame placeholder in --color (e.g. shot.####.exr)");
    Backend backend(o.device);
    const std::unique_ptr<VolumeStage> volumes = VolumeStage::create(o.volumes, backend.runtime());
    apply_frame(o, {o.color_path, o.depth_path, o.out_path, o.png_path}, backend, o.verbose, volumes.get(), -1);
    return 0;
  }

  if (!out.is_sequence)
    throw Error("--out '" + o.out_path + "' needs a frame placeholder (#### or %04d) when --color is a sequence");
  if (!o.png_path.empty() && !png.is_sequence)
    throw Error("--png '" + o.png_path + "' needs a frame placeholder (#### or %04d) when --color is a sequence");
  const std::vector<int> frames = o.frames.empty() ? frames_on_disk(color) : parse_frame_range(o.frames);
  if (frames.empty()) throw Error("'" + o.color_path + "': no frames found (give --frames FIRST-LAST)");

  Backend backend(o.device);  // one device, one context, one program cache for every frame
  const std::unique_ptr<VolumeStage> volumes = VolumeStage::create(o.volumes, backend.runtime());
  ProgressBar progress(int(frames.size()), true);
  std::vector<std::string> failures;
  int done = 0;
  for (int frame : frames) {
    const FramePaths paths{frame_path(color, frame), o.depth_path.empty() ? "" : frame_path(depth, frame),
                           frame_path(out, frame), o.png_path.empty() ? "" : frame_path(png, frame)};
    try {
      apply_frame(o, paths, backend, o.verbose && done == 0 && failures.empty(), volumes.get(), frame);
    } catch (const std::exception& e) {
      progress.clear();
      if (!o.keep_going) throw Error("frame " + std::to_string(frame) + ": " + e.what());
      std::fprintf(stderr, "fogcl: frame %d failed: %s\n", frame, e.what());
      failures.push_back("frame " + std::to_string(frame) + ": " + e.what());
    }
    progress.update(++done);
  }
  progress.finish();
  if (!failures.empty()) {
    std::fprintf(stderr, "fogcl: error: %zu of %zu frames failed:\n", failures.size(), frames.size());
    for (const std::string& f : failures) std::fprintf(stderr, "  %s\n", f.c_str());
    return 1;
  }
  if (o.verbose)
    std::fprintf(stderr, "fogged %zu frames, %zu program build(s)\n", frames.size(),
                 backend.is_scalar() ? std::size_t(0) : backend.pass()->programs().builds());
  return 0;
}

}  // namespace fogcl::cli
