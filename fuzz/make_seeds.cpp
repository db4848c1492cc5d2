// Writes the fuzz targets' seed corpora: for the EXR target, small files of every kind fogcl reads
// (tests/exr_fixtures.h), so the fuzzer starts from valid multi-part, tiled, layered, windowed,
// deep, half and float files; for the VOLUMES.json target, the demo's volume files (what `fogcl
// demo` writes: volumes.json, volumes-physical.json) and a few of the file's other forms.
// Usage: fogcl_make_seeds EXR_DIR [JSON_DIR]
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "exr_fixtures.h"
#include "fogcl/demo_scene.h"
#include "fogcl/volumes_json.h"

namespace {

void write_json_seeds(const std::string& dir) {
  std::filesystem::create_directories(dir);
  const auto put = [&](const std::string& name, const std::string& text) { std::ofstream(dir + "/" + name) << text; };
  put("volumes.json", fogcl::volumes_to_json(fogcl::demo_fog_volumes(fogcl::VolumeIntegrator::stylized)));
  put("volumes-physical.json", fogcl::volumes_to_json(fogcl::demo_fog_volumes(fogcl::VolumeIntegrator::physical)));
  put("minimal.json", R"({"volumes": [{"center": [0, 1, 0], "radius": 2}]})");
  put("homogeneous.json", R"({"volumes": [{"center": [0, 1, 0], "radius": 2, "medium": "homogeneous", "albedo": [0.5, 0.5, 0.5]}]})");
  put("empty.json", R"({"volumes": []})");
  put("lights.json", R"({"volumes": [{"center": [0, 1, 0], "radius": 2}], "lights": [{"type": "point", "position": [0, 1, 0], "intensity": 5, "range": 4}, {"type": "spot", "position": [1, 3, 0], "direction": [0, -1, 0], "inner_angle": 10, "outer_angle": 25}]})");
  std::printf("wrote 6 seed files to %s\n", dir.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  using namespace fogcl::fixtures;
  if (argc != 2 && argc != 3) {
    std::fprintf(stderr, "usage: %s EXR_DIR [JSON_DIR]\n", argv[0]);
    return 2;
  }
  if (argc == 3) write_json_seeds(argv[2]);
  const std::string dir = argv[1];
  std::filesystem::create_directories(dir);
  const auto box = [](int x0, int y0, int x1, int y1) { return Imath::Box2i(Imath::V2i(x0, y0), Imath::V2i(x1, y1)); };
  const RenderFrame f = make_render_frame(box(0, 0, 7, 5), box(0, 0, 7, 5), 1);
  const RenderFrame w = make_render_frame(box(-2, -1, 9, 6), box(1, 0, 6, 4), 2);
  const auto rgbz = [](const RenderFrame& fr, const std::string& prefix, Imf::PixelType t) {
    std::vector<Channel> c = color_channels(fr, prefix, t);
    c.push_back(depth_channel(fr, "Z"));
    return c;
  };
  write_flat(dir + "/half_rgbaz.exr", f, {{"", rgbz(f, "", Imf::HALF), false, false}});
  write_flat(dir + "/float_tiled_camera.exr", f, {{"", rgbz(f, "", Imf::FLOAT), true, true}});
  write_flat(dir + "/multipart.exr", f,
             {{"rgba", color_channels(f, "", Imf::HALF), true, false}, {"depth", {depth_channel(f, "Z")}, false, true}});
  write_flat(dir + "/layered.exr", f, {{"", rgbz(f, "beauty.", Imf::FLOAT), false, false}});
  write_flat(dir + "/window.exr", w, {{"", rgbz(w, "", Imf::HALF), false, false}});
  write_flat(dir + "/depth_only.exr", f, {{"", {depth_channel(f, "depth")}, false, false}});
  std::vector<float> flat, nearest;
  write_deep(dir + "/deep.exr", f, &flat, &nearest);
  std::printf("wrote 7 seed files to %s\n", dir.c_str());
  return 0;
}
