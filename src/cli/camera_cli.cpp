#include "cli/camera_cli.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <CLI/CLI.hpp>

#include "cli/cli.h"
#include "cli/flag_values.h"
#include "cli/number_list.h"
#include "cli/volumes_cli.h"
#include "runtime/format.h"

namespace fogcl::cli {

namespace {

const char* const kCameraFlags[] = {"--camera-to-world", "--axes",         "--focal-length",
                                    "--sensor-width",    "--sensor-height", "--sensor-fit"};

using detail::str;

// A library message about `subject` ("axes must be ...", "camera-to-world matrix: ...") as the
// flag's: "--axes must be ...", "--camera-to-world: ...".
std::string as_flag(const std::string& message, const std::string& subject, const std::string& flag) {
  if (message.rfind(subject, 0) == 0) return flag + message.substr(subject.size());
  return flag + ": " + message;
}

bool has(const std::vector<std::string>& given, const std::string& flag) {
  return std::find(given.begin(), given.end(), flag) != given.end();
}

// "m00,m01,...,m33": 16 finite numbers, or an error naming --camera-to-world and the element.
std::array<double, 16> parse_sixteen(const std::string& text) {
  const std::vector<double> numbers =
      parse_numbers("--camera-to-world", text, 16, "16 comma-separated numbers m00,m01,...,m33, row by row");
  for (std::size_t i = 0; i < numbers.size(); ++i)
    if (!(std::isfinite(numbers[i]) && std::fabs(numbers[i]) <= 3.4028234663852886e38))
      throw Error("--camera-to-world element " + std::to_string(i) + " must be finite in float, |x| <= 3.4e38 (got '" +
                  text + "')");
  std::array<double, 16> v{};
  std::copy(numbers.begin(), numbers.end(), v.begin());
  return v;
}

}  // namespace

void add_camera_options(CLI::App& app, CameraCliOptions& o) {
  const char* group = "The renderer's camera (instead of --fov and --eye/--forward/--up)";
  app.add_option("--camera-to-world", o.camera_to_world,
                 "The camera's camera-to-world matrix as the renderer prints it: 16 numbers m00,m01,...,m33 row by "
                 "row (unity, blender: column vectors, translation in the last column; houdini, maya: row vectors, "
                 "translation in the last row); rigid (no scale); needs --axes; not with --eye/--forward/--up")
      ->check(value_check([](const std::string& text) { parse_sixteen(text); }))
      ->group(group);
  app.add_option("--axes", o.axes,
                 "The renderer's world of every world-space input (--camera-to-world, --eye/--forward/--up, "
                 "--light-dir, --light-view-proj, the volumes, the file's worldToCamera): unity (left-handed, +y up; "
                 "fogcl's own, the default), blender (right-handed, +z up), houdini or maya (right-handed, +y up)")
      ->check(keyword_check("--axes", {"unity", "blender", "houdini", "maya"}))
      ->group(group);
  app.add_option("--focal-length", o.focal_length,
                 "Lens focal length [mm], > 0: with --sensor-width, the vertical fov by Blender's sensor-fit rules; "
                 "not with --fov or --ortho-size")
      ->check(real_check("--focal-length", kPositive))
      ->group(group);
  app.add_option("--sensor-width", o.sensor_width, "Sensor width [mm], > 0 (Blender's default 36); needs --focal-length")
      ->check(real_check("--sensor-width", kPositive))
      ->group(group);
  app.add_option("--sensor-height", o.sensor_height,
                 "Sensor height [mm], > 0; read only with --sensor-fit vertical (as Blender)")
      ->check(real_check("--sensor-height", kPositive))
      ->group(group);
  app.add_option("--sensor-fit", o.sensor_fit,
                 "auto (the sensor width spans the larger image dimension), horizontal (the width spans the image "
                 "width) or vertical (the sensor height spans the image height)")
      ->check(keyword_check("--sensor-fit", {"auto", "horizontal", "vertical"}))
      ->capture_default_str()
      ->group(group);
}

void resolve_camera_flags(const CLI::App& app, ApplyOptions& ap) {
  CameraCliOptions& o = ap.camera;
  o.given.clear();
  for (const char* flag : kCameraFlags)
    if (app.count(flag) > 0) o.given.push_back(flag);
  const auto given = [&](const char* flag) { return has(o.given, flag); };
  const std::vector<std::string>& volume_flags = ap.volumes.given;

  if (given("--axes")) try {
      o.axes_value = parse_axes(o.axes);
    } catch (const Error& e) {
      throw Error(as_flag(e.what(), "axes", "--axes"));
    }
  // The lens: all of its flags need --focal-length, which replaces --fov.
  if (given("--focal-length")) {
    if (app.count("--fov") > 0) throw Error("give either --fov or --focal-length (lens data), not both");
    if (app.count("--ortho-size") > 0)
      throw Error("--focal-length is a perspective lens; it does not go with --ortho-size");
    if (!given("--sensor-width"))
      throw Error("--focal-length needs --sensor-width (the sensor's width in mm; Blender's default is 36)");
    Lens lens;
    lens.focal_length_mm = o.focal_length;
    lens.sensor_width_mm = o.sensor_width;
    try {
      lens.fit = parse_sensor_fit(o.sensor_fit);
    } catch (const Error& e) {
      throw Error(as_flag(e.what(), "sensor fit", "--sensor-fit"));
    }
    if (lens.fit == SensorFit::vertical && !given("--sensor-height"))
      throw Error("--sensor-fit vertical needs --sensor-height (the sensor height then spans the image height)");
    if (given("--sensor-height")) lens.sensor_height_mm = o.sensor_height;
    const auto positive = [](const char* flag, float v) {
      if (!(std::isfinite(v) && v > 0.0f))
        throw Error(std::string(flag) + " must be finite and > 0 [mm] (got " + str(double(v)) + ")");
    };
    positive("--focal-length", lens.focal_length_mm);
    positive("--sensor-width", lens.sensor_width_mm);
    if (given("--sensor-height")) positive("--sensor-height", lens.sensor_height_mm);
    o.lens = lens;
  } else {
    for (const char* flag : {"--sensor-width", "--sensor-height", "--sensor-fit"})
      if (given(flag)) throw Error(std::string(flag) + " needs --focal-length (lens data replaces --fov)");
  }
  // The pose: the matrix replaces --eye/--forward/--up.
  if (given("--camera-to-world")) {
    for (const char* flag : {"--eye", "--forward", "--up"})
      if (has(volume_flags, flag))
        throw Error(std::string("give either --camera-to-world or ") + flag + " (--eye/--forward/--up), not both");
    if (!o.axes_value)
      throw Error("--camera-to-world needs --axes unity|blender|houdini|maya (which way the camera looks in the "
                  "matrix, and the world's axes)");
    try {
      o.matrix = camera_to_world_from_rows(parse_sixteen(o.camera_to_world), *o.axes_value);
      camera_frame(*o.matrix, *o.axes_value);  // rigid, before any file is read
    } catch (const Error& e) {
      const std::string what = e.what();
      throw Error(what.rfind("--camera-to-world", 0) == 0
                      ? what
                      : as_flag(what, "camera-to-world matrix", "--camera-to-world"));
    }
  }
  VolumeCliOptions& v = ap.volumes;
  v.axes = o.axes_value;
  v.pose_per_frame = !v.volumes_path.empty() &&
                     (o.matrix || !(has(volume_flags, "--eye") || has(volume_flags, "--forward") ||
                                    has(volume_flags, "--up")));
}

float lens_fov_deg(const CameraCliOptions& o, float aspect) {
  RendererCamera c;
  if (o.matrix) c.camera_to_world = *o.matrix;
  c.axes = o.axes_value.value_or(Axes::unity);
  c.lens = o.lens;
  try {
    return to_fogcl_camera(c, aspect).fov_y_deg;
  } catch (const Error& e) {
    throw Error(std::string("--focal-length/--sensor-width: ") + e.what());
  }
}

std::optional<CameraPose> frame_pose(const CameraCliOptions& o, const VolumeCliOptions& v, const ExrInput& color,
                                     std::string* from) {
  if (!v.pose_per_frame) return std::nullopt;
  return renderer_pose(o, color, from);
}

CameraPose renderer_pose(const CameraCliOptions& o, const ExrInput& color, std::string* from) {
  const Axes axes = o.axes_value.value_or(Axes::unity);
  if (o.matrix) {
    RendererCamera c;  // the fov is not needed here: the frame's comes from frame_camera
    c.camera_to_world = *o.matrix;
    c.axes = axes;
    *from = std::string("--camera-to-world, --axes ") + to_string(axes);
    return to_fogcl_camera(c, 1.0f).pose;
  }
  const ExrCamera& cam = color.camera;
  if (!cam.present || !cam.pose_present)
    throw Error(color.path + ": --volumes needs the camera pose: give --camera-to-world with --axes, or --eye, "
                "--forward and --up; the file has none (" +
                (!cam.present ? (cam.note.empty() ? std::string("no worldToNDC and worldToCamera attributes") : cam.note)
                              : cam.pose_note) +
                ")");
  try {
    *from = std::string("the file's worldToCamera / worldToNDC, ") +
            (o.axes_value ? std::string("--axes ") + to_string(axes) : std::string("fogcl's axes (no --axes)"));
    return camera_pose(cam.frame, axes);
  } catch (const Error& e) {
    throw Error(color.path + ": worldToCamera: " + e.what() +
                (o.axes_value ? "" : " (fogcl's world is left-handed, +y up: give the renderer's --axes)"));
  }
}

CameraPose flag_pose(const VolumeCliOptions& v) {
  CameraPose p;
  p.eye = parse_finite_vec3("--eye", v.eye);
  p.forward = parse_direction("--forward", v.forward);
  p.up = parse_direction("--up", v.up);
  return p;
}

std::string pose_text(const CameraPose& p) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "eye (%g, %g, %g), forward (%g, %g, %g), up (%g, %g, %g)", double(p.eye.x),
                double(p.eye.y), double(p.eye.z), double(p.forward.x), double(p.forward.y), double(p.forward.z),
                double(p.up.x), double(p.up.y), double(p.up.z));
  return buf;
}

}  // namespace fogcl::cli
