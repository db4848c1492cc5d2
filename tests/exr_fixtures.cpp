#include "exr_fixtures.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <Imath/ImathMatrix.h>
#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDeepFrameBuffer.h>
#include <OpenEXR/ImfDeepScanLineOutputFile.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfTiledOutputPart.h>

namespace fogcl::fixtures {

namespace {

class Rng {  // xorshift32: deterministic per seed
 public:
  explicit Rng(unsigned seed) : s_(seed * 2654435761u + 1u) {}
  float unit() {
    s_ ^= s_ << 13;
    s_ ^= s_ >> 17;
    s_ ^= s_ << 5;
    return float(s_ >> 8) / 16777216.0f;
  }

 private:
  std::uint32_t s_;
};

}  // namespace

RenderFrame make_render_frame(const Imath::Box2i& display, const Imath::Box2i& data, unsigned seed) {
  RenderFrame f;
  f.display = display;
  f.data = data;
  f.camera.fov_y_deg = 50.0f;
  f.camera.aspect = float(display.max.x - display.min.x + 1) / float(display.max.y - display.min.y + 1);
  f.camera.near_plane = 0.3f;
  f.camera.far_plane = 1000.0f;
  Rng rng(seed);
  const std::size_t n = std::size_t(f.width()) * std::size_t(f.height());
  f.rgba.resize(4 * n);
  f.eye.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) f.rgba[4 * i + c] = 4.0f * rng.unit();
    f.rgba[4 * i + 3] = 0.25f + 0.75f * rng.unit();
    const float r = rng.unit();
    if (i % 8 == 3)
      f.eye[i] = (i / 8) % 2 == 0 ? 0.0f : std::numeric_limits<float>::infinity();
    else
      f.eye[i] = f.camera.near_plane * std::pow(0.9f * f.camera.far_plane / f.camera.near_plane, r);
  }
  return f;
}

std::vector<float> to_half_values(const std::vector<float>& v) {
  std::vector<float> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out[i] = float(Imath::half(v[i]));
  return out;
}

std::vector<Channel> color_channels(const RenderFrame& frame, const std::string& prefix, Imf::PixelType type) {
  std::vector<Channel> out;
  const char* names[4] = {"R", "G", "B", "A"};
  for (int c = 0; c < 4; ++c) {
    Channel ch{prefix + names[c], type, {}};
    for (std::size_t i = 0; i < frame.eye.size(); ++i) ch.values.push_back(frame.rgba[4 * i + std::size_t(c)]);
    out.push_back(std::move(ch));
  }
  return out;
}

Channel depth_channel(const RenderFrame& frame, const std::string& name, Imf::PixelType type) {
  return Channel{name, type, frame.eye};
}

void camera_matrices(const PerspectiveCamera& camera, float w2c_out[4][4], float w2n_out[4][4]) {
  const double pi = 3.14159265358979323846;
  const double tan_v = std::tan(double(camera.fov_y_deg) * pi / 360.0);
  const double tan_h = tan_v * double(camera.aspect);
  Imath::M44d w2c;  // rotate 30 degrees about y, then move: any rigid transform will do
  w2c.setAxisAngle(Imath::V3d(0, 1, 0), pi / 6);
  w2c[3][0] = 2.5;
  w2c[3][1] = -1.0;
  w2c[3][2] = 4.0;
  Imath::M44d c2n(0.0);
  c2n[0][0] = 0.5 / tan_h;   // ndc_x = 0.5 + 0.5 x / (z tan_h)
  c2n[2][0] = 0.5;
  c2n[1][1] = -0.5 / tan_v;  // ndc_y = 0.5 - 0.5 y / (z tan_v): y points down in NDC
  c2n[2][1] = 0.5;
  c2n[2][2] = 1.0;
  c2n[3][2] = -double(camera.near_plane);
  c2n[2][3] = 1.0;           // w = z
  const Imath::M44d w2n = w2c * c2n;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      w2c_out[i][j] = float(w2c[i][j]);
      w2n_out[i][j] = float(w2n[i][j]);
    }
}

void write_flat(const std::string& path, const RenderFrame& frame, const std::vector<Part>& parts) {
  std::vector<Imf::Header> headers;
  for (const Part& p : parts) {
    Imf::Header h(frame.display, frame.data);
    for (const Channel& c : p.channels) h.channels().insert(c.name, Imf::Channel(c.type));
    h.insert("renderer", Imf::StringAttribute("fogcl fixtures"));
    if (parts.size() > 1) h.setName(p.name);
    if (p.tiled) {
      h.setTileDescription(Imf::TileDescription(8, 8, Imf::ONE_LEVEL));
      h.setType(Imf::TILEDIMAGE);
    } else {
      h.setType(Imf::SCANLINEIMAGE);
    }
    if (p.with_camera) {
      float w2c[4][4], w2n[4][4];
      camera_matrices(frame.camera, w2c, w2n);
      Imath::M44f a(w2c), b(w2n);
      if (p.world != Imath::M44d()) {  // identity: the matrices as camera_matrices gives them, bit for bit
        a = Imath::M44f(p.world * Imath::M44d(a));
        b = Imath::M44f(p.world * Imath::M44d(b));
      }
      Imf::addWorldToCamera(h, a);
      Imf::addWorldToNDC(h, b);
    }
    headers.push_back(h);
  }
  Imf::MultiPartOutputFile file(path.c_str(), headers.data(), int(headers.size()));
  const std::size_t w = std::size_t(frame.width());
  for (std::size_t pi = 0; pi < parts.size(); ++pi) {
    std::vector<std::vector<Imath::half>> halves;
    std::vector<std::vector<std::uint32_t>> uints;
    halves.reserve(parts[pi].channels.size());
    uints.reserve(parts[pi].channels.size());
    Imf::FrameBuffer fb;
    for (const Channel& c : parts[pi].channels) {
      if (c.type == Imf::HALF) {
        halves.emplace_back(c.values.begin(), c.values.end());
        fb.insert(c.name, Imf::Slice::Make(Imf::HALF, halves.back().data(), frame.data, 2, 2 * w));
      } else if (c.type == Imf::UINT) {
        uints.emplace_back();
        for (float v : c.values) uints.back().push_back(std::uint32_t(std::max(0.0f, std::min(v, 1e9f))));
        fb.insert(c.name, Imf::Slice::Make(Imf::UINT, uints.back().data(), frame.data, 4, 4 * w));
      } else {
        fb.insert(c.name, Imf::Slice::Make(Imf::FLOAT, c.values.data(), frame.data, 4, 4 * w));
      }
    }
    if (parts[pi].tiled) {
      Imf::TiledOutputPart part(file, int(pi));
      part.setFrameBuffer(fb);
      part.writeTiles(0, part.numXTiles() - 1, 0, part.numYTiles() - 1);
    } else {
      Imf::OutputPart part(file, int(pi));
      part.setFrameBuffer(fb);
      part.writePixels(frame.height());
    }
  }
}

void write_deep(const std::string& path, const RenderFrame& frame, std::vector<float>* flat_rgba,
                std::vector<float>* nearest_z) {
  const std::size_t w = std::size_t(frame.width()), n = frame.eye.size();
  std::vector<unsigned int> counts(n);
  std::vector<std::vector<float>> samples(5);  // R, G, B, A, Z
  std::vector<std::vector<float*>> pointers(5, std::vector<float*>(n));
  std::vector<std::size_t> first(n);
  for (std::size_t i = 0; i < n; ++i) {
    counts[i] = unsigned(i % 4);
    first[i] = samples[0].size();
    for (unsigned k = 0; k < counts[i]; ++k) {
      // Sample k of pixel i: in front of or behind the frame's depth; scrambled order 2, 0, 1.
      const float z = frame.eye[i] > 0 && std::isfinite(frame.eye[i]) ? frame.eye[i] * (1.0f + 0.5f * float((k + 2) % 3))
                                                                     : 10.0f + float((k + 2) % 3);
      const float alpha = k == 0 ? 0.5f : 0.75f;
      for (int c = 0; c < 3; ++c) samples[std::size_t(c)].push_back(alpha * frame.rgba[4 * i + std::size_t(c)] / float(k + 1));
      samples[3].push_back(alpha);
      samples[4].push_back(z);
    }
  }
  for (std::size_t c = 0; c < 5; ++c)
    for (std::size_t i = 0; i < n; ++i) pointers[c][i] = samples[c].data() + first[i];

  flat_rgba->assign(4 * n, 0.0f);
  nearest_z->assign(n, std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<unsigned> order(counts[i]);
    for (unsigned k = 0; k < counts[i]; ++k) order[k] = k;
    std::sort(order.begin(), order.end(), [&](unsigned a, unsigned b) { return pointers[4][i][a] < pointers[4][i][b]; });
    double acc[4] = {0, 0, 0, 0};
    for (unsigned k : order) {
      const double t = 1.0 - acc[3];
      for (std::size_t c = 0; c < 4; ++c) acc[c] += t * double(pointers[c][i][k]);
    }
    for (std::size_t c = 0; c < 4; ++c) (*flat_rgba)[4 * i + c] = float(acc[c]);
    if (counts[i] > 0) (*nearest_z)[i] = pointers[4][i][order[0]];
  }

  Imf::Header h(frame.display, frame.data);
  const char* names[5] = {"R", "G", "B", "A", "Z"};
  for (const char* c : names) h.channels().insert(c, Imf::Channel(Imf::FLOAT));
  h.setType(Imf::DEEPSCANLINE);
  h.compression() = Imf::ZIPS_COMPRESSION;
  h.insert("renderer", Imf::StringAttribute("fogcl fixtures"));
  Imf::DeepScanLineOutputFile file(path.c_str(), h);
  Imf::DeepFrameBuffer fb;
  fb.insertSampleCountSlice(Imf::Slice::Make(Imf::UINT, counts.data(), frame.data, sizeof(unsigned), sizeof(unsigned) * w));
  for (std::size_t c = 0; c < 5; ++c) {
    char* base = reinterpret_cast<char*>(pointers[c].data()) -
                 (std::ptrdiff_t(frame.data.min.x) + std::ptrdiff_t(frame.data.min.y) * std::ptrdiff_t(w)) *
                     std::ptrdiff_t(sizeof(float*));
    fb.insert(names[c], Imf::DeepSlice(Imf::FLOAT, base, sizeof(float*), sizeof(float*) * w, sizeof(float)));
  }
  file.setFrameBuffer(fb);
  file.writePixels(frame.height());
}

}  // namespace fogcl::fixtures
