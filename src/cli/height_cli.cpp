#include "cli/height_cli.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include <CLI/CLI.hpp>

#include "camera/camera_basis.h"
#include "cli/cli.h"
#include "cli/flag_values.h"
#include "cli/number_list.h"
#include "cli/usage.h"
#include "fogcl/renderer_camera.h"
#include "runtime/format.h"

namespace fogcl::cli {

namespace {

const char* const kHeightFlags[] = {"--extinction", "--inscattering", "--height-falloff", "--base-height", "--cutoff",
                                    "--max-opacity", "--sun-color", "--sun-exponent", "--sun-start",
                                    "--height-volumetric"};

using detail::str;

// One number (nan and inf read as such, for the rules to name them); malformed text is a usage error.
double parse_number(const std::string& flag, const std::string& text) { return read_number(flag, text); }

glm::vec3 non_negative_rgb(const std::string& flag, const std::string& text) {
  const glm::dvec3 c = parse_triple(flag, text, "R,G,B");
  for (int k = 0; k < 3; ++k)
    if (!(std::isfinite(c[k]) && c[k] >= 0.0 && c[k] <= 3.4e38))
      throw Error(flag + " must be finite and >= 0 in each channel (got '" + text + "')");
  return glm::vec3(c);
}

}  // namespace

void add_height_options(CLI::App& app, HeightCliOptions& o) {
  const auto rgb = [](const char* flag) {
    return value_check([flag](const std::string& text) { non_negative_rgb(flag, text); });
  };
  const char* group = "Height and atmospheric fog (--mode height; docs/DESIGN.md §6)";
  app.add_option("--extinction", o.extinction,
                 "Extinction R,G,B [1/world unit], >= 0 (instead of --density, which sets all three)")
      ->check(rgb("--extinction"))
      ->group(group);
  app.add_option("--inscattering", o.inscattering, "In-scattering R,G,B [1/world unit], >= 0 (default: the extinction)")
      ->check(rgb("--inscattering"))
      ->group(group);
  app.add_option("--height-falloff", o.falloff,
                 "Height falloff k [1/world unit], finite: > 0 thins upward, < 0 thickens, 0 homogeneous (default 0)")
      ->check(real_check("--height-falloff", kFinite))
      ->group(group);
  app.add_option("--base-height", o.base_height, "World y where the coefficients hold, finite (default 0)")
      ->check(real_check("--base-height", kFinite))
      ->group(group);
  app.add_option("--cutoff", o.cutoff, "No fog beyond this distance along the ray [world units], finite and > --start (default: none)")
      ->check(real_check("--cutoff", kFinite))
      ->group(group);
  app.add_option("--max-opacity", o.max_opacity, "Maximum fog opacity in [0, 1] (default 1)")
      ->check(real_check("--max-opacity", RealRule{"in [0, 1]", 0.0, false, 1.0, false}))
      ->group(group);
  app.add_option("--sun-color", o.sun_color,
                 "Sun in-scattering lobe color R,G,B >= 0 toward --light-dir (default: no lobe)")
      ->check(rgb("--sun-color"))
      ->group(group);
  app.add_option("--sun-exponent", o.sun_exponent, "Sun lobe exponent, > 0 (default 8; larger is tighter)")
      ->check(real_check("--sun-exponent", kPositive))
      ->group(group);
  app.add_flag("--height-volumetric", o.volumetric,
               "March the height fog in the volumetric pass: light shafts where --shadow-map shadows the sun "
               "(--light-dir); lit, the same image as without it (docs/DESIGN.md §6.5)")
      ->group(group);
  app.add_option("--sun-start", o.sun_start, "Sun lobe start distance along the ray [world units], >= 0 (default 0)")
      ->check(real_check("--sun-start", kNonNegative))
      ->group(group);
}

void resolve_height_flags(const CLI::App& app, ApplyOptions& ap) {
  const auto given = [&](const char* flag) { return app.count(flag) > 0; };
  HeightCliOptions& o = ap.height;
  if (ap.settings.mode != FogMode::height) {
    for (const char* flag : kHeightFlags)
      if (given(flag)) throw Error(std::string(flag) + " needs --mode height (it is a height-fog setting)");
    return;
  }
  // --eye/--forward/--up and --light-dir are this mode's too: not only the volumes'.
  auto& vg = ap.volumes.given;
  if (ap.volumes.volumes_path.empty() && !o.volumetric)
    for (const char* flag : {"--eye", "--forward", "--up", "--light-dir"})
      vg.erase(std::remove(vg.begin(), vg.end(), std::string(flag)), vg.end());

  // The camera pose: --eye/--forward/--up (in --axes' world), or --camera-to-world per frame.
  const Axes axes = ap.camera.axes_value.value_or(Axes::unity);
  if (!ap.camera.matrix) {
    for (const char* flag : {"--eye", "--forward", "--up"})
      if (!given(flag))
        throw Error(std::string(flag) + " is required with --mode height (the camera pose X,Y,Z: --eye, --forward "
                    "and --up, or --camera-to-world with --axes)");
    const CameraPose p = flag_pose(ap.volumes);
    if (detail::up_parallel_to_forward(p.up, p.forward))
      throw Error("--up must not be parallel to --forward (got --up '" + ap.volumes.up + "', --forward '" +
                  ap.volumes.forward + "')");
    const glm::mat3 to_fogcl = axes_to_fogcl(axes);
    o.pose = CameraPose{to_fogcl * p.eye, to_fogcl * p.forward, to_fogcl * p.up};
    o.pose_from = std::string("--eye/--forward/--up") +
                  (ap.camera.axes_value ? std::string(", --axes ") + to_string(axes) : "");
  }

  HeightFogSettings& h = ap.settings.height;
  h = HeightFogSettings{};
  if (given("--extinction")) {
    if (given("--density")) throw Error("give either --density or --extinction, not both");
    h.extinction = non_negative_rgb("--extinction", o.extinction);
  } else if (!(std::isfinite(ap.settings.density) && ap.settings.density >= 0.0f)) {
    throw Error("--density must be finite and >= 0 (got " + flag_value(app, "--density") + ")");
  }
  if (given("--inscattering")) h.inscattering = non_negative_rgb("--inscattering", o.inscattering);
  if (given("--height-falloff")) {
    const double k = parse_number("--height-falloff", o.falloff);
    if (!(std::isfinite(k) && std::fabs(k) <= 3.4e38)) throw Error("--height-falloff must be finite (got " + o.falloff + ")");
    h.falloff = float(k);
  }
  if (given("--base-height")) {
    const double b = parse_number("--base-height", o.base_height);
    if (!(std::isfinite(b) && std::fabs(b) <= 3.4e38)) throw Error("--base-height must be finite (got " + o.base_height + ")");
    h.base_height = float(b);
  }
  if (given("--start")) {
    if (!(std::isfinite(ap.settings.start) && ap.settings.start >= 0.0f))
      throw Error("--start must be finite and >= 0 with --mode height (got " + flag_value(app, "--start") + ")");
    h.start = ap.settings.start;
  }
  if (given("--cutoff")) {
    const double c = parse_number("--cutoff", o.cutoff);
    if (!(c > double(h.start)))
      throw Error("--cutoff must be > --start (got --cutoff " + o.cutoff + ", --start " +
                  (given("--start") ? flag_value(app, "--start") : str(h.start)) + ")");
    h.cutoff = float(c);
  }
  if (given("--max-opacity")) {
    const double m = parse_number("--max-opacity", o.max_opacity);
    if (!(m >= 0.0 && m <= 1.0)) throw Error("--max-opacity must be in [0, 1] (got " + o.max_opacity + ")");
    h.max_opacity = float(m);
  }
  if (given("--sun-color")) {
    if (!given("--light-dir"))
      throw Error("--sun-color needs --light-dir (the direction toward the sun, X,Y,Z)");
    SunLobe sun;
    sun.color = non_negative_rgb("--sun-color", o.sun_color);
    sun.direction = parse_direction("--light-dir", ap.volumes.light_dir);
    sun.direction = axes_to_fogcl(axes) * sun.direction;
    if (given("--sun-exponent")) {
      const double e = parse_number("--sun-exponent", o.sun_exponent);
      if (!(std::isfinite(e) && e > 0.0 && e <= 3.4e38))
        throw Error("--sun-exponent must be finite and > 0 (got " + o.sun_exponent + ")");
      sun.exponent = float(e);
    }
    if (given("--sun-start")) {
      const double s = parse_number("--sun-start", o.sun_start);
      if (!(std::isfinite(s) && s >= 0.0 && s <= 3.4e38))
        throw Error("--sun-start must be finite and >= 0 (got " + o.sun_start + ")");
      sun.start = float(s);
    }
    h.sun = sun;
  } else {
    for (const char* flag : {"--sun-exponent", "--sun-start"})
      if (given(flag)) throw Error(std::string(flag) + " needs --sun-color (the sun lobe's color)");
  }
  validate(ap.settings);  // the library's own rules, after the flags' (the same rules: a safety net)
  if (o.volumetric) {
    if (ap.camera.matrix)
      throw Error("--height-volumetric takes the pose from --eye/--forward/--up, not --camera-to-world");
    // The volumetric pass marches the fog; the deferred pass then has none to apply.
    ap.volumes.height_fog = ap.settings;
    ap.settings.mode = FogMode::off;
  }
}

std::optional<CameraPose> height_frame_pose(const ApplyOptions& ap, const ExrInput& color, std::string* from) {
  if (ap.settings.mode != FogMode::height) return std::nullopt;
  if (ap.height.pose) {
    *from = ap.height.pose_from;
    return ap.height.pose;
  }
  return renderer_pose(ap.camera, color, from);  // the same conversion as the volumes' (cli/camera_cli.h)
}

}  // namespace fogcl::cli
