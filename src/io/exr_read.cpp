// Reading what renderers write: multi-part files, layered channel names, deep scanline parts,
// HALF or FLOAT channels, data windows inside the display window, and the camera standard
// attributes (docs/cli.md#renderer-exr-files; docs/DESIGN.md §2: the display window is the frame).
//
// Everything goes through one Imf::MultiPartInputFile opened on an Imf::IStream: a file on disk
// for the CLI, bytes in memory for the fuzz target, so that the fuzzer runs exactly the code the
// tool runs. Flat parts are read the way OpenEXR's examples do (readGZ1.cpp): one FLOAT slice per
// channel whose base pointer is offset by the data window (Slice::Make), straight into the
// display-window-sized frame. Every OpenEXR / Iex / std exception becomes one fogcl::Error line
// that names the file.

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include <Iex.h>
#include <Imath/ImathBox.h>
#include <Imath/ImathMatrix.h>
#include <glm/geometric.hpp>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDeepFrameBuffer.h>
#include <OpenEXR/ImfDeepScanLineInputPart.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStdIO.h>

#include "fogcl/error.h"
#include "fogcl/exr_io.h"
#include "io/atomic_file.h"
#include "io/exr_common.h"
#include "io/exr_precheck.h"

namespace fogcl {

namespace detail {

// An Imf::IStream over bytes owned by the caller. read() throws at the end of the data, as
// OpenEXR's own streams do, so a truncated buffer behaves like a truncated file.
class MemoryIStream : public Imf::IStream {
 public:
  MemoryIStream(const char* data, std::size_t size, const std::string& name)
      : Imf::IStream(name.c_str()), data_(data), size_(size) {}
  bool read(char c[], int n) override {
    if (n < 0 || pos_ > size_ || std::uint64_t(n) > size_ - pos_)
      throw Iex::InputExc("unexpected end of file");
    if (n > 0) std::memcpy(c, data_ + pos_, std::size_t(n));
    pos_ += std::size_t(n);
    return pos_ < size_;
  }
  std::uint64_t tellg() override { return pos_; }
  void seekg(std::uint64_t pos) override { pos_ = pos; }  // a later read past the end throws
  void clear() override {}

 private:
  const char* data_;
  std::size_t size_;
  std::uint64_t pos_ = 0;
};

}  // namespace detail

namespace {

using detail::box_string;
using detail::extent;

struct Source {
  std::string path;
  std::unique_ptr<std::ifstream> file_stream;
  std::unique_ptr<Imf::IStream> stream;
  std::unique_ptr<Imf::MultiPartInputFile> file;
};

bool is_deep(const Imf::Header& h) { return h.hasType() && Imf::isDeepData(h.type()); }
bool is_tiled_deep(const Imf::Header& h) { return h.hasType() && h.type() == Imf::DEEPTILE; }

std::string part_label(const Source& s, int part) {
  if (s.file->parts() == 1) return "";
  const Imf::Header& h = s.file->header(part);
  return "part " + std::to_string(part) + (h.hasName() ? " '" + h.name() + "'" : std::string()) + ": ";
}

// "A, B, G, R" for one part; "part 0 'rgba': A, B, G, R; part 1 'depth': Z" for several.
std::string channels_present(const Source& s) {
  std::string out;
  for (int p = 0; p < s.file->parts(); ++p) {
    if (p > 0) out += "; ";
    out += part_label(s, p) + detail::channel_names(s.file->header(p).channels());
  }
  return out;
}

// HALF or FLOAT, full resolution: what fogcl can use as color or depth.
void check_channel(const Source& s, int part, const std::string& name, const Imf::Channel& c) {
  if (c.type != Imf::HALF && c.type != Imf::FLOAT)
    throw Error(s.path + ": " + part_label(s, part) + "channel " + name +
                " has pixel type UINT; fogcl reads HALF or FLOAT color and depth");
  if (c.xSampling != 1 || c.ySampling != 1)
    throw Error(s.path + ": " + part_label(s, part) + "channel " + name + " is subsampled (" +
                std::to_string(c.xSampling) + "x" + std::to_string(c.ySampling) +
                "); fogcl reads full-resolution color and depth");
}

// The frame of a part: windows validated before anything is allocated.
struct Frame {
  Imath::Box2i display, data;
  int width = 0, height = 0;
};

Frame frame_of(const Source& s, int part, const ExrReadRequest& r, ExrWindows* windows) {
  const Imf::Header& header = s.file->header(part);
  Frame f;
  f.display = header.displayWindow();
  f.data = header.dataWindow();
  const std::string where = s.path + ": cannot read EXR: " + part_label(s, part);
  const std::int64_t w = extent(f.display.min.x, f.display.max.x);
  const std::int64_t h = extent(f.display.min.y, f.display.max.y);
  if (w < 1 || h < 1) throw Error(where + "empty display window " + box_string(f.display));
  if (w > std::numeric_limits<int>::max() || h > std::numeric_limits<int>::max() ||
      w * h > r.max_pixels)  // w, h < 2^31 here, so w * h cannot overflow int64
    throw Error(where + "display window " + box_string(f.display) + " is " + std::to_string(w) + "x" +
                std::to_string(h) + " pixels, more than the limit of " +
                (r.max_pixels == (std::int64_t(1) << 31) ? std::string("2^31") : std::to_string(r.max_pixels)));
  if (extent(f.data.min.x, f.data.max.x) < 1 || extent(f.data.min.y, f.data.max.y) < 1)
    throw Error(where + "empty data window " + box_string(f.data));
  if (!detail::inside(f.data, f.display))
    throw Error(where + "data window " + box_string(f.data) + " is not inside the display window " +
                box_string(f.display) + " (fogcl's frame is the display window)");
  f.width = int(w);
  f.height = int(h);
  if (windows != nullptr) *windows = detail::to_windows(f.display, f.data);
  return f;
}

// Where a read does not write every pixel of the display-window frame (a smaller data window, a
// deep part's empty pixels), the frame must start as a new one does.
bool read_leaves_gaps(const Frame& f, bool deep) { return deep || f.data != f.display; }

// The frame to read into: *into when it has the size and storage (its pixels reset where the read
// leaves gaps), else a new one ((0, 0, 0, 0)).
ColorImage color_frame(ColorImage* into, const Frame& f, ColorFormat format, bool gaps) {
  if (into == nullptr || into->width() != f.width || into->height() != f.height || into->format() != format)
    return ColorImage(f.width, f.height, format);
  ColorImage image = std::move(*into);
  if (gaps) std::memset(image.data(), 0, image.size_bytes());
  return image;
}

DepthImage depth_frame(DepthImage* into, const Frame& f, float outside, bool gaps) {
  if (into == nullptr || into->width() != f.width || into->height() != f.height)
    return DepthImage(f.width, f.height, outside);
  DepthImage image = std::move(*into);
  if (gaps) std::fill(image.data(), image.data() + image.pixel_count(), outside);
  return image;
}

// Reads `type` slices (or fills) for `names` into a frame with `stride` values per pixel.
void read_flat(Source& s, int part, const Frame& f, void* frame, Imf::PixelType type, int stride,
               const std::vector<std::string>& names, const std::vector<double>& fill) {
  Imf::InputPart in(*s.file, part);
  const std::size_t value_size = type == Imf::HALF ? 2 : 4;
  const std::size_t x_stride = std::size_t(stride) * value_size;
  const std::size_t y_stride = x_stride * std::size_t(f.width);
  Imf::FrameBuffer fb;
  for (std::size_t c = 0; c < names.size(); ++c)
    fb.insert(names[c], Imf::Slice::Make(type, static_cast<char*>(frame) + c * value_size, f.display, x_stride,
                                         y_stride, 1, 1, fill[c]));
  in.setFrameBuffer(fb);
  in.readPixels(f.data.min.y, f.data.max.y);
}

// Deep scanline part, flattened. color (may be null): premultiplied "over", front to back, after
// sorting each pixel's samples by Z (NaN last); depth (may be null): the nearest sample's value of
// `depth_name`. Pixels without samples keep the frames' initial values.
void read_deep(Source& s, int part, const Frame& f, const ExrReadRequest& r, const std::string& prefix,
               float* color, float* depth, const std::string& depth_name) {
  const Imf::Header& header = s.file->header(part);
  Imf::DeepScanLineInputPart in(*s.file, part);
  const Imath::Box2i& dw = f.data;
  const std::size_t w = std::size_t(extent(dw.min.x, dw.max.x)), h = std::size_t(extent(dw.min.y, dw.max.y));
  // OpenEXR's order (readDeepScanLineFile in its documentation): the frame buffer with the count
  // slice and every sample slice (arrays of per-pixel pointers) first, then the counts, then the
  // pointers are aimed at storage of that size, then the samples.
  std::vector<unsigned int> counts(w * h);
  Imf::DeepFrameBuffer fb;
  fb.insertSampleCountSlice(
      Imf::Slice::Make(Imf::UINT, counts.data(), dw, sizeof(unsigned int), sizeof(unsigned int) * w));

  // Channels wanted: color (R, G, B, A), the sort key Z, the depth channel. Missing -> fill.
  const bool has_z = header.channels().findChannel("Z") != nullptr;
  std::vector<std::string> names;
  std::vector<double> fills;
  if (color != nullptr) {
    for (const char* c : {"R", "G", "B", "A"}) names.push_back(prefix + c);
    fills = {0.0, 0.0, 0.0, 1.0};
  }
  const std::size_t z_index = names.size();
  names.push_back(has_z ? "Z" : depth_name);
  fills.push_back(0.0);
  std::size_t d_index = z_index;
  if (depth != nullptr && names[z_index] != depth_name) {
    d_index = names.size();
    names.push_back(depth_name);
    fills.push_back(0.0);
  }
  std::vector<std::vector<float*>> pointers(names.size(), std::vector<float*>(w * h));
  for (std::size_t c = 0; c < names.size(); ++c) {
    // Base pointer addressed by absolute (x, y), as Slice::Make computes it, without forming
    // an out-of-range pointer in C++.
    const std::uintptr_t base = reinterpret_cast<std::uintptr_t>(pointers[c].data()) -
                                std::uintptr_t(std::intptr_t(dw.min.x) * std::intptr_t(sizeof(float*))) -
                                std::uintptr_t(std::intptr_t(dw.min.y) * std::intptr_t(sizeof(float*) * w));
    fb.insert(names[c], Imf::DeepSlice(Imf::FLOAT, reinterpret_cast<char*>(base), sizeof(float*),
                                       sizeof(float*) * w, sizeof(float), 1, 1, fills[c]));
  }
  in.setFrameBuffer(fb);
  in.readPixelSampleCounts(dw.min.y, dw.max.y);
  std::int64_t total = 0;
  for (unsigned int c : counts) total += c;
  if (total > r.max_deep_samples)
    throw Error(s.path + ": cannot read EXR: " + part_label(s, part) + "deep part holds " + std::to_string(total) +
                " samples, more than the limit of " + std::to_string(r.max_deep_samples));
  std::vector<std::vector<float>> samples(names.size(), std::vector<float>(std::size_t(total)));
  for (std::size_t c = 0; c < names.size(); ++c) {
    std::size_t at = 0;
    for (std::size_t i = 0; i < w * h; ++i) {
      pointers[c][i] = samples[c].data() + at;
      at += counts[i];
    }
  }
  in.readPixels(dw.min.y, dw.max.y);

  std::vector<unsigned int> order;
  for (std::size_t y = 0; y < h; ++y) {
    for (std::size_t x = 0; x < w; ++x) {
      const std::size_t i = y * w + x;
      const unsigned int n = counts[i];
      if (n == 0) continue;
      const float* z = pointers[z_index][i];
      const auto key = [&](unsigned int k) { return std::isnan(z[k]) ? std::numeric_limits<float>::infinity() : z[k]; };
      order.resize(n);
      for (unsigned int k = 0; k < n; ++k) order[k] = k;
      std::stable_sort(order.begin(), order.end(), [&](unsigned int a, unsigned int b) { return key(a) < key(b); });
      const std::size_t frame_index =
          std::size_t(dw.min.y - f.display.min.y + std::int64_t(y)) * std::size_t(f.width) +
          std::size_t(dw.min.x - f.display.min.x + std::int64_t(x));
      if (depth != nullptr) depth[frame_index] = pointers[d_index][i][order[0]];
      if (color != nullptr) {
        double acc[4] = {0, 0, 0, 0};  // premultiplied; front to back: C += (1 - A) * c
        for (unsigned int k : order) {
          const double t = 1.0 - acc[3];
          for (int c = 0; c < 4; ++c) acc[c] += t * double(pointers[std::size_t(c)][i][k]);
        }
        for (int c = 0; c < 4; ++c) color[4 * frame_index + std::size_t(c)] = float(acc[c]);
      }
    }
  }
}

// Derives a symmetric perspective camera from worldToCamera and worldToNDC (row vectors, as
// Imath: p_ndc ~ p_cam * inverse(worldToCamera) * worldToNDC). OpenEXR's camera space looks down
// +z with NDC (0, 0) at the top left: ndc_x = 0.5 + 0.5 x / (z tan(h/2)), ndc_y = 0.5 - 0.5 y /
// (z tan(v/2)). A camera space looking down -z (w = -z) is read the same way: the viewing
// direction is the camera axis along which w grows, and image right and up are the camera axes
// along which ndc x grows and ndc y falls; their signs come from the matrices, not a convention.
ExrCamera camera_of(const Imf::Header& header) {
  ExrCamera cam;
  if (!Imf::hasWorldToNDC(header) || !Imf::hasWorldToCamera(header)) return cam;
  const Imath::M44f& w2c_f = Imf::worldToCameraAttribute(header).value();
  const Imath::M44f& w2n_f = Imf::worldToNDCAttribute(header).value();
  Imath::M44d w2c, w2n;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      w2c[i][j] = w2c_f[i][j];
      w2n[i][j] = w2n_f[i][j];
    }
  Imath::M44d c2w;
  try {
    c2w = w2c.inverse(true);
  } catch (const std::exception&) {
    cam.note = "worldToCamera is not invertible";
    return cam;
  }
  const Imath::M44d m = c2w * w2n;
  const double wz = m[2][3];
  if (!std::isfinite(wz) || wz == 0.0) {
    cam.note = "worldToNDC is not a perspective projection";
    return cam;
  }
  const auto a = [&](int i, int j) { return m[i][j] / wz; };
  const double tol = 1e-4;
  const bool perspective = std::fabs(a(0, 3)) < tol && std::fabs(a(1, 3)) < tol && std::fabs(a(3, 3)) < tol;
  const bool centred = std::fabs(a(2, 0) - 0.5) < tol && std::fabs(a(2, 1) - 0.5) < tol &&
                       std::fabs(a(1, 0)) < tol && std::fabs(a(0, 1)) < tol && std::fabs(a(3, 0)) < tol &&
                       std::fabs(a(3, 1)) < tol;
  if (!perspective || !centred || a(0, 0) == 0.0 || a(1, 1) == 0.0) {
    cam.note = "worldToNDC is not a symmetric perspective projection along the camera's z axis";
    return cam;
  }
  const double tan_h = 0.5 / std::fabs(a(0, 0)), tan_v = 0.5 / std::fabs(a(1, 1));
  const double fov = 2.0 * std::atan(tan_v) * 180.0 / 3.14159265358979323846;
  if (!std::isfinite(fov) || !(fov > 0.0 && fov < 180.0) || !std::isfinite(tan_h / tan_v)) {
    cam.note = "worldToNDC gives no finite field of view";
    return cam;
  }
  cam.present = true;
  cam.fov_y_deg = float(fov);
  cam.aspect = float(tan_h / tan_v);

  // The pose. Row vectors: c2w's rows 0-2 are the camera axes in the world, row 3 its position.
  // In front of the camera w = wz * z > 0: it looks along +z when wz > 0 (OpenEXR's), along -z when
  // wz < 0. There, a step along camera x moves ndc x by m[0][0] / w: image right is +x when
  // m[0][0] > 0; ndc y grows downward, so image up is +y when m[1][1] < 0.
  glm::dvec3 axis[3];
  for (int i = 0; i < 3; ++i) axis[i] = glm::dvec3(c2w[i][0], c2w[i][1], c2w[i][2]);
  const glm::dvec3 right = axis[0] * (m[0][0] > 0.0 ? 1.0 : -1.0);
  const glm::dvec3 up = axis[1] * (m[1][1] < 0.0 ? 1.0 : -1.0);
  const glm::dvec3 forward = axis[2] * (wz > 0.0 ? 1.0 : -1.0);
  for (int i = 0; i < 3; ++i) {
    const double len = glm::length(axis[i]);
    if (!(std::fabs(len - 1.0) <= tol)) {
      cam.pose_note = "worldToCamera is not rigid: camera axis " + std::to_string(i) + " has length " +
                      std::to_string(len) + " in the world (a scale)";
      return cam;
    }
  }
  const double d01 = glm::dot(axis[0], axis[1]), d02 = glm::dot(axis[0], axis[2]), d12 = glm::dot(axis[1], axis[2]);
  if (!(std::fabs(d01) <= tol && std::fabs(d02) <= tol && std::fabs(d12) <= tol)) {
    cam.pose_note = "worldToCamera is not rigid: its camera axes are not orthogonal in the world (a shear)";
    return cam;
  }
  if (!(std::fabs(c2w[0][3]) <= tol && std::fabs(c2w[1][3]) <= tol && std::fabs(c2w[2][3]) <= tol &&
        std::fabs(c2w[3][3] - 1.0) <= tol)) {
    cam.pose_note = "worldToCamera is not affine (its last column is not 0 0 0 1)";
    return cam;
  }
  cam.pose_present = true;
  cam.frame.eye = glm::vec3(float(c2w[3][0]), float(c2w[3][1]), float(c2w[3][2]));
  cam.frame.right = glm::vec3(glm::normalize(right));
  cam.frame.up = glm::vec3(glm::normalize(up));
  cam.frame.forward = glm::vec3(glm::normalize(forward));
  return cam;
}

int find_part(const Source& s, const std::vector<std::string>& channels, int prefer = -1) {
  const auto has_all = [&](int p) {
    for (const std::string& c : channels)
      if (s.file->header(p).channels().findChannel(c) == nullptr) return false;
    return true;
  };
  if (prefer >= 0 && has_all(prefer)) return prefer;
  for (int p = 0; p < s.file->parts(); ++p)
    if (has_all(p)) return p;
  return -1;
}

// The storage of the color frame: half when asked for and every color channel of a flat part is HALF.
ColorFormat color_storage(const Source& s, int part, const std::string& prefix, const ExrReadRequest& r) {
  const Imf::Header& h = s.file->header(part);
  bool all_half = !is_deep(h);
  for (const char* c : {"R", "G", "B", "A"})
    if (const Imf::Channel* channel = h.channels().findChannel(prefix + c)) all_half = all_half && channel->type == Imf::HALF;
  return r.keep_half && all_half ? ColorFormat::rgba16f : ColorFormat::rgba32f;
}

ExrInput read_source(Source& s, const ExrReadRequest& r) {
  ExrInput out;
  out.path = s.path;
  out.parts = s.file->parts();
  out.layer = r.layer;
  const std::string prefix = r.layer.empty() ? "" : r.layer + ".";
  ColorFormat color_format = ColorFormat::rgba32f;  // the color frame's storage, once its part is found
  // Once, before the first frame is allocated (the depth's when it comes first).
  bool announced = false;
  const auto before_allocating = [&](const Frame& f) {
    if (announced || !r.before_allocating) return;
    announced = true;
    ExrFrameShape shape;
    shape.windows = detail::to_windows(f.display, f.data);
    shape.color = r.read_color;
    if (r.read_color) shape.color_format = color_format;
    for (const int part : {out.color_part, out.depth_part})
      if (part >= 0) shape.deep = shape.deep || is_deep(s.file->header(part));
    r.before_allocating(shape);
  };

  if (r.read_color) {
    const std::vector<std::string> rgb{prefix + "R", prefix + "G", prefix + "B"};
    out.color_part = find_part(s, rgb);
    if (out.color_part < 0) {
      // Name the first channel missing from every part (as the single-part message always did).
      std::string missing = rgb[0];
      for (const std::string& c : rgb)
        if (find_part(s, {c}) < 0) {
          missing = c;
          break;
        }
      throw Error(s.path + ": missing channel " + missing + " (channels present: " + channels_present(s) + ")" +
                  (r.layer.empty() ? "" : " for layer '" + r.layer + "'"));
    }
    color_format = color_storage(s, out.color_part, prefix, r);
  }
  if (!r.depth_channel.empty()) {
    out.depth_part = find_part(s, {r.depth_channel}, out.color_part);
    std::string name = r.depth_channel;
    if (out.depth_part < 0 && r.depth_single_channel_fallback && s.file->parts() == 1) {
      // A single-channel file is a depth file whatever its channel is called.
      const Imf::ChannelList& ch = s.file->header(0).channels();
      Imf::ChannelList::ConstIterator first = ch.begin(), second = first;
      if (first != ch.end() && ++second == ch.end()) {
        out.depth_part = 0;
        name = first.name();
      }
    }
    if (out.depth_part < 0)
      throw Error(s.path + ": no depth channel '" + r.depth_channel + "' (channels present: " + channels_present(s) +
                  ")");
    const int frame_part = r.read_color ? out.color_part : out.depth_part;
    const Imf::Header& dh = s.file->header(out.depth_part);
    check_channel(s, out.depth_part, name, *dh.channels().findChannel(name));
    if (is_tiled_deep(dh))
      throw Error(s.path + ": " + part_label(s, out.depth_part) +
                  "deep tiled parts are not supported (deep scanline parts are flattened)");
    ExrWindows depth_windows;
    const Frame df = frame_of(s, out.depth_part, r, &depth_windows);
    if (frame_part != out.depth_part) {
      ExrWindows color_windows;
      frame_of(s, frame_part, r, &color_windows);
      if (!(color_windows == depth_windows))
        throw Error(s.path + ": " + part_label(s, out.depth_part) + "depth windows (display " +
                    box_string(dh.displayWindow()) + ", data " + box_string(dh.dataWindow()) +
                    ") differ from the color part's: depth and color must cover the same pixels");
    }
    before_allocating(df);
    out.depth = depth_frame(r.depth_into, df, r.depth_outside, read_leaves_gaps(df, is_deep(dh)));
    if (is_deep(dh))
      read_deep(s, out.depth_part, df, r, prefix, nullptr, out.depth.data(), name);
    else
      read_flat(s, out.depth_part, df, out.depth.data(), Imf::FLOAT, 1, {name}, {0.0});
    if (!r.read_color) {
      out.windows = depth_windows;
      out.compression = int(dh.compression());
      return out;
    }
  }

  const Imf::Header& ch = s.file->header(out.color_part);
  for (const char* c : {"R", "G", "B", "A"})
    if (const Imf::Channel* channel = ch.channels().findChannel(prefix + c))
      check_channel(s, out.color_part, prefix + c, *channel);
  if (is_tiled_deep(ch))
    throw Error(s.path + ": " + part_label(s, out.color_part) +
                "deep tiled parts are not supported (deep scanline parts are flattened)");
  const Frame f = frame_of(s, out.color_part, r, &out.windows);
  out.camera = camera_of(ch);
  out.compression = int(ch.compression());
  const bool half = color_format == ColorFormat::rgba16f;
  before_allocating(f);
  out.color = color_frame(r.color_into, f, color_format, read_leaves_gaps(f, is_deep(ch)));
  if (is_deep(ch)) {
    out.deep = true;
    read_deep(s, out.color_part, f, r, prefix, out.color.rgba32f(), nullptr, "Z");
  } else {
    // Only A can be missing here: opaque.
    read_flat(s, out.color_part, f, out.color.data(), half ? Imf::HALF : Imf::FLOAT, 4,
              {prefix + "R", prefix + "G", prefix + "B", prefix + "A"}, {0.0, 0.0, 0.0, 1.0});
  }
  return out;
}

template <class Open>
ExrInput read_with(const std::string& name, const ExrReadRequest& r, Open&& open) {
  return detail::with_read_errors(name, [&] {
    Source s;
    s.path = name;
    open(s);
    return read_source(s, r);
  });
}

}  // namespace

ExrInput read_exr(const std::string& path, const ExrReadRequest& request) {
  return read_with(path, request, [&](Source& s) {
    // Not opened: a FIFO would block the open, a device has no size to check the header against.
    if (const std::string kind = detail::non_regular_kind(path); !kind.empty())
      throw Error(path + ": cannot read EXR: it is " + kind + ", not a regular file");
    s.file_stream = std::make_unique<std::ifstream>(path, std::ios::binary);
    if (!*s.file_stream) throw Error(path + ": cannot read EXR: cannot open the file: " + std::strerror(errno));
    std::ifstream& f = *s.file_stream;
    f.seekg(0, std::ios::end);
    const std::streamoff size = f.tellg();
    if (size < 0) throw Error(path + ": cannot read EXR: cannot tell the file's size (not a regular file?)");
    detail::precheck_exr_header(path, std::uint64_t(size), request.max_pixels,
                                [&](std::uint64_t offset, std::size_t n, char* dst) {
                                  f.seekg(std::streamoff(offset));
                                  if (!f.read(dst, std::streamsize(n)))
                                    throw Error(path + ": cannot read EXR: read error in the header");
                                });
    f.seekg(0);
    s.stream = std::make_unique<Imf::StdIFStream>(*s.file_stream, path.c_str());
    s.file = std::make_unique<Imf::MultiPartInputFile>(*s.stream);
  });
}

ExrInput read_exr_memory(const void* data, std::size_t size, const std::string& name,
                         const ExrReadRequest& request) {
  return read_with(name, request, [&](Source& s) {
    const char* bytes = static_cast<const char*>(data);
    detail::precheck_exr_header(name, size, request.max_pixels,
                                [&](std::uint64_t offset, std::size_t n, char* dst) {
                                  if (n > 0) std::memcpy(dst, bytes + offset, n);
                                });
    s.stream = std::make_unique<detail::MemoryIStream>(bytes, size, name);
    s.file = std::make_unique<Imf::MultiPartInputFile>(*s.stream);
  });
}

}  // namespace fogcl
