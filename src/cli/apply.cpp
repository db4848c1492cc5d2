#include <cstdio>

#include "cli/cli.h"
#include "fogcl/exr_io.h"

namespace fogcl::cli {

int run_apply(const ApplyOptions& o) {
  ExrWindows color_windows, depth_windows;
  const ColorImage color = read_exr_color(o.color_path, &color_windows);

  PerspectiveCamera camera;
  camera.near_plane = o.near_plane;
  camera.far_plane = o.far_plane;
  camera.fov_y_deg = o.fov;
  camera.reversed_z = o.reversed_z;
  camera.aspect = o.aspect != 0.0f ? o.aspect : float(color.width()) / float(color.height());
  const CameraParams params = make_camera_params(camera);
  validate(o.settings);

  // Outside the depth's data window there is nothing: treat it as sky.
  const DepthImage depth = read_exr_depth(o.depth_path, &depth_windows, o.depth_channel,
                                          o.reversed_z ? 0.0f : 1.0f);
  if (!(depth_windows == color_windows))
    throw Error(o.depth_path + ": data/display window differs from " + o.color_path +
                "'s: depth and color must cover the same pixels");

  Backend backend(o.device);
  if (o.verbose) {
    std::fprintf(stderr, "device: %s\n", backend.name().c_str());
    std::fprintf(stderr, "variant: %s\n", describe(select_variant(o.settings, params, color.format())).c_str());
    if (!backend.is_scalar() && select_variant(o.settings, params, color.format()).needs_pass())
      std::fprintf(stderr, "build options: %s\n",
                   backend.pass()->build_options_for(select_variant(o.settings, params, color.format())).c_str());
  }
  ColorImage out;
  backend.apply(color, depth, out, params, o.settings);
  write_exr_rgba(o.out_path, out, &color_windows);
  if (!o.png_path.empty()) write_png_preview(o.png_path, out);
  return 0;
}

}  // namespace fogcl::cli
