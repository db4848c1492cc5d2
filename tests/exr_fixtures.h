// Generated EXR files that look like renderer output (multi-part with Z in its own part, layered
// channel names, a data window inside the display window, deep scanline, half and float, linear
// Z with background 0 and +inf, camera attributes). Used by the tests and by the fuzz target's
// seed corpus generator (fuzz/make_seeds.cpp), so they are written with OpenEXR directly.
#pragma once

#include <string>
#include <vector>

#include <Imath/ImathBox.h>
#include <Imath/ImathMatrix.h>
#include <OpenEXR/ImfPixelType.h>

#include "fogcl/camera.h"

namespace fogcl::fixtures {

// A frame as a renderer would produce it: display window `display`, pixels stored in `data`
// (inside it), linear RGBA and linear eye depth (0 or +inf where there is only sky).
struct RenderFrame {
  Imath::Box2i display, data;
  PerspectiveCamera camera;            // the camera that "rendered" it (near 0.3, far 1000)
  std::vector<float> rgba;             // data window, 4 per pixel, row 0 = top
  std::vector<float> eye;              // data window, eye depth [world units]; 0 / inf = sky
  int width() const { return data.max.x - data.min.x + 1; }
  int height() const { return data.max.y - data.min.y + 1; }
};

// Random HDR colors, alpha in [0.25, 1], eye depths log-uniform in [near, 0.9 far), ~1 pixel in 8
// background (alternately 0 and +inf).
RenderFrame make_render_frame(const Imath::Box2i& display, const Imath::Box2i& data, unsigned seed);

// Values as a half channel stores them (round to nearest even).
std::vector<float> to_half_values(const std::vector<float>& v);

struct Channel {
  std::string name;
  Imf::PixelType type;        // HALF, FLOAT (or UINT: values are truncated to integers)
  std::vector<float> values;  // data window, row 0 = top
};
struct Part {
  std::string name;           // part name (multi-part files); "" for single-part files
  std::vector<Channel> channels;
  bool with_camera = false;   // adds worldToCamera / worldToNDC of the frame's camera
  bool tiled = false;
  Imath::M44d world{};        // with_camera: a rigid motion of the world first (row vectors: worldToCamera =
                              // world * camera_matrices' worldToCamera; identity by default)
};

// Writes a flat file: one part -> single-part file, several -> multi-part. Every part has the
// frame's windows. Adds a string attribute "renderer" = "fogcl fixtures" to every part.
void write_flat(const std::string& path, const RenderFrame& frame, const std::vector<Part>& parts);

// The channels of the frame: R, G, B, A with `prefix` ("" or "beauty."), and the eye depth Z.
std::vector<Channel> color_channels(const RenderFrame& frame, const std::string& prefix, Imf::PixelType type);
Channel depth_channel(const RenderFrame& frame, const std::string& name, Imf::PixelType type = Imf::FLOAT);

// A deep scanline file of the frame: pixel i holds (i % 4) samples (0: background) with
// premultiplied RGBA and Z, written in a scrambled depth order; `flat_rgba` / `nearest_z` get what
// flattening must give (sorted front to back, premultiplied "over", in double; nearest Z, or
// +inf for pixels without samples).
void write_deep(const std::string& path, const RenderFrame& frame, std::vector<float>* flat_rgba,
                std::vector<float>* nearest_z);

// The worldToCamera / worldToNDC pair OpenEXR defines for `camera` (camera space looking down +z,
// NDC (0, 0) at the display window's top left), with a non-trivial world transform.
void camera_matrices(const PerspectiveCamera& camera, float world_to_camera[4][4], float world_to_ndc[4][4]);

}  // namespace fogcl::fixtures
