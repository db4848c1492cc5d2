// Umbrella header of the fogcl library: the whole public API of fogcl::fogcl (pkg-config fogcl).
// The image files' API is fogcl::io's, in fogcl/io.h.
#pragma once

#include "fogcl/camera.h"
#include "fogcl/depth_kinds.h"
#include "fogcl/error.h"
#include "fogcl/external_memory.h"
#include "fogcl/fog_pass.h"
#include "fogcl/fog_settings.h"
#include "fogcl/image.h"
#include "fogcl/noise.h"
#include "fogcl/opencl_types.h"
#include "fogcl/renderer_camera.h"
#include "fogcl/runtime.h"
#include "fogcl/scalar.h"
#include "fogcl/variant.h"
#include "fogcl/version.h"
#include "fogcl/volume_pass.h"
#include "fogcl/volume_scalar.h"
#include "fogcl/volumes.h"
