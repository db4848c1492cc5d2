// `fogcl apply --volumes`: the volumetric fog volumes pass (docs/volumetric.md) in the CLI. Kept apart
// from apply.cpp, which only registers the flags (add_volume_options), builds a VolumeStage once
// per run and calls VolumeStage::apply on each frame before the deferred fog.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>

#include "fogcl/fogcl.h"
#include "fogcl/renderer_camera.h"
#include "fogcl/volume_pass.h"
#include "fogcl/volumes.h"
#include "fogcl/volumes_json.h"

namespace CLI {
class App;
}

namespace fogcl::cli {

// The volume flags as given (vectors as text "X,Y,Z", parsed with messages that name the flag).
struct VolumeCliOptions {
  std::string volumes_path;      // --volumes: "" = no volumes (no volumetric pass unless height_fog)
  // The document itself instead of the file (the Python module's volumes= dict or list, as JSON);
  // volumes_path then names it in messages.
  std::string volumes_text;
  // --mode height --height-volumetric: the height fog marched in the volumetric pass (set by
  // resolve_height_flags; the deferred pass then runs no height fog).
  std::optional<FogSettings> height_fog;
  std::string eye, forward, up;  // required with --volumes
  std::string light_dir = "0,1,0", light_color = "1,1,1";
  double time = 0.0;    // --time [s]
  long long frame = 0;  // --frame: jitter seed
  double fps = 24.0;    // sequences: default time = frame number / fps
  std::string integrator = "stylized", resolution = "half", upsample = "depth-aware", noise_sampling = "auto";
  long long steps = 50, noise_size = 64, noise_seed = 1;
  std::string shadow_map_path, light_view_proj;
  bool shadow_reversed_z = false;
  std::vector<std::string> given;  // the volume flags on the command line
  // --max-error E (fogcl apply's): picks steps, resolution, upsampling and noise sampling from the
  // volumetric error budget (fogcl/volume_report.h); an error together with any of those flags.
  bool max_error_given = false;
  double max_error = 0;
  std::string max_memory;  // fogcl apply's --max-memory ("": the default): the shadow map is checked against it
  // From the camera flags (cli/camera_cli.h): the renderer's axes of every world-space input here
  // (unset: fogcl's own), and whether each frame brings its pose (set_frame_pose) instead of
  // --eye/--forward/--up: with --camera-to-world, or from the color file's worldToCamera.
  std::optional<Axes> axes;
  bool pose_per_frame = false;
};

// Registers the volume flags on `fogcl apply`.
void add_volume_options(CLI::App& apply, VolumeCliOptions& o);
// After parsing: records which volume flags were given (their defaults depend on it).
void note_given_volume_flags(const CLI::App& apply, VolumeCliOptions& o);

// VOLUMES.json is read by the library (fogcl/volumes_json.h: read_volumes_file, volumes_to_json).


// "m00,m01,...,m33": 16 numbers, row-major (the first four are the first row) -> GLM's
// column-major. Throws fogcl::Error naming --light-view-proj for a count, a non-number or a
// non-finite element; invertibility is ShadowMapParams' validate().
glm::mat4 parse_light_view_proj(const std::string& text);

// The light's raw depth from channel Z of `path` (or its only channel). A map that needs more
// memory than `max_memory` (--max-memory's text; "": the default) is refused before it is read.
ShadowMap read_shadow_map(const std::string& path, const glm::mat4& world_to_light_clip, bool reversed_z,
                          const std::string& max_memory = {});

// One run's volumetric pass: the volumes, light, settings and shadow map loaded and checked once;
// the scene of each frame (jitter index and time) derived from the frame number.
class VolumeStage {
 public:
  // nullptr without --volumes. Throws fogcl::Error, naming the flag, for any bad volume input,
  // before any frame is read. runtime null: the scalar path.
  static std::unique_ptr<VolumeStage> create(const VolumeCliOptions& o, const Runtime* runtime);

  // sequence_frame: the frame number in a sequence, -1 for a single file. --frame defaults to it
  // (0 for a single file), --time to sequence_frame / --fps (0 for a single file).
  VolumeScene scene_for(int sequence_frame) const;
  // The pose of the next frames (fogcl's world) when the options say it comes with each frame;
  // `from` says where it came from (--verbose).
  void set_frame_pose(const std::optional<CameraPose>& pose, const std::string& from);
  const VolumeSettings& settings() const { return settings_; }
  const ShadowMap* shadow() const { return shadow_ ? &*shadow_ : nullptr; }
  // The volume pass's convenience-call transfers (--host-transfer); nothing on the scalar path.
  void set_host_transfer(HostTransfer transfer) {
    if (pass_) pass_->set_host_transfer(transfer);
  }

  // Composites the volumes onto `in` into `out` (the OpenCL pass, or the scalar path in float).
  // verbose: prints the variant (integrator, steps, resolution, visible volumes, build options),
  // and with --max-error the candidates and why one was chosen. With --max-error the first frame
  // (and a frame of another storage) picks the variant for its storage.
  void apply(const ColorImage& in, const DepthImage& depth, ColorImage& out, const CameraParams& camera,
             int sequence_frame, bool verbose);
  // The same over the caller's memory (a frame in memory: the Python module).
  void apply(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out, const CameraParams& camera,
             int sequence_frame, bool verbose);

 private:
  template <class In, class Depth, class Out>
  void apply_frame(const In& in, const Depth& depth, Out& out, const CameraParams& camera, int sequence_frame,
                   bool verbose);

  VolumeCliOptions options_;
  std::vector<FogVolume> volumes_;
  std::vector<LocalLight> lights_;
  CameraPose pose_;
  std::optional<CameraPose> frame_pose_;  // options_.pose_per_frame: the current frame's
  std::string pose_from_;
  MainLight light_;
  VolumeSettings settings_;
  std::optional<ShadowMap> shadow_;
  std::unique_ptr<VolumePass> pass_;  // null: scalar
  const Runtime* runtime_ = nullptr;
  bool chosen_ = false;                // --max-error: a variant was picked for chosen_storage_
  ColorFormat chosen_storage_ = ColorFormat::rgba32f;
  std::string budget_why_;             // --max-error: what --verbose prints
};

// `fogcl demo`'s volumetric rows (cli/demo_volumes.cpp): demo_fog_volumes() run on each
// backend after the deferred ones; `deferred` is the fog of the row that runs both passes.
struct DemoOptions;
class Backend;
void run_demo_volumes(const DemoOptions& o, std::vector<std::unique_ptr<Backend>>& backends,
                      const FogSettings& deferred);
// `fogcl demo`'s light-shaft rows (cli/demo_shafts.cpp): the marched height fog under a low sun.
void run_demo_shafts(const DemoOptions& o, std::vector<std::unique_ptr<Backend>>& backends);  // and street lamps

}  // namespace fogcl::cli
