// find_package(fogcl COMPONENTS io): fogcl::io links, with OpenEXR and libpng found by the package
// (and VOLUMES.json read without nlohmann-json: the library's private build dependency).
#include <fogcl/depth_kinds.h>
#include <fogcl/exr_io.h>
#include <fogcl/volumes_json.h>

#include <cstdio>

int main() {
  std::printf("fogcl::io component: depth kind '%s'\n", fogcl::to_string(fogcl::parse_depth_kind("eye")));
  const auto volumes = fogcl::parse_volumes_json(R"({"volumes": [{"center": [0, 1, 4], "radius": 2}]})", "check.json");
  std::printf("fogcl::io component: %zu volume(s) from VOLUMES.json, radius %g\n", volumes.size(), volumes[0].radius);
  return fogcl::parse_depth_kind("eye") == fogcl::DepthKind::eye && volumes.size() == 1 ? 0 : 1;
}
