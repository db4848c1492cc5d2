#include "cli/volumes_cli.h"

#include <algorithm>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <type_traits>
#include <utility>
#include <variant>

#include <CLI/CLI.hpp>

#include "cli/camera_cli.h"
#include "cli/flag_values.h"
#include "cli/frame_memory.h"
#include "cli/number_list.h"
#include "cli/usage.h"
#include "fogcl/exr_io.h"
#include "fogcl/volume_report.h"
#include "fogcl/volume_scalar.h"
#include "fogcl/volumes_json.h"
#include "runtime/format.h"

namespace fogcl::cli {

namespace {

using detail::str;

const std::map<std::string, VolumeIntegrator> kIntegrators{{"stylized", VolumeIntegrator::stylized},
                                                           {"physical", VolumeIntegrator::physical}};
const std::map<std::string, int> kResolutions{{"full", 1}, {"half", 2}, {"quarter", 4}};
const std::map<std::string, VolumeUpsampling> kUpsamplings{{"depth-aware", VolumeUpsampling::depth_aware},
                                                           {"bilinear", VolumeUpsampling::bilinear}};
const std::map<std::string, NoiseSampling> kSamplings{{"auto", NoiseSampling::automatic},
                                                      {"buffer", NoiseSampling::buffer},
                                                      {"image", NoiseSampling::image}};

// The flags that mean nothing without --volumes.
const char* const kVolumeFlags[] = {"--eye",
                                    "--forward",
                                    "--up",
                                    "--light-dir",
                                    "--light-color",
                                    "--time",
                                    "--frame",
                                    "--fps",
                                    "--integrator",
                                    "--steps",
                                    "--volume-resolution",
                                    "--upsample",
                                    "--noise-size",
                                    "--noise-seed",
                                    "--noise-sampling",
                                    "--shadow-map",
                                    "--light-view-proj",
                                    "--shadow-reversed-z"};

glm::vec3 light_color_value(const std::string& text) {
  const glm::vec3 c = parse_finite_vec3("--light-color", text);
  for (int k = 0; k < 3; ++k)
    if (c[k] < 0.0f) throw Error("--light-color must be >= 0 in each channel (got '" + text + "')");
  return c;
}

bool given(const VolumeCliOptions& o, const std::string& flag) {
  return std::find(o.given.begin(), o.given.end(), flag) != o.given.end();
}

}  // namespace

void add_volume_options(CLI::App& app, VolumeCliOptions& o) {
  const char* group = "Volumetric fog volumes (docs/volumetric.md; run before the deferred fog)";
  app.add_option("--volumes", o.volumes_path,
                 "VOLUMES.json: {\"volumes\": [{\"center\": [x,y,z], \"radius\": r, ...}]} (docs/cli.md#volumesjson); "
                 "--mode may then be left out (off: only the volumes)")
      ->check(text_check("--volumes", "the VOLUMES.json file"))
      ->group(group);
  const std::string pose = " (--volumes needs the pose: these three, or --camera-to-world, or none of them to read "
                           "the color file's worldToCamera)";
  const auto direction = [](const char* flag) {
    return value_check([flag](const std::string& text) { parse_direction(flag, text); });
  };
  app.add_option("--eye", o.eye, "Camera position X,Y,Z [world units]" + pose)
      ->check(value_check([](const std::string& text) { parse_finite_vec3("--eye", text); }))
      ->group(group);
  app.add_option("--forward", o.forward, "Camera view direction X,Y,Z, non-zero" + pose)
      ->check(direction("--forward"))
      ->group(group);
  app.add_option("--up", o.up, "Camera up X,Y,Z, not parallel to --forward" + pose)->check(direction("--up"))->group(group);
  app.add_option("--light-dir", o.light_dir, "Main light direction X,Y,Z, from the scene toward the light")
      ->check(direction("--light-dir"))
      ->capture_default_str()
      ->group(group);
  app.add_option("--light-color", o.light_color, "Main light color, linear R,G,B >= 0")
      ->check(value_check([](const std::string& text) { light_color_value(text); }))
      ->capture_default_str()
      ->group(group);
  app.add_option("--time", o.time, "Noise scroll time [s], finite (default 0; sequences: frame number / --fps)")
      ->check(real_check("--time", kFinite))
      ->group(group);
  app.add_option("--frame", o.frame, "Jitter frame index >= 0 (default 0; sequences: the frame number)")
      ->check(integer_in(0, 4294967295LL, "in [0, 4294967295]"))
      ->group(group);
  app.add_option("--fps", o.fps, "Sequences: frames per second for the default --time, > 0")
      ->check(real_check("--fps", kPositive))
      ->capture_default_str()
      ->group(group);
  app.add_option("--integrator", o.integrator, "stylized (the seed's look) or physical (energy-conserving)")
      ->check(keyword_check("--integrator", {"stylized", "physical"}))
      ->capture_default_str()
      ->group(group);
  app.add_option("--steps", o.steps, "March steps per ray, in [1, 4096]")
      ->check(integer_in(1, 4096, "in [1, 4096]"))
      ->capture_default_str()
      ->group(group);
  app.add_option("--volume-resolution", o.resolution, "March target: full, half or quarter resolution")
      ->check(keyword_check("--volume-resolution", {"full", "half", "quarter"}))
      ->capture_default_str()
      ->group(group);
  app.add_option("--upsample", o.upsample, "depth-aware (no fog bleeding across silhouettes) or bilinear")
      ->check(keyword_check("--upsample", {"depth-aware", "bilinear"}))
      ->capture_default_str()
      ->group(group);
  app.add_option("--noise-size", o.noise_size, "Noise texels per side: 32, 64 or 128")
      ->check(integer_in(32, 128, "32, 64 or 128", {32, 64, 128}))
      ->capture_default_str()
      ->group(group);
  app.add_option("--noise-seed", o.noise_seed, "Noise seed, in [0, 4294967295]")
      ->check(integer_in(0, 4294967295LL, "in [0, 4294967295]"))
      ->capture_default_str()
      ->group(group);
  app.add_option("--noise-sampling", o.noise_sampling,
                 "auto (image on GPUs and accelerators with 3D images, else buffer), buffer (trilinear in the "
                 "kernel) or image (OpenCL 3D image, hardware filtering on GPUs)")
      ->check(keyword_check("--noise-sampling", {"auto", "buffer", "image"}))
      ->capture_default_str()
      ->group(group);
  app.add_option("--shadow-map", o.shadow_map_path,
                 "Main light's shadow map: EXR with the light's raw depth in channel Z (or its only channel); "
                 "needs --light-view-proj")
      ->check(text_check("--shadow-map", "the shadow map EXR"))
      ->group(group);
  app.add_option("--light-view-proj", o.light_view_proj,
                 "World -> light clip matrix, 16 numbers m00,m01,...,m33 row-major (the first four are the first "
                 "row); clip xy in [-1, 1] map to the shadow map's uv, clip z / w is its depth")
      ->check(value_check([](const std::string& text) { parse_light_view_proj(text); }))
      ->group(group);
  app.add_flag("--shadow-reversed-z", o.shadow_reversed_z,
               "The shadow map holds reversed Z (1 at the light's near plane)")
      ->group(group);
}

void note_given_volume_flags(const CLI::App& app, VolumeCliOptions& o) {
  o.given.clear();
  for (const char* flag : kVolumeFlags)
    if (app.count(flag) > 0) o.given.push_back(flag);
}

glm::mat4 parse_light_view_proj(const std::string& text) {
  const std::vector<double> v = parse_numbers("--light-view-proj", text, 16, "16 comma-separated numbers, row-major");
  glm::mat4 m(1.0f);
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) {
      const double d = v[std::size_t(row * 4 + col)];
      if (!(std::isfinite(d) && std::fabs(d) <= double(FLT_MAX)))
        throw Error("--light-view-proj element (row " + std::to_string(row) + ", column " + std::to_string(col) +
                    ") must be a finite float (got " + str(d) + ")");
      m[col][row] = float(d);  // GLM: m[column][row]
    }
  return m;
}

ShadowMap read_shadow_map(const std::string& path, const glm::mat4& world_to_light_clip, bool reversed_z,
                          const std::string& max_memory) {
  ExrReadRequest request;
  const MemoryLimit limit = memory_limit(max_memory);
  request.before_allocating = [&](const ExrFrameShape& shape) { check_shadow_map_memory(path, shape, limit); };
  request.read_color = false;
  request.depth_channel = "Z";
  request.depth_single_channel_fallback = true;
  // Outside the data window nothing was drawn: the light's far plane, which shadows nothing.
  request.depth_outside = reversed_z ? 0.0f : 1.0f;
  ShadowMap map;
  try {
    map.depth = std::move(read_exr(path, request).depth);
  } catch (const Error& e) {
    throw Error(std::string("--shadow-map: ") + e.what());
  }
  map.params.world_to_light_clip = world_to_light_clip;
  map.params.reversed_z = reversed_z;
  try {
    validate(map.params);
  } catch (const Error& e) {
    throw Error(std::string("--light-view-proj: ") + e.what());
  }
  return map;
}

std::unique_ptr<VolumeStage> VolumeStage::create(const VolumeCliOptions& o, const Runtime* runtime) {
  if (o.volumes_path.empty() && !o.height_fog) {
    if (!o.given.empty()) throw Error(o.given.front() + " needs --volumes (it sets up the volumetric pass)");
    return nullptr;
  }
  if (!o.pose_per_frame)  // else each frame brings its pose (set_frame_pose)
    for (const char* flag : {"--eye", "--forward", "--up"})
      if (!given(o, flag))
        throw UsageError(std::string(flag) + " is required with --volumes or --height-volumetric (the camera pose, X,Y,Z; or give "
                         "--camera-to-world, or none of --eye/--forward/--up to take the color file's worldToCamera)");
  auto stage = std::unique_ptr<VolumeStage>(new VolumeStage);
  VolumeStage& s = *stage;
  s.options_ = o;
  // With --axes every world-space input below is in the renderer's world (the pose, the light
  // direction, the shadow matrix, the volumes): mapped into fogcl's here (fogcl/renderer_camera.h).
  const Axes axes = o.axes.value_or(Axes::unity);
  const glm::mat3 to_fogcl = axes_to_fogcl(axes);

  // Camera pose and light, each checked with the flag's name before the library's own rules.
  if (!o.pose_per_frame) {
    s.pose_ = flag_pose(o);
    try {
      validate(s.pose_);
    } catch (const Error& e) {
      throw Error(std::string("--forward/--up: ") + e.what());
    }
    s.pose_ = {to_fogcl * s.pose_.eye, to_fogcl * s.pose_.forward, to_fogcl * s.pose_.up};
    s.pose_from_ = std::string("--eye/--forward/--up") + (o.axes ? std::string(", --axes ") + to_string(axes) : "");
  }
  s.light_.direction = parse_direction("--light-dir", o.light_dir);
  s.light_.color = light_color_value(o.light_color);
  s.light_.direction = to_fogcl * s.light_.direction;

  if (!std::isfinite(o.time)) throw Error("--time must be finite (got " + str(o.time) + ")");
  if (!(std::isfinite(o.fps) && o.fps > 0.0)) throw Error("--fps must be finite and > 0 (got " + str(o.fps) + ")");
  if (o.frame < 0 || o.frame > 4294967295LL)
    throw Error("--frame must be in [0, 4294967295] (got " + std::to_string(o.frame) + ")");

  VolumeSettings& st = s.settings_;
  st.integrator = kIntegrators.at(o.integrator);
  st.resolution_divisor = kResolutions.at(o.resolution);
  st.upsampling = kUpsamplings.at(o.upsample);
  st.noise_sampling = kSamplings.at(o.noise_sampling);
  if (o.steps < 1 || o.steps > 4096) throw Error("--steps must be in [1, 4096] (got " + std::to_string(o.steps) + ")");
  st.steps = int(o.steps);
  if (o.noise_size != 32 && o.noise_size != 64 && o.noise_size != 128)
    throw Error("--noise-size must be 32, 64 or 128 (got " + std::to_string(o.noise_size) + ")");
  st.noise_size = int(o.noise_size);
  if (o.noise_seed < 0 || o.noise_seed > 4294967295LL)
    throw Error("--noise-seed must be in [0, 4294967295] (got " + std::to_string(o.noise_seed) + ")");
  st.noise_seed = std::uint32_t(o.noise_seed);
  if (o.height_fog) {
    st.height_fog = o.height_fog;
    if (!given(o, "--integrator")) st.integrator = VolumeIntegrator::physical;  // the march's only integrator
    if (st.integrator == VolumeIntegrator::stylized)
      throw Error("--height-volumetric needs --integrator physical (got stylized)");
  }
  validate(st);

  // Shadow map: both halves or neither.
  const bool map = !o.shadow_map_path.empty(), matrix = given(o, "--light-view-proj");
  if (map && !matrix) throw Error("--shadow-map needs --light-view-proj (the world -> light clip matrix)");
  if (matrix && !map) throw Error("--light-view-proj needs --shadow-map (the light's depth)");
  if (o.shadow_reversed_z && !map) throw Error("--shadow-reversed-z needs --shadow-map");
  if (map) {
    // The matrix first: a bad matrix fails before the file is read. It takes the renderer's world.
    const glm::mat4 m = world_matrix_to_fogcl(axes, parse_light_view_proj(o.light_view_proj));
    ShadowMapParams p;
    p.world_to_light_clip = m;
    p.reversed_z = o.shadow_reversed_z;
    try {
      validate(p);
    } catch (const Error& e) {
      throw Error(std::string("--light-view-proj: ") + e.what());
    }
    s.shadow_ = read_shadow_map(o.shadow_map_path, m, o.shadow_reversed_z, o.max_memory);
  }
  if (o.height_fog && o.volumes_path.empty()) {
    // Only the marched fog is lit, by its sun lobe: these flags would change nothing in the image.
    if (given(o, "--light-color"))
      throw Error("--light-color colors the fog volumes' light (--volumes); the marched height fog's sun is "
                  "--sun-color");
    if (map && !o.height_fog->height.sun)
      throw Error("--shadow-map with --height-volumetric needs --sun-color (the sun's in-scattering that the map "
                  "shadows) or --volumes");
  }

  if (o.max_error_given) {
    // The budget picks these four; a flag that names one too is a contradiction, not a hint.
    for (const char* flag : {"--steps", "--volume-resolution", "--upsample", "--noise-sampling"})
      if (given(o, flag))
        throw Error(std::string("give either ") + flag +
                    " or --max-error (which picks the volumetric steps, resolution, upsampling and noise sampling), "
                    "not both");
    if (runtime == nullptr)
      throw Error("--max-error picks an OpenCL kernel variant; the scalar path (--device scalar) has none");
    if (!(o.max_error >= 0.0))
      throw Error("--max-error must be a number >= 0 (got " + str(o.max_error) + ")");
  }

  if (!o.volumes_text.empty() || !o.volumes_path.empty()) {
    VolumesFile file = !o.volumes_text.empty() ? parse_volumes_file(o.volumes_text, o.volumes_path)
                                               : read_volumes_file(o.volumes_path);
    s.volumes_ = std::move(file.volumes);
    s.lights_ = std::move(file.lights);
  }
  for (FogVolume& v : s.volumes_) v = volume_to_fogcl(axes, v);
  for (LocalLight& l : s.lights_) {  // a point and a direction; the rest are lengths, angles, colors
    l.position = to_fogcl * l.position;
    l.direction = to_fogcl * l.direction;
  }
  s.runtime_ = runtime;
  if (runtime != nullptr) s.pass_ = std::make_unique<VolumePass>(*runtime);
  return stage;
}

VolumeScene VolumeStage::scene_for(int sequence_frame) const {
  VolumeScene scene;
  scene.volumes = volumes_;
  scene.lights = lights_;
  if (options_.pose_per_frame && !frame_pose_)
    throw Error("--volumes: no camera pose for this frame (set_frame_pose was not called)");
  scene.pose = options_.pose_per_frame ? *frame_pose_ : pose_;
  scene.light = light_;
  const bool sequence = sequence_frame >= 0;
  scene.frame_index = std::uint32_t(given(options_, "--frame") ? options_.frame : sequence ? sequence_frame : 0);
  scene.time = float(given(options_, "--time") ? options_.time
                     : sequence                ? double(sequence_frame) / options_.fps
                                               : 0.0);
  return scene;
}

void VolumeStage::set_frame_pose(const std::optional<CameraPose>& pose, const std::string& from) {
  if (!options_.pose_per_frame) return;
  frame_pose_ = pose;
  pose_from_ = from;
}

void VolumeStage::apply(const ColorImage& in, const DepthImage& depth, ColorImage& out, const CameraParams& camera,
                        int sequence_frame, bool verbose) {
  apply_frame(in, depth, out, camera, sequence_frame, verbose);
}

void VolumeStage::apply(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                        const CameraParams& camera, int sequence_frame, bool verbose) {
  apply_frame(in, depth, out, camera, sequence_frame, verbose);
}

template <class In, class Depth, class Out>
void VolumeStage::apply_frame(const In& in, const Depth& depth, Out& out, const CameraParams& camera,
                              int sequence_frame, bool verbose) {
  const VolumeScene scene = scene_for(sequence_frame);
  if (options_.max_error_given && (!chosen_ || chosen_storage_ != in.format())) {
    // A missing measurement takes minutes (the 4096-step references, then every variant): say so.
    VolumeBudgetOptions budget;
    std::size_t last = 0;
    budget.measure.progress = [&last](std::size_t done, std::size_t total) {
      if (done == 0)
        std::fprintf(stderr,
                     "fogcl: --max-error: measuring %zu volumetric variants x scenes once for this device (the "
                     "references first); the result is cached\n",
                     total);
      else if (10 * done / total != 10 * last / total)
        std::fprintf(stderr, "  %zu/%zu\n", done, total);
      last = done;
    };
    const VolumeQualityChoice c =
        choose_volume_quality(*runtime_, settings_, in.format(), options_.max_error, budget);
    settings_ = c.settings;
    chosen_ = true;
    chosen_storage_ = in.format();
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  "volumetric error budget: --max-error %g, %s integrator%s, %s storage; measurement %s (%s)\n",
                  options_.max_error, to_string(settings_.integrator),
                  settings_.height_fog ? " with the marched height fog" : "", to_string(in.format()),
                  c.from_cache ? "read from the cache" : "taken now and cached", c.measured_on.c_str());
    budget_why_ = buf;
    budget_why_ += "  cache: " + c.cache_file + "\n";
    // Fastest first: every candidate before the chosen one is over the budget; show the last 10
    // of them, the chosen one, and the next 3 (slower, for comparison).
    std::size_t at = 0;
    while (at < c.candidates.size() && !(c.candidates[at].max_abs_err <= options_.max_error)) ++at;
    const std::size_t first = at > 10 ? at - 10 : 0;
    if (first > 0) budget_why_ += "  (" + std::to_string(first) + " faster candidates over the budget not shown)\n";
    for (std::size_t i = first; i < std::min(c.candidates.size(), at + 4); ++i) {
      const VolumeVariantMeasurement& m = c.candidates[i];
      std::snprintf(buf, sizeof buf, "  candidate %-30s worst color error %.3g, time %.3f ms over the scenes: %s\n",
                    volume_quality_name(m.steps, m.divisor, m.upsampling, m.noise).c_str(), m.max_abs_err, m.time_ms,
                    i == at ? "CHOSEN" : m.max_abs_err <= options_.max_error ? "meets the budget, slower"
                                                                          : "over the budget");
      budget_why_ += buf;
    }
    budget_why_ += "volumes: " + c.reason + "\n";
  }
  try {
    if (pass_)
      pass_->apply(in, depth, out, camera, scene, settings_, shadow());
    else
      apply_volumes_scalar(in, depth, out, camera, scene, settings_, shadow());
  } catch (const ClError&) {
    throw;  // the device's
  } catch (const Error& e) {
    throw Error(options_.volumes_path.empty() ? std::string(e.what()) : options_.volumes_path + ": " + e.what());  // what the volumes make in this frame (how many are visible)
  }
  if (!verbose) return;
  std::fprintf(stderr, "%s", budget_why_.c_str());
  const std::size_t visible = visible_volumes(scene, camera, max_eye_depth(depth, camera)).size();
  const int s = settings_.resolution_divisor;
  std::fprintf(
      stderr,
      "volumes: %zu of %zu visible (%s)%s, %s integrator, %d steps, %s resolution (%dx%d target), %s upsampling\n",
      visible, scene.volumes.size(), options_.volumes_path.empty() ? "no --volumes" : options_.volumes_path.c_str(),
      settings_.height_fog ? " and the marched height fog" : "", to_string(settings_.integrator), settings_.steps,
      resolution_name(s), (in.width() + s - 1) / s, (in.height() + s - 1) / s, to_string(settings_.upsampling));
  std::fprintf(stderr, "  camera pose (fogcl's world): %s, from %s\n", pose_text(scene.pose).c_str(),
               pose_from_.c_str());
  std::fprintf(stderr, "  noise: %d^3 texels, seed %u, %s sampling; shadow map: %s\n", settings_.noise_size,
               unsigned(settings_.noise_seed),
               pass_ ? to_string(pass_->noise_sampling(settings_.noise_sampling)) : "trilinear (scalar)",
               shadow_ ? (std::to_string(shadow_->depth.width()) + "x" + std::to_string(shadow_->depth.height()) +
                          (shadow_->params.reversed_z ? ", reversed Z" : ", conventional Z"))
                             .c_str()
                       : "none (no shadow term)");
  std::fprintf(stderr, "  frame index %u%s, time %g s%s\n", unsigned(scene.frame_index),
               given(options_, "--frame") ? " (--frame)"
               : sequence_frame >= 0      ? " (the frame number)"
                                          : " (default)",
               double(scene.time),
               given(options_, "--time") ? " (--time)"
               : sequence_frame >= 0     ? " (frame number / --fps)"
                                         : " (default)");
  if (!pass_)
    std::fprintf(stderr, "  path: scalar C++ in float (no build options)\n");
  else if (pass_->last_march_options().empty())
    std::fprintf(stderr, "  no volume visible: no dispatch, the volumes leave the frame as it was\n");
  else
    std::fprintf(stderr, "  march build options: %s\n  composite build options: %s\n",
                 pass_->last_march_options().c_str(), pass_->last_composite_options().c_str());
}

}  // namespace fogcl::cli
