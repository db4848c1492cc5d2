// `fogcl demo`: the built-in scene fogged in several settings, on the chosen OpenCL device and
// on the scalar path, with run time (median) and error against the float64 path per row.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include "cli/cli.h"
#include "cli/frame_memory.h"
#include "fogcl/demo_scene.h"
#include "fogcl/exr_io.h"

namespace fogcl::cli {

namespace {

struct DemoSetting {
  const char* name;
  FogSettings settings;
  bool reversed_z;
};

std::vector<DemoSetting> demo_settings() {
  std::vector<DemoSetting> out;
  const auto add = [&](const char* name, FogMode mode, FogMetric metric, bool skybox, bool reversed) {
    FogSettings s;
    s.mode = mode;
    s.metric = metric;
    s.fog_skybox = skybox;
    s.color = glm::vec3(0.62f, 0.68f, 0.76f);
    s.start = 2.0f;
    s.end = 70.0f;
    s.density = mode == FogMode::exp ? 0.035f : 0.025f;
    out.push_back({name, s, reversed});
  };
  add("linear-depth", FogMode::linear, FogMetric::depth, false, false);
  add("exp-depth", FogMode::exp, FogMetric::depth, false, false);
  add("exp2-depth", FogMode::exp2, FogMetric::depth, false, false);
  add("exp2-distance", FogMode::exp2, FogMetric::distance, false, false);
  add("exp-distance-fogsky", FogMode::exp, FogMetric::distance, true, false);
  add("linear-distance-revz", FogMode::linear, FogMetric::distance, false, true);
  // Height fog (docs/DESIGN.md §6): a valley fog lying on the ground, a blue atmospheric haze with
  // per-channel coefficients, and the same haze with a low sun's lobe ahead, against the sky.
  FogSettings valley;
  valley.mode = FogMode::height;
  valley.color = glm::vec3(0.78f, 0.8f, 0.84f);
  valley.density = 0.5f;
  valley.height.falloff = 1.6f;
  valley.height.base_height = 0.0f;
  out.push_back({"height-valley", valley, false});
  FogSettings haze;
  haze.mode = FogMode::height;
  haze.color = glm::vec3(0.42f, 0.58f, 0.86f);
  haze.height.extinction = glm::vec3(0.006f, 0.011f, 0.024f);
  haze.height.falloff = 0.04f;
  haze.fog_skybox = true;
  out.push_back({"height-haze-fogsky", haze, false});
  FogSettings sun = haze;
  SunLobe lobe;
  lobe.direction = glm::vec3(0.35f, 0.12f, 1.0f);
  lobe.color = glm::vec3(1.1f, 0.85f, 0.55f);
  lobe.exponent = 24.0f;
  sun.height.sun = lobe;
  out.push_back({"height-sun-fogsky", sun, false});
  return out;
}

// Median of `runs` timed calls [ms].
template <class Fn>
double median_ms(int runs, Fn&& fn) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    const auto a = std::chrono::steady_clock::now();
    fn();
    t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

}  // namespace

int run_demo(const DemoOptions& o) {
  namespace fs = std::filesystem;
  // Before anything is allocated (or the folder made): a 16384x16384 scene needs about 90 GiB.
  check_demo_memory(o.width, o.height, memory_limit(o.max_memory));
  set_memory_stage("rendering and fogging the demo scene");
  const auto path = [&](const std::string& name) { return (fs::path(o.out_dir) / name).string(); };

  std::vector<std::unique_ptr<Backend>> backends;
  if (resolve_device_choice(o.device) != "scalar") {
    // Without a choice (no --device, no FOGCL_DEVICE) a machine without OpenCL still runs the
    // demo on the scalar path; a device asked for that cannot be had is an error, as in apply.
    const char* env = std::getenv("FOGCL_DEVICE");
    const bool chosen = !o.device.empty() || (env != nullptr && *env != '\0');
    try {
      backends.push_back(std::make_unique<Backend>(o.device));
    } catch (const Error& e) {
      if (chosen) throw;
      std::fprintf(stderr, "fogcl demo: no OpenCL path (%s); running the scalar path only\n", e.what());
    }
  }
  backends.push_back(std::make_unique<Backend>("scalar"));
  fs::create_directories(o.out_dir);  // once the device is there: a failed run leaves nothing

  std::printf("scene: %dx%d, %zu settings\n", o.width, o.height, demo_settings().size());
  for (const auto& b : backends) std::printf("path: %s\n", b->name().c_str());
  std::printf("\n%-22s %-8s %12s %14s\n", "setting", "path", "median ms", "max err f64");

  int rendered_z = -1;
  DemoFrame frame;
  for (const DemoSetting& d : demo_settings()) {
    if (rendered_z != int(d.reversed_z)) {
      PerspectiveCamera camera;
      camera.reversed_z = d.reversed_z;
      frame = render_demo_scene(o.width, o.height, camera);
      const DemoView view;  // the pose height fog needs (the other modes ignore it)
      frame.params.pose = CameraPose{view.eye, view.target - view.eye, glm::vec3(0.0f, 1.0f, 0.0f)};
      rendered_z = int(d.reversed_z);
      const std::string tag = d.reversed_z ? "scene-revz" : "scene";
      write_exr_rgba(path(tag + ".exr"), frame.color);
      write_exr_depth(path(tag + "-depth.exr"), frame.depth);
      if (!d.reversed_z) write_png_preview(path("scene.png"), frame.color);
    }
    const FogResult<double> ref = fog_scalar<double>(frame.color, frame.depth, frame.params, d.settings);
    for (const auto& b : backends) {
      ColorImage out;
      b->apply(frame.color, frame.depth, out, frame.params, d.settings);  // warm-up: builds the variant
      const int runs = b->is_scalar() ? 3 : 9;
      const double ms = median_ms(runs, [&] { b->apply(frame.color, frame.depth, out, frame.params, d.settings); });
      const char* kind = b->is_scalar() ? "scalar" : "opencl";
      std::printf("%-22s %-8s %12.3f %14.3g\n", d.name, kind, ms, max_abs_rgb_error(out, ref));
      const std::string stem = std::string(d.name) + "-" + kind;
      write_exr_rgba(path(stem + ".exr"), out);
      write_png_preview(path(stem + ".png"), out);
    }
  }
  for (const DemoSetting& d : demo_settings())  // the volumetric rows; one adds this deferred fog
    if (std::string(d.name) == "exp2-distance") {
      set_memory_stage("running the demo's volumetric rows");
      run_demo_volumes(o, backends, d.settings);
    }
  set_memory_stage("running the demo's light-shaft rows");
  run_demo_shafts(o, backends);
  std::printf("\nwrote EXR and PNG images to %s/\n", o.out_dir.c_str());
  return 0;
}

}  // namespace fogcl::cli
