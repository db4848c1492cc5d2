// OpenEXR input and output for the fog pass (docs/DESIGN.md §2: the display window is the frame).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

#include <glm/vec2.hpp>

#include "fogcl/image.h"
#include "fogcl/renderer_camera.h"

namespace fogcl {

// Inclusive pixel boxes, as OpenEXR's Box2i.
struct ExrWindows {
  glm::ivec2 display_min{0}, display_max{-1};
  glm::ivec2 data_min{0}, data_max{-1};
  bool operator==(const ExrWindows& o) const {
    return display_min == o.display_min && display_max == o.display_max &&
           data_min == o.data_min && data_max == o.data_max;
  }
};

// ---- Renderer output: layers, multi-part files, deep files, camera attributes ----------------
//
// What fogcl reads from a renderer's EXR (docs/cli.md#renderer-exr-files):
//  - color: the channels LAYER.R, LAYER.G, LAYER.B (LAYER.A optional, 1 when missing) of the
//    first part that has them; LAYER "" is the unnamed layer (R, G, B, A). HALF or FLOAT; UINT
//    and subsampled color/depth channels are rejected.
//  - depth: the channel named by the request, in the color's part or else the first part that
//    has it (same display and data window as the color).
//  - deep scanline parts are flattened front to back (samples sorted by Z, premultiplied "over");
//    the depth is the nearest sample's; a pixel without samples is (0, 0, 0, 0) and background.
//    Deep tiled parts are rejected.

// What a read is about to allocate, told to ExrReadRequest::before_allocating.
struct ExrFrameShape {
  ExrWindows windows;         // the frame's: the display window is its size
  ColorFormat color_format = ColorFormat::rgba32f;  // the color frame's storage (when color is read)
  bool color = true;          // a color frame is read (false: depth only)
  bool deep = false;          // a deep part is flattened (its pixel tables need memory of their own)
};

struct ExrReadRequest {
  std::string layer;                 // "" = R, G, B, A; "beauty" = beauty.R, beauty.G, ...
  bool read_color = true;            // false: depth only (a --depth file)
  std::string depth_channel;         // "" = no depth wanted
  bool depth_single_channel_fallback = false;  // no such channel: use a one-channel part's channel
  float depth_outside = 1.0f;        // depth outside the data window / of empty deep pixels
  bool keep_half = false;            // color stored as HALF (flat part): read into an rgba16f frame,
                                     // bit for bit; otherwise (or when false) an rgba32f frame
  // Frames to read into, e.g. a sequence's previous frames: used (moved from) when they have the
  // frame's size (and, for color, its storage), which spares allocating and zero-filling the
  // frame (100 MB for a 4K float frame and its depth); left alone otherwise. Null: a new frame.
  ColorImage* color_into = nullptr;
  DepthImage* depth_into = nullptr;
  std::int64_t max_pixels = std::int64_t(1) << 31;   // per frame (display window); more is corrupt
  std::int64_t max_deep_samples = std::int64_t(1) << 28;  // per deep part
  // Called once the header is read and the windows are checked, before any pixel memory is
  // allocated; may throw to refuse the frame (fogcl apply's --max-memory). Empty: not called.
  std::function<void(const ExrFrameShape&)> before_allocating;
};

// A perspective camera read from the standard attributes worldToNDC and worldToCamera (OpenEXR's
// ImfStandardAttributes.h: camera space is left-handed and looks down +z, x right, y up; NDC (0, 0)
// is the display window's top left; Imath's row vectors, p_ndc ~ p_world * worldToNDC). The pose
// is in the file's world, the renderer's (fogcl/renderer_camera.h says how it becomes fogcl's).
struct ExrCamera {
  bool present = false;     // both matrices there and they describe a symmetric perspective
  float fov_y_deg = 0.0f;   // vertical field of view [degrees]
  float aspect = 0.0f;      // tan(horizontal half fov) / tan(vertical half fov)
  std::string note;         // why the camera is absent when the matrices exist but do not fit
  // The pose: the camera's position and its image right, image up and viewing directions in the
  // file's world, as worldToNDC places them on the image (also for a camera space that looks down
  // -z, as some renderers write). Present with the camera when worldToCamera is rigid (a rotation,
  // with a reflection for a right-handed world, and a translation; 1e-4).
  bool pose_present = false;
  CameraFrame frame;
  std::string pose_note;    // why the pose is absent when the camera is present
};

struct ExrInput {
  std::string path;          // the file read (or the name given for a memory buffer)
  ColorImage color;          // display-window frame, float RGBA (half: see keep_half); empty when !read_color
  DepthImage depth;          // display-window frame; empty when no depth was asked for
  ExrWindows windows;        // of the color part (of the depth part when !read_color)
  int color_part = -1;       // part index of the color (or of the depth when !read_color)
  int depth_part = -1;
  int parts = 0;             // parts in the file
  bool deep = false;         // the color came from a deep part, flattened
  std::string layer;         // the layer read
  int compression = -1;      // Imf::Compression of the color part (of the depth part when !read_color)
  ExrCamera camera;          // from the color part's attributes
};

// Reads a renderer's EXR (see above). Throws fogcl::Error "FILE: what: why" for every failure:
// missing file, not an EXR, truncated or corrupt data, missing or unsupported channels.
ExrInput read_exr(const std::string& path, const ExrReadRequest& request);
// The same from bytes in memory (the fuzz target's entry point); `name` appears in messages.
ExrInput read_exr_memory(const void* data, std::size_t size, const std::string& name,
                         const ExrReadRequest& request);

// Output choices of `fogcl apply` (--pixel-type, --compression) for the fogged R, G, B, A.
struct ExrWriteOptions {
  bool half = false;      // HALF channels (an rgba16f frame is written bit for bit); else FLOAT
  int compression = -1;   // Imf::Compression of the color part; -1: the input's
};
// "zip" -> Imf::ZIP_COMPRESSION, ... (none, rle, zips, zip, piz, pxr24, b44, dwaa, dwab); throws
// fogcl::Error naming the value and the choices.
int parse_exr_compression(const std::string& name);
const char* exr_compression_name(int compression);  // "zip", ...; "unknown" outside the list

// Writes `fogged` (the frame of `source.color`) as the output of `fogcl apply`: the source file's
// parts, attributes and other channels are kept (other parts copied as they are stored; the color
// part rewritten as scanlines with the layer's R, G, B, A in float, or as `options` say); with
// `rgba_only`, only R, G, B, A (unnamed layer) and the windows, compressed as the color part was.
// The file appears complete or not at all (src/io/atomic_file.h), even after a kill -9.
void write_exr_output(const std::string& path, const ColorImage& fogged, const ExrInput& source,
                      bool rgba_only, const ExrWriteOptions& options = {});

// ---- Simple files --------------------------------------------------------------------------------

// Reads R, G, B and A (half or float; A missing -> 1) into a frame the size of the display
// window; pixels outside the data window are (0, 0, 0, 0). Throws fogcl::Error
// ("FILE: what: why") for a missing, unreadable or non-RGB file.
ColorImage read_exr_color(const std::string& path, ExrWindows* windows = nullptr,
                          ColorFormat format = ColorFormat::rgba32f);

// Reads raw device depth from `channel` (default "Z", in any part; a single-channel file's only
// channel is used whatever its name; deep parts give the nearest sample's depth) into a display-window-sized frame; pixels outside the data window get
// `outside_value`. Throws fogcl::Error for a missing channel or an unreadable file.
DepthImage read_exr_depth(const std::string& path, ExrWindows* windows = nullptr,
                          const std::string& channel = "Z", float outside_value = 1.0f);

// Writes RGBA float32 (only the data window's pixels, both windows kept). The file appears
// complete or not at all: it is written under a temporary name and renamed.
void write_exr_rgba(const std::string& path, const ColorImage& image, const ExrWindows* windows = nullptr);

// Writes a single float32 channel named "Z" holding raw device depth.
void write_exr_depth(const std::string& path, const DepthImage& depth);

// Writes an 8-bit sRGB PNG preview of linear RGB: clamped to [0, 1], sRGB-encoded, with a
// triangular (TPDF) dither of +-1 code before quantisation so slow gradients do not band.
// Alpha is written as is (clamped). Written under a temporary name and renamed.
void write_png_preview(const std::string& path, const ColorImage& image);

}  // namespace fogcl
