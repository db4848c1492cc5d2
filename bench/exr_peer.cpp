// The ceiling of `fogcl apply` on a sequence: OpenEXR alone doing the same file work with the same
// thread count and no fog. Per frame, in order: read R, G, B, A of the color file and Z of the
// depth file (the color in the output's pixel type: OpenEXR's reader converts, its writer does not;
// the depth as float), then write R, G, B, A with the output pixel type and compression. Thread count as fogcl
// --threads N sets it: Imf::setGlobalThreadCount(N). Prints the wall time of the frame loop.
//   fogcl_exr_peer COLOR.%04d.exr DEPTH.%04d.exr OUT.%04d.exr FIRST LAST THREADS half|float COMPRESSION|input
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfThreading.h>

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

std::string frame_name(const char* pattern, int frame) {
  char buf[4096];
  std::snprintf(buf, sizeof buf, pattern, frame);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  Imf::Compression compression{};
  const bool input_compression = argc == 9 && std::string(argv[8]) == "input";
  if (argc != 9 || std::atoi(argv[6]) < 1 ||
      (std::string(argv[7]) != "half" && std::string(argv[7]) != "float") ||
      (!input_compression && !compression_of(argv[8], &compression))) {
    std::fprintf(stderr, "usage: %s COLOR.%%04d.exr DEPTH.%%04d.exr OUT.%%04d.exr FIRST LAST THREADS half|float "
                 "none|rle|zips|zip|piz|pxr24|b44|dwaa|dwab|input\n", argv[0]);
    return 2;
  }
  const int first = std::atoi(argv[4]), last = std::atoi(argv[5]);
  const bool half_out = std::string(argv[7]) == "half";
  Imf::setGlobalThreadCount(std::atoi(argv[6]));
  const char* const rgba[4] = {"R", "G", "B", "A"};
  const auto start = std::chrono::steady_clock::now();
  try {
    std::vector<char> color, depth;
    for (int frame = first; frame <= last; ++frame) {
      Imf::InputFile in(frame_name(argv[1], frame).c_str());
      const Imath::Box2i dw = in.header().dataWindow();
      const std::size_t w = std::size_t(dw.max.x - dw.min.x + 1), h = std::size_t(dw.max.y - dw.min.y + 1);
      const Imf::PixelType type = half_out ? Imf::HALF : Imf::FLOAT;  // a writer wants the file's type
      const std::size_t size = type == Imf::HALF ? 2 : 4;
      color.resize(4 * size * w * h);
      Imf::FrameBuffer fb;
      for (int c = 0; c < 4; ++c)
        fb.insert(rgba[c], Imf::Slice::Make(type, color.data() + c * size, dw, 4 * size, 4 * size * w, 1, 1,
                                            c == 3 ? 1.0 : 0.0));
      in.setFrameBuffer(fb);
      in.readPixels(dw.min.y, dw.max.y);

      Imf::InputFile din(frame_name(argv[2], frame).c_str());
      depth.resize(4 * w * h);
      Imf::FrameBuffer dfb;
      dfb.insert("Z", Imf::Slice::Make(Imf::FLOAT, depth.data(), dw, 4, 4 * w));
      din.setFrameBuffer(dfb);
      din.readPixels(dw.min.y, dw.max.y);

      Imf::Header header(in.header().displayWindow(), dw);
      header.compression() = input_compression ? in.header().compression() : compression;
      for (const char* c : rgba) header.channels().insert(c, Imf::Channel(half_out ? Imf::HALF : Imf::FLOAT));
      Imf::OutputFile out(frame_name(argv[3], frame).c_str(), header);
      out.setFrameBuffer(fb);  // the color slices, as read
      out.writePixels(int(h));
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fogcl_exr_peer: %s\n", e.what());
    return 1;
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const int frames = last - first + 1;
  std::printf("frames %d seconds %.3f frames/s %.3f\n", frames, s, frames / s);
  return 0;
}
