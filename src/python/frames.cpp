// fogcl.apply: a numpy frame through `fogcl apply`'s frame code (cli/memory_frame.h), on the
// arrays' own memory (docs/python.md, "Zero copy and alignment").
#include <atomic>
#include <map>
#include <mutex>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "cli/memory_frame.h"
#include "python/arrays.h"
#include "python/bindings.h"
#include "python/options.h"

namespace py = pybind11;

namespace fogcl::python {

namespace {

// `fogcl apply` flags about files, sequences and the command's own output: fogcl.apply takes arrays
// and returns one (fogcl.read_exr and fogcl.write_exr take the files' choices).
const std::map<std::string, std::string> kFileOptions{
    {"color", "the color is the first argument"},
    {"depth", "the depth is the second argument"},
    {"out", "out= takes an array to fog into (write a file with fogcl.write_exr)"},
    {"png", "write a file with fogcl.write_exr"},
    {"layer", "fogcl.read_exr(path, layer=...) reads a layer"},
    {"depth_channel", "fogcl.read_exr(path, depth_channel=...) reads it"},
    {"rgba_only", "fogcl.write_exr(path, color, rgba_only=True) writes only R, G, B, A"},
    {"pixel_type", "the array's dtype (float32 or float16) is the storage; fogcl.write_exr(pixel_type=...) writes it"},
    {"compression", "fogcl.write_exr(path, color, compression=...) compresses"},
    {"frames", "fog each frame of a sequence with its own call (examples/python/fog_sequence.py)"},
    {"keep_going", "fog each frame of a sequence with its own call (examples/python/fog_sequence.py)"},
    {"threads", "each call fogs on the threads the device uses; call from several Python threads to overlap frames"},
    {"verbose", "fogcl.apply prints nothing"},
};

// Devices opened for one set of options, kept for the next call with the same options (opening
// PoCL and building programs costs more than a frame); one caller at a time each.
class FoggerPool {
 public:
  std::unique_ptr<cli::MemoryFogger> take(const std::string& key) {
    std::lock_guard<std::mutex> lock(m_);
    auto it = idle_.find(key);
    if (it == idle_.end() || it->second.empty()) return nullptr;
    std::unique_ptr<cli::MemoryFogger> f = std::move(it->second.back());
    it->second.pop_back();
    return f;
  }
  void give(const std::string& key, std::unique_ptr<cli::MemoryFogger> f) {
    std::lock_guard<std::mutex> lock(m_);
    if (idle_.size() >= kMaxKeys && idle_.count(key) == 0) idle_.clear();  // option sets come and go
    auto& list = idle_[key];
    if (list.size() < kMaxPerKey) list.push_back(std::move(f));
  }
  void clear() {
    std::lock_guard<std::mutex> lock(m_);
    idle_.clear();
  }

 private:
  static constexpr std::size_t kMaxKeys = 8, kMaxPerKey = 4;
  std::mutex m_;
  std::map<std::string, std::vector<std::unique_ptr<cli::MemoryFogger>>> idle_;
};

FoggerPool& pool() {
  static FoggerPool* p = new FoggerPool();  // never destroyed: the devices outlive the interpreter's teardown
  return *p;
}

std::atomic<int> g_in_flight{0};  // frames being fogged now, without the GIL

PassStats pass_stats(cli::Backend& backend) { return backend.pass() != nullptr ? backend.pass()->stats() : PassStats(); }

// What one call did: the pass's counters since `before`.
py::dict stats_dict(cli::Backend& backend, cli::VolumeStage* volumes, const PassStats& before) {
  py::dict d;
  d["device"] = backend.name();
  d["volumes"] = volumes != nullptr;
  if (FogPass* pass = backend.pass()) {
    const PassStats& s = pass->stats();
    d["host_transfer"] = std::string(to_string(pass->host_transfer()));
    d["kernel_dispatches"] = s.kernel_dispatches - before.kernel_dispatches;
    d["zero_copy_frames"] = s.zero_copy_frames - before.zero_copy_frames;
    d["copied_frames"] = s.copied_frames - before.copied_frames;
  }
  return d;
}

py::array apply(const py::array& color, const py::array& depth, const py::object& out, const py::object& camera,
                const py::object& stats, const py::kwargs& options) {
  for (const auto& item : options) {
    const std::string key = py::str(item.first);
    if (auto it = kFileOptions.find(key); it != kFileOptions.end())
      throw py::value_error("fogcl.apply takes no " + key + "= (fogcl apply's --" + cli_flag_name(key) +
                            "): " + it->second);
  }
  const cli::ApplyOptions o = apply_options(options);
  const ConstColorView in = color_view(color, "color");
  const ConstDepthView d = depth_view(depth, "depth");
  py::array result = out.is_none() ? new_color_like(color) : py::reinterpret_borrow<py::array>(out);
  if (!out.is_none() && !py::isinstance<py::array>(out))
    throw py::value_error("out= must be a numpy array of the color's shape and dtype (got " +
                          py::repr(out).cast<std::string>() + ")");
  const ColorView o_view = writable_color_view(result, "out");
  std::optional<ExrCamera> file_camera;
  if (!camera.is_none()) file_camera = camera.cast<ExrCamera>();

  cli::MemoryFrame frame;
  frame.color = in;
  frame.depth = d;
  frame.out = o_view;
  frame.camera = file_camera ? &*file_camera : nullptr;
  frame.name = "fogcl.apply";
  // The options as typed, the document given and the files named pick the devices to reuse.
  const std::string key = options_key(options, o);

  std::unique_ptr<cli::MemoryFogger> fogger;
  PassStats before;
  {
    py::gil_scoped_release release;
    struct InFlight {
      InFlight() { ++g_in_flight; }
      ~InFlight() { --g_in_flight; }
    } in_flight;
    fogger = pool().take(key);
    if (!fogger) {
      // One opening at a time: the OpenCL ICD loader's and PoCL's first platform query are not
      // safe from several threads at once (the others find no device).
      static std::mutex opening;
      std::lock_guard<std::mutex> lock(opening);
      fogger = std::make_unique<cli::MemoryFogger>(o);
    }
    before = pass_stats(fogger->backend());
    fogger->fog(frame);
  }
  if (!stats.is_none()) {
    py::dict s = stats_dict(fogger->backend(), fogger->volumes(), before);
    for (auto item : s) stats[item.first] = item.second;
  }
  pool().give(key, std::move(fogger));
  return result;
}

}  // namespace

void bind_frames(py::module_& m) {
  m.def("apply", &apply, py::arg("color"), py::arg("depth"), py::kw_only(), py::arg("out") = py::none(),
        py::arg("camera") = py::none(), py::arg("stats") = py::none(),
        R"(Fogs a frame as `fogcl apply` with the same options does (bit for bit).

color: H x W x 4 float32 or float16 (linear RGBA, row 0 the top); depth: H x W float32 of the kind
depth_kind= says (raw by default). out: an array to fog into (color itself: in place); by default a
new one. camera: the file's camera (fogcl.read_exr(...).camera) for the flags' defaults. stats: a dict
to fill with what the device did (zero-copy or copied frames). Every other keyword is a flag of
`fogcl apply`, dashes as underscores: near=0.3, far=1000, mode="exp2", fog_color=(0.6, 0.7, 0.8),
distance=True, ... (docs/python.md). Returns the fogged color (out when given).)");
  m.def(
      "empty",
      [](const std::vector<py::ssize_t>& shape, const py::object& dtype) {
        return aligned_empty(shape, py::dtype::from_args(dtype));
      },
      py::arg("shape"), py::arg("dtype") = py::dtype::of<float>(),
      "A new array on page-aligned memory, which a CPU device reads and writes in place (numpy.empty's "
      "memory is only 16- or 64-byte aligned: fogcl.apply then copies it once).");
  m.def("_frames_in_flight", [] { return g_in_flight.load(); },
        "Frames being fogged now by fogcl.apply, which releases the GIL meanwhile (for the tests).");
  m.def("_release_devices", [] { pool().clear(); }, "Closes the devices kept for the next fogcl.apply calls.");
}

}  // namespace fogcl::python
