// The fogcl Python module's parts (docs/python.md): each file registers its functions on the
// module from one of these, called by the module's init (module.cpp).
#pragma once

#include <pybind11/pybind11.h>

namespace fogcl::python {

void bind_frames(pybind11::module_& m);       // apply (frames.cpp)
void bind_exr(pybind11::module_& m);          // read_exr, write_exr (exr.cpp)
void bind_report(pybind11::module_& m);       // report (report.cpp)
void bind_integration(pybind11::module_& m);  // passes on the caller's OpenCL objects (integration.cpp)

}  // namespace fogcl::python
