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

Imf::PixelType pixel_type_of(ColorFormat f) { return f == ColorFormat::rgba16f ? Imf::HALF : Imf::FLOAT; }

// `image` in half or float storage: itself, or converted into `converted` (half -> float is exact,
// float -> half rounds to nearest even). OpenEXR writes a channel only from a slice of its own type.
const ColorImage& in_format(const ColorImage& image, bool half, ColorImage& converted) {
  const ColorFormat want = half ? ColorFormat::rgba16f : ColorFormat::rgba32f;
  return image.format() == want ? image : (converted = convert(image, want));
}

// Writes channels `names` from interleaved pixels (`channel_count` values of `memory_type` per
// pixel) of a display-window-sized frame, as `file_type` (OpenEXR wants the same type: a writer
// does not convert); only the data window's pixels go to the file.
void write_exr_channels(std::ostream& out, const std::string& name, const ExrWindows& w, const char* pixels,
                        Imf::PixelType memory_type, int width, const char* const* names, int channel_count,
                        Imf::PixelType file_type, Imf::Compression compression) {
  const Imath::Box2i display = to_box(w.display_min, w.display_max);
  const Imath::Box2i data = to_box(w.data_min, w.data_max);
  detail::OStreamAdapter stream(out, name);
  Imf::Header header(display, data);
  header.compression() = compression;
  for (int c = 0; c < channel_count; ++c) header.channels().insert(names[c], Imf::Channel(file_type));
  Imf::OutputFile file(stream, header);
  const std::size_t value_size = memory_type == Imf::HALF ? 2 : 4;
  const std::size_t x_stride = std::size_t(channel_count) * value_size;
  const std::size_t y_stride = x_stride * std::size_t(width);
  Imf::FrameBuffer frame_buffer;
  for (int c = 0; c < channel_count; ++c)
    frame_buffer.insert(names[c],
                        Imf::Slice::Make(memory_type, pixels + std::size_t(c) * value_size, display, x_stride, y_stride));
  file.setFrameBuffer(frame_buffer);
  file.writePixels(data.max.y - data.min.y + 1);
  // ~OutputFile writes the line offset table but cannot report a failure; write_file_atomically
  // checks the stream after the body returns.
}

void write_rgba(const std::string& path, const ColorImage& image, const ExrWindows* windows, bool half,
                Imf::Compression compression) {
  if (image.empty()) throw Error(path + ": cannot write EXR: the image is empty");
  const ExrWindows w = windows != nullptr ? *windows : full_frame(image.width(), image.height());
  check_windows(path, w, image.width(), image.height());
  ColorImage converted;
  const ColorImage& source = in_format(image, half, converted);
  static const char* const names[4] = {"R", "G", "B", "A"};
  const char* pixels = static_cast<const char*>(source.data());
  const Imf::PixelType type = pixel_type_of(source.format());
  detail::write_file_atomically(path, "EXR", [&](std::ostream& out, const std::string& name) {
    write_exr_channels(out, name, w, pixels, type, source.width(), names, 4, type, compression);
  });
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
  write_rgba(path, image, windows, false, Imf::ZIP_COMPRESSION);  // half images are widened (exact)
}

void write_exr_depth(const std::string& path, const DepthImage& depth) {
  if (depth.empty()) throw Error(path + ": cannot write EXR: the depth image is empty");
  const ExrWindows w = full_frame(depth.width(), depth.height());
  static const char* const names[1] = {"Z"};
  detail::write_file_atomically(path, "EXR", [&](std::ostream& out, const std::string& name) {
    write_exr_channels(out, name, w, reinterpret_cast<const char*>(depth.data()), Imf::FLOAT, depth.width(), names, 1,
                       Imf::FLOAT, Imf::ZIP_COMPRESSION);
  });
}

namespace {

std::size_t pixel_type_size(Imf::PixelType t) { return t == Imf::HALF ? 2 : 4; }

const struct {
  const char* name;
  Imf::Compression compression;
} kCompressions[] = {{"none", Imf::NO_COMPRESSION}, {"rle", Imf::RLE_COMPRESSION},   {"zips", Imf::ZIPS_COMPRESSION},
                     {"zip", Imf::ZIP_COMPRESSION},  {"piz", Imf::PIZ_COMPRESSION},   {"pxr24", Imf::PXR24_COMPRESSION},
                     {"b44", Imf::B44_COMPRESSION},  {"b44a", Imf::B44A_COMPRESSION}, {"dwaa", Imf::DWAA_COMPRESSION},
                     {"dwab", Imf::DWAB_COMPRESSION}};

// A channel of the color part other than the fogged layer's R, G, B, A, kept in the output.
struct KeptChannel {
  std::string name;
  Imf::Channel channel;
  std::vector<char> pixels;  // data window samples (subsampled as stored)
  std::size_t row_samples = 0;
};

}  // namespace

int parse_exr_compression(const std::string& name) {
  for (const auto& c : kCompressions)
    if (name == c.name) return int(c.compression);
  std::string names;
  for (const auto& c : kCompressions) names += std::string(names.empty() ? "" : ", ") + c.name;
  throw Error("--compression must be one of " + names + " (got '" + name + "')");
}

const char* exr_compression_name(int compression) {
  for (const auto& c : kCompressions)
    if (int(c.compression) == compression) return c.name;
  return "unknown";
}

void write_exr_output(const std::string& path, const ColorImage& fogged, const ExrInput& source, bool rgba_only,
                      const ExrWriteOptions& options) {
  if (rgba_only || source.color_part < 0 || source.path.empty()) {
    const int compression = options.compression >= 0 ? options.compression
                            : source.compression >= 0 ? source.compression
                                                      : int(Imf::ZIP_COMPRESSION);
    write_rgba(path, fogged, &source.windows, options.half, Imf::Compression(compression));
    return;
  }
  if (fogged.empty()) throw Error(path + ": cannot write EXR: the image is empty");
  check_windows(path, source.windows, fogged.width(), fogged.height());
  ColorImage converted;
  const ColorImage& image = in_format(fogged, options.half, converted);
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
    for (const std::string& c : rgba) channels.insert(c, Imf::Channel(options.half ? Imf::HALF : Imf::FLOAT));
    h.channels() = channels;
    if (options.compression >= 0) h.compression() = Imf::Compression(options.compression);
    for (const char* structural : {"tiles", "chunkCount", "version", "maxSamplesPerPixel"})
      if (h.find(structural) != h.end()) h.erase(structural);
    if (h.hasType()) h.setType(Imf::SCANLINEIMAGE);
    if (h.lineOrder() == Imf::RANDOM_Y) h.lineOrder() = Imf::INCREASING_Y;

    detail::write_file_atomically(path, "EXR", [&](std::ostream& out, const std::string& name) {
      detail::OStreamAdapter ostream(out, name);
      Imf::MultiPartOutputFile file(ostream, headers.data(), int(headers.size()));
      for (int p = 0; p < in.parts(); ++p) {
        if (p == source.color_part) {
          Imf::OutputPart part(file, p);
          Imf::FrameBuffer fb;
          const Imf::PixelType type = pixel_type_of(image.format());
          const std::size_t value_size = type == Imf::HALF ? 2 : 4;
          const std::size_t x_stride = 4 * value_size, y_stride = x_stride * std::size_t(image.width());
          const char* pixels = static_cast<const char*>(image.data());
          for (int c = 0; c < 4; ++c)
            fb.insert(rgba[c], Imf::Slice::Make(type, pixels + std::size_t(c) * value_size, display, x_stride, y_stride));
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
