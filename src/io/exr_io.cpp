// OpenEXR input and output (docs/DESIGN.md §2: the display window is the frame; pixels keep their
// display-window positions; row 0 is the top row).
//
// Reading follows OpenEXR's own examples (website/src/readGZ1.cpp): a FrameBuffer with one FLOAT
// Slice per channel whose base pointer is offset so that the file's absolute pixel coordinates
// address the buffer (Slice::Make computes that offset without pointer overflow), a fill value for
// a channel the file lacks, and readPixels over the data window. The buffer addressed is the
// display-window-sized frame itself, so pixels outside the data window keep the frame's initial
// value and no intermediate copy is needed.
//
// Every OpenEXR / Iex / std exception is turned into one fogcl::Error line that names the file.

#include "fogcl/exr_io.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <new>
#include <string>
#include <system_error>

#include <Imath/ImathBox.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfDeepScanLineInputPart.h>
#include <OpenEXR/ImfDeepScanLineOutputPart.h>
#include <OpenEXR/ImfDeepTiledInputPart.h>
#include <OpenEXR/ImfDeepTiledOutputPart.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStdIO.h>
#include <OpenEXR/ImfTiledInputPart.h>
#include <OpenEXR/ImfTiledOutputPart.h>
#include <vector>

#include "fogcl/error.h"
#include "io/atomic_file.h"
#include "io/exr_common.h"

namespace fogcl {


namespace {

using detail::box_string;
using detail::extent;
using detail::inside;
using detail::to_box;

// Checks caller-given windows against an image of width x height.
void check_windows(const std::string& path, const ExrWindows& w, int width, int height) {
  const std::int64_t dw = extent(w.display_min.x, w.display_max.x);
  const std::int64_t dh = extent(w.display_min.y, w.display_max.y);
  if (dw != width || dh != height)
    throw Error(path + ": cannot write EXR: display window " + box_string(w.display_min, w.display_max) +
                " is " + std::to_string(dw) + "x" + std::to_string(dh) + " but the image is " +
                std::to_string(width) + "x" + std::to_string(height));
  if (extent(w.data_min.x, w.data_max.x) < 1 || extent(w.data_min.y, w.data_max.y) < 1)
    throw Error(path + ": cannot write EXR: empty data window " + box_string(w.data_min, w.data_max));
  if (!inside(to_box(w.data_min, w.data_max), to_box(w.display_min, w.display_max)))
    throw Error(path + ": cannot write EXR: data window " + box_string(w.data_min, w.data_max) +
                " is not inside the display window " + box_string(w.display_min, w.display_max));
}

ExrWindows full_frame(int width, int height) {
  ExrWindows w;
  w.display_min = w.data_min = {0, 0};
  w.display_max = w.data_max = {width - 1, height - 1};
  return w;
}

// Writes FLOAT channels `names` from interleaved float pixels (`stride` floats per pixel) of a
// display-window-sized frame; only the data window's pixels go to the file.
void write_float_exr(std::ofstream& out, const std::string& temp_path, const ExrWindows& w,
                     const float* pixels, int width, const char* const* names, int channel_count) {
  const Imath::Box2i display = to_box(w.display_min, w.display_max);
  const Imath::Box2i data = to_box(w.data_min, w.data_max);
  Imf::StdOFStream stream(out, temp_path.c_str());
  Imf::Header header(display, data);
  for (int c = 0; c < channel_count; ++c) header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
  Imf::OutputFile file(stream, header);
  const std::size_t x_stride = std::size_t(channel_count) * sizeof(float);
  const std::size_t y_stride = x_stride * std::size_t(width);
  Imf::FrameBuffer frame_buffer;
  for (int c = 0; c < channel_count; ++c)
    frame_buffer.insert(names[c], Imf::Slice::Make(Imf::FLOAT, pixels + c, display, x_stride, y_stride));
  file.setFrameBuffer(frame_buffer);
  file.writePixels(data.max.y - data.min.y + 1);
  // ~OutputFile writes the line offset table but cannot report a failure; the caller checks the
  // std::ofstream after closing it.
}

}  // namespace


ColorImage read_exr_color(const std::string& path, ExrWindows* windows, ColorFormat format) {
  ExrReadRequest request;
  ExrInput in = read_exr(path, request);
  if (windows != nullptr) *windows = in.windows;
  // Half storage: Imath::half rounds to nearest even (image.h's convert()).
  return format == ColorFormat::rgba32f ? std::move(in.color) : convert(in.color, format);
}

DepthImage read_exr_depth(const std::string& path, ExrWindows* windows, const std::string& channel,
                          float outside_value) {
  ExrReadRequest request;
  request.read_color = false;
  request.depth_channel = channel;
  request.depth_single_channel_fallback = true;
  request.depth_outside = outside_value;
  ExrInput in = read_exr(path, request);
  if (windows != nullptr) *windows = in.windows;
  return std::move(in.depth);
}

void write_exr_rgba(const std::string& path, const ColorImage& image, const ExrWindows* windows) {
  if (image.empty()) throw Error(path + ": cannot write EXR: the image is empty");
  const ExrWindows w = windows != nullptr ? *windows : full_frame(image.width(), image.height());
  check_windows(path, w, image.width(), image.height());
  ColorImage converted;  // half images are widened to float (exact)
  const ColorImage& source =
      image.format() == ColorFormat::rgba32f ? image : (converted = convert(image, ColorFormat::rgba32f));
  static const char* const names[4] = {"R", "G", "B", "A"};
  detail::write_file_atomically(path, "EXR", [&](std::ofstream& out, const std::string& temp_path) {
    write_float_exr(out, temp_path, w, source.rgba32f(), source.width(), names, 4);
  });
}

void write_exr_depth(const std::string& path, const DepthImage& depth) {
  if (depth.empty()) throw Error(path + ": cannot write EXR: the depth image is empty");
  const ExrWindows w = full_frame(depth.width(), depth.height());
  static const char* const names[1] = {"Z"};
  detail::write_file_atomically(path, "EXR", [&](std::ofstream& out, const std::string& temp_path) {
    write_float_exr(out, temp_path, w, depth.data(), depth.width(), names, 1);
  });
}

namespace {

std::size_t pixel_type_size(Imf::PixelType t) { return t == Imf::HALF ? 2 : 4; }

// A channel of the color part other than the fogged layer's R, G, B, A, kept in the output.
struct KeptChannel {
  std::string name;
  Imf::Channel channel;
  std::vector<char> pixels;  // data window samples (subsampled as stored)
  std::size_t row_samples = 0;
};

}  // namespace

void write_exr_output(const std::string& path, const ColorImage& fogged, const ExrInput& source, bool rgba_only) {
  if (rgba_only || source.color_part < 0 || source.path.empty()) {
    write_exr_rgba(path, fogged, &source.windows);
    return;
  }
  if (fogged.empty()) throw Error(path + ": cannot write EXR: the image is empty");
  check_windows(path, source.windows, fogged.width(), fogged.height());
  ColorImage converted;  // half images are widened to float (exact)
  const ColorImage& image =
      fogged.format() == ColorFormat::rgba32f ? fogged : (converted = convert(fogged, ColorFormat::rgba32f));
  const std::string prefix = source.layer.empty() ? "" : source.layer + ".";
  const std::string rgba[4] = {prefix + "R", prefix + "G", prefix + "B", prefix + "A"};

  // The source is opened again: its other parts are copied as stored (no decoding), and the color
  // part's other channels are read back in their own pixel types.
  detail::with_read_errors(source.path, [&] {
    std::ifstream file_stream(source.path, std::ios::binary);
    if (!file_stream) throw Error(source.path + ": cannot read EXR: cannot open the file: " + std::strerror(errno));
    Imf::StdIFStream stream(file_stream, source.path.c_str());
    Imf::MultiPartInputFile in(stream);
    if (in.parts() != source.parts || source.color_part >= in.parts())
      throw Error(source.path + ": cannot read EXR: the file changed while fogcl was running");

    std::vector<Imf::Header> headers;
    for (int p = 0; p < in.parts(); ++p) headers.push_back(in.header(p));
    Imf::Header& h = headers[std::size_t(source.color_part)];
    const bool deep = h.hasType() && Imf::isDeepData(h.type());
    const Imath::Box2i display = h.displayWindow(), data = h.dataWindow();

    // Other flat channels of the color part, read in their own types.
    std::vector<KeptChannel> kept;
    if (!deep) {
      for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
        const std::string name = it.name();
        if (name == rgba[0] || name == rgba[1] || name == rgba[2] || name == rgba[3]) continue;
        KeptChannel k{name, it.channel(), {}, 0};
        k.row_samples = std::size_t(extent(data.min.x, data.max.x) / k.channel.xSampling);
        const std::size_t rows = std::size_t(extent(data.min.y, data.max.y) / k.channel.ySampling);
        k.pixels.resize(k.row_samples * rows * pixel_type_size(k.channel.type));
        kept.push_back(std::move(k));
      }
      if (!kept.empty()) {
        Imf::InputPart part(in, source.color_part);
        Imf::FrameBuffer fb;
        for (KeptChannel& k : kept) {
          const std::size_t size = pixel_type_size(k.channel.type);
          fb.insert(k.name, Imf::Slice::Make(k.channel.type, k.pixels.data(), data, size, size * k.row_samples,
                                             k.channel.xSampling, k.channel.ySampling));
        }
        part.setFrameBuffer(fb);
        part.readPixels(data.min.y, data.max.y);
      }
    }

    // The color part becomes a flat scanline part: the layer in FLOAT plus the kept channels.
    Imf::ChannelList channels;
    for (const KeptChannel& k : kept) channels.insert(k.name, k.channel);
    for (const std::string& c : rgba) channels.insert(c, Imf::Channel(Imf::FLOAT));
    h.channels() = channels;
    for (const char* structural : {"tiles", "chunkCount", "version", "maxSamplesPerPixel"})
      if (h.find(structural) != h.end()) h.erase(structural);
    if (h.hasType()) h.setType(Imf::SCANLINEIMAGE);
    if (h.lineOrder() == Imf::RANDOM_Y) h.lineOrder() = Imf::INCREASING_Y;

    detail::write_file_atomically(path, "EXR", [&](std::ofstream& out, const std::string& temp_path) {
      Imf::StdOFStream ostream(out, temp_path.c_str());
      Imf::MultiPartOutputFile file(ostream, headers.data(), int(headers.size()));
      for (int p = 0; p < in.parts(); ++p) {
        if (p == source.color_part) {
          Imf::OutputPart part(file, p);
          Imf::FrameBuffer fb;
          const std::size_t x_stride = 4 * sizeof(float), y_stride = x_stride * std::size_t(image.width());
          for (int c = 0; c < 4; ++c)
            fb.insert(rgba[c], Imf::Slice::Make(Imf::FLOAT, image.rgba32f() + c, display, x_stride, y_stride));
          for (KeptChannel& k : kept) {
            const std::size_t size = pixel_type_size(k.channel.type);
            fb.insert(k.name, Imf::Slice::Make(k.channel.type, k.pixels.data(), data, size, size * k.row_samples,
                                               k.channel.xSampling, k.channel.ySampling));
          }
          part.setFrameBuffer(fb);
          part.writePixels(data.max.y - data.min.y + 1);
          continue;
        }
        const Imf::Header& ph = in.header(p);
        const std::string type = ph.hasType() ? ph.type() : Imf::SCANLINEIMAGE;
        if (type == Imf::TILEDIMAGE) {
          Imf::TiledInputPart ip(in, p);
          Imf::TiledOutputPart(file, p).copyPixels(ip);
        } else if (type == Imf::DEEPSCANLINE) {
          Imf::DeepScanLineInputPart ip(in, p);
          Imf::DeepScanLineOutputPart(file, p).copyPixels(ip);
        } else if (type == Imf::DEEPTILE) {
          Imf::DeepTiledInputPart ip(in, p);
          Imf::DeepTiledOutputPart(file, p).copyPixels(ip);
        } else {
          Imf::InputPart ip(in, p);
          Imf::OutputPart(file, p).copyPixels(ip);
        }
      }
    });
    return 0;
  });
}

}  // namespace fogcl
