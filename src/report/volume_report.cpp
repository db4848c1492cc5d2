// fogcl report --volumetric: error against run time of the volumetric pass (fogcl/volume_report.h).
// Device time comes from CL profiling events as bench/volume_bench.cpp's BM_VolumeDevice measures
// it: from a marker enqueued just before the march to the end of the upsample + composite.
#include "fogcl/volume_report.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include "fogcl/demo_scene.h"
#include "fogcl/error.h"
#include "fogcl/version.h"
#include "fogcl/volume_pass.h"
#include "fogcl/volume_scalar.h"
#include "report/report_common.h"
#include "runtime/clhpp.h"
#include "volume/volume_formulas.h"
#include "volume_report_plot_py.h"  // generated from report/plot_volume_report.py

namespace fogcl {

namespace {

using report_detail::json_num;
using report_detail::json_string;
using report_detail::num;

// The report's volumes share the demo's look: its colours, ambient and phase for the physical
// integrator, its noise tiling.
FogVolume report_volume(glm::vec3 center, float radius) {
  FogVolume v;
  v.center = center;
  v.radius = radius;
  v.fog_color = glm::vec4(0.85f, 0.9f, 1.0f, 1.0f);
  v.tiling = glm::vec3(0.2f);
  v.detail_tiling = glm::vec3(0.6f);
  v.detail_strength = 0.4f;
  v.speed = glm::vec3(0.6f, -0.1f, 0.3f);
  return v;
}

void physical_light(FogVolume& v) {  // as demo_fog_volumes() lights its physical volumes
  v.ambient = glm::vec3(0.6f, 0.65f, 0.75f);
  v.anisotropy = 0.2f;
}

std::string scene_list() {
  std::string names;
  for (const std::string& n : volume_report_scene_names()) names += (names.empty() ? "" : ", ") + n;
  return names;
}

// The volumes of a scene for an integrator (riemann: the physical volumes).
std::vector<FogVolume> scene_volumes(const std::string& name, VolumeIntegrator integrator) {
  const bool physical = integrator != VolumeIntegrator::stylized;
  if (volume_report_scene_marches_height_fog(name)) return {};  // the fog alone: its shafts' error
  if (name == "demo") return demo_fog_volumes(physical ? VolumeIntegrator::physical : VolumeIntegrator::stylized);
  // dense and thin: a sphere of diameter 5 in front of the camera, dipping into the ground (rays
  // that end on the ground inside it have shorter chords).
  const float diameter = 5.0f;
  FogVolume v = report_volume(glm::vec3(0.5f, 1.5f, 4.0f), 0.5f * diameter);
  if (name == "dense") {
    // sigma_t * diameter = 50 (physical; stylized: the alpha scale, which saturates): the stiff
    // case. No noise and no fades, so the extinction is constant and the exact weight is exact.
    v.noise = false;
    v.fade_edge = v.fade_y = v.proximity_fade = 0.0f;
    v.density = 50.0f / diameter;
  } else if (name == "thin") {
    // sigma_t * diameter = 1e-4 at full noise: thin media must keep their digits.
    v.fade_edge = 1.0f;
    v.proximity_fade = 0.5f;
    v.density = 1e-4f / diameter;
  } else if (name == "inside") {
    // The camera (0, 1.6, -6) inside a noisy volume of radius 9 that reaches past the near spheres.
    v.center = glm::vec3(0.0f, 1.6f, -3.0f);
    v.radius = 9.0f;
    v.fade_edge = 2.0f;
    v.proximity_fade = 0.5f;
    v.fog_cutoff = 0.3f;
    v.density = physical ? 0.25f : 1.5f;
  } else {
    throw Error("volume report scene '" + name + "' is not one of " + scene_list());
  }
  if (physical) physical_light(v);
  return {v};
}

struct DeviceResult {
  double time_ms = 0;
  ColorImage out;
};

// The pass on the runtime's queue over zero-copy buffers (CPU devices; copies elsewhere): one
// untimed warm-up (after prepare() built the variant and the first frame uploaded the noise),
// then `runs` timed frames; `out` holds the last.
DeviceResult device_run(const Runtime& rt, VolumePass& pass, const ColorImage& in, const DepthImage& depth,
                        const CameraParams& params, const VolumeScene& scene, const VolumeSettings& settings,
                        const ShadowMap* shadow, float max_eye, int runs) {
  return with_cl_errors([&] {
    DeviceResult r;
    r.out = ColorImage(in.width(), in.height(), in.format());
    const bool cpu = rt.is_cpu();
    const cl_mem_flags host = cpu ? CL_MEM_USE_HOST_PTR : CL_MEM_COPY_HOST_PTR;
    const cl::Context ctx = wrap(rt.context());
    const cl::CommandQueue queue = wrap(rt.queue());
    const cl::Buffer color_in(ctx, CL_MEM_READ_ONLY | host, in.size_bytes(), const_cast<void*>(in.data()));
    const cl::Buffer depth_buffer(ctx, CL_MEM_READ_ONLY | host, depth.size_bytes(), const_cast<float*>(depth.data()));
    const cl::Buffer color_out(ctx, CL_MEM_READ_WRITE | host, r.out.size_bytes(), r.out.data());
    FrameBuffers fb;
    fb.width = in.width();
    fb.height = in.height();
    fb.format = in.format();
    fb.color_in = color_in();
    fb.depth = depth_buffer();
    fb.color_out = color_out();
    cl::Buffer shadow_depth;
    ShadowMapBuffer sm;
    if (shadow != nullptr) {
      shadow_depth = cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, shadow->depth.size_bytes(),
                                const_cast<float*>(shadow->depth.data()));
      sm = {shadow_depth(), shadow->depth.width(), shadow->depth.height(), shadow->params};
    }
    const ShadowMapBuffer* smp = shadow != nullptr ? &sm : nullptr;
    pass.prepare(params, scene, settings, in.format(), shadow != nullptr ? &shadow->params : nullptr);
    adopt(pass.enqueue(rt.queue(), fb, params, scene, settings, smp, {}, max_eye)).wait();
    std::vector<double> ms;
    for (int i = 0; i < runs; ++i) {
      cl::Event before;
      queue.enqueueMarkerWithWaitList(nullptr, &before);
      const cl::Event done = adopt(pass.enqueue(rt.queue(), fb, params, scene, settings, smp, {}, max_eye));
      done.wait();
      ms.push_back(double(done.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                          before.getProfilingInfo<CL_PROFILING_COMMAND_END>()) *
                   1e-6);
    }
    if (cpu)  // make the host view of the USE_HOST_PTR output valid (no copy on CPU devices)
      queue.enqueueUnmapMemObject(color_out,
                                  queue.enqueueMapBuffer(color_out, CL_TRUE, CL_MAP_READ, 0, r.out.size_bytes()));
    else
      queue.enqueueReadBuffer(color_out, CL_TRUE, 0, r.out.size_bytes(), r.out.data());
    queue.finish();
    r.time_ms = report_detail::median(ms);
    return r;
  });
}

// A scene's frame, camera and light, and what the pass takes besides the volumes: the demo's view;
// the volume scenes under the demo's light, the light-shaft scene under its low sun ahead, with
// its shadow map and its marched fog, the lamps' scene at night with its street lamps and mist
// (fogcl/demo_scene.h).
struct SceneSetup {
  DemoFrame frame;
  float max_eye = 0;
  VolumeScene base;  // pose and light; the volumes come per integrator
  std::optional<ShadowMap> shadow;
  std::optional<FogSettings> height_fog;
};

SceneSetup scene_setup(const std::string& name, int width, int height) {
  SceneSetup s;
  const DemoView view;
  const bool shafts = name == "shafts", lamps = name == "lamps";
  MainLight light = shafts ? demo_low_sun() : demo_light();
  s.frame = lamps ? demo_night_frame(width, height)
                  : render_demo_scene(width, height, PerspectiveCamera{}, view, ColorFormat::rgba32f,
                                      shafts ? std::optional<glm::vec3>(light.direction) : std::nullopt);
  if (lamps) {
    light.color = glm::vec3(0.0f);  // night: the lamps and the mist's ambient light it
    s.base.lights = demo_street_lamps();
    s.height_fog = demo_night_fog();
  }
  s.max_eye = max_eye_depth(s.frame.depth, s.frame.params);
  s.base.pose = CameraPose{view.eye, view.target - view.eye, glm::vec3(0.0f, 1.0f, 0.0f)};
  s.base.light = light;
  if (shafts) {
    s.shadow = render_demo_shadow_map(1024, 1024, DemoShadowRegion{}, light.direction);
    s.height_fog = demo_shaft_fog();
  }
  return s;
}

// The reference composited over `in` (the same frame in another storage): the reference march is
// at full resolution, so each pixel's (P, A) is its own target pixel; the composite is the pass's
// (vol_composite; A = 0 passes the pixel through).
std::vector<double> recomposite(const VolumeResult<double>& ref, const ColorImage& in) {
  std::vector<double> rgba(4 * in.pixel_count());
  for (int y = 0; y < in.height(); ++y)
    for (int x = 0; x < in.width(); ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(in.width()) + std::size_t(x);
      const glm::vec4 c = in.pixel(x, y);
      const double a = ref.low[4 * i + 3];
      for (int k = 0; k < 4; ++k)
        rgba[4 * i + k] = k == 3 || a == 0.0
                              ? double(c[k])
                              : volume_formulas::vol_composite<double>(double(c[k]), ref.low[4 * i + k], a);
    }
  return rgba;
}

}  // namespace

void validate(const VolumeReportOptions& o) {
  if (o.width < 1 || o.height < 1)
    throw Error("volume report frame size must be >= 1x1 (got " + std::to_string(o.width) + "x" +
                std::to_string(o.height) + ")");
  if (o.runs < 3) throw Error("volume report runs must be >= 3 for a median (got " + std::to_string(o.runs) + ")");
  for (int s : o.steps)
    if (s < 1 || s > 4096) throw Error("volume report steps must be in [1, 4096] (got " + std::to_string(s) + ")");
  for (int d : o.divisors)
    if (d != 1 && d != 2 && d != 4)
      throw Error("volume report resolution divisor must be 1, 2 or 4 (got " + std::to_string(d) + ")");
  if (o.reference_steps < 1 || o.reference_steps > 4096)
    throw Error("volume report reference steps must be in [1, 4096] (got " + std::to_string(o.reference_steps) + ")");
  for (VolumeIntegrator i : o.integrators)
    if (i == VolumeIntegrator::riemann)
      throw Error("volume report integrators are stylized and physical; the Riemann rows come with options.riemann");
  const std::vector<std::string> names = volume_report_scene_names();
  const bool physical =
      std::find(o.integrators.begin(), o.integrators.end(), VolumeIntegrator::physical) != o.integrators.end();
  for (const std::string& s : o.scenes) {
    if (std::find(names.begin(), names.end(), s) == names.end())
      throw Error("volume report scene '" + s + "' is not one of " + scene_list());
    if (volume_report_scene_marches_height_fog(s) && !physical)
      throw Error("volume report scene '" + s +
                  "' marches the height fog, which needs the physical integrator (add physical to the integrators)");
  }
  for (NoiseSampling n : o.noise)  // rows name what ran: the device's choice is one of these two
    if (n != NoiseSampling::buffer && n != NoiseSampling::image)
      throw Error(std::string("volume report noise sampling must be buffer or image (got ") + to_string(n) + ")");
  if (o.steps.empty() || o.divisors.empty() || o.integrators.empty() || o.storages.empty() || o.noise.empty())
    throw Error("volume report needs at least one step count, resolution, integrator, storage and noise sampling");
}

std::vector<std::string> volume_report_scene_names() {
  return {"demo", "dense", "thin", "inside", "shafts", "lamps"};
}

bool volume_report_scene_marches_height_fog(const std::string& scene) { return scene == "shafts" || scene == "lamps"; }

std::string volume_quality_name(int steps, int divisor, VolumeUpsampling upsampling, NoiseSampling noise) {
  std::string s = "s" + std::to_string(steps) + " " + resolution_name(divisor);
  if (divisor > 1) s += std::string(" ") + to_string(upsampling);
  return s + " " + to_string(noise);
}

VolumeReport run_volume_report(const Runtime& runtime, const VolumeReportOptions& o) {
  const bool images =
      with_cl_errors([&] { return wrap(runtime.device()).getInfo<CL_DEVICE_IMAGE_SUPPORT>() == CL_TRUE; });
  validate(o);
  if (!images && std::find(o.noise.begin(), o.noise.end(), NoiseSampling::buffer) == o.noise.end())
    throw Error("volume report: noise sampling 'image' needs a device with image support; " + runtime.description() +
                " has none (add 'buffer')");
  VolumeReport report;
  report.version = library_version();
  report.width = o.width;
  report.height = o.height;
  report.runs = o.runs;
  report.reference_steps = o.reference_steps;
  report.device = runtime.description();
  report.driver = with_cl_errors([&] { return wrap(runtime.device()).getInfo<CL_DRIVER_VERSION>(); });

  const std::vector<std::string> scenes = o.scenes.empty() ? volume_report_scene_names() : o.scenes;
  std::map<std::string, SceneSetup> setups;
  for (const std::string& name : scenes) setups.emplace(name, scene_setup(name, o.width, o.height));
  std::vector<VolumeIntegrator> integrators = o.integrators;
  const bool riemann_rows = o.riemann && std::find(scenes.begin(), scenes.end(), "dense") != scenes.end();
  if (riemann_rows &&
      std::find(integrators.begin(), integrators.end(), VolumeIntegrator::physical) == integrators.end())
    integrators.push_back(VolumeIntegrator::physical);  // the Riemann rows' reference
  // The marched height fog has the physical integrator only.
  const auto runs_with = [](const std::string& scene, VolumeIntegrator i) {
    return !volume_report_scene_marches_height_fog(scene) || i == VolumeIntegrator::physical;
  };

  struct Job {
    std::string scene;
    VolumeSettings settings;
    ColorFormat storage;
  };
  std::vector<Job> jobs;
  for (const std::string& scene : scenes) {
    for (VolumeIntegrator integrator : o.integrators)
      for (ColorFormat storage : o.storages) {
        if (!runs_with(scene, integrator)) continue;
        for (int steps : o.steps)
          for (int divisor : o.divisors)
            for (VolumeUpsampling up : {VolumeUpsampling::depth_aware, VolumeUpsampling::bilinear}) {
              if (up == VolumeUpsampling::bilinear && (divisor == 1 || !o.bilinear)) continue;
              for (NoiseSampling noise : o.noise) {
                if (noise == NoiseSampling::image && !images) continue;
                VolumeSettings s;
                s.integrator = integrator;
                s.steps = steps;
                s.resolution_divisor = divisor;
                s.upsampling = up;
                s.noise_sampling = noise;
                s.height_fog = setups.at(scene).height_fog;
                jobs.push_back({scene, s, storage});
              }
            }
      }
    if (scene == "dense" && riemann_rows)
      for (int steps : o.steps) {
        VolumeSettings s;
        s.integrator = VolumeIntegrator::riemann;
        s.steps = steps;
        s.resolution_divisor = 1;
        s.noise_sampling = NoiseSampling::buffer;  // rows name what ran (the dense scene has no noise)
        jobs.push_back({scene, s, ColorFormat::rgba32f});
      }
  }

  if (o.progress) o.progress(0, jobs.size());

  // The references first, in threads (one per scene x integrator, at most the machine's cores at
  // once); the timed device runs come after, on a quiet machine.
  std::map<std::pair<std::string, int>, VolumeResult<double>> refs;
  {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<std::pair<std::string, VolumeIntegrator>> refs_to_do;
    for (const std::string& s : scenes)
      for (VolumeIntegrator i : integrators)
        if (runs_with(s, i)) refs_to_do.emplace_back(s, i);
    const std::size_t threads = std::max(1u, std::thread::hardware_concurrency());
    for (std::size_t at = 0; at < refs_to_do.size(); at += threads) {
      std::vector<std::future<VolumeResult<double>>> running;
      for (std::size_t j = at; j < std::min(refs_to_do.size(), at + threads); ++j)
        running.push_back(std::async(std::launch::async, [&, j] {
          const SceneSetup& setup = setups.at(refs_to_do[j].first);
          VolumeScene scene = setup.base;
          scene.volumes = scene_volumes(refs_to_do[j].first, refs_to_do[j].second);
          VolumeSettings s;
          s.integrator = refs_to_do[j].second;
          s.steps = o.reference_steps;
          s.resolution_divisor = 1;
          s.jitter = false;
          s.height_fog = setup.height_fog;
          return volumes_scalar<double>(setup.frame.color, setup.frame.depth, setup.frame.params, scene, s,
                                        setup.shadow ? &*setup.shadow : nullptr);
        }));
      for (std::size_t j = at; j < std::min(refs_to_do.size(), at + threads); ++j)
        refs.emplace(std::make_pair(refs_to_do[j].first, int(refs_to_do[j].second)), running[j - at].get());
    }
    report.reference_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }

  VolumePass pass(runtime);
  std::map<std::pair<std::string, int>, ColorImage> inputs;  // (scene, storage): the frame in that storage
  std::map<std::tuple<std::string, int, int>, std::vector<double>> ref_rgba;  // (scene, integrator, storage)
  for (std::size_t n = 0; n < jobs.size(); ++n) {
    const Job& job = jobs[n];
    const VolumeSettings& s = job.settings;
    const SceneSetup& setup = setups.at(job.scene);
    const DemoFrame& frame = setup.frame;
    VolumeScene scene = setup.base;
    scene.volumes = scene_volumes(job.scene, s.integrator);
    auto in_it = inputs.find({job.scene, int(job.storage)});
    if (in_it == inputs.end())
      in_it = inputs.emplace(std::make_pair(job.scene, int(job.storage)), convert(frame.color, job.storage)).first;
    const ColorImage& in = in_it->second;
    const VolumeIntegrator truth =
        s.integrator == VolumeIntegrator::riemann ? VolumeIntegrator::physical : s.integrator;
    const auto ref_key = std::make_tuple(job.scene, int(truth), int(job.storage));
    auto ref_it = ref_rgba.find(ref_key);
    if (ref_it == ref_rgba.end())
      ref_it = ref_rgba.emplace(ref_key, recomposite(refs.at({job.scene, int(truth)}), in)).first;

    const DeviceResult r = device_run(runtime, pass, in, frame.depth, frame.params, scene, s,
                                      setup.shadow ? &*setup.shadow : nullptr, setup.max_eye, o.runs);
    const report_detail::ColorErrorStats e = report_detail::color_error_stats(r.out, in, ref_it->second, job.storage);
    VolumeReportRow row;
    row.scene = job.scene;
    row.integrator = s.integrator;
    row.steps = s.steps;
    row.divisor = s.resolution_divisor;
    row.upsampling = s.upsampling;
    row.noise = s.noise_sampling;
    row.storage = job.storage;
    row.variant =
        std::string(to_string(s.integrator)) + "-s" + std::to_string(s.steps) + "-" +
        resolution_name(s.resolution_divisor) +
        (s.resolution_divisor > 1 ? std::string(s.upsampling == VolumeUpsampling::depth_aware ? "-depth" : "-bilinear")
                                  : std::string()) +
        "-" + to_string(s.noise_sampling) + "-" + to_string(job.storage);
    row.time_ms = r.time_ms;
    row.max_abs_err = e.max_abs;
    row.p999_abs_err = e.p999_abs;
    row.pct_8bit_off = e.pct_8bit_off;
    // Every output value counts: the volumes must never make a NaN/Inf over a finite frame.
    row.nonfinite = e.nonfinite;
    report.rows.push_back(row);
    if (o.progress) o.progress(n + 1, jobs.size());
  }
  return report;
}

void write_volume_report_csv(const VolumeReport& r, const std::string& path) {
  std::ostringstream s;
  s << "scene,variant,integrator,steps,resolution,upsampling,noise,storage,time_ms,max_abs_err,p999_abs_err,"
       "pct_8bit_off,nonfinite\n";
  for (const VolumeReportRow& row : r.rows)
    s << row.scene << ',' << row.variant << ',' << to_string(row.integrator) << ',' << row.steps << ','
      << resolution_name(row.divisor) << ',' << to_string(row.upsampling) << ',' << to_string(row.noise) << ','
      << to_string(row.storage) << ',' << num(row.time_ms) << ',' << num(row.max_abs_err) << ','
      << num(row.p999_abs_err) << ',' << num(row.pct_8bit_off) << ',' << row.nonfinite << '\n';
  report_detail::write_file(path, s.str());
}

void write_volume_report_json(const VolumeReport& r, const std::string& path) {
  std::ostringstream s;
  s << "{\n  \"device\": " << json_string(r.device) << ",\n  \"driver\": " << json_string(r.driver)
    << ",\n  \"version\": " << json_string(r.version) << ",\n  \"width\": " << r.width
    << ",\n  \"height\": " << r.height << ",\n  \"runs\": " << r.runs
    << ",\n  \"reference_steps\": " << r.reference_steps
    << ",\n  \"reference_seconds\": " << json_num(r.reference_seconds) << ",\n  \"rows\": [";
  for (std::size_t i = 0; i < r.rows.size(); ++i) {
    const VolumeReportRow& row = r.rows[i];
    s << (i ? ",\n" : "\n") << "    {\"scene\": " << json_string(row.scene)
      << ", \"variant\": " << json_string(row.variant) << ", \"integrator\": " << json_string(to_string(row.integrator))
      << ", \"steps\": " << row.steps << ", \"resolution\": " << json_string(resolution_name(row.divisor))
      << ", \"upsampling\": " << json_string(to_string(row.upsampling))
      << ", \"noise\": " << json_string(to_string(row.noise))
      << ", \"storage\": " << json_string(to_string(row.storage)) << ", \"time_ms\": " << json_num(row.time_ms)
      << ", \"max_abs_err\": " << json_num(row.max_abs_err) << ", \"p999_abs_err\": " << json_num(row.p999_abs_err)
      << ", \"pct_8bit_off\": " << json_num(row.pct_8bit_off) << ", \"nonfinite\": " << row.nonfinite << "}";
  }
  s << "\n  ]\n}\n";
  report_detail::write_file(path, s.str());
}

void plot_volume_report(const std::string& dir, const std::string& python) {
  report_detail::run_plot_script(dir, python, volume_report_plot_py, sizeof(volume_report_plot_py) - 1,
                                 "volume-report.png");
}

}  // namespace fogcl
