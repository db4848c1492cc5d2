// fogcl.report's measurement (fogcl/report.h, fogcl/volume_report.h): the rows of `fogcl report`
// and `fogcl report --volumetric`, which the package turns into numpy structured arrays
// (fogcl/__init__.py).
#include <memory>

#include <pybind11/stl.h>

#include "cli/cli.h"
#include "cli/flag_values.h"
#include "fogcl/report.h"
#include "fogcl/volume_report.h"
#include "python/bindings.h"

namespace py = pybind11;

namespace fogcl::python {

namespace {

py::tuple report_rows(int width, int height, int runs, const std::string& device) {
  // `fogcl report`'s rules, in its words.
  for (const auto& [flag, value] : {std::pair<const char*, int>{"--width", width}, {"--height", height}})
    if (value < 1 || value > 16384)
      throw Error(std::string(flag) + " must be in [1, 16384] (got " + std::to_string(value) + ")");
  if (runs < 7 || runs > 1000)
    throw Error("--runs must be >= 7 for the deferred report (got " + std::to_string(runs) + ")");
  if (!device.empty()) cli::check_device("--device", device);
  Report report;
  {
    py::gil_scoped_release release;
    std::unique_ptr<Runtime> runtime;
    const std::string resolved = resolve_device_choice(device);
    try {
      if (resolved != "scalar") runtime = std::make_unique<Runtime>(resolved);
    } catch (const Error& e) {
      throw Error(cli::device_choice_source(device) + e.what());
    }
    ReportOptions options;
    options.width = width;
    options.height = height;
    options.runs = runs;
    report = run_report(runtime.get(), options);
  }
  py::list rows;
  for (const ReportRow& r : report.rows)
    rows.append(py::make_tuple(r.scene, r.variant, r.scalar, std::string(to_string(r.precision)),
                               std::string(to_string(r.storage)), r.time_ms, r.max_abs_err_factor,
                               r.max_abs_err_color, r.p999_abs_err_color, r.max_ulp, r.pct_8bit_off, r.nonfinite,
                               r.eye_depth_rel_err));
  return py::make_tuple(report.device, report.driver, rows);
}

// --volumetric: the lists come as the flags' text ("16,32"), checked by the flags' own parsers.
py::tuple volume_report_rows(int width, int height, int runs, const std::string& device, const py::object& steps,
                             const py::object& scenes, const py::object& integrators) {
  for (const auto& [flag, value] : {std::pair<const char*, int>{"--width", width}, {"--height", height}})
    if (value < 1 || value > 16384)
      throw Error(std::string(flag) + " must be in [1, 16384] (got " + std::to_string(value) + ")");
  if (runs < 3 || runs > 1000)
    throw Error("--runs must be >= 3 with --volumetric (got " + std::to_string(runs) + ")");
  if (!device.empty()) cli::check_device("--device", device);
  cli::ReportCliOptions o;
  o.width = width;
  o.height = height;
  o.runs = runs;
  o.device = device;
  if (!steps.is_none()) o.steps = cli::parse_step_list("--steps", steps.cast<std::string>());
  if (!scenes.is_none())
    o.scenes = cli::keyword_list_value("--scenes", scenes.cast<std::string>(), volume_report_scene_names());
  if (!integrators.is_none())
    o.integrators = cli::keyword_list_value("--integrators", integrators.cast<std::string>(), {"stylized", "physical"});
  const VolumeReportOptions options = cli::volume_report_options(o);
  VolumeReport report;
  {
    py::gil_scoped_release release;
    const std::string resolved = resolve_device_choice(device);
    if (resolved == "scalar")
      throw Error("fogcl.report(volumetric=True) measures OpenCL kernel variants; the scalar path (device='scalar') "
                  "has none");
    std::unique_ptr<Runtime> runtime;
    try {
      runtime = std::make_unique<Runtime>(resolved);
    } catch (const Error& e) {
      throw Error(cli::device_choice_source(device) + e.what());
    }
    report = run_volume_report(*runtime, options);
  }
  py::list rows;
  for (const VolumeReportRow& r : report.rows)
    rows.append(py::make_tuple(r.scene, r.variant, std::string(to_string(r.integrator)), r.steps,
                               std::string(resolution_name(r.divisor)), std::string(to_string(r.upsampling)),
                               std::string(to_string(r.noise)), std::string(to_string(r.storage)), r.time_ms,
                               r.max_abs_err, r.p999_abs_err, r.pct_8bit_off, r.nonfinite));
  py::dict meta;
  meta["device"] = report.device;
  meta["driver"] = report.driver;
  meta["version"] = report.version;
  meta["width"] = report.width;
  meta["height"] = report.height;
  meta["runs"] = report.runs;
  meta["reference_steps"] = report.reference_steps;
  meta["reference_seconds"] = report.reference_seconds;
  return py::make_tuple(meta, rows);
}

}  // namespace

void bind_report(py::module_& m) {
  m.def("_report_rows", &report_rows, py::arg("width"), py::arg("height"), py::arg("runs"), py::arg("device"),
        "fogcl report's rows as tuples, with the device and driver: (device, driver, rows).");
  m.def("_volume_report_rows", &volume_report_rows, py::arg("width"), py::arg("height"), py::arg("runs"),
        py::arg("device"), py::arg("steps"), py::arg("scenes"), py::arg("integrators"),
        "fogcl report --volumetric's rows as tuples, with what volume-report.json says of the run: (meta, rows).");
}

}  // namespace fogcl::python
