// Internal to the fogcl command-line tool.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cli/camera_cli.h"
#include "cli/height_cli.h"
#include "cli/volumes_cli.h"
#include "fogcl/fogcl.h"
#include "fogcl/volume_report.h"

namespace fogcl::cli {

// The path chosen by --device / FOGCL_DEVICE: an OpenCL device, or "scalar" (the C++ path, also
// the fallback when a machine has no OpenCL; run in row bands on OpenEXR's global thread pool when
// it has more than one thread, i.e. in `fogcl apply` with --threads > 1).
class Backend {
 public:
  // choice: "" (FOGCL_DEVICE or cpu), cpu, gpu, scalar or part of a device name.
  explicit Backend(const std::string& choice);
  bool is_scalar() const { return pass_ == nullptr; }
  std::string name() const;  // "scalar" or the OpenCL device's description
  void apply(const ColorImage& in, const DepthImage& depth, ColorImage& out,
             const CameraParams& camera, const FogSettings& settings);
  // FogPass::apply_async on a device (the result is in `out` after wait()); apply() on the
  // scalar path (a finished frame).
  PendingFrame apply_async(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                           const CameraParams& camera, const FogSettings& settings);
  // apply() over the caller's memory (a frame in memory: the Python module); out may be in.
  void apply(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
             const CameraParams& camera, const FogSettings& settings);
  FogPass* pass() { return pass_.get(); }
  const Runtime* runtime() const { return runtime_.get(); }  // null for scalar

 private:
  std::unique_ptr<Runtime> runtime_;
  std::unique_ptr<FogPass> pass_;
};

// "--device: " when `choice` (the flag's value) is set, "FOGCL_DEVICE: " when that variable chose
// the device, else "": the prefix of a message about the device chosen.
std::string device_choice_source(const std::string& choice);

struct DemoOptions {
  std::string out_dir = "fogcl-demo";
  int width = 1280;
  int height = 720;
  std::string device;
  std::string max_memory;  // --max-memory: "" = half of the machine's memory (cli/frame_memory.h)
};
int run_demo(const DemoOptions& options);

struct ApplyOptions {
  std::string color_path, depth_path, out_path, png_path;
  std::string depth_channel = "Z";
  std::string depth_kind = "raw";  // raw | eye | distance
  std::string layer;               // "" = the unnamed layer (R, G, B, A)
  float near_plane = 0, far_plane = 0;
  float fov = 0;                   // 0: from the color file's worldToNDC / worldToCamera
  float aspect = 0;                // 0: from the file's camera, else the display window
  bool rgba_only = false;          // output only R, G, B, A (no other channels, parts, attributes)
  std::string frames;              // "FIRST-LAST" for sequences; "" = the frames on disk
  bool keep_going = false;         // sequences: continue past a bad frame
  std::string max_memory;          // --max-memory: "" = half of the machine's memory (cli/frame_memory.h)
  int threads = 0;                 // OpenEXR's (de)compression threads (and PoCL's); 0 = every core
  std::string host_transfer = "auto";  // --host-transfer: auto | direct | staged (fogcl::HostTransfer)
  std::string pixel_type = "float";  // of the fogged R, G, B, A: float | half
  std::string compression;         // of the output's color part; "" = the input's
  bool reversed_z = false;
  float ortho_size = 0;            // > 0: orthographic camera (Unity's orthographicSize), no fov
  bool infinite_far = false;       // reversed Z with the far plane at infinity (implies reversed_z)
  bool precision_given = false;    // --precision was on the command line
  bool max_error_given = false;    // --max-error E picks the precision variant
  double max_error = 0;            // E, >= 0
  FogSettings settings;
  std::string camera_flags;        // the camera flags as typed ("--near 0.3, --far 1000"), for messages
  std::string device;
  bool verbose = false;
  VolumeCliOptions volumes;        // --volumes and its flags (cli/volumes_cli.h)
  CameraCliOptions camera;         // --camera-to-world, --axes, the lens flags (cli/camera_cli.h)
  HeightCliOptions height;         // --mode height's flags (cli/height_cli.h)
};
int run_apply(const ApplyOptions& options);

struct ReportCliOptions {
  std::string out_dir = "fogcl-report";
  int width = 640;
  int height = 360;
  int runs = 9;
  std::string device;
  bool volumetric = false;  // --volumetric: the volumetric pass's report (fogcl/volume_report.h)
  std::vector<int> steps;   // --volumetric: only these (empty: the report's default)
  std::vector<std::string> scenes, integrators;
};
int run_report(const ReportCliOptions& options);
// --volumetric: the report's options from the flags (their rules checked, naming the flag or value).
VolumeReportOptions volume_report_options(const ReportCliOptions& options);
int run_volume_report_cli(const ReportCliOptions& options);

}  // namespace fogcl::cli
