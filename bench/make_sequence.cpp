// Writes a frame sequence of the demo scene for the sequence benchmark (bench/sequence_bench.py):
// the camera dollies forward a little each frame, so no two frames compress alike. Per frame
//   DIR/color.NNNN.exr  R, G, B, A in half or float, the chosen compression
//   DIR/depth.NNNN.exr  Z (raw device depth) in float, the same compression
// The camera goes into the color file's worldToCamera / worldToNDC too, but the bench passes --fov.
//   fogcl_make_sequence DIR WIDTH HEIGHT FRAMES half|float zip|piz|...
#include <cstdio>
#include <cstdlib>
#include <string>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfThreading.h>

#include "fogcl/demo_scene.h"

#include "fogcl/error.h"
#include "fogcl/exr_io.h"

namespace {

// fogcl's own list of OpenEXR compression names (the CLI's --compression).
bool compression_of(const std::string& name, Imf::Compression* c) {
  try {
    *c = Imf::Compression(fogcl::parse_exr_compression(name));
    return true;
  } catch (const fogcl::Error&) {
    return false;
  }
}

std::string frame_name(const std::string& dir, const char* stem, int frame) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%s.%04d.exr", stem, frame);
  return dir + "/" + buf;
}

}  // namespace

int main(int argc, char** argv) {
  Imf::Compression compression{};
  if (argc != 7 || std::atoi(argv[2]) < 1 || std::atoi(argv[3]) < 1 || std::atoi(argv[4]) < 1 ||
      (std::string(argv[5]) != "half" && std::string(argv[5]) != "float") || !compression_of(argv[6], &compression)) {
    std::fprintf(stderr, "usage: %s DIR WIDTH HEIGHT FRAMES half|float none|rle|zips|zip|piz|pxr24|b44|dwaa|dwab\n",
                 argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  const int width = std::atoi(argv[2]), height = std::atoi(argv[3]), frames = std::atoi(argv[4]);
  const bool half = std::string(argv[5]) == "half";
  Imf::setGlobalThreadCount(4);
  try {
    for (int frame = 1; frame <= frames; ++frame) {
      fogcl::DemoView view;
      view.eye.z += 0.05f * float(frame);  // a slow dolly: every frame differs
      fogcl::PerspectiveCamera camera;
      camera.fov_y_deg = 60.0f;
      camera.near_plane = 0.3f;
      camera.far_plane = 1000.0f;
      const fogcl::DemoFrame f = fogcl::render_demo_scene(width, height, camera, view);
      const Imath::Box2i window(Imath::V2i(0, 0), Imath::V2i(width - 1, height - 1));

      Imf::Header color_header(window, window);
      color_header.compression() = compression;
      const Imf::PixelType type = half ? Imf::HALF : Imf::FLOAT;
      const char* const rgba[4] = {"R", "G", "B", "A"};
      for (const char* c : rgba) color_header.channels().insert(c, Imf::Channel(type));
      Imf::OutputFile color(frame_name(dir, "color", frame).c_str(), color_header);
      Imf::FrameBuffer fb;
      // An OpenEXR writer does not convert: half channels from an rgba16f copy (round to nearest even).
      const fogcl::ColorImage color_half = half ? fogcl::convert(f.color, fogcl::ColorFormat::rgba16f) : fogcl::ColorImage();
      const char* pixels = static_cast<const char*>(half ? color_half.data() : f.color.data());
      const std::size_t size = half ? 2 : 4;
      for (int c = 0; c < 4; ++c)
        fb.insert(rgba[c], Imf::Slice(type, const_cast<char*>(pixels + c * size), 4 * size, 4 * size * std::size_t(width)));
      color.setFrameBuffer(fb);
      color.writePixels(height);

      Imf::Header depth_header(window, window);
      depth_header.compression() = compression;
      depth_header.channels().insert("Z", Imf::Channel(Imf::FLOAT));
      Imf::OutputFile depth(frame_name(dir, "depth", frame).c_str(), depth_header);
      Imf::FrameBuffer dfb;
      dfb.insert("Z", Imf::Slice(Imf::FLOAT, (char*)f.depth.data(), 4, 4 * std::size_t(width)));
      depth.setFrameBuffer(dfb);
      depth.writePixels(height);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fogcl_make_sequence: %s\n", e.what());
    return 1;
  }
  return 0;
}
