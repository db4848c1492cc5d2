// Umbrella header of the fogcl library.
#pragma once

#include "fogcl/camera.h"
#include "fogcl/error.h"
#include "fogcl/opencl_types.h"
#include "fogcl/fog_pass.h"
#include "fogcl/fog_settings.h"
#include "fogcl/image.h"
#include "fogcl/noise.h"
#include "fogcl/runtime.h"
#include "fogcl/scalar.h"
#include "fogcl/variant.h"
#include "fogcl/version.h"
