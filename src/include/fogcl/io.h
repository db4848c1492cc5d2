// Umbrella header of fogcl::io (pkg-config fogcl-io, find_package(fogcl COMPONENTS io)): OpenEXR
// in and out, PNG previews, VOLUMES.json, on top of the whole library (fogcl/fogcl.h).
#pragma once

#include "fogcl/exr_io.h"
#include "fogcl/fogcl.h"
#include "fogcl/volumes_json.h"
