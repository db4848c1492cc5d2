// fogcl.FogPass and fogcl.VolumePass: the integration API (fogcl/fog_pass.h, fogcl/volume_pass.h)
// on PyOpenCL's context, queues, buffers and events, with the keyword options of fogcl.apply.
// docs/python.md, "On your PyOpenCL context".
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli/memory_frame.h"
#include "cli/volumes_cli.h"
#include "fogcl/fog_pass.h"
#include "fogcl/volume_pass.h"
#include "python/bindings.h"
#include "python/options.h"
#include "python/pyopencl_objects.h"

namespace py = pybind11;

namespace fogcl::python {

namespace {

ColorFormat parse_format(const std::string& format) {
  if (format == "rgba32f") return ColorFormat::rgba32f;
  if (format == "rgba16f") return ColorFormat::rgba16f;
  throw py::value_error("format must be 'rgba32f' (float32 RGBA) or 'rgba16f' (float16 RGBA) (got '" + format + "')");
}

void check_size(int width, int height, const std::string& who) {
  if (width < 1 || height < 1)
    throw py::value_error(who + ": width and height must be at least 1 (got " + std::to_string(width) + "x" +
                          std::to_string(height) + ")");
}

// The context, device and default queue of a pass, retained while it lives.
struct PassHandles {
  cl::Context context;
  cl::Device device;
  std::optional<cl::CommandQueue> queue;  // the constructor's queue=: enqueue's default

  PassHandles(const py::handle& context_obj, const py::handle& device_obj, const py::handle& queue_obj,
              const char* who) {
    const std::string w = who;
    context = cl::Context(context_handle(context_obj, w + ": context"), true);
    const std::vector<cl::Device> devices = with_cl_errors([&] { return context.getInfo<CL_CONTEXT_DEVICES>(); });
    if (!device_obj.is_none()) {
      device = cl::Device(device_handle(device_obj, w + ": device"), true);
      bool found = false;
      for (const cl::Device& d : devices) found = found || d() == device();
      if (!found)
        throw py::value_error(w + ": device " + with_cl_errors([&] { return device.getInfo<CL_DEVICE_NAME>(); }) +
                              " is not one of the context's devices");
    }
    if (!queue_obj.is_none()) {
      const cl::CommandQueue q(queue_handle(queue_obj, w + ": queue"), true);
      if (device_obj.is_none()) device = with_cl_errors([&] { return q.getInfo<CL_QUEUE_DEVICE>(); });
      queue = checked_queue(queue_obj, context, device, w + ": queue");
    }
    if (device() == nullptr) {
      if (devices.size() != 1)
        throw py::value_error(w + ": the context has " + std::to_string(devices.size()) +
                              " devices: say which with device= or queue=");
      device = devices.front();
    }
  }

  // enqueue's queue: the call's, else the constructor's.
  cl::CommandQueue queue_for(const py::handle& queue_obj, const std::string& who) const {
    if (!queue_obj.is_none()) return checked_queue(queue_obj, context, device, who + ": queue");
    if (queue) return *queue;
    throw py::value_error(who + ": no queue: give queue= here or to the constructor");
  }

  py::object context_object() const {
    return py::module_::import("pyopencl").attr("Context").attr("from_int_ptr")(
        reinterpret_cast<std::intptr_t>(context()), py::arg("retain") = true);
  }
  py::object device_object() const {
    return py::module_::import("pyopencl").attr("Device").attr("from_int_ptr")(
        reinterpret_cast<std::intptr_t>(device()), py::arg("retain") = true);
  }
};

// The frame's buffers, each checked against the pass (context, exact size) under its keyword.
FrameBuffers frame_buffers(const PassHandles& h, const py::handle& color, const py::handle& depth,
                           const py::handle& out, int width, int height, ColorFormat format, const std::string& who) {
  check_size(width, height, who);
  const std::string frame = "a " + std::to_string(width) + "x" + std::to_string(height) + " " + to_string(format) + " frame";
  FrameBuffers fb;
  fb.width = width;
  fb.height = height;
  fb.format = format;
  fb.color_in = checked_buffer(color, h.context, color_buffer_bytes(width, height, format), frame, who + ": color");
  fb.depth = checked_buffer(depth, h.context, depth_buffer_bytes(width, height),
                            "a " + std::to_string(width) + "x" + std::to_string(height) + " float32 depth", who + ": depth");
  fb.color_out = out.is_none() ? fb.color_in
                               : checked_buffer(out, h.context, color_buffer_bytes(width, height, format), frame,
                                                who + ": out");
  return fb;
}

// Runs a library call without the GIL (a build takes seconds; other Python threads go on). Its
// errors reach Python through the module's translator (module.cpp).
template <class Fn>
auto library_call(Fn&& fn) -> decltype(fn()) {
  py::gil_scoped_release unlocked;
  return fn();
}

// Runs fn, the options' rules as Python sees them: a library rule (fogcl::Error, or
// python/options.h's ValueError) becomes ValueError naming `who` once; Python's own errors, memory
// and OpenCL errors pass as they are.
template <class Fn>
auto option_errors(const std::string& who, Fn&& fn) -> decltype(fn()) {
  try {
    return fn();
  } catch (const py::error_already_set&) {
    throw;  // Python's own (a volumes= document json cannot write, an interrupt)
  } catch (const OutOfMemory&) {
    throw;
  } catch (const ClError&) {
    throw;
  } catch (const std::exception& e) {
    const std::string what = e.what();
    throw py::value_error(what.rfind(who, 0) == 0 ? what : who + ": " + what);  // named once
  }
}

// What a frame's keyword options make for the passes: fogcl.apply's words (python/options.h),
// resolved as `fogcl apply` resolves them for a width x height frame with no file behind it.
struct FrameSetup {
  CameraParams camera;
  FogSettings settings;                        // the deferred fog (FogPass)
  cli::VolumeCliOptions volume_options;        // for a volume stage (VolumePass)
  std::unique_ptr<cli::VolumeStage> volumes;   // with_volumes: volumes= or height_volumetric=True
  std::optional<CameraPose> pose;              // the volumes' pose when it comes with the frame
  std::string pose_from;
  std::string key;                             // python/options.h's options_key, camera= aside
};

// fogcl.apply's options that choose a device or measure one: a pass runs on its context's.
constexpr const char* kNotPassOptions[] = {"device", "host_transfer", "max_memory", "max_error"};

// with_volumes: the volume stage too (VolumePass); a FogPass leaves the volume options alone.
FrameSetup frame_setup(const py::kwargs& kwargs, int width, int height, const std::string& who, bool with_volumes) {
  for (const char* key : kNotPassOptions)
    if (kwargs.contains(key))
      throw py::value_error(who + ": " + key + "= is fogcl.apply's (it opens or measures a device); a pass runs on "
                            "its context's device with the options' precision and volume settings");
  // camera=: a file's camera (fogcl.read_exr(...).camera), as fogcl.apply takes it; the rest are flags.
  py::dict flags(kwargs);
  std::optional<ExrCamera> file_camera;
  if (flags.contains("camera")) {
    const py::object given = flags.attr("pop")("camera");
    if (!given.is_none()) {
      if (!py::isinstance<ExrCamera>(given))
        throw py::type_error(who + ": camera must be a fogcl.Camera (fogcl.read_exr(...).camera) or None");
      file_camera = given.cast<ExrCamera>();
    }
  }
  return option_errors(who, [&] {
    const cli::ApplyOptions o = apply_options(flags);
    // The frame has no file behind it: its camera is the options' and camera='s.
    const cli::FrameCamera camera =
        cli::memory_frame_camera(o, width, height, file_camera ? &*file_camera : nullptr, who);
    FrameSetup s;
    s.camera = camera.params;
    s.settings = o.settings;
    s.volume_options = o.volumes;
    s.pose = camera.pose;
    s.pose_from = camera.pose_from;
    s.key = std::to_string(width) + "x" + std::to_string(height) + '\0' + options_key(flags, o);
    if (with_volumes) {
      s.volumes = cli::VolumeStage::create(o.volumes, nullptr);
      if (s.volumes) s.volumes->set_frame_pose(camera.pose, camera.pose_from);
    }
    return s;
  });
}

// An enqueue's arguments, checked before the pass runs.
struct FrameCall {
  PassHandles handles;  // retained: release() may come while the call runs
  FrameBuffers buffers;
  cl::CommandQueue queue;
  std::vector<cl_event> waits;  // borrowed from wait_for's events
  FrameSetup setup;
};

// A pass and its handles; release() (or the end of a with block) lets them go before the Python
// object does. One call at a time: the C++ passes are not thread-safe, and the GIL is released
// while they run.
template <class Pass>
class PassObject {
 public:
  PassObject(const py::object& context, const py::object& device, const py::object& queue, const char* who)
      : who_(who) {
    handles_.emplace(context, device, queue, who);
    pass_ = library_call([&] { return std::make_unique<Pass>(handles_->context(), handles_->device()); });
  }

  // Runs fn(pass, handles) under the pass's lock, without the GIL (library_call); ValueError once
  // released.
  template <class Fn>
  auto locked(const std::string& call, Fn&& fn) -> decltype(fn(std::declval<Pass&>(), std::declval<PassHandles&>())) {
    return library_call([&] {
      std::lock_guard<std::mutex> lock(m_);
      if (!pass_) throw py::value_error(who_ + "." + call + ": the pass was released (release() or the end of its with block)");
      return fn(*pass_, *handles_);
    });
  }

  // A copy of the handles (retained) for checks made before the call: release() may come meanwhile.
  // Nothing under the lock needs the GIL, so taking it with the GIL held cannot deadlock.
  PassHandles handles(const std::string& call) {
    std::lock_guard<std::mutex> lock(m_);
    if (!handles_) throw py::value_error(who_ + "." + call + ": the pass was released (release() or the end of its with block)");
    return *handles_;
  }

  void release() {
    library_call([&] {
      std::lock_guard<std::mutex> lock(m_);
      pass_.reset();
      handles_.reset();
    });
  }
  bool released() {
    std::lock_guard<std::mutex> lock(m_);
    return !pass_;
  }
  const std::string& who() const { return who_; }

  // prepare's options for a width x height frame.
  FrameSetup prepare_setup(int width, int height, const py::kwargs& options, bool with_volumes) {
    check_size(width, height, who_ + ".prepare");
    return frame_setup(options, width, height, who_ + ".prepare", with_volumes);
  }

  // enqueue's arguments, each checked under its own name.
  FrameCall frame_call(const py::object& color, const py::object& depth, const py::object& out, int width, int height,
                       const std::string& format, const py::object& queue, const py::object& wait_for,
                       const py::kwargs& options, bool with_volumes) {
    const std::string who = who_ + ".enqueue";
    PassHandles h = handles("enqueue");
    const FrameBuffers fb = frame_buffers(h, color, depth, out, width, height, parse_format(format), who);
    cl::CommandQueue q = h.queue_for(queue, who);
    std::vector<cl_event> waits = wait_list(wait_for, h.context, who);
    FrameSetup setup = frame_setup(options, width, height, who, with_volumes);
    return {std::move(h), fb, std::move(q), std::move(waits), std::move(setup)};
  }

 private:
  std::string who_;
  std::mutex m_;
  std::optional<PassHandles> handles_;
  std::unique_ptr<Pass> pass_;
};

class PyFogPass : public PassObject<FogPass> {
 public:
  PyFogPass(const py::object& context, const py::object& device, const py::object& queue)
      : PassObject(context, device, queue, "fogcl.FogPass") {}

  void prepare(int width, int height, const std::string& format, const py::kwargs& options) {
    const ColorFormat storage = parse_format(format);
    const FrameSetup setup = prepare_setup(width, height, options, false);
    locked("prepare", [&](FogPass& pass, PassHandles&) { pass.prepare(setup.settings, setup.camera, storage); });
  }

  py::object enqueue(const py::object& color, const py::object& depth, const py::object& out, int width, int height,
                     const std::string& format, const py::object& queue, const py::object& wait_for,
                     const py::kwargs& options) {
    const FrameCall c = frame_call(color, depth, out, width, height, format, queue, wait_for, options, false);
    return adopt_event(locked("enqueue", [&](FogPass& pass, PassHandles&) {
      return pass.enqueue(c.queue(), c.buffers, c.setup.camera, c.setup.settings, c.waits);
    }));
  }
};

class PyVolumePass : public PassObject<VolumePass> {
 public:
  PyVolumePass(const py::object& context, const py::object& device, const py::object& queue)
      : PassObject(context, device, queue, "fogcl.VolumePass") {}

  void prepare(int width, int height, const std::string& format, const py::kwargs& options) {
    const ColorFormat storage = parse_format(format);
    const FrameSetup setup = prepare_setup(width, height, options, true);
    const cli::VolumeStage& stage = volumes_of(setup, "prepare");
    const VolumeScene scene = stage.scene_for(-1);
    locked("prepare", [&](VolumePass& pass, PassHandles&) {
      pass.prepare(setup.camera, scene, stage.settings(), storage, stage.shadow() ? &stage.shadow()->params : nullptr);
    });
  }

  py::object enqueue(const py::object& color, const py::object& depth, const py::object& out, int width, int height,
                     const std::string& format, const py::object& queue, const py::object& wait_for,
                     const py::kwargs& options) {
    // The frame's camera and buffers every call; the volume stage (VOLUMES.json, the shadow map
    // and its device copy) only when the options or the files they name have changed.
    FrameCall c = frame_call(color, depth, out, width, height, format, queue, wait_for, options, false);
    std::shared_ptr<const Stage> stage;
    {
      std::lock_guard<std::mutex> lock(stage_m_);
      if (stage_ && stage_->key == c.setup.key) stage = stage_;
    }
    if (!stage) stage = make_stage(c.setup, c.handles);
    VolumeScene scene;
    {
      std::lock_guard<std::mutex> lock(stage_m_);  // the pose is the stage's state: one frame at a time
      stage->volumes->set_frame_pose(c.setup.pose, c.setup.pose_from);
      scene = stage->volumes->scene_for(-1);
    }
    return adopt_event(locked("enqueue", [&](VolumePass& pass, PassHandles&) {
      return pass.enqueue(c.queue(), c.buffers, c.setup.camera, scene, stage->volumes->settings(),
                          stage->shadow ? &*stage->shadow : nullptr, c.waits);
    }));
  }

 private:
  // The volume stage of one set of options, and the light's depth map on the device (read-only:
  // frames in flight share it; each enqueue keeps the stage alive until it returns, and OpenCL
  // keeps the buffer until the march has read it).
  struct Stage {
    std::string key;
    std::unique_ptr<cli::VolumeStage> volumes;
    std::optional<cl::Buffer> map;
    std::optional<ShadowMapBuffer> shadow;
  };

  std::shared_ptr<const Stage> make_stage(FrameSetup& setup, const PassHandles& handles) {
    const std::string who = this->who() + ".enqueue";
    setup.volumes = option_errors(who, [&] { return cli::VolumeStage::create(setup.volume_options, nullptr); });
    volumes_of(setup, "enqueue");
    auto stage = std::make_shared<Stage>();
    stage->key = setup.key;
    stage->volumes = std::move(setup.volumes);
    if (const ShadowMap* s = stage->volumes->shadow()) {
      stage->map = library_call([&] {
        return with_cl_errors([&] {
          return cl::Buffer(handles.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                            depth_buffer_bytes(s->depth.width(), s->depth.height()),
                            const_cast<float*>(s->depth.data()));
        });
      });
      stage->shadow = ShadowMapBuffer{(*stage->map)(), s->depth.width(), s->depth.height(), s->params};
    }
    std::lock_guard<std::mutex> lock(stage_m_);
    stage_ = stage;
    return stage;
  }

  std::mutex stage_m_;
  std::shared_ptr<Stage> stage_;  // the last options' (one entry: a renderer's frames share theirs)

  const cli::VolumeStage& volumes_of(const FrameSetup& setup, const char* call) const {
    if (!setup.volumes)
      throw py::value_error(who() + "." + call + ": no volumes: give volumes= (a VOLUMES.json path or its document) "
                            "or height_volumetric=True, as to fogcl.apply");
    return *setup.volumes;
  }
};

template <class Pass>
void bind_pass(py::module_& m, const char* name, const char* doc) {
  py::class_<Pass>(m, name, doc)
      .def(py::init<const py::object&, const py::object&, const py::object&>(), py::arg("context"),
           py::arg("device") = py::none(), py::arg("queue") = py::none())
      .def("prepare", &Pass::prepare, py::arg("width"), py::arg("height"), py::arg("format") = "rgba32f",
           "Builds the programs the frames of these options need (blocks; the GIL is released).")
      .def("enqueue", &Pass::enqueue, py::arg("color"), py::arg("depth"), py::arg("out") = py::none(),
           py::kw_only(), py::arg("width"), py::arg("height"), py::arg("format") = "rgba32f",
           py::arg("queue") = py::none(), py::arg("wait_for") = py::none(),
           "Enqueues the pass on pyopencl Buffers after wait_for; returns its pyopencl.Event. Never blocks, "
           "never builds.")
      .def("release", &Pass::release, "Lets the pass and its OpenCL objects go now.")
      .def_property_readonly("released", &Pass::released)
      .def_property_readonly("context", [](Pass& p) { return p.handles("context").context_object(); })
      .def_property_readonly("device", [](Pass& p) { return p.handles("device").device_object(); })
      .def("__enter__", [](py::object self) { return self; })
      .def("__exit__", [](Pass& p, const py::args&) { p.release(); });
}

}  // namespace

void bind_integration(py::module_& m) {
  bind_pass<PyFogPass>(m, "FogPass",
                       "The deferred fog pass on a PyOpenCL context (fogcl/fog_pass.h's integration API).");
  bind_pass<PyVolumePass>(m, "VolumePass",
                          "The fog volumes pass on a PyOpenCL context (fogcl/volume_pass.h's integration API).");
}

}  // namespace fogcl::python
