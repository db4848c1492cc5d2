// `fogcl demo`, the marched height fog's rows (docs/DESIGN.md §6.5):
// - light shafts: the scene under a low sun ahead (demo_low_sun()), its ground haze
//   (demo_shaft_fog()) marched with the scene's shadow map, so the spheres cut shafts out of the
//   sun's glow, and without it (the lit limit: §6.2's closed form);
// - street lamps: the scene at night (demo_night_frame()), a ground mist (demo_night_fog()) with
//   demo_street_lamps()' spot and point lights glowing in it, and the same mist without them.
// Each row: median time on OpenCL, one timed scalar run, max error against volumes_scalar<double>.
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

struct MarchRow {
  const char* name;
  const DemoFrame* frame;
  VolumeScene scene;
  const ShadowMap* shadow;  // null: none
};

// runs: timed OpenCL runs after the warm-up (the scalar path runs once).
void run_rows(const DemoOptions& o, std::vector<std::unique_ptr<Backend>>& backends, const VolumeSettings& settings,
              int runs, const std::vector<MarchRow>& rows) {
  namespace fs = std::filesystem;
  const auto path = [&](const std::string& name) { return (fs::path(o.out_dir) / name).string(); };
  std::printf("%-26s %-8s %12s %14s\n", "setting", "path", "ms", "max err f64");
  std::unique_ptr<VolumePass> pass;
  for (const MarchRow& row : rows) {
    const DemoFrame& frame = *row.frame;
    const VolumeResult<double> ref =
        volumes_scalar<double>(frame.color, frame.depth, frame.params, row.scene, settings, row.shadow);
    for (const auto& b : backends) {
      ColorImage out;
      const auto run = [&] {
        if (b->is_scalar()) {
          apply_volumes_scalar(frame.color, frame.depth, out, frame.params, row.scene, settings, row.shadow);
        } else {
          if (!pass) pass = std::make_unique<VolumePass>(*b->runtime());
          pass->apply(frame.color, frame.depth, out, frame.params, row.scene, settings, row.shadow);
        }
      };
      std::vector<double> ms;
      if (!b->is_scalar()) run();  // warm-up: builds the variant
      for (int i = 0; i < (b->is_scalar() ? 1 : runs); ++i) {
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

}  // namespace

void run_demo_shafts(const DemoOptions& o, std::vector<std::unique_ptr<Backend>>& backends) {
  namespace fs = std::filesystem;
  const auto path = [&](const std::string& name) { return (fs::path(o.out_dir) / name).string(); };
  const DemoView view;
  VolumeScene scene;
  scene.pose = CameraPose{view.eye, view.target - view.eye, glm::vec3(0.0f, 1.0f, 0.0f)};
  VolumeSettings settings;
  settings.integrator = VolumeIntegrator::physical;  // the marched fog's integrator

  const MainLight sun = demo_low_sun();
  {  // one scene frame at a time (fogcl demo's memory check counts two: cli/frame_memory.cpp)
    const DemoFrame day = render_demo_scene(o.width, o.height, PerspectiveCamera{}, view, ColorFormat::rgba32f,
                                            sun.direction);
    write_exr_rgba(path("scene-low-sun.exr"), day.color);
    write_png_preview(path("scene-low-sun.png"), day.color);
    const ShadowMap shadow = render_demo_shadow_map(1024, 1024, DemoShadowRegion{}, sun.direction);
    scene.light = sun;
    settings.height_fog = demo_shaft_fog();
    std::printf(
        "\nlight shafts (the height fog marched, docs/DESIGN.md §6.5): a low sun ahead, %d steps, half resolution, "
        "depth-aware; shadow map %dx%d\n",
        settings.steps, shadow.depth.width(), shadow.depth.height());
    std::printf("(opencl: median of 3 runs after a warm-up; scalar: 1 run)\n");
    run_rows(o, backends, settings, 3,
             {{"height-shafts", &day, scene, &shadow}, {"height-shafts-lit", &day, scene, nullptr}});
  }

  const DemoFrame night = demo_night_frame(o.width, o.height);
  write_exr_rgba(path("scene-night.exr"), night.color);
  VolumeScene lamps = scene;
  lamps.light = demo_light();
  lamps.light.color = glm::vec3(0.0f);  // no sun at night: the lamps and the mist's ambient
  VolumeScene dark = lamps;
  lamps.lights = demo_street_lamps();
  settings.height_fog = demo_night_fog();
  // The lights' inverse square is exact per piece whatever the steps, and the mist is smooth: 16
  // steps look as 50 do, at a third of the time.
  settings.steps = 16;
  std::printf("\nstreet lamps in a night mist (the height fog marched with %zu local lights): %d steps, half "
              "resolution, depth-aware\n",
              lamps.lights.size(), settings.steps);
  std::printf("(opencl: median of 3 runs after a warm-up; scalar: 1 run)\n");
  run_rows(o, backends, settings, 3,
           {{"street-lamps", &night, lamps, nullptr}, {"street-lamps-off", &night, dark, nullptr}});
}

}  // namespace fogcl::cli
