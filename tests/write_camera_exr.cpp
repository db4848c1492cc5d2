// Writes a renderer-like EXR with OpenEXR's worldToCamera / worldToNDC attributes of the camera that
// "rendered" it (tests/exr_fixtures.h), in a world moved by a rigid motion drawn from SEED: R, G, B,
// A and eye depth Z, float, one part. The Python
// module's tests take it through fogcl.read_exr and `fogcl apply`; they have no EXR writer of
// their own for those attributes. Prints the worldToCamera matrix (16 numbers, row-major, row
// vectors as Imath) so that a test can check the pose read back.
// Usage: fogcl_write_camera_exr OUT.exr WIDTH HEIGHT FOV_Y_DEG SEED
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "exr_fixtures.h"

namespace {

bool parse(const char* text, double lo, double hi, double* value) {
  char* end = nullptr;
  *value = std::strtod(text, &end);
  return end != text && *end == '\0' && *value >= lo && *value <= hi;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace fogcl::fixtures;
  double w = 0, h = 0, fov = 0, seed = 0;
  if (argc != 6 || !parse(argv[2], 1, 4096, &w) || !parse(argv[3], 1, 4096, &h) || !parse(argv[4], 1, 179, &fov) ||
      !parse(argv[5], 0, 4294967295.0, &seed) || w != int(w) || h != int(h) || seed != double(unsigned(seed))) {
    std::fprintf(stderr,
                 "usage: fogcl_write_camera_exr OUT.exr WIDTH HEIGHT FOV_Y_DEG SEED (sizes in [1, 4096], fov in "
                 "[1, 179] degrees, seed an unsigned integer)\n");
    return 2;
  }
  const Imath::Box2i window(Imath::V2i(0, 0), Imath::V2i(int(w) - 1, int(h) - 1));
  RenderFrame frame = make_render_frame(window, window, unsigned(seed));
  frame.camera.fov_y_deg = float(fov);
  std::vector<Channel> channels = color_channels(frame, "", Imf::FLOAT);
  channels.push_back(depth_channel(frame, "Z"));
  Part part{"", channels, true, false, Imath::M44d()};
  // A rotation about a random axis, then a move: the frame's values do not depend on it.
  std::mt19937 rng(static_cast<unsigned>(seed));
  const auto unit = [&rng] { return double(rng()) / double(std::mt19937::max()); };
  Imath::V3d axis(unit() - 0.5, unit() - 0.5, unit() - 0.5);
  axis = axis.length() > 1e-3 ? axis.normalized() : Imath::V3d(0, 1, 0);
  part.world.setAxisAngle(axis, 2 * M_PI * unit());
  for (int j = 0; j < 3; ++j) part.world[3][j] = 20 * (unit() - 0.5);
  try {
    write_flat(argv[1], frame, {part});
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fogcl_write_camera_exr: %s\n", e.what());
    return 1;
  }
  float w2c[4][4], w2n[4][4];
  camera_matrices(frame.camera, w2c, w2n);
  const Imath::M44f written(part.world * Imath::M44d(Imath::M44f(w2c)));
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) std::printf("%.9g%c", double(written[i][j]), i == 3 && j == 3 ? '\n' : ' ');
  return 0;
}
