// `fogcl apply --mode height`: height and atmospheric fog (docs/DESIGN.md §6) in the CLI. apply.cpp
// and main.cpp only register the flags (add_height_options), resolve them once after parsing
// (resolve_height_flags) and ask each frame for its camera pose (height_frame_pose).
#pragma once

#include <optional>
#include <string>

#include "fogcl/camera.h"
#include "fogcl/exr_io.h"

namespace CLI {
class App;
}

namespace fogcl::cli {

struct ApplyOptions;

// The height-fog flags as given (text, parsed with messages that name the flag).
struct HeightCliOptions {
  std::string extinction, inscattering, falloff, base_height, cutoff, max_opacity;
  std::string sun_color, sun_exponent, sun_start;
  bool volumetric = false;  // --height-volumetric: marched with the volumes (docs/DESIGN.md §6.5)
  // Resolved by resolve_height_flags: the fixed pose from --eye/--forward/--up (fogcl's world),
  // or none when each frame brings it (--camera-to-world).
  std::optional<CameraPose> pose;
  std::string pose_from;
};

// Registers --extinction, --inscattering, --height-falloff, --base-height, --cutoff,
// --max-opacity, --sun-color, --sun-exponent, --sun-start (--eye, --forward, --up and --light-dir
// are the volume flags', --start, --density, --fog-color and --fog-skybox the deferred fog's).
void add_height_options(CLI::App& apply, HeightCliOptions& o);

// After parsing, note_given_volume_flags and resolve_camera_flags, with ap.settings.mode set:
// refuses a height flag with another mode, and with --mode height checks every flag (one line
// naming the flag and the rule), fills ap.settings.height and the pose. Throws fogcl::Error.
void resolve_height_flags(const CLI::App& apply, ApplyOptions& ap);

// The camera pose of one frame for height fog (nullopt for other modes): the fixed one, or from
// --camera-to-world. *from says where it came from.
std::optional<CameraPose> height_frame_pose(const ApplyOptions& ap, const ExrInput& color, std::string* from);

}  // namespace fogcl::cli
