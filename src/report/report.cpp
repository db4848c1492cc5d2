// fogcl report: error against run time for every precision variant and color storage on a set of
// scenes (docs/DESIGN.md §4). Device time comes from CL profiling events of FogPass::enqueue on
// zero-copy buffers, as bench/fog_bench.cpp's BM_OpenCLDevice measures it.
#include "fogcl/report.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <sstream>

#include "fogcl/camera.h"
#include "fogcl/demo_scene.h"
#include "fogcl/error.h"
#include "fogcl/fog_pass.h"
#include "fogcl/scalar.h"
#include "pass/formulas.h"
#include "runtime/clhpp.h"
#include "report/report_common.h"
#include "report_plot_py.h"  // generated from report/plot_report.py

namespace fogcl {

using report_detail::json_num;
using report_detail::json_string;
using report_detail::median;
using report_detail::nonfinite_from_finite;
using report_detail::num;
using report_detail::write_file;

// library_version(): src/runtime/version.cpp (fogcl/version.h).

namespace {

struct Scene {
  std::string name;
  DemoFrame frame;  // rgba32f color, raw depth, camera
  FogSettings settings;
  bool eye_depth_check = false;  // the far/near scene: report the eye-depth error
};

FogSettings fog(FogMode mode, FogMetric metric, float density, bool skybox) {
  FogSettings s;
  s.mode = mode;
  s.metric = metric;
  s.density = density;
  s.fog_skybox = skybox;
  s.color = glm::vec3(0.62f, 0.68f, 0.76f);  // the demo's fog color
  return s;
}

// Every scene is the demo scene (analytic, exact depth) seen through a different camera / fog.
std::vector<Scene> make_scenes(int w, int h) {
  std::vector<Scene> out;
  const auto add = [&](const char* name, PerspectiveCamera camera, FogSettings s, bool eye_check = false) {
    out.push_back({name, render_demo_scene(w, h, camera), s, eye_check});
  };
  const PerspectiveCamera standard;  // fov 60, near 0.3, far 1000
  // The demo: exp2 distance fog as `fogcl demo`'s exp2-distance row.
  add("demo", standard, fog(FogMode::exp2, FogMetric::distance, 0.025f, false));
  PerspectiveCamera wide = standard;
  wide.fov_y_deg = 120.0f;
  add("wide-fov-120", wide, fog(FogMode::exp, FogMetric::distance, 0.035f, false));
  PerspectiveCamera huge = standard;
  huge.near_plane = 0.01f;
  huge.far_plane = 1e6f;
  add("near0.01-far1e6-conventional", huge, fog(FogMode::exp, FogMetric::depth, 0.01f, false), true);
  huge.reversed_z = true;
  add("near0.01-far1e6-reversed", huge, fog(FogMode::exp, FogMetric::depth, 0.01f, false), true);
  // density * d up to ~1e3: the fogged sky lies at d = far = 1000.
  add("dense-exp", standard, fog(FogMode::exp, FogMetric::distance, 1.0f, true));
  // density * d up to ~1e-4.
  add("thin-exp2", standard, fog(FogMode::exp2, FogMetric::distance, 1e-7f, true));
  // Height fog (docs/DESIGN.md §6), as `fogcl demo`'s rows: a valley fog with falloff, and an
  // atmospheric haze with per-channel coefficients, the sky fogged and a sun lobe.
  FogSettings valley = fog(FogMode::height, FogMetric::distance, 0.5f, false);
  valley.height.falloff = 1.6f;
  add("height-valley", standard, valley);
  FogSettings haze = fog(FogMode::height, FogMetric::distance, 0.0f, true);
  haze.color = glm::vec3(0.42f, 0.58f, 0.86f);
  haze.height.extinction = glm::vec3(0.006f, 0.011f, 0.024f);
  haze.height.falloff = 0.04f;
  SunLobe sun;
  sun.direction = glm::vec3(0.35f, 0.12f, 1.0f);
  sun.color = glm::vec3(1.1f, 0.85f, 0.55f);
  sun.exponent = 24.0f;
  haze.height.sun = sun;
  add("height-haze-sun", standard, haze);
  const DemoView view;  // the pose height fog needs (the other modes ignore it)
  for (Scene& scene : out)
    scene.frame.params.pose = CameraPose{view.eye, view.target - view.eye, glm::vec3(0.0f, 1.0f, 0.0f)};
  return out;
}

// Max relative error of eye depth (Linear01Depth * far) from the float formulas the kernel runs,
// against the true eye depth whose raw depth (rounded to float, as a depth buffer holds it) they
// read; eye depths swept geometrically over [2 near, 0.99 far] (tests/extreme_cases_test.cpp).
double eye_depth_rel_err(const CameraParams& cam) {
  const double n = cam.near_plane(), f = cam.far_plane();
  const double zx = cam.zbuffer_params.x, zy = cam.zbuffer_params.y;
  double worst = 0;
  for (double eye = 2 * n; eye < 0.99 * f; eye *= 1.37) {
    const float raw = float((f / eye - zy) / zx);
    const float l01 = formulas::fog_linear01_depth(raw, cam.zbuffer_params.x, cam.zbuffer_params.y,
                                                   int(cam.reversed_z));
    worst = std::max(worst, std::fabs(double(l01) * f - eye) / eye);
  }
  return worst;
}

// Fills the color error columns of `row` from the output of a run on `in`.
void color_errors(const ColorImage& out, const ColorImage& in, const FogResult<double>& ref, ReportRow& row) {
  const report_detail::ColorErrorStats e = report_detail::color_error_stats(out, in, ref.rgba, row.storage);
  row.max_abs_err_color = e.max_abs;
  row.p999_abs_err_color = e.p999_abs;
  row.max_ulp = e.max_ulp;
  row.pct_8bit_off = e.pct_8bit_off;
  row.nonfinite += e.nonfinite;
}

ColorImage white_like(const ColorImage& like) {
  return uniform_image(like.width(), like.height(), like.format(), glm::vec4(1.0f));
}

// The pass on the runtime's queue, zero-copy buffers over the images' memory on CPU devices
// (copied buffers elsewhere). Returns the median device time [ms] of `runs` enqueues after one
// untimed warm-up (after prepare() built the variant); `out` holds the result.
double device_run(const Runtime& rt, FogPass& pass, const ColorImage& in, const DepthImage& depth,
                  ColorImage& out, const CameraParams& params, const FogSettings& s, int runs) {
  return with_cl_errors([&] {
    const bool cpu = rt.is_cpu();
    const cl_mem_flags host = cpu ? CL_MEM_USE_HOST_PTR : CL_MEM_COPY_HOST_PTR;
    const cl::Context ctx = wrap(rt.context());
    const cl::CommandQueue queue = wrap(rt.queue());
    out = ColorImage(in.width(), in.height(), in.format());
    const cl::Buffer color_in(ctx, CL_MEM_READ_ONLY | host, in.size_bytes(), const_cast<void*>(in.data()));
    const cl::Buffer depth_buffer(ctx, CL_MEM_READ_ONLY | host, depth.size_bytes(), const_cast<float*>(depth.data()));
    const cl::Buffer color_out(ctx, CL_MEM_READ_WRITE | host, out.size_bytes(), out.data());
    FrameBuffers fb;
    fb.width = in.width();
    fb.height = in.height();
    fb.format = in.format();
    fb.color_in = color_in();
    fb.depth = depth_buffer();
    fb.color_out = color_out();
    pass.prepare(s, params, in.format());
    adopt(pass.enqueue(rt.queue(), fb, params, s)).wait();
    std::vector<double> ms;
    for (int i = 0; i < runs; ++i) {
      const cl::Event e = adopt(pass.enqueue(rt.queue(), fb, params, s));
      e.wait();
      ms.push_back(double(e.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                          e.getProfilingInfo<CL_PROFILING_COMMAND_START>()) * 1e-6);
    }
    if (cpu)  // make the host view of the USE_HOST_PTR output valid (no copy on CPU devices)
      queue.enqueueUnmapMemObject(color_out, queue.enqueueMapBuffer(color_out, CL_TRUE, CL_MAP_READ, 0, out.size_bytes()));
    else
      queue.enqueueReadBuffer(color_out, CL_TRUE, 0, out.size_bytes(), out.data());
    queue.finish();
    return median(ms);
  });
}

double scalar_run(const ColorImage& in, const DepthImage& depth, ColorImage& out, const CameraParams& params,
                  const FogSettings& s, int runs) {
  apply_fog_scalar(in, depth, out, params, s);
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) {
    const auto a = std::chrono::steady_clock::now();
    apply_fog_scalar(in, depth, out, params, s);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
  }
  return median(ms);
}

std::string variant_name(bool scalar, Precision p, ColorFormat storage) {
  return std::string(scalar ? "scalar" : to_string(p)) + "-" + to_string(storage);
}

}  // namespace

std::vector<std::string> report_scene_names() {
  return {"demo",           "wide-fov-120", "near0.01-far1e6-conventional", "near0.01-far1e6-reversed",
          "dense-exp", "thin-exp2", "height-valley", "height-haze-sun"};
}

Report run_report(const Runtime* runtime, const ReportOptions& o) {
  if (o.width < 1 || o.height < 1)
    throw Error("report frame size must be >= 1x1 (got " + std::to_string(o.width) + "x" + std::to_string(o.height) + ")");
  if (o.runs < 7) throw Error("report runs must be >= 7 for a median (got " + std::to_string(o.runs) + ")");
  Report report;
  report.version = library_version();
  report.width = o.width;
  report.height = o.height;
  report.runs = o.runs;
  report.device = runtime ? runtime->description() : "scalar";
  if (runtime) report.driver = with_cl_errors([&] { return wrap(runtime->device()).getInfo<CL_DRIVER_VERSION>(); });

  std::unique_ptr<FogPass> pass;
  if (runtime) pass = std::make_unique<FogPass>(*runtime);
  for (const Scene& scene : make_scenes(o.width, o.height)) {
    const double eye_err = scene.eye_depth_check ? eye_depth_rel_err(scene.frame.params) : -1.0;
    FogSettings probe_settings = scene.settings;
    probe_settings.color = glm::vec3(0.0f);
    // Height fog: the probe (color 1, fog color 0, no sun) gives each channel's transmittance T,
    // compared channel by channel (the reference's rgba), not against one factor per pixel.
    const bool height = scene.settings.mode == FogMode::height;
    if (height) probe_settings.height.sun.reset();
    const auto probe_error = [&](const ColorImage& probe, const FogResult<double>& ref_probe) {
      return height ? max_abs_rgb_error(probe, ref_probe) : max_abs_factor_error(probe, ref_probe);
    };
    for (ColorFormat storage : {ColorFormat::rgba32f, ColorFormat::rgba16f}) {
      const ColorImage in = convert(scene.frame.color, storage);
      const ColorImage white = white_like(in);
      const FogResult<double> ref = fog_scalar<double>(in, scene.frame.depth, scene.frame.params, scene.settings);
      const FogResult<double> ref_probe =
          fog_scalar<double>(white, scene.frame.depth, scene.frame.params, probe_settings);
      std::vector<ReportRow> rows;
      if (pass) {
        for (Precision p : {Precision::precise, Precision::fast}) {
          ReportRow row;
          row.precision = p;
          row.storage = storage;
          FogSettings s = scene.settings, ps = probe_settings;
          s.precision = ps.precision = p;
          ColorImage out, probe;
          row.time_ms = device_run(*runtime, *pass, in, scene.frame.depth, out, scene.frame.params, s, o.runs);
          device_run(*runtime, *pass, white, scene.frame.depth, probe, scene.frame.params, ps, 0);
          color_errors(out, in, ref, row);
          row.max_abs_err_factor = probe_error(probe, ref_probe);
          row.nonfinite += nonfinite_from_finite(probe, white);
          rows.push_back(row);
        }
      }
      if (o.scalar && storage == ColorFormat::rgba32f) {
        ReportRow row;
        row.scalar = true;
        row.storage = storage;
        ColorImage out, probe;
        row.time_ms = scalar_run(in, scene.frame.depth, out, scene.frame.params, scene.settings, o.runs);
        apply_fog_scalar(white, scene.frame.depth, probe, scene.frame.params, probe_settings);
        color_errors(out, in, ref, row);
        row.max_abs_err_factor = probe_error(probe, ref_probe);
        row.nonfinite += nonfinite_from_finite(probe, white);
        rows.push_back(row);
      }
      for (ReportRow& row : rows) {
        row.scene = scene.name;
        row.variant = variant_name(row.scalar, row.precision, row.storage);
        row.eye_depth_rel_err = eye_err;
        report.rows.push_back(row);
      }
    }
  }
  return report;
}

void write_report_csv(const Report& r, const std::string& path) {
  std::ostringstream s;
  s << "scene,variant,time_ms,max_abs_err_factor,max_abs_err_color,p999_abs_err_color,max_ulp,pct_8bit_off,"
       "nonfinite,eye_depth_rel_err\n";
  for (const ReportRow& row : r.rows)
    s << row.scene << ',' << row.variant << ',' << num(row.time_ms) << ',' << num(row.max_abs_err_factor) << ','
      << num(row.max_abs_err_color) << ',' << num(row.p999_abs_err_color) << ',' << num(row.max_ulp) << ','
      << num(row.pct_8bit_off) << ',' << row.nonfinite << ','
      << (row.eye_depth_rel_err < 0 ? std::string() : num(row.eye_depth_rel_err)) << '\n';
  write_file(path, s.str());
}

void write_report_json(const Report& r, const std::string& path) {
  std::ostringstream s;
  s << "{\n  \"device\": " << json_string(r.device) << ",\n  \"driver\": " << json_string(r.driver)
    << ",\n  \"version\": " << json_string(r.version) << ",\n  \"width\": " << r.width
    << ",\n  \"height\": " << r.height << ",\n  \"runs\": " << r.runs << ",\n  \"rows\": [";
  for (std::size_t i = 0; i < r.rows.size(); ++i) {
    const ReportRow& row = r.rows[i];
    s << (i ? ",\n" : "\n") << "    {\"scene\": " << json_string(row.scene) << ", \"variant\": " << json_string(row.variant)
      << ", \"time_ms\": " << json_num(row.time_ms) << ", \"max_abs_err_factor\": " << json_num(row.max_abs_err_factor)
      << ", \"max_abs_err_color\": " << json_num(row.max_abs_err_color)
      << ", \"p999_abs_err_color\": " << json_num(row.p999_abs_err_color) << ", \"max_ulp\": " << json_num(row.max_ulp)
      << ", \"pct_8bit_off\": " << json_num(row.pct_8bit_off) << ", \"nonfinite\": " << row.nonfinite
      << ", \"eye_depth_rel_err\": " << (row.eye_depth_rel_err < 0 ? "null" : json_num(row.eye_depth_rel_err)) << "}";
  }
  s << "\n  ]\n}\n";
  write_file(path, s.str());
}

void plot_report(const std::string& dir, const std::string& python) {
  report_detail::run_plot_script(dir, python, report_plot_py, sizeof(report_plot_py) - 1, "report.png");
}

}  // namespace fogcl
