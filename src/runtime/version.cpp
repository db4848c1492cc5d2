#include "fogcl/version.h"

namespace fogcl {
const char* library_version() { return FOGCL_VERSION_STRING; }
}  // namespace fogcl
