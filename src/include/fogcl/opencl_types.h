// The OpenCL handle types of fogcl's API (cl_context, cl_device_id, cl_command_queue, cl_mem,
// cl_event, cl_program). fogcl's public headers include <CL/cl.h> through this file only, and
// change no OpenCL or CLHPP macro (docs/DESIGN.md §1.1): the integrator's own settings apply.
// Set CL_TARGET_OPENCL_VERSION (and any CL_HPP_* macro) before the first OpenCL or fogcl header,
// as before <CL/cl.h> itself. The handle types are the same for every target version, so any
// choice links with fogcl.
#pragma once

// Unset, it gets the Khronos headers' own default, 300, here without the #pragma message they
// print in every file that includes fogcl (and fails no -Werror build over a choice fogcl does
// not need).
#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 300
#endif
#include <CL/cl.h>
