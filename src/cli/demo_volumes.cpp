// `fogcl demo`, volumetric rows: the demo scene with fog volumes (one around the camera, one
// behind a sphere, one crossing the ground, a bank further off) in both integrators, with and
// without the light's shadow map, and once followed by the deferred fog. Each row: median time on
// OpenCL, one timed scalar run (the scalar march is slow), max error against volumes_scalar<double>.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "cli/cli.h"
#include "cli/volumes_cli.h"
#include "fogcl/demo_scene.h"
#include "fogcl/exr_io.h"
#include "fogcl/volume_scalar.h"
#include "runtime/format.h"

namespace fogcl::cli {

namespace {

double elapsed_ms(std::chrono::steady_clock::time_point a) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count();
}

struct VolumeRow {
  const char* name;
  VolumeIntegrator integrator;
  bool shadow;
  bool deferred;  // the demo's exp2-distance fog after the volumes
};

// The row matrix of the brief: both integrators, the shadow map in at least one, and the two
// passes together once.
const VolumeRow kRows[] = {
    {"volumes-stylized", VolumeIntegrator::stylized, false, false},
    {"volumes-stylized-shadow", VolumeIntegrator::stylized, true, false},
    {"volumes-physical", VolumeIntegrator::physical, false, false},
    {"volumes-physical-shadow", VolumeIntegrator::physical, true, false},
    {"volumes-shadow+exp2", VolumeIntegrator::stylized, true, true},
};

}  // namespace

void run_demo_volumes(const DemoOptions& o, std::vector<std::unique_ptr<Backend>>& backends,
                      const FogSettings& deferred) {
  namespace fs = std::filesystem;
  const auto path = [&](const std::string& name) { return (fs::path(o.out_dir) / name).string(); };

  PerspectiveCamera camera;  // as scene.exr: conventional Z, Unity's defaults
  const DemoView view;
  const DemoFrame frame = render_demo_scene(o.width, o.height, camera, view);
  VolumeScene scene;
  scene.pose.eye = view.eye;
  scene.pose.forward = view.target - view.eye;
  scene.pose.up = glm::vec3(0.0f, 1.0f, 0.0f);
  scene.light = demo_light();
  const ShadowMap shadow = render_demo_shadow_map();

  // The inputs of `fogcl apply --volumes` for these rows.
  for (const VolumeIntegrator i : {VolumeIntegrator::stylized, VolumeIntegrator::physical}) {
    const std::string name = i == VolumeIntegrator::stylized ? "volumes.json" : "volumes-physical.json";
    std::ofstream json(path(name));
    json << volumes_to_json(demo_fog_volumes(i));
    if (!json) throw Error(path(name) + ": write error");
  }
  write_exr_depth(path("light-shadow.exr"), shadow.depth);
  std::ostringstream matrix;
  matrix.precision(9);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) matrix << (r + c > 0 ? "," : "") << shadow.params.world_to_light_clip[c][r];
  {
    std::ofstream txt(path("light-view-proj.txt"));
    txt << matrix.str() << "\n";
  }

  std::printf(
      "\nvolumetric fog volumes (volumes.json, volumes-physical.json): 4 volumes, %d steps, half resolution, "
      "depth-aware; shadow map %dx%d\n",
      VolumeSettings{}.steps, shadow.depth.width(), shadow.depth.height());
  std::printf("(opencl: median of 3 runs after a warm-up; scalar: 1 run, the march is slow on one thread)\n");
  std::printf("%-26s %-8s %12s %14s\n", "setting", "path", "ms", "max err f64");

  std::map<const Runtime*, std::unique_ptr<VolumePass>> passes;
  std::map<std::pair<int, bool>, VolumeResult<double>> refs;  // (integrator, shadow): rows share them
  for (const VolumeRow& row : kRows) {
    VolumeSettings settings;
    settings.integrator = row.integrator;
    scene.volumes = demo_fog_volumes(row.integrator);
    const ShadowMap* sm = row.shadow ? &shadow : nullptr;
    // Reference: the whole pass in double; with the deferred fog, its frame (rounded to float)
    // fogged by the double deferred path.
    const std::pair<int, bool> key(int(row.integrator), row.shadow);
    if (refs.count(key) == 0)
      refs[key] = volumes_scalar<double>(frame.color, frame.depth, frame.params, scene, settings, sm);
    const VolumeResult<double>& ref = refs[key];
    FogResult<double> ref_fog;
    if (row.deferred) {
      ColorImage mid(frame.color.width(), frame.color.height());
      for (int y = 0; y < mid.height(); ++y)
        for (int x = 0; x < mid.width(); ++x) {
          const std::size_t i = 4 * (std::size_t(y) * std::size_t(mid.width()) + std::size_t(x));
          mid.set_pixel(
              x, y,
              glm::vec4(float(ref.rgba[i]), float(ref.rgba[i + 1]), float(ref.rgba[i + 2]), float(ref.rgba[i + 3])));
        }
      ref_fog = fog_scalar<double>(mid, frame.depth, frame.params, deferred);
    }
    for (const auto& b : backends) {
      ColorImage out;
      const auto run = [&] {
        if (b->is_scalar()) {
          apply_volumes_scalar(frame.color, frame.depth, out, frame.params, scene, settings, sm);
        } else {
          auto& pass = passes[b->runtime()];
          if (!pass) pass = std::make_unique<VolumePass>(*b->runtime());
          pass->apply(frame.color, frame.depth, out, frame.params, scene, settings, sm);
        }
        if (row.deferred) b->apply(out, frame.depth, out, frame.params, deferred);
      };
      std::vector<double> ms;
      if (b->is_scalar()) {
        const auto a = std::chrono::steady_clock::now();
        run();
        ms.push_back(elapsed_ms(a));
      } else {
        run();  // warm-up: builds the variants, uploads the noise
        for (int i = 0; i < 3; ++i) {
          const auto a = std::chrono::steady_clock::now();
          run();
          ms.push_back(elapsed_ms(a));
        }
      }
      std::sort(ms.begin(), ms.end());
      const double err = row.deferred ? max_abs_rgb_error(out, ref_fog) : max_abs_rgb_error(out, ref);
      const char* kind = b->is_scalar() ? "scalar" : "opencl";
      std::printf("%-26s %-8s %12.3f %14.3g\n", row.name, kind, ms[ms.size() / 2], err);
      const std::string stem = std::string(row.name) + "-" + kind;
      write_exr_rgba(path(stem + ".exr"), out);
      write_png_preview(path(stem + ".png"), out);
    }
  }
  std::printf(
      "\nthe same with fogcl apply (volumes-stylized-shadow; physical: --integrator physical --volumes %s):\n  fogcl "
      "apply --color %s --depth %s --out OUT.exr "
      "--near %g --far %g --fov %g --volumes %s --eye %s --forward %s --up %s --light-dir %s --light-color %s "
      "--shadow-map %s --light-view-proj %s\n",
      path("volumes-physical.json").c_str(), path("scene.exr").c_str(), path("scene-depth.exr").c_str(),
      double(camera.near_plane), double(camera.far_plane), double(camera.fov_y_deg), path("volumes.json").c_str(),
      detail::comma_list(scene.pose.eye).c_str(), detail::comma_list(scene.pose.forward).c_str(),
      detail::comma_list(scene.pose.up).c_str(), detail::comma_list(scene.light.direction).c_str(),
      detail::comma_list(scene.light.color).c_str(), path("light-shadow.exr").c_str(),
      matrix.str().c_str());
}

}  // namespace fogcl::cli
