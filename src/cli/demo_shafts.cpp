// `fogcl demo`, light-shaft rows: the scene under a low sun ahead (demo_low_sun()), its ground
// haze (demo_shaft_fog()) marched in the volumetric pass (docs/DESIGN.md §6.5) with the scene's
// shadow map, so the spheres cut shafts out of the sun's glow, and without it (the lit limit:
// §6.2's closed form). Each row: median time on OpenCL, one timed scalar run, max error against
// volumes_scalar<double>.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>

#include "cli/cli.h"
#include "cli/volumes_cli.h"
#include "fogcl/demo_scene.h"
#include "fogcl/exr_io.h"
#include "fogcl/volume_scalar.h"

namespace fogcl::cli {

namespace {

struct ShaftRow {
  const char* name;
  bool shadow;
};

const ShaftRow kShaftRows[] = {{"height-shafts", true}, {"height-shafts-lit", false}};

}  // namespace

void run_demo_shafts(const DemoOptions& o, std::vector<std::unique_ptr<Backend>>& backends) {
  namespace fs = std::filesystem;
  const auto path = [&](const std::string& name) { return (fs::path(o.out_dir) / name).string(); };

  const MainLight sun = demo_low_sun();
  const DemoView view;
  const DemoFrame frame = render_demo_scene(o.width, o.height, PerspectiveCamera{}, view, ColorFormat::rgba32f,
                                            sun.direction);
  write_exr_rgba(path("scene-low-sun.exr"), frame.color);
  write_png_preview(path("scene-low-sun.png"), frame.color);
  const ShadowMap shadow = render_demo_shadow_map(1024, 1024, DemoShadowRegion{}, sun.direction);
  VolumeScene scene;
  scene.pose = CameraPose{view.eye, view.target - view.eye, glm::vec3(0.0f, 1.0f, 0.0f)};
  scene.light = sun;
  VolumeSettings settings;
  settings.integrator = VolumeIntegrator::physical;  // the marched fog's integrator
  settings.height_fog = demo_shaft_fog();

  std::printf(
      "\nlight shafts (the height fog marched, docs/DESIGN.md §6.5): a low sun ahead, %d steps, half resolution, "
      "depth-aware; shadow map %dx%d\n",
      settings.steps, shadow.depth.width(), shadow.depth.height());
  std::printf("%-26s %-8s %12s %14s\n", "setting", "path", "ms", "max err f64");
  std::unique_ptr<VolumePass> pass;
  for (const ShaftRow& row : kShaftRows) {
    const ShadowMap* sm = row.shadow ? &shadow : nullptr;
    const VolumeResult<double> ref = volumes_scalar<double>(frame.color, frame.depth, frame.params, scene, settings, sm);
    for (const auto& b : backends) {
      ColorImage out;
      const auto run = [&] {
        if (b->is_scalar()) {
          apply_volumes_scalar(frame.color, frame.depth, out, frame.params, scene, settings, sm);
        } else {
          if (!pass) pass = std::make_unique<VolumePass>(*b->runtime());
          pass->apply(frame.color, frame.depth, out, frame.params, scene, settings, sm);
        }
      };
      std::vector<double> ms;
      if (!b->is_scalar()) run();  // warm-up: builds the variant
      for (int i = 0; i < (b->is_scalar() ? 1 : 3); ++i) {
        const auto a = std::chrono::steady_clock::now();
        run();
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
      }
      std::sort(ms.begin(), ms.end());
      const char* kind = b->is_scalar() ? "scalar" : "opencl";
      std::printf("%-26s %-8s %12.3f %14.3g\n", row.name, kind, ms[ms.size() / 2], max_abs_rgb_error(out, ref));
      const std::string stem = std::string(row.name) + "-" + kind;
      write_exr_rgba(path(stem + ".exr"), out);
      write_png_preview(path(stem + ".png"), out);
    }
  }
}

}  // namespace fogcl::cli
