// OpenEXR input and output for the fog pass (DESIGN.md §2: the display window is the frame).
#pragma once

#include <string>

#include <glm/vec2.hpp>

#include "fogcl/image.h"

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

// Reads R, G, B and A (half or float; A missing -> 1) into a frame the size of the display
// window; pixels outside the data window are (0, 0, 0, 0). Throws fogcl::Error
// ("FILE: what: why") for a missing, unreadable or non-RGB file.
ColorImage read_exr_color(const std::string& path, ExrWindows* windows = nullptr,
                          ColorFormat format = ColorFormat::rgba32f);

// Reads raw device depth from `channel` (default "Z"; a single-channel file's only channel is
// used whatever its name) into a display-window-sized frame; pixels outside the data window get
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
