// PyOpenCL's objects as OpenCL handles, and OpenCL events back as PyOpenCL events: the ownership
// rules of the two libraries meet here only. pyopencl is imported when first needed, so `import
// fogcl` works without it.
#pragma once

#include <pybind11/pybind11.h>

#include <cstddef>
#include <string>
#include <vector>

#include "runtime/clhpp.h"

namespace fogcl::python {

// The handle inside a pyopencl object of class `cls` (e.g. "Buffer"), borrowed from it: as long as
// the Python object lives, so does the handle (unless its owner called release(), which PyOpenCL
// does not let anyone see). `what` names the argument in messages: TypeError for another type.
cl_context context_handle(const pybind11::handle& obj, const std::string& what);
cl_device_id device_handle(const pybind11::handle& obj, const std::string& what);
cl_command_queue queue_handle(const pybind11::handle& obj, const std::string& what);
cl_mem buffer_handle(const pybind11::handle& obj, const std::string& what);

// The events of a wait_for= argument (None: none), each checked to be of `context`: ValueError
// naming the item otherwise. Borrowed from the list's objects.
std::vector<cl_event> wait_list(const pybind11::handle& wait_for, const cl::Context& context,
                                const std::string& who);

// A pyopencl.Event that takes over `owned` (a reference the caller holds, released by PyOpenCL
// when the Python object goes). If the wrapping fails the reference is released here.
pybind11::object adopt_event(cl_event owned);

// A command queue retained for as long as the owner keeps it; checked to be of `context` and
// `device` (ValueError naming `what` otherwise).
cl::CommandQueue checked_queue(const pybind11::handle& obj, const cl::Context& context, const cl::Device& device,
                               const std::string& what);

// A device buffer `what` checked against the pass: of `context`, exactly `bytes` long. `rule`
// says what the size is for (e.g. "a 64x32 rgba32f frame"). ValueError otherwise.
cl_mem checked_buffer(const pybind11::handle& obj, const cl::Context& context, std::size_t bytes,
                      const std::string& rule, const std::string& what);

}  // namespace fogcl::python
