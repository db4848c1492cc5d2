// find_package(fogcl COMPONENTS io): fogcl::io links, with OpenEXR and libpng found by the package.
#include <fogcl/depth_kinds.h>
#include <fogcl/exr_io.h>

#include <cstdio>

int main() {
  std::printf("fogcl::io component: depth kind '%s'\n", fogcl::to_string(fogcl::parse_depth_kind("eye")));
  return fogcl::parse_depth_kind("eye") == fogcl::DepthKind::eye ? 0 : 1;
}
