// OpenEXR input and output (DESIGN.md §2: the display window is the frame; pixels keep their
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
#include <OpenEXR/ImfStdIO.h>

#include "fogcl/error.h"
#include "io/atomic_file.h"

namespace fogcl {


namespace {

constexpr std::int64_t kMaxPixels = std::int64_t(1) << 31;  // per frame; beyond is treated as corrupt


std::string box_string(const Imath::Box2i& b) {
  return "(" + std::to_string(b.min.x) + ", " + std::to_string(b.min.y) + ")-(" +
         std::to_string(b.max.x) + ", " + std::to_string(b.max.y) + ")";
}

std::string box_string(const glm::ivec2& min, const glm::ivec2& max) {
  return box_string(Imath::Box2i(Imath::V2i(min.x, min.y), Imath::V2i(max.x, max.y)));
}

std::string channel_names(const Imf::ChannelList& channels) {
  std::string names;
  for (auto it = channels.begin(); it != channels.end(); ++it) {
    if (!names.empty()) names += ", ";
    names += it.name();
  }
  return names.empty() ? std::string("none") : names;
}

Imath::Box2i to_box(const glm::ivec2& min, const glm::ivec2& max) {
  return Imath::Box2i(Imath::V2i(min.x, min.y), Imath::V2i(max.x, max.y));
}

bool inside(const Imath::Box2i& inner, const Imath::Box2i& outer) {
  return inner.min.x >= outer.min.x && inner.min.y >= outer.min.y && inner.max.x <= outer.max.x &&
         inner.max.y <= outer.max.y;
}

// Size of an inclusive box along one axis, in 64 bits (max - min overflows int for huge boxes).
std::int64_t extent(int min, int max) { return std::int64_t(max) - std::int64_t(min) + 1; }

// The frame an EXR file describes: its display window (the frame) and data window (the pixels
// stored), validated before anything is allocated.
struct Frame {
  Imath::Box2i display, data;
  int width = 0, height = 0;
};

Frame frame_of(const std::string& path, const Imf::Header& header, ExrWindows* windows) {
  Frame f;
  f.display = header.displayWindow();
  f.data = header.dataWindow();
  const std::int64_t w = extent(f.display.min.x, f.display.max.x);
  const std::int64_t h = extent(f.display.min.y, f.display.max.y);
  if (w < 1 || h < 1)
    throw Error(path + ": cannot read EXR: empty display window " + box_string(f.display));
  if (w > std::numeric_limits<int>::max() || h > std::numeric_limits<int>::max() ||
      w * h > kMaxPixels)  // w, h < 2^31 here, so w * h cannot overflow int64
    throw Error(path + ": cannot read EXR: display window " + box_string(f.display) + " is " +
                std::to_string(w) + "x" + std::to_string(h) + " pixels, more than the limit of 2^31");
  if (extent(f.data.min.x, f.data.max.x) < 1 || extent(f.data.min.y, f.data.max.y) < 1)
    throw Error(path + ": cannot read EXR: empty data window " + box_string(f.data));
  if (!inside(f.data, f.display))
    throw Error(path + ": cannot read EXR: data window " + box_string(f.data) +
                " is not inside the display window " + box_string(f.display) +
                " (fogcl's frame is the display window)");
  f.width = int(w);
  f.height = int(h);
  if (windows != nullptr) {
    windows->display_min = {f.display.min.x, f.display.min.y};
    windows->display_max = {f.display.max.x, f.display.max.y};
    windows->data_min = {f.data.min.x, f.data.min.y};
    windows->data_max = {f.data.max.x, f.data.max.y};
  }
  return f;
}

// Runs `read` and turns whatever OpenEXR (Iex), the standard library or the allocator throws into
// one fogcl::Error line naming the file. Our own fogcl::Errors already name it and pass through.
template <class Read>
auto with_read_errors(const std::string& path, Read&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw Error(path + ": cannot read EXR: out of memory");
  } catch (const std::exception& e) {  // Iex::BaseExc derives from std::exception
    throw Error(path + ": cannot read EXR: " + detail::one_line(e.what()));
  } catch (...) {
    throw Error(path + ": cannot read EXR: unknown error");
  }
}

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
  return with_read_errors(path, [&] {
    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    const Imf::ChannelList& channels = header.channels();
    for (const char* name : {"R", "G", "B"})
      if (channels.findChannel(name) == nullptr)
        throw Error(path + ": missing channel " + name + " (channels present: " + channel_names(channels) + ")");
    const Frame f = frame_of(path, header, windows);

    ColorImage frame(f.width, f.height, ColorFormat::rgba32f);  // starts (0, 0, 0, 0)
    const std::size_t x_stride = 4 * sizeof(float);
    const std::size_t y_stride = x_stride * std::size_t(f.width);
    Imf::FrameBuffer frame_buffer;
    const char* const names[4] = {"R", "G", "B", "A"};
    const double fill[4] = {0.0, 0.0, 0.0, 1.0};  // only A can be missing here: opaque
    for (int c = 0; c < 4; ++c)
      frame_buffer.insert(names[c], Imf::Slice::Make(Imf::FLOAT, frame.rgba32f() + c, f.display, x_stride,
                                                     y_stride, 1, 1, fill[c]));
    file.setFrameBuffer(frame_buffer);
    file.readPixels(f.data.min.y, f.data.max.y);
    // Half storage: Imath::half rounds to nearest even (image.h's convert()).
    return format == ColorFormat::rgba32f ? frame : convert(frame, format);
  });
}

DepthImage read_exr_depth(const std::string& path, ExrWindows* windows, const std::string& channel,
                          float outside_value) {
  return with_read_errors(path, [&] {
    Imf::InputFile file(path.c_str());
    const Imf::Header& header = file.header();
    const Imf::ChannelList& channels = header.channels();
    std::string name = channel;
    if (channels.findChannel(name) == nullptr) {
      // A single-channel file is a depth file whatever its channel is called.
      Imf::ChannelList::ConstIterator first = channels.begin(), second = first;
      if (first != channels.end() && ++second == channels.end())
        name = first.name();
      else
        throw Error(path + ": no depth channel '" + channel + "' (channels present: " + channel_names(channels) +
                    ")");
    }
    const Frame f = frame_of(path, header, windows);

    DepthImage depth(f.width, f.height, outside_value);
    Imf::FrameBuffer frame_buffer;
    frame_buffer.insert(name, Imf::Slice::Make(Imf::FLOAT, depth.data(), f.display, sizeof(float),
                                               sizeof(float) * std::size_t(f.width)));
    file.setFrameBuffer(frame_buffer);
    file.readPixels(f.data.min.y, f.data.max.y);
    return depth;
  });
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

}  // namespace fogcl
