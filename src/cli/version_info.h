// `fogcl --version` and `fogcl version`.
#pragma once

namespace fogcl::cli {

// Prints fogcl's version (fogcl/version.h), the git commit the build was configured from
// ("unknown" outside a git checkout, e.g. from a tarball) and the OpenCL platforms and devices
// the ICD loader offers ("none" without one). Returns 0.
int print_version();

}  // namespace fogcl::cli
