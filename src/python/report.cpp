// fogcl.report's measurement (fogcl/report.h): the rows of `fogcl report`, which the package turns
// into a numpy structured array (fogcl/__init__.py).
#include <memory>

#include <pybind11/stl.h>

#include "cli/cli.h"
#include "cli/flag_values.h"
#include "fogcl/report.h"
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

}  // namespace

void bind_report(py::module_& m) {
  m.def("_report_rows", &report_rows, py::arg("width"), py::arg("height"), py::arg("runs"), py::arg("device"),
        "fogcl report's rows as tuples, with the device and driver: (device, driver, rows).");
}

}  // namespace fogcl::python
