// fogcl.read_exr / fogcl.write_exr: renderer EXR files as `fogcl apply` reads and writes them
// (cli/memory_frame.h's read_frame_files, fogcl/exr_io.h's write_exr_output: atomic writes).
#include <algorithm>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "cli/flag_values.h"
#include "cli/memory_frame.h"
#include "fogcl/exr_io.h"
#include "io/atomic_file.h"
#include "python/arrays.h"
#include "python/bindings.h"

namespace py = pybind11;

namespace fogcl::python {

namespace {

struct OsError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// What fogcl.read_exr returns: the pixels as arrays, the camera, and the file's description that
// fogcl.write_exr(source=...) writes the fogged frame into (its other parts, channels, attributes).
struct ExrFrame {
  py::array color, depth;
  ExrInput header;  // without pixels
};

// A file that cannot be read or written (missing, not an EXR, corrupt, a folder that is not there)
// is Python's OSError, as for open(); with the library's message, which names the file.
template <class F>
void file_call(F&& f) {
  try {
    f();
  } catch (const OutOfMemory&) {
    throw;
  } catch (const Error& e) {
    throw OsError(e.what());
  }
}

py::tuple vec3(const glm::vec3& v) { return py::make_tuple(v.x, v.y, v.z); }
py::tuple window(const glm::ivec2& lo, const glm::ivec2& hi) { return py::make_tuple(lo.x, lo.y, hi.x, hi.y); }

ExrFrame read(const std::string& path, const std::string& depth_path, const std::string& layer,
              const std::string& depth_channel, const std::string& depth_kind, bool reversed_z, bool infinite_far,
              const std::string& pixel_type) {
  // The flags' own rules and messages (cli/flag_values.h).
  cli::ApplyOptions o;
  cli::require_text("--color", path, "the color EXR");
  o.layer = layer;
  cli::require_text("--depth-channel", depth_channel, "a channel name");
  cli::check_keyword("--depth-kind", depth_kind, {"raw", "eye", "distance"});
  cli::check_keyword("--pixel-type", pixel_type, {"float", "half"});
  o.depth_channel = depth_channel;
  o.depth_kind = depth_kind;
  o.reversed_z = reversed_z || infinite_far;  // an infinite far plane exists only in reversed Z
  o.pixel_type = pixel_type;
  ExrFrame f;
  DepthImage depth;
  {
    py::gil_scoped_release release;
    file_call([&] { cli::read_frame_files(o, path, depth_path, f.header, depth); });
  }
  f.color = color_array(std::move(f.header.color));
  f.depth = depth_array(std::move(depth));
  f.header.color = ColorImage();
  f.header.depth = DepthImage();
  return f;
}

void write(const std::string& path, const py::array& color, const py::object& source, const std::string& pixel_type,
           const py::object& compression, bool rgba_only) {
  cli::require_text("--out", path, "the output EXR");
  cli::check_keyword("--pixel-type", pixel_type, {"float", "half"});
  ExrWriteOptions w;
  w.half = pixel_type == "half";
  if (!compression.is_none()) {
    const std::string c = py::str(compression);
    cli::check_keyword("--compression", c, {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"});
    w.compression = parse_exr_compression(c);
  }
  ExrInput header;
  if (!source.is_none()) {
    header = source.cast<const ExrFrame&>().header;
  } else {
    // No file to take parts and attributes from: R, G, B, A over the whole frame, zip unless told.
    header.windows.display_max = header.windows.data_max =
        glm::ivec2(int(color.ndim() >= 2 ? color.shape(1) : 0) - 1, int(color.ndim() >= 2 ? color.shape(0) : 0) - 1);
  }
  const ColorImage image = color_image_of(color, "color");
  py::gil_scoped_release release;
  file_call([&] { write_exr_output(path, image, header, rgba_only, w); });
}

void write_depth(const std::string& path, const py::array& depth) {
  cli::require_text("--depth", path, "the depth EXR");
  const ConstDepthView v = depth_view(depth, "depth");
  DepthImage image(v.width(), v.height());
  for (int y = 0; y < v.height(); ++y) std::copy_n(v.row(y), v.width(), image.view().row(y));
  py::gil_scoped_release release;
  file_call([&] { write_exr_depth(path, image); });
}

}  // namespace

void bind_exr(py::module_& m) {
  py::register_local_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const OsError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    }
  });
  py::class_<ExrCamera>(m, "Camera", "The camera of an EXR's worldToNDC and worldToCamera attributes (fogcl.read_exr).")
      .def_readonly("present", &ExrCamera::present, "Both matrices there and a symmetric perspective")
      .def_readonly("fov_y_deg", &ExrCamera::fov_y_deg, "Vertical field of view [degrees]")
      .def_readonly("aspect", &ExrCamera::aspect, "tan(horizontal half fov) / tan(vertical half fov)")
      .def_readonly("note", &ExrCamera::note, "Why the camera is absent when the matrices are there")
      .def_readonly("pose_present", &ExrCamera::pose_present, "worldToCamera is rigid: the pose below is the file's")
      .def_property_readonly("eye", [](const ExrCamera& c) { return vec3(c.frame.eye); }, "Position, the file's world")
      .def_property_readonly("right", [](const ExrCamera& c) { return vec3(c.frame.right); })
      .def_property_readonly("up", [](const ExrCamera& c) { return vec3(c.frame.up); })
      .def_property_readonly("forward", [](const ExrCamera& c) { return vec3(c.frame.forward); })
      .def_readonly("pose_note", &ExrCamera::pose_note, "Why the pose is absent when the camera is present")
      .def("__repr__", [](const ExrCamera& c) {
        return c.present ? "fogcl.Camera(fov_y_deg=" + std::to_string(c.fov_y_deg) +
                               ", aspect=" + std::to_string(c.aspect) + (c.pose_present ? ", pose" : "") + ")"
                         : "fogcl.Camera(absent" + (c.note.empty() ? std::string() : ": " + c.note) + ")";
      });

  py::class_<ExrFrame>(m, "ExrFrame", "A frame read by fogcl.read_exr.")
      .def_readonly("color", &ExrFrame::color, "H x W x 4 float32 (float16 with pixel_type='half' of a half file)")
      .def_readonly("depth", &ExrFrame::depth, "H x W float32 (background outside the data window)")
      .def_property_readonly("camera", [](const ExrFrame& f) { return f.header.camera; })
      .def_property_readonly("path", [](const ExrFrame& f) { return f.header.path; })
      .def_property_readonly("layer", [](const ExrFrame& f) { return f.header.layer; })
      .def_property_readonly("deep", [](const ExrFrame& f) { return f.header.deep; })
      .def_property_readonly("parts", [](const ExrFrame& f) { return f.header.parts; })
      .def_property_readonly("compression",
                             [](const ExrFrame& f) { return std::string(exr_compression_name(f.header.compression)); })
      .def_property_readonly("display_window", [](const ExrFrame& f) {
        return window(f.header.windows.display_min, f.header.windows.display_max);
      }, "(xmin, ymin, xmax, ymax), inclusive")
      .def_property_readonly("data_window", [](const ExrFrame& f) {
        return window(f.header.windows.data_min, f.header.windows.data_max);
      }, "(xmin, ymin, xmax, ymax), inclusive");

  m.def("read_exr", &read, py::arg("path"), py::kw_only(), py::arg("depth") = "", py::arg("layer") = "",
        py::arg("depth_channel") = "Z", py::arg("depth_kind") = "raw", py::arg("reversed_z") = false,
        py::arg("infinite_far") = false, py::arg("pixel_type") = "float",
        R"(Reads a renderer's EXR as `fogcl apply --color PATH` does; returns a fogcl.ExrFrame.

depth: a separate depth file (else the color file's depth_channel); layer: NAME reads NAME.R, ...;
depth_kind raw / eye / distance and reversed_z / infinite_far set the background outside the data
window; pixel_type='half' keeps a half file's color as float16.)");
  m.def("write_exr", &write, py::arg("path"), py::arg("color"), py::kw_only(), py::arg("source") = py::none(),
        py::arg("pixel_type") = "float", py::arg("compression") = py::none(), py::arg("rgba_only") = false,
        R"(Writes a fogged frame as `fogcl apply --out PATH` does: source (a fogcl.ExrFrame) gives the file's
other parts, channels and attributes, rgba_only=True only R, G, B, A; pixel_type float or half;
compression none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa or dwab (default: the source's, else
zip). The file appears complete or not at all.)");
  m.def("write_exr_depth", &write_depth, py::arg("path"), py::arg("depth"),
        "Writes H x W float32 depth as the one float channel Z of an EXR (a --depth file of `fogcl apply`, "
        "fogcl.read_exr(color_path, depth=path)); complete or not at all.");
}

}  // namespace fogcl::python
