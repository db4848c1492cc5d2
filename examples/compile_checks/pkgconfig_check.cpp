// Built by the install test with nothing but `pkg-config --cflags --libs fogcl`: the installed
// headers and library are usable without CMake.
#include <fogcl/fogcl.h>
#include <fogcl/version.h>

#include <cstdio>
#include <cstring>

int main() {
  fogcl::PerspectiveCamera camera;
  fogcl::validate(fogcl::make_camera_params(camera));
  std::printf("pkg-config build: fogcl %s\n", fogcl::library_version());
  return std::strcmp(fogcl::library_version(), FOGCL_VERSION_STRING) == 0 ? 0 : 1;
}
