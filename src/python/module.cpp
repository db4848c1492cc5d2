// The compiled part of the fogcl Python package (fogcl._fogcl; docs/python.md).
#include <new>

#include <pybind11/pybind11.h>

#include "cli/usage.h"
#include "fogcl/error.h"
#include "fogcl/version.h"
#include "python/bindings.h"

namespace py = pybind11;

PYBIND11_MODULE(_fogcl, m) {
  m.doc() = "fogcl: deferred and volumetric fog on OpenCL devices and in C++ (docs/python.md)";
  // The library's errors as Python's: a rule broken by the caller's input is a ValueError, a
  // device's failure a RuntimeError, memory that could not be had a MemoryError (with the
  // library's message, which names what was being allocated).
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const fogcl::OutOfMemory& e) {
      PyErr_SetString(PyExc_MemoryError, e.what());
    } catch (const fogcl::ClError& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    } catch (const fogcl::Error& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const std::bad_alloc&) {
      PyErr_SetString(PyExc_MemoryError, "out of memory");
    }
  });
  m.def("version", [] { return std::string(fogcl::library_version()); },
        "The version of the fogcl library the module is built with, e.g. '0.1.0'.");
  fogcl::python::bind_frames(m);
  fogcl::python::bind_exr(m);
  fogcl::python::bind_report(m);
  fogcl::python::bind_integration(m);
}
