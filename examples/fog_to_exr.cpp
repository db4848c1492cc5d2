// fogcl::io (pkg-config fogcl-io, find_package(fogcl COMPONENTS io)): a frame fogged on the
// OpenCL device, written as an OpenEXR file with its depth and as a PNG preview, then read back.
// A VOLUMES.json document is parsed by the same library (the CLI's --volumes).
// Usage: fog_to_exr OUT_DIR. Exit status 0 when the file holds the fogged frame bit for bit.
#include <fogcl/io.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

int main(int argc, char** argv) try {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fog_to_exr OUT_DIR\n");
    return 2;
  }
  const std::string dir = argv[1];
  const int width = 64, height = 48;
  fogcl::PerspectiveCamera lens;  // Unity's defaults, with the frame's aspect
  lens.aspect = float(width) / float(height);
  const fogcl::CameraParams camera = fogcl::make_camera_params(lens);
  fogcl::ColorImage color(width, height);
  fogcl::DepthImage depth(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      color.set_pixel(x, y, {float(x) / width, 0.5f, float(y) / height, 1.0f});
      // Eye depth from 2 to 400 units along the frame's diagonal, as raw conventional Z.
      const double eye = 2.0 + 398.0 * (x + y) / double(width + height - 2);
      depth.at(x, y) = float(fogcl::raw_from_eye_depth(eye, camera));
    }
  fogcl::ColorImage fogged(width, height);
  const fogcl::Runtime runtime;  // FOGCL_DEVICE's choice, or PoCL's CPU device
  fogcl::FogPass pass(runtime);
  pass.apply(color, depth, fogged, camera, fogcl::FogSettings{});

  fogcl::write_exr_rgba(dir + "/fogged.exr", fogged);
  fogcl::write_exr_depth(dir + "/depth.exr", depth);
  fogcl::write_png_preview(dir + "/fogged.png", fogged);
  const fogcl::ColorImage back = fogcl::read_exr_color(dir + "/fogged.exr");
  const fogcl::DepthImage depth_back = fogcl::read_exr_depth(dir + "/depth.exr");
  const bool same = std::memcmp(back.data(), fogged.data(), fogged.size_bytes()) == 0 &&
                    std::memcmp(depth_back.data(), depth.data(), depth.size_bytes()) == 0;
  const bool changed = std::memcmp(fogged.data(), color.data(), color.size_bytes()) != 0;
  std::printf("fogcl %s: wrote %s/fogged.exr, depth.exr, fogged.png; read back %s; fog %s the frame\n",
              fogcl::library_version(), dir.c_str(), same ? "bit for bit" : "DIFFERENT",
              changed ? "changed" : "did NOT change");
  const std::vector<fogcl::FogVolume> volumes =
      fogcl::parse_volumes_json(R"({"volumes": [{"center": [0, 1, 4], "radius": 2}]})", "inline.json");
  std::printf("VOLUMES.json: %zu volume(s), radius %g\n", volumes.size(), double(volumes.at(0).radius));
  return same && changed && volumes.size() == 1 && volumes[0].radius == 2.0f ? 0 : 1;
} catch (const fogcl::Error& e) {
  std::fprintf(stderr, "fog_to_exr: %s\n", e.what());
  return 1;
}
