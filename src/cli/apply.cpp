// `fogcl apply`: fogs renderer EXR output, one file or a frame sequence, with one device setup
// and one program build for the whole sequence. A sequence runs through a bounded pipeline
// (frame_pipeline.h): reading, fogging and writing of three consecutive frames overlap.
#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <functional>
#include <future>
#include <optional>
#include <limits>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <OpenEXR/ImfThreading.h>

#include "cli/cli.h"
#include "cli/file_checks.h"
#include "cli/frame_memory.h"
#include "cli/frame_pipeline.h"
#include "cli/memory_frame.h"
#include "cli/sequence.h"
#include "cli/volumes_cli.h"
#include "fogcl/depth_kinds.h"
#include "fogcl/exr_io.h"
#include "fogcl/report.h"
#include "io/atomic_file.h"

namespace fogcl::cli {

namespace {
// Outside the depth's data window (and in empty deep pixels) there is nothing: background. Raw
// depth gets the sky value; eye / distance depth gets +inf, which converts to it.
float depth_outside(const ApplyOptions& o) {
  return parse_depth_kind(o.depth_kind) == DepthKind::raw ? (o.reversed_z ? 0.0f : 1.0f)
                                                          : std::numeric_limits<float>::infinity();
}
}  // namespace

void read_frame_files(const ApplyOptions& o, const std::string& color_path, const std::string& depth_path,
                      ExrInput& color, DepthImage& depth, const FrameReadHooks& hooks) {
  const float outside = depth_outside(o);
  ExrReadRequest request;
  request.layer = o.layer;
  request.depth_outside = outside;
  // Half output of half input: fog in half storage, so that f == 1 pixels keep their bits (§2).
  request.keep_half = o.pixel_type == "half";
  if (depth_path.empty()) request.depth_channel = o.depth_channel;
  request.color_into = hooks.color_into;
  request.depth_into = hooks.depth_into;
  request.before_allocating = hooks.before_allocating;
  color = read_exr(color_path, request);
  if (hooks.color_read) hooks.color_read(color);

  if (depth_path.empty()) {
    depth = std::move(color.depth);
  } else {
    ExrReadRequest depth_request;
    depth_request.read_color = false;
    depth_request.depth_channel = o.depth_channel;
    depth_request.depth_single_channel_fallback = true;
    depth_request.depth_outside = outside;
    depth_request.depth_into = hooks.depth_into;
    // Before its frame is allocated: a depth file describing another (larger) frame costs nothing.
    depth_request.before_allocating = [&](const ExrFrameShape& shape) {
      if (!(shape.windows == color.windows))
        throw Error(depth_path + ": data/display window differs from " + color_path +
                    "'s: depth and color must cover the same pixels");
    };
    ExrInput d = read_exr(depth_path, depth_request);
    depth = std::move(d.depth);
  }
}

namespace {

struct FramePaths {
  std::string color, depth, out, png;
};

// A frame's files before it is read (cli/file_checks.h): no output replaces an input or another
// output, every destination can be written.
void check_frame_files(const ApplyOptions& o, const FramePaths& p) {
  check_files({{"--color", p.color}, {"--depth", p.depth}, {"--volumes", o.volumes.volumes_path},
               {"--shadow-map", o.volumes.shadow_map_path}},
              {{"--out", p.out}, {"--png", p.png}});
}

// Every output of the run against every input of the run and every other output, before the first
// frame is read (cli/file_checks.h): a frame's own check cannot see frame 1's output replacing frame
// 10's input.
void check_sequence_outputs(const ApplyOptions& o, const FramePattern& color, const FramePattern& depth,
                            const FramePattern& out, const FramePattern& png, const std::vector<int>& frames) {
  std::vector<FrameFile> inputs = {{"--volumes", FrameFile::kEveryFrame, o.volumes.volumes_path},
                                   {"--shadow-map", FrameFile::kEveryFrame, o.volumes.shadow_map_path}};
  if (!depth.is_sequence) inputs.push_back({"--depth", FrameFile::kEveryFrame, o.depth_path});
  std::vector<FrameFile> outputs;
  for (int f : frames) {
    inputs.push_back({"--color", f, frame_path(color, f)});
    if (depth.is_sequence) inputs.push_back({"--depth", f, frame_path(depth, f)});
    outputs.push_back({"--out", f, frame_path(out, f)});
    if (!o.png_path.empty()) outputs.push_back({"--png", f, frame_path(png, f)});
  }
  check_sequence_files(inputs, outputs);
}

// Width / height of the frame: its display window (also for a frame in memory, whose pixels
// ExrInput does not hold).
float display_aspect(const ExrInput& color) {
  const glm::ivec2 size = color.windows.display_max - color.windows.display_min + 1;
  return float(size.x) / float(size.y);
}

// The camera of one frame: flags win over the color file's worldToNDC / worldToCamera.
PerspectiveCamera frame_camera(const ApplyOptions& o, const ExrInput& color, std::string* from) {
  PerspectiveCamera camera;
  camera.near_plane = o.near_plane;
  camera.far_plane = o.far_plane;
  camera.reversed_z = o.reversed_z;
  camera.infinite_far = o.infinite_far;
  if (o.camera.lens) {  // lens data: the fov for this frame's aspect (cli/camera_cli.h)
    camera.aspect = o.aspect != 0.0f ? o.aspect : display_aspect(color);
    camera.fov_y_deg = lens_fov_deg(o.camera, camera.aspect);
    *from = std::string("--focal-length, --sensor-fit ") + to_string(o.camera.lens->fit);
    return camera;
  }
  if (o.fov != 0.0f) {
    camera.fov_y_deg = o.fov;
    *from = "flags";
  } else if (color.camera.present) {
    camera.fov_y_deg = color.camera.fov_y_deg;
    *from = "worldToNDC";
  } else {
    throw Error(color.path + ": no --fov or --focal-length given (nor --ortho-size) and the file has no usable camera (" +
                (color.camera.note.empty() ? std::string("no worldToNDC and worldToCamera attributes")
                                           : color.camera.note) +
                ")");
  }
  if (o.aspect != 0.0f)
    camera.aspect = o.aspect;
  else if (o.fov == 0.0f && color.camera.present)
    camera.aspect = color.camera.aspect;
  else
    camera.aspect = display_aspect(color);
  return camera;
}

CameraParams frame_params_of(const ApplyOptions& o, const ExrInput& color, std::string* text);

// The camera constants of one frame: orthographic with --ortho-size, else perspective (finite or
// infinite far). *text describes it for --verbose. The library's rules on what the flags and the
// file make together (a frustum beyond float's range) name both.
CameraParams frame_params(const ApplyOptions& o, const ExrInput& color, std::string* text) {
  try {
    const CameraParams params = frame_params_of(o, color, text);
    validate(params);  // here, where the flags and the file can be named, rather than in the pass
    return params;
  } catch (const Error& e) {
    const std::string what = e.what();
    if (what.rfind("--", 0) == 0 || what.rfind(color.path, 0) == 0) throw;  // already names its flag or file
    throw Error(color.path + ": the camera of " + (o.camera_flags.empty() ? "the file" : o.camera_flags) +
                " and this frame: " + what);
  }
}

CameraParams frame_params_of(const ApplyOptions& o, const ExrInput& color, std::string* text) {
  char buf[256];
  const char* z = o.infinite_far ? "reversed Z (implied by --infinite-far)" : o.reversed_z ? "reversed Z" : "conventional Z";
  if (o.ortho_size > 0.0f) {
    OrthographicCamera camera;
    camera.ortho_size = o.ortho_size;
    camera.aspect = o.aspect != 0.0f ? o.aspect : display_aspect(color);
    camera.near_plane = o.near_plane;
    camera.far_plane = o.far_plane;
    camera.reversed_z = o.reversed_z;
    std::snprintf(buf, sizeof buf, "orthographic, size %g (half height), aspect %g, near %g, far %g, %s",
                  camera.ortho_size, camera.aspect, camera.near_plane, camera.far_plane, z);
    *text = buf;
    CameraParams params = make_camera_params(camera);
    params.non_square_pixels = o.aspect != 0.0f;  // --aspect: a frustum unlike the frame on purpose
    return params;
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
  CameraParams params = make_camera_params(camera);
  // --aspect, or the file's own camera (the projection it was rendered with, whatever its pixels'
  // shape): the frustum may differ from the frame on purpose. Otherwise the library checks it.
  params.non_square_pixels = o.aspect != 0.0f || from == "worldToNDC";
  return params;
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
  if (s.mode == FogMode::off) {  // only the volumes run: --max-error picks their variant alone
    *why = "precision: not chosen (--mode off: no deferred fog runs; --max-error picks the volumetric variant)\n";
    return s;
  }
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

// The camera of one frame (cli/memory_frame.h's FrameCamera) from the options and the color file's
// header.
FrameCamera frame_camera_setup(const ApplyOptions& o, const ExrInput& color) {
  const DepthKind kind = parse_depth_kind(o.depth_kind);
  FrameCamera c;
  c.params = frame_params(o, color, &c.text);
  c.pose = frame_pose(o.camera, o.volumes, color, &c.pose_from);
  c.params.pose = height_frame_pose(o, color, &c.height_pose_from);  // --mode height: the pose per frame
  validate(o.settings);
  if (kind == DepthKind::distance && c.params.projection == Projection::orthographic)
    throw Error("--depth-kind distance needs a perspective camera (an orthographic camera's rays are parallel: "
                "give eye or raw depth with --ortho-size)");
  // Linear depth reaches the kernels as it is (a variant of its own), never through raw depth.
  c.params.depth_kind = kind;
  return c;
}

// One frame in flight through read -> fog -> write (frame_pipeline.h).
struct FrameJob {
  int frame = 0;       // the frame number (0 for a single file)
  std::string error;   // what failed ("" = fine so far)
  bool device_failed = false;  // error is the device's, which failed to open: it stops the run
  FramePaths paths;
  ExrInput color;      // its pixels are released once fogged; the rest describes the output
  DepthImage depth;    // raw device depth
  CameraParams params;
  std::string camera_text;
  std::optional<CameraPose> pose;  // for the volumes, when it comes with the frame (cli/camera_cli.h)
  std::string pose_from;
  std::string height_pose_from;  // --mode height: where the pose came from (--verbose)
  ColorImage out;      // the fogged frame: holds it once `pending` has been waited for
  // The deferred pass in flight (staged transfers, a GPU): its download overlaps the next frame's
  // upload and kernels; the writer waits for it.
  PendingFrame pending;
};

// A fogged frame's inputs, kept for the next frame's read (ExrReadRequest::color_into).
struct InputFrames {
  ColorImage color;
  DepthImage depth;
};

// Reads a frame's color and depth and derives its camera (reader thread). limit: --max-memory's,
// the run's. spare: frames to read into when they fit (may be null).
void read_frame(const ApplyOptions& o, const MemoryLimit& limit, FrameJob& job, InputFrames* spare = nullptr) {
  const FramePaths& paths = job.paths;
  FrameReadHooks hooks;
  if (spare != nullptr) {
    hooks.color_into = &spare->color;
    hooks.depth_into = &spare->depth;
  }
  // What the frame will need is checked from its header, before anything is allocated.
  const FrameMemoryNeeds needs = frame_memory_needs(o);
  hooks.before_allocating = [&](const ExrFrameShape& shape) { check_frame_memory(paths.color, shape, needs, limit); };
  hooks.color_read = [&](const ExrInput& color) {
    FrameCamera camera = frame_camera_setup(o, color);
    job.params = camera.params;
    job.camera_text = std::move(camera.text);
    job.pose = camera.pose;
    job.pose_from = std::move(camera.pose_from);
    job.height_pose_from = std::move(camera.height_pose_from);
  };
  read_frame_files(o, paths.color, paths.depth, job.color, job.depth, hooks);
}

// Frames that are done with (written outputs, fogged inputs), kept for the next frames: a fresh
// frame costs its page faults and zeroing every time (33 MB for 1080p float color, 133 MB at 4K),
// on the reader's thread for inputs. Two of each are enough for the pipeline's frames in flight.
template <class Frames>
class Spares {
 public:
  void give(Frames frames) {
    std::lock_guard<std::mutex> lock(m_);
    if (spares_.size() < 2) spares_.push_back(std::move(frames));
  }
  Frames take() {
    std::lock_guard<std::mutex> lock(m_);
    if (spares_.empty()) return Frames();
    Frames frames = std::move(spares_.back());
    spares_.pop_back();
    return frames;
  }

 private:
  std::mutex m_;
  std::vector<Frames> spares_;
};

// The device and the volume stage of a run. Opening a PoCL device loads its LLVM libraries:
// 0.2-0.35 s a process on the 16-core machine (bench/results/device-16core-startup), a quarter of
// a 12-frame 4K sequence at 16 threads. So frames are read meanwhile (and fogged and written when
// tiered, below). The device opens on the main thread, which lives as long as the process: LLVM
// gives the thread that initialises it an alternate signal stack of its own, which a thread's exit
// then fails to release (ASan aborts).
struct Devices {
  Backend backend;
  std::unique_ptr<VolumeStage> volumes;
  double open_s = 0;     // wall seconds the opening took (--verbose)
  double prepare_s = -1;  // tiered: wall seconds of the first frame's program build (-1: none)
  // Its kernel gives the scalar path's bits (PoCL's CPU device): it may take over from frames
  // fogged on the scalar path (tiering, below).
  bool scalar_bits;
  explicit Devices(const ApplyOptions& o)
      : backend(o.device),
        volumes(VolumeStage::create(o.volumes, backend.runtime())),
        scalar_bits(backend.runtime() != nullptr && device_is_pocl_cpu(backend.runtime()->device())) {
    const HostTransfer transfer = o.host_transfer == "staged"   ? HostTransfer::staged
                                  : o.host_transfer == "direct" ? HostTransfer::direct
                                                                : HostTransfer::automatic;
    if (backend.pass() != nullptr) backend.pass()->set_host_transfer(transfer);
    if (volumes) volumes->set_host_transfer(transfer);
  }
};

// Tiering: PoCL takes 0.2-0.4 s to open (the dynamic loader relocating LLVM and clang), the
// scalar path nothing, and at the precise precision the two give the same bits (KernelOutputBits
// in tests/kernel_factor_bits_test.cpp). So in a sequence, frames that reach the fog stage while
// PoCL's CPU device is opening are fogged on the scalar path (row bands on OpenEXR's pool), and
// the device takes over from the first frame after it has opened. Not with --volumes (the scalar
// march takes seconds a frame), --precision fast or --max-error (kernel variants the scalar path
// does not have), nor for a GPU or a device named by text, whose bits differ or are not known
// before it has opened. Nor on a single core: nothing overlaps there, so a frame fogged on the
// scalar path only adds its cost over the kernel's (~45 ms a 1080p half frame on the 2-core
// machine) to the run, which opening PoCL first and waiting for it does not. FOGCL_TIERING=off
// turns it off: every frame waits for the device and runs on it (to measure or exercise the
// device; the tests compare both ways).
bool tiers(const ApplyOptions& o, int cores) {
  const char* env = std::getenv("FOGCL_TIERING");
  const std::string choice = env == nullptr ? "" : env;
  if (choice != "" && choice != "on" && choice != "off")
    throw Error("FOGCL_TIERING must be on or off (got '" + choice + "')");
  return choice != "off" && cores > 1 && o.volumes.volumes_path.empty() && !o.volumes.height_fog &&
         !o.max_error_given &&
         o.settings.precision == Precision::precise && resolve_device_choice(o.device) == "cpu";
}

// Opens the devices into `result` (its value, or the exception that stopped them); returns that
// exception's message, "" when they opened. prepare (may be empty): builds programs before the
// devices are handed over; its failures are left to the fog stage, which meets them again.
std::string open_devices(const ApplyOptions& o, std::promise<std::shared_ptr<Devices>>& result,
                         const std::function<void(Devices&)>& prepare = {}) {
  try {
    auto start = std::chrono::steady_clock::now();
    auto devices = naming_allocations("opening the device and loading the volume inputs", "",
                                      [&] { return std::make_shared<Devices>(o); });
    const auto seconds_since = [&] {
      const auto now = std::chrono::steady_clock::now();
      const double s = std::chrono::duration<double>(now - start).count();
      start = now;
      return s;
    };
    devices->open_s = seconds_since();
    if (prepare) {
      try {
        prepare(*devices);
        devices->prepare_s = seconds_since();
      } catch (const std::exception&) {
      }
    }
    result.set_value(std::move(devices));
    return "";
  } catch (const std::exception& e) {
    result.set_exception(std::current_exception());
    return e.what();
  } catch (...) {
    result.set_exception(std::current_exception());
    return "the device failed to open (unknown error)";
  }
}

// The volume pass of a frame, which reads eye depth: distance depth is converted first
// (to_eye_depth: no digit lost).
template <class In, class Depth, class Out>
void apply_volumes(VolumeStage& volumes, const In& in, const Depth& depth, Out& out, const CameraParams& params,
                   int sequence_frame, bool verbose) {
  if (params.depth_kind != DepthKind::distance) {
    volumes.apply(in, depth, out, params, sequence_frame, verbose);
    return;
  }
  DepthImage eye(depth.width(), depth.height());
  for (int y = 0; y < depth.height(); ++y)
    std::copy_n(ConstDepthView(depth).row(y), depth.width(), eye.view().row(y));
  to_eye_depth(eye, params.depth_kind, params);
  CameraParams eye_params = params;
  eye_params.depth_kind = DepthKind::eye;
  volumes.apply(in, eye, out, eye_params, sequence_frame, verbose);
}

void print_build_options(Backend& backend, const Variant& variant) {
  if (!backend.is_scalar() && variant.needs_pass())
    std::fprintf(stderr, "build options: %s\n", backend.pass()->build_options_for(variant).c_str());
}

// The passes of one frame (fog thread; the only user of the backend and the volume stage).
// job.frame is the frame number, for passes that depend on it (sequence_frame: -1 for a single
// file). job.out may hold a spare frame to fog into. volumes: null without --volumes.
void fog_frame(const ApplyOptions& o, Backend& backend, FrameJob& job, bool print_setup, VolumeStage* volumes,
               int sequence_frame) {
  const ExrInput& color = job.color;
  const CameraParams& params = job.params;
  // A clear line where the OpenCL call would fail with CL_INVALID_BUFFER_SIZE.
  if (backend.runtime() != nullptr)
    check_device_allocations(job.paths.color, *backend.runtime(), color.color.width(), color.color.height(),
                             color.color.format(), frame_memory_needs(o));
  std::string precision_why;
  const FogSettings settings = pass_settings(o, backend, color.color.format(), &precision_why);
  if (print_setup) {
    const DepthKind kind = parse_depth_kind(o.depth_kind);
    const Variant variant = select_variant(settings, params, color.color.format());
    std::fprintf(stderr, "device: %s\n", backend.name().c_str());
    if (FogPass* pass = backend.pass())
      std::fprintf(stderr, "host transfers: %s\n", pass->host_transfer() == HostTransfer::staged
                                                       ? "staged (pinned staging, frames overlapped)"
                                                       : "direct (the device uses the images' memory)");
    std::fprintf(stderr, "camera: %s\n", job.camera_text.c_str());
    if (settings.mode == FogMode::height && params.pose)  // --mode height: the pose its rays come from
      std::fprintf(stderr, "height fog pose (fogcl's world): %s, from %s\n", pose_text(*params.pose).c_str(),
                   job.height_pose_from.c_str());
    std::fprintf(stderr, "depth: %s, channel %s%s\n", to_string(kind), o.depth_channel.c_str(),
                 color.deep ? " (deep color, flattened)" : "");
    std::fprintf(stderr, "%s", precision_why.c_str());
    if (backend.is_scalar()) std::fprintf(stderr, "(the scalar path computes in float; it has no precision variants)\n");
    std::fprintf(stderr, "variant: %s\n", describe(variant).c_str());
    if (variant.needs_pass())
      std::fprintf(stderr,
                   "  why: %s fog (--mode), %s, %s, %s projection, %s storage (the input's); what the scene "
                   "does not use is not compiled\n",
                   to_string(variant.mode), variant.mode == KernelMode::height ? "along the ray (height fog: --distance changes nothing)" : variant.distance ? "distance-based (--distance)" : "depth-based (no sqrt)",
                   variant.fog_skybox ? "no sky test (--fog-skybox)" : "sky test (sky stays unfogged)",
                   params.projection == Projection::orthographic                ? "orthographic (--ortho-size)"
                   : params.projection == Projection::perspective_infinite_far ? "infinite-far (--infinite-far)"
                                                                                : "perspective",
                   to_string(variant.storage));
    else
      std::fprintf(stderr, volumes != nullptr
                               ? "  why: no deferred fog pass (fog off or density 0): the output is the volumes' result\n"
                               : "  why: no pass runs (fog off or density 0): the output is the input\n");
    print_build_options(backend, variant);
    std::fprintf(stderr, "output: %s, compression %s\n", o.pixel_type.c_str(),
                 o.compression.empty() ? (std::string(exr_compression_name(color.compression)) + " (the input's)").c_str()
                                       : o.compression.c_str());
  }
  if (volumes != nullptr) volumes->set_frame_pose(job.pose, job.pose_from);
  // docs/DESIGN.md §5: the volumes first, the deferred fog on their result. In place: the input's
  // pixels are not needed again, and a sequence allocates no extra frame.
  if (volumes != nullptr)
    apply_volumes(*volumes, job.color.color, job.depth, job.color.color, params, sequence_frame, print_setup);
  job.pending = backend.apply_async(color.color, job.depth, job.out, params, settings);
}

// The fogged frame's input pixels are not needed any more: memory stays bounded.
InputFrames take_inputs(FrameJob& job) {
  InputFrames inputs{std::move(job.color.color), std::move(job.depth)};
  job.color.color = ColorImage();
  job.depth = DepthImage();
  return inputs;
}

// Writes a fogged frame (and its preview) (writer thread).
void write_frame(const ApplyOptions& o, FrameJob& job) {
  job.pending.wait();
  ExrWriteOptions w;
  w.half = o.pixel_type == "half";
  w.compression = o.compression.empty() ? -1 : parse_exr_compression(o.compression);
  // Both files are written completely before either replaces its destination: a preview that
  // fails leaves the EXR's destination as it was (and a frame fogged in place unfogged).
  detail::WriteBatch batch;
  write_exr_output(job.paths.out, job.out, job.color, o.rgba_only, w);
  if (!job.paths.png.empty()) write_png_preview(job.paths.png, job.out);
  batch.commit();
}

// Set by SIGINT / SIGTERM during a sequence: stop after the write in progress.
std::atomic<int> g_interrupt{0};
// A second signal ends the process at once, by that signal; a write then in progress leaves
// nothing either: an unnamed temporary vanishes with the process, a named one is removed here.
extern "C" void on_interrupt(int signo) {
  if (g_interrupt.exchange(signo) == 0) return;
  detail::remove_temporaries_now();
  ::signal(signo, SIG_DFL);
  ::raise(signo);
}

void catch_interrupts() {
  struct sigaction action {};
  action.sa_handler = on_interrupt;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

// Every core this process may run on (taskset, cgroup cpusets), as --threads' default.
int available_cores() {
  cpu_set_t set;
  if (sched_getaffinity(0, sizeof set, &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1u, std::thread::hardware_concurrency());
}

// A frame name too long to appear whole in its temporary's name (atomic_file.h's
// temporary_key) is known by its leading bytes `head`: they must begin a frame name (stem, digits,
// suffix).
bool begins_frame_name(const std::string& head, const std::string& stem, const std::string& suffix) {
  if (head.size() <= stem.size()) return stem.compare(0, head.size(), head) == 0;
  if (head.compare(0, stem.size(), stem) != 0) return false;
  for (std::size_t end = stem.size() + 1; end <= head.size() && std::isdigit(static_cast<unsigned char>(head[end - 1]));
       ++end)
    if (end == head.size() || suffix.compare(0, head.size() - end, head, end) == 0) return true;
  return false;
}

// The temporaries that killed runs left next to this sequence's outputs (atomic_file.h): only
// those of frame names of `pattern`.
int sweep_stale_temporaries(const FramePattern& pattern) {
  if (!pattern.is_sequence) return 0;
  // "out/shot." + digits + ".exr": the folder, and the file name's stem before the digits.
  const std::filesystem::path probe(pattern.prefix + "x");
  const std::string dir = probe.parent_path().empty() ? std::string(".") : probe.parent_path().string();
  std::string stem = probe.filename().string();
  stem.pop_back();
  const std::string& suffix = pattern.suffix;
  return detail::remove_stale_temporaries(dir, [&](const std::string& target) {
    if (std::string head; detail::is_shortened_temporary_key(target, &head)) return begins_frame_name(head, stem, suffix);
    if (target.size() <= stem.size() + suffix.size() || target.compare(0, stem.size(), stem) != 0 ||
        target.compare(target.size() - suffix.size(), suffix.size(), suffix) != 0)
      return false;
    const std::string digits = target.substr(stem.size(), target.size() - stem.size() - suffix.size());
    return std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
  });
}

}  // namespace

namespace {

// The rules the options make together, before any file is touched (also for a frame in memory).
void check_apply_options(const ApplyOptions& o) {
  parse_depth_kind(o.depth_kind);
  memory_limit(o.max_memory);
  if (o.fov != 0.0f && o.ortho_size != 0.0f)
    throw Error("give either --fov (perspective) or --ortho-size (orthographic), not both");
  if (o.ortho_size != 0.0f && o.infinite_far)
    throw Error("--infinite-far is a perspective projection; it does not go with --ortho-size");
  if (o.max_error_given && o.precision_given)
    throw Error("give either --precision or --max-error (which picks the precision), not both");
  if (o.host_transfer != "auto" && resolve_device_choice(o.device) == "scalar")
    throw Error("--host-transfer " + o.host_transfer +
                " moves frames to an OpenCL device; the scalar path (--device scalar) has none");
  if (o.pixel_type != "float" && o.pixel_type != "half")
    throw Error("--pixel-type must be half or float (got '" + o.pixel_type + "')");
  if (!o.compression.empty()) parse_exr_compression(o.compression);
}

}  // namespace

int run_apply(const ApplyOptions& o) {
  set_memory_stage("checking the options and the files");
  check_apply_options(o);
  const MemoryLimit memory = memory_limit(o.max_memory);
  const FramePattern color = parse_frame_pattern(o.color_path);
  const FramePattern depth = parse_frame_pattern(o.depth_path);
  const FramePattern out = parse_frame_pattern(o.out_path);
  const FramePattern png = parse_frame_pattern(o.png_path);

  // --threads N: OpenEXR's pool (de)compresses with N threads, and PoCL runs the pass on N unless
  // told otherwise (it reads POCL_MAX_PTHREAD_COUNT when the device is created).
  const int threads = o.threads == 0 ? available_cores() : o.threads;
  Imf::setGlobalThreadCount(threads);
  setenv("POCL_MAX_PTHREAD_COUNT", std::to_string(threads).c_str(), 0);

  if (!color.is_sequence) {
    for (const FramePattern* p : {&depth, &out, &png})
      if (p->is_sequence)
        throw Error("'" + p->text + "' has a frame placeholder but --color '" + o.color_path + "' has none");
    if (!o.frames.empty()) throw Error("--frames needs a frame placeholder in --color (e.g. shot.####.exr)");
    FrameJob job;
    job.paths = {frame_path(color, 0), frame_path(depth, 0), frame_path(out, 0), frame_path(png, 0)};  // '%%' is '%'
    check_frame_files(o, job.paths);  // before anything is read or written
    const int swept = detail::remove_stale_temporaries_of({job.paths.out, job.paths.png});
    if (o.verbose && swept > 0) std::fprintf(stderr, "removed %d stale temporary file(s) of killed runs\n", swept);
    set_memory_stage("fogging the frame");
    const std::string hint = frame_memory_hint(memory);
    std::future<void> reading = std::async(std::launch::async, [&] {
      naming_allocations("reading '" + job.paths.color + "'", hint, [&] { read_frame(o, memory, job); });
    });
    std::promise<std::shared_ptr<Devices>> opened;
    open_devices(o, opened);
    reading.get();  // a bad input is named whether or not the device opened
    const std::shared_ptr<Devices> devices = opened.get_future().get();
    naming_allocations("fogging '" + job.paths.color + "'", hint,
                       [&] { fog_frame(o, devices->backend, job, o.verbose, devices->volumes.get(), -1); });
    take_inputs(job);
    naming_allocations("writing '" + job.paths.out + "'", hint, [&] { write_frame(o, job); });
    return 0;
  }

  if (!out.is_sequence)
    throw Error("--out '" + o.out_path + "' needs a frame placeholder (#### or %04d) when --color is a sequence");
  if (!o.png_path.empty() && !png.is_sequence)
    throw Error("--png '" + o.png_path + "' needs a frame placeholder (#### or %04d) when --color is a sequence");
  // The frames on disk (within --frames); those missing from the range, or from the run of frames
  // on disk, fail the run as ranges, before any frame is read (--keep-going: the others are fogged).
  const SequenceFrames found =
      find_sequence_frames(color, o.frames.empty() ? std::nullopt : std::optional(parse_frame_range(o.frames)));
  const std::vector<int>& frames = found.present;
  const std::string missing = found.missing.empty() ? std::string()
                              : "missing frames " + ranges_text(found.missing) + " (" +
                                    std::to_string(found.missing_count) + " of " + std::to_string(found.requested) +
                                    " frames: no such files)";
  if (!missing.empty() && (!o.keep_going || frames.empty()))
    throw Error("'" + o.color_path + "': " + missing + (frames.empty() ? "" : "; --keep-going fogs the others"));
  if (frames.empty()) throw Error("'" + o.color_path + "': no frames found (give --frames FIRST-LAST)");
  if (!missing.empty())
    std::fprintf(stderr, "fogcl: '%s': %s; fogging the other %zu\n", o.color_path.c_str(), missing.c_str(),
                 frames.size());

  // The files every frame reads (each frame's own are checked as it is read).
  check_files({{"--depth", depth.is_sequence ? "" : frame_path(depth, 0)}, {"--volumes", o.volumes.volumes_path},
               {"--shadow-map", o.volumes.shadow_map_path}},
              {});
  check_sequence_outputs(o, color, depth, out, png, frames);
  const int swept = sweep_stale_temporaries(out) + (o.png_path.empty() ? 0 : sweep_stale_temporaries(png));
  // One device, one context, one program cache for every frame: opened by the pipeline's start
  // (this thread) while the first frames go through, taken by the fog stage when it needs it
  // (tiered: once it has opened). A device that fails to open stops the run (not a frame failure).
  const int cores = available_cores();
  const bool tiered = tiers(o, cores);
  // One core: the stages run one after another on this thread (FramePipeline::run, serial).
  const bool serial = cores == 1;
  std::promise<std::shared_ptr<Devices>> opened;
  const std::shared_future<std::shared_ptr<Devices>> opening = opened.get_future();
  std::string device_error;  // this thread's (start() runs here)
  if (o.verbose) {
    std::fprintf(stderr, "threads: %d (OpenEXR (de)compression%s)\n", threads,
                 resolve_device_choice(o.device) == "scalar" ? "" : "; PoCL's POCL_MAX_PTHREAD_COUNT unless set");
    if (serial)
      std::fprintf(stderr, "pipeline: one core available: each frame is read, fogged and written in turn on one "
                   "thread (nothing can overlap; interleaved stages would evict each other's caches)\n");
    if (tiered)
      std::fprintf(stderr, "tiering: frames that reach the fog stage while the device opens are fogged on the scalar "
                   "path (the same bits as PoCL's CPU kernel)\n");
    const std::filesystem::path out_dir = std::filesystem::path(out.prefix + "x").parent_path();
    std::fprintf(stderr, "temporary files: %s\n",
                 detail::temporary_file_kind(out_dir.empty() ? "." : out_dir.string()).c_str());
    if (swept > 0) std::fprintf(stderr, "removed %d stale temporary file(s) of killed runs\n", swept);
  }
  ProgressBar progress(int(frames.size()), true);
  const std::string frame_hint = frame_memory_hint(memory);
  set_memory_stage("running the frame sequence");
  std::vector<std::string> failures;
  std::string stop_error;
  int written = 0, last_written = -1;

  // The fog thread's.
  std::shared_ptr<Devices> devices;  // once taken from `opening`
  Backend scalar("scalar");          // tiered: the frames fogged before the device has opened
  int scalar_frames = 0, first_scalar = -1, last_scalar = -1, device_frames = 0;
  bool setup_printed = false;
  // Tiered frames were fogged on the scalar path but the device that opened is not PoCL's CPU
  // device: its kernel's bits are not the scalar path's, so the run stays on the scalar path.
  bool stay_scalar = false;

  Spares<ColorImage> spares;
  Spares<InputFrames> spare_inputs;
  // Tiered: the first frame's variant (nullopt: it failed to read), for the main thread's build.
  std::promise<std::optional<Variant>> first_variant;
  FramePipeline<FrameJob>::Stages stages;
  stages.read = [&](FrameJob& job) {
    const int f = job.frame;
    job.paths = {frame_path(color, f), o.depth_path.empty() ? "" : frame_path(depth, f), frame_path(out, f),
                 o.png_path.empty() ? "" : frame_path(png, f)};
    InputFrames spare = spare_inputs.take();
    const bool first = f == frames.front();
    try {
      check_frame_files(o, job.paths);
      naming_allocations("reading '" + job.paths.color + "'", frame_hint, [&] { read_frame(o, memory, job, &spare); });
    } catch (...) {
      if (first && tiered) first_variant.set_value(std::nullopt);
      throw;
    }
    if (first && tiered) first_variant.set_value(select_variant(o.settings, job.params, job.color.color.format()));
  };
  // Tiered, the first frame's program is built here too once the device has opened (0.09 s of
  // PoCL's clang on the 2-core machine), while the fog stage goes on on the scalar path.
  const auto prepare_first = [&](Devices& d) {
    std::future<std::optional<Variant>> variant = first_variant.get_future();
    while (variant.wait_for(std::chrono::milliseconds(20)) != std::future_status::ready)
      if (g_interrupt.load() != 0) return;  // the reader may stop before its first frame
    if (const std::optional<Variant> v = variant.get(); v && d.backend.pass() != nullptr) d.backend.pass()->prepare(*v);
  };
  stages.start = [&] { device_error = tiered ? open_devices(o, opened, prepare_first) : open_devices(o, opened); };
  stages.fog = [&](FrameJob& job) {
    // Tiered, the device is taken only once it has opened (never waited for); else it is waited for.
    if (!devices && !stay_scalar &&
        (!tiered || opening.wait_for(std::chrono::seconds(0)) == std::future_status::ready)) {
      try {
        devices = opening.get();  // rethrows what stopped the opening
      } catch (...) {
        job.device_failed = true;
        throw;
      }
      if (scalar_frames > 0 && !devices->scalar_bits) {
        stay_scalar = true;
        std::fprintf(stderr, "fogcl: note: the device is %s, not PoCL's CPU device: its kernel's bits are not the "
                     "scalar path's, so the frames after the %d fogged on the scalar path while it opened are "
                     "fogged there too\n", devices->backend.name().c_str(), scalar_frames);
      }
    }
    const bool on_device = devices && !stay_scalar;
    if (!on_device) {
      if (first_scalar < 0) first_scalar = job.frame;
      last_scalar = job.frame;
      ++scalar_frames;
    }
    Backend& backend = on_device ? devices->backend : scalar;
    const bool first_on_device = on_device && device_frames++ == 0;
    job.out = spares.take();  // the passes reuse it when it has the frame's size and storage
    const auto start = std::chrono::steady_clock::now();
    naming_allocations("fogging '" + job.paths.color + "'", frame_hint, [&] {
      fog_frame(o, backend, job, o.verbose && !setup_printed, on_device ? devices->volumes.get() : nullptr, job.frame);
    });
    const double passes_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (o.verbose && first_on_device) {
      if (scalar_frames == 0)
        std::fprintf(stderr, "start-up: device opened in %.3f s (%s frame %d was read); "
                     "frame %d's passes %.3f s (program builds included)\n", devices->open_s,
                     serial ? "before" : "while", job.frame, job.frame, passes_s);
      else {
        std::fprintf(stderr, "start-up: device %s opened in %.3f s, the first frame's program built in %.3f s on the "
                     "main thread; %d frame(s) fogged on the scalar path meanwhile (%d-%d); from frame %d on the "
                     "device: its passes %.3f s (program builds included)\n",
                     backend.name().c_str(), devices->open_s, std::max(0.0, devices->prepare_s), scalar_frames,
                     first_scalar, last_scalar, job.frame, passes_s);
        print_build_options(backend, backend.pass()->last_variant());
      }
    }
    spare_inputs.give(take_inputs(job));
    setup_printed = true;
  };
  stages.write = [&](FrameJob& job) {
    naming_allocations("writing '" + job.paths.out + "'", frame_hint, [&] { write_frame(o, job); });
    spares.give(std::move(job.out));
  };
  stages.done = [&](const FrameJob& job) {
    if (job.device_failed) return false;  // the run's error (device_error), not the frame's
    if (!job.error.empty()) {
      progress.clear();
      if (!o.keep_going) {
        stop_error = "frame " + std::to_string(job.frame) + ": " + job.error;
        return false;
      }
      std::fprintf(stderr, "fogcl: frame %d failed: %s\n", job.frame, job.error.c_str());
      failures.push_back("frame " + std::to_string(job.frame) + ": " + job.error);
    } else {
      ++written;
      last_written = job.frame;
    }
    progress.update(written + int(failures.size()));
    return true;
  };
  g_interrupt = 0;
  catch_interrupts();
  const auto outcome = FramePipeline<FrameJob>::run(frames, stages, &g_interrupt, serial);
  // A device that fails to open is one error for the run whenever it fails, also after frames
  // fogged on the scalar path meanwhile were written (tiered): those stay, complete and with the
  // bits PoCL's CPU kernel gives, and the message says which.
  if (!device_error.empty()) {
    progress.clear();
    throw Error(written == 0 ? device_error
                             : device_error + " (the device failed to open after " + std::to_string(written) + " of " +
                                   std::to_string(frames.size()) + " frames were fogged on the scalar path and "
                                   "written, the last: frame " + std::to_string(last_written) + ")");
  }
  if (!stop_error.empty()) throw Error(stop_error);
  progress.finish();
  if (outcome.interrupted) {
    progress.clear();
    std::fprintf(stderr, "fogcl: interrupted: %d of %zu frames written%s; no partial file left\n", written,
                 frames.size(), last_written >= 0 ? (" (the last: frame " + std::to_string(last_written) + ")").c_str() : "");
    return 128 + g_interrupt.load();
  }
  if (!failures.empty() || !missing.empty()) {
    std::fprintf(stderr, "fogcl: error: %lld of %lld frames failed:\n", (long long)failures.size() + found.missing_count,
                 found.requested);
    if (!missing.empty()) std::fprintf(stderr, "  %s\n", missing.c_str());
    for (const std::string& f : failures) std::fprintf(stderr, "  %s\n", f.c_str());
    return 1;
  }
  if (o.verbose) {
    // The device opened (device_error is empty); tiered, its builds may all be the main thread's.
    Backend& device = opening.get()->backend;
    if (scalar_frames > 0 && !devices)
      std::fprintf(stderr, "start-up: device opened in %.3f s, after the last frame: all %d frames were fogged on "
                   "the scalar path\n", opening.get()->open_s, scalar_frames);
    std::fprintf(stderr, "fogged %zu frames, %zu program build(s)\n", frames.size(),
                 device.is_scalar() ? std::size_t(0) : device.pass()->programs().builds());
    // Where the time went: the stages overlap, so the busiest one bounds the frame rate.
    const double n = double(std::max(outcome.finished, 1));
    std::fprintf(stderr, "stages per frame: read %.3f s, fog %.3f s, write %.3f s; wall %.3f s (%.2f frames/s)\n",
                 outcome.read_s / n, outcome.fog_s / n, outcome.write_s / n, outcome.total_s / n,
                 outcome.total_s > 0 ? double(outcome.finished) / outcome.total_s : 0.0);
  }
  return 0;
}

// ---- A frame in memory (cli/memory_frame.h) ------------------------------------------------------

struct MemoryFogger::Opened {
  Devices devices;
  explicit Opened(const ApplyOptions& o) : devices(o) {}
};

MemoryFogger::MemoryFogger(const ApplyOptions& options) : options_(options) {
  check_apply_options(options_);
  devices_ = std::make_unique<Opened>(options_);
}
MemoryFogger::~MemoryFogger() = default;
Backend& MemoryFogger::backend() { return devices_->devices.backend; }
VolumeStage* MemoryFogger::volumes() { return devices_->devices.volumes.get(); }

FrameCamera memory_frame_camera(const ApplyOptions& o, int width, int height, const ExrCamera* camera,
                                const std::string& name) {
  check_apply_options(o);
  // What the frame code reads of a file besides its pixels: its name, size and camera.
  ExrInput header;
  header.path = name;
  header.windows.display_max = header.windows.data_max = glm::ivec2(width - 1, height - 1);
  if (camera != nullptr) header.camera = *camera;
  return frame_camera_setup(o, header);
}

void MemoryFogger::fog(const MemoryFrame& f) {
  const ApplyOptions& o = options_;
  validate_frame(f.color, f.depth, f.out);
  const FrameCamera camera = memory_frame_camera(o, f.color.width(), f.color.height(), f.camera, f.name);
  const CameraParams& params = camera.params;
  Backend& backend = devices_->devices.backend;
  if (backend.runtime() != nullptr)
    check_device_allocations(f.name, *backend.runtime(), f.color.width(), f.color.height(), f.color.format(),
                             frame_memory_needs(o));
  std::string precision_why;
  const FogSettings settings = pass_settings(o, backend, f.color.format(), &precision_why);
  VolumeStage* volumes = devices_->devices.volumes.get();
  if (volumes == nullptr) {
    backend.apply(f.color, f.depth, f.out, params, settings);
    return;
  }
  // As fog_frame: the volumes first, the deferred fog on their result (here in `out`).
  volumes->set_frame_pose(camera.pose, camera.pose_from);
  apply_volumes(*volumes, f.color, f.depth, f.out, params, -1, false);
  backend.apply(f.out, f.depth, f.out, params, settings);
}

}  // namespace fogcl::cli
