#include "python/pyopencl_objects.h"

#include <cstdint>

namespace py = pybind11;

namespace fogcl::python {

namespace {

py::module_ pyopencl() {
  try {
    return py::module_::import("pyopencl");
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_ImportError)) throw;
    throw py::import_error("fogcl.FogPass and fogcl.VolumePass work on PyOpenCL's objects: install pyopencl "
                           "(Debian: python3-pyopencl) (" + std::string(e.what()) + ")");
  }
}

std::string type_name(const py::handle& obj) { return py::str(py::type::handle_of(obj).attr("__qualname__")); }

template <class Handle>
Handle handle_of(const py::handle& obj, const char* cls, const std::string& what) {
  if (!py::isinstance(obj, pyopencl().attr(cls)))
    throw py::type_error(what + " must be a pyopencl." + cls + " (got " +
                         (obj.is_none() ? std::string("None") : type_name(obj)) + ")");
  return reinterpret_cast<Handle>(obj.attr("int_ptr").cast<std::intptr_t>());
}

}  // namespace

cl_context context_handle(const py::handle& obj, const std::string& what) {
  return handle_of<cl_context>(obj, "Context", what);
}
cl_device_id device_handle(const py::handle& obj, const std::string& what) {
  return handle_of<cl_device_id>(obj, "Device", what);
}
cl_command_queue queue_handle(const py::handle& obj, const std::string& what) {
  return handle_of<cl_command_queue>(obj, "CommandQueue", what);
}
cl_mem buffer_handle(const py::handle& obj, const std::string& what) {
  return handle_of<cl_mem>(obj, "Buffer", what);
}

std::vector<cl_event> wait_list(const py::handle& wait_for, const cl::Context& context, const std::string& who) {
  std::vector<cl_event> events;
  if (wait_for.is_none()) return events;
  if (!py::isinstance<py::sequence>(wait_for) || py::isinstance<py::str>(wait_for))
    throw py::type_error(who + ": wait_for must be a list of pyopencl.Event (got " + type_name(wait_for) + ")");
  std::size_t i = 0;
  for (const py::handle item : wait_for) {
    const std::string what = who + ": wait_for[" + std::to_string(i++) + "]";
    const auto event = handle_of<cl_event>(item, "Event", what);
    cl_context of = nullptr;
    if (const cl_int err = clGetEventInfo(event, CL_EVENT_CONTEXT, sizeof of, &of, nullptr); err != CL_SUCCESS)
      throw ClError("clGetEventInfo(" + what + ")", err);
    if (of != context())
      throw py::value_error(what + ": the event belongs to another OpenCL context than the pass (an event "
                            "can only be waited for in its own context)");
    events.push_back(event);
  }
  return events;
}

py::object adopt_event(cl_event owned) {
  try {
    return pyopencl().attr("Event").attr("from_int_ptr")(reinterpret_cast<std::intptr_t>(owned),
                                                          py::arg("retain") = false);
  } catch (...) {
    clReleaseEvent(owned);
    throw;
  }
}

cl::CommandQueue checked_queue(const py::handle& obj, const cl::Context& context, const cl::Device& device,
                               const std::string& what) {
  const cl::CommandQueue queue(queue_handle(obj, what), true);
  return with_cl_errors([&] {
    if (queue.getInfo<CL_QUEUE_CONTEXT>()() != context())
      throw py::value_error(what + ": the queue belongs to another OpenCL context than the pass (a pass "
                            "enqueues on queues of the context it was made for)");
    if (queue.getInfo<CL_QUEUE_DEVICE>()() != device())
      throw py::value_error(what + ": the queue is on " + queue.getInfo<CL_QUEUE_DEVICE>().getInfo<CL_DEVICE_NAME>() +
                            ", the pass on " + device.getInfo<CL_DEVICE_NAME>() +
                            " (a pass enqueues on queues of its device)");
    return queue;
  });
}

cl_mem checked_buffer(const py::handle& obj, const cl::Context& context, std::size_t bytes, const std::string& rule,
                      const std::string& what) {
  const cl_mem mem = buffer_handle(obj, what);
  cl_context of = nullptr;
  std::size_t size = 0;
  if (const cl_int err = clGetMemObjectInfo(mem, CL_MEM_CONTEXT, sizeof of, &of, nullptr); err != CL_SUCCESS)
    throw ClError("clGetMemObjectInfo(" + what + ")", err);
  if (of != context())
    throw py::value_error(what + ": the buffer belongs to another OpenCL context than the pass");
  if (const cl_int err = clGetMemObjectInfo(mem, CL_MEM_SIZE, sizeof size, &size, nullptr); err != CL_SUCCESS)
    throw ClError("clGetMemObjectInfo(" + what + ")", err);
  if (size != bytes)
    throw py::value_error(what + ": the buffer holds " + std::to_string(size) + " bytes but " + rule + " needs exactly " +
                          std::to_string(bytes) +
                          " (frames are packed and buffers exact-size; use buffer.get_sub_region(origin, size) "
                          "for part of a larger one)");
  return mem;
}

}  // namespace fogcl::python
