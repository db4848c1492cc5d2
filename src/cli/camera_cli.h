// `fogcl apply`'s renderer-camera flags (fogcl/renderer_camera.h): the camera as a renderer states
// it, --camera-to-world with --axes, and lens data (--focal-length, --sensor-width, --sensor-height,
// --sensor-fit) instead of --fov. apply.cpp only registers them (add_camera_options), resolves them
// once (resolve_camera_flags) and asks each frame for its fov and pose.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>

#include "fogcl/exr_io.h"
#include "fogcl/renderer_camera.h"

namespace CLI {
class App;
}

namespace fogcl::cli {

struct ApplyOptions;
struct VolumeCliOptions;

struct CameraCliOptions {
  std::string camera_to_world;   // --camera-to-world: 16 numbers as the renderer prints them
  std::string axes;              // --axes: "" = fogcl's own (unity's)
  float focal_length = 0.0f;     // --focal-length [mm]
  float sensor_width = 0.0f;     // --sensor-width [mm]
  float sensor_height = 0.0f;    // --sensor-height [mm]
  std::string sensor_fit = "auto";
  std::vector<std::string> given;  // the camera flags on the command line
  // Resolved by resolve_camera_flags.
  std::optional<Axes> axes_value;
  std::optional<glm::mat4> matrix;  // column vectors, checked rigid
  std::optional<Lens> lens;
};

// Registers the flags on `fogcl apply`.
void add_camera_options(CLI::App& apply, CameraCliOptions& o);

// After parsing (and note_given_volume_flags): records the flags given, refuses conflicting
// combinations with one line naming the flags, parses and checks the matrix and the lens, and
// tells the volume stage the axes and whether the pose comes with each frame (--camera-to-world,
// or the color file's worldToCamera when no --eye/--forward/--up is given). Throws fogcl::Error.
void resolve_camera_flags(const CLI::App& apply, ApplyOptions& o);

// The vertical fov [degrees] of the lens flags for a frame of `aspect` (width / height), through
// to_fogcl_camera. Needs o.lens.
float lens_fov_deg(const CameraCliOptions& o, float aspect);

// The pose (fogcl's world) of one frame for the volume pass: from --camera-to-world, else from the
// color file's worldToCamera / worldToNDC in the --axes world. nullopt when the volume stage does
// not take the pose from the frames. Throws fogcl::Error naming the file when it has no usable pose.
// *from describes the source, for --verbose.
std::optional<CameraPose> frame_pose(const CameraCliOptions& o, const VolumeCliOptions& volumes,
                                     const ExrInput& color, std::string* from);

// frame_pose's conversion without asking the volume stage: the pose from --camera-to-world, else
// from the color file (height fog's, which takes it whenever --eye/--forward/--up are not given).
CameraPose renderer_pose(const CameraCliOptions& o, const ExrInput& color, std::string* from);

// --eye/--forward/--up as given (the flags' own world, before --axes): each finite, forward and up
// non-zero, or an error naming the flag. Whether up is parallel to forward each caller says.
CameraPose flag_pose(const VolumeCliOptions& volumes);

// "eye (X, Y, Z), forward (X, Y, Z), up (X, Y, Z)" (%g), for --verbose.
std::string pose_text(const CameraPose& pose);

}  // namespace fogcl::cli
