// One frame held in memory through `fogcl apply`'s own frame code (the Python module's
// fogcl.apply): the camera from the options (and the header of the file it came from), the
// volumes, then the deferred fog; what the command does to a frame between reading and writing it,
// so the same options give the same bits.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "cli/cli.h"
#include "fogcl/exr_io.h"

namespace fogcl::cli {

struct MemoryFrame {
  ConstColorView color;  // the frame
  ConstDepthView depth;  // of the kind --depth-kind says, the color's size
  ColorView out;         // the color's size and format: color itself (in place) or apart from both
  // The camera attributes of the file the frame came from (read_exr), which --fov's default and the
  // renderer poses read; null: none (then --fov or the lens flags are needed, as for a file without).
  const ExrCamera* camera = nullptr;
  std::string name = "the frame";  // names the frame in messages, as a file's path does
};

// Reads a frame's color and its depth (the color file's, or depth_path's when not empty) as
// `fogcl apply` does with the options' --layer, --depth-channel, --depth-kind (the background
// outside the data window), --reversed-z and --pixel-type (half: half color kept half). Throws
// fogcl::Error naming the file.
struct FrameReadHooks {
  ColorImage* color_into = nullptr;  // as ExrReadRequest's
  DepthImage* depth_into = nullptr;
  std::function<void(const ExrFrameShape&)> before_allocating;
  std::function<void(const ExrInput&)> color_read;  // the color file read, before the depth file
};
void read_frame_files(const ApplyOptions& o, const std::string& color_path, const std::string& depth_path,
                      ExrInput& color, DepthImage& depth, const FrameReadHooks& hooks = {});

// The camera of one frame, and the poses the volumes and height fog take from it. text,
// pose_from, height_pose_from: what --verbose says of them.
struct FrameCamera {
  CameraParams params;
  std::string text;
  std::optional<CameraPose> pose;  // for the volumes, when it comes with the frame (cli/camera_cli.h)
  std::string pose_from, height_pose_from;
};
// The camera of a width x height frame in memory as `fogcl apply` derives a file's: from the
// options, and `camera` (the attributes of the file it came from; null: none), after the rules the
// options make together. `name` names the frame in messages. For callers that run the passes
// themselves (the Python module's FogPass and VolumePass on the caller's OpenCL objects). Throws
// fogcl::Error naming the flags.
FrameCamera memory_frame_camera(const ApplyOptions& o, int width, int height, const ExrCamera* camera,
                                const std::string& name);

// The device and the volume stage of `options`, opened once for the frames given to it one at a
// time (a thread of its own each: not shared between threads).
class MemoryFogger {
 public:
  explicit MemoryFogger(const ApplyOptions& options);
  ~MemoryFogger();
  MemoryFogger(const MemoryFogger&) = delete;
  MemoryFogger& operator=(const MemoryFogger&) = delete;
  // Fogs `frame` as `fogcl apply` with these options fogs a file's frame. Throws fogcl::Error
  // (naming frame.name and the flags) for a rule broken, ClError for the device's failures.
  void fog(const MemoryFrame& frame);
  Backend& backend();
  VolumeStage* volumes();  // null without volumes

 private:
  struct Opened;
  ApplyOptions options_;
  std::unique_ptr<Opened> devices_;
};

}  // namespace fogcl::cli
