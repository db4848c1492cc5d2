// The OpenCL handle types of fogcl's API (cl_context, cl_device_id, cl_command_queue, cl_mem,
// cl_event, cl_program). fogcl's public headers include <CL/cl.h> through this file only, and
// define no OpenCL or CLHPP macro (docs/DESIGN.md §1.1): the integrator's own settings apply.
// Set CL_TARGET_OPENCL_VERSION (and any CL_HPP_* macro) before the first OpenCL or fogcl header,
// as before <CL/cl.h> itself; when it is not set, the Khronos headers default to 300 and say so.
// The handle types are the same for every target version, so any choice links with fogcl.
#pragma once

#include <CL/cl.h>
