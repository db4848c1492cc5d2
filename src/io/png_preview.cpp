// 8-bit sRGB PNG previews of linear frames (row 0 = top, as the frame).
//
// Per color channel: NaN -> 0, clamp to [0, 1], encode with the sRGB transfer function, scale to
// code units (x 255), add a triangular (TPDF) dither, round, clamp to [0, 255]. Alpha is linear
// coverage, not a color: it is clamped to [0, 1] and rounded, neither encoded nor dithered.
// The PNG itself is written by libpng's simplified API, which tags 8-bit color as sRGB.

#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <png.h>

#include <glm/vec4.hpp>

#include "fogcl/error.h"
#include "fogcl/exr_io.h"
#include "io/atomic_file.h"

namespace fogcl {


namespace {

// SplitMix64's output function (Steele, Lea, Flood, "Fast splittable pseudorandom number
// generators", OOPSLA 2014; constants of Stafford's "Mix13"): a bijective 64-bit mixer, used as a
// stateless per-pixel hash so that the same image always gives the same PNG.
std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// 24 random bits -> uniform in [-0.5, 0.5).
float centred_uniform(std::uint32_t bits) { return float(bits >> 8) * (1.0f / 16777216.0f) - 0.5f; }

// Triangular (TPDF) dither in code units: the sum of two independent uniforms in [-0.5, 0.5),
// so in [-1, 1) with mean 0; it makes the expected quantised value equal to the input (no
// banding, no bias) and the noise power independent of the signal.
float tpdf_dither(int x, int y, int channel) {
  const std::uint64_t key = (std::uint64_t(std::uint32_t(y)) << 32 | std::uint32_t(x)) +
                            std::uint64_t(channel + 1) * 0x9e3779b97f4a7c15ull;  // golden-ratio stride
  const std::uint64_t h = mix64(key);
  return centred_uniform(std::uint32_t(h >> 32)) + centred_uniform(std::uint32_t(h));
}

float clamp01(float v) {
  if (std::isnan(v)) return 0.0f;
  return v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
}

std::uint8_t quantise(float code) {
  const float r = std::floor(code + 0.5f);
  return std::uint8_t(r < 0.0f ? 0.0f : (r > 255.0f ? 255.0f : r));
}

std::uint8_t encode_color(float linear, int x, int y, int channel) {
  const float l = clamp01(linear);
  // Black and white stay exact: dithering them could only move them inwards (clamping), i.e.
  // add bias and noise to flat black or saturated areas.
  if (l == 0.0f) return 0;
  if (l == 1.0f) return 255;
  return quantise(float(srgb_encode(l)) * 255.0f + tpdf_dither(x, y, channel));
}

}  // namespace

void write_png_preview(const std::string& path, const ColorImage& image) {
  if (image.empty()) throw Error(path + ": cannot write PNG: the image is empty");
  const int width = image.width(), height = image.height();

  std::vector<std::uint8_t> pixels(image.pixel_count() * 4);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const glm::vec4 p = image.pixel(x, y);
      std::uint8_t* out = &pixels[4 * (std::size_t(y) * std::size_t(width) + std::size_t(x))];
      for (int c = 0; c < 3; ++c) out[c] = encode_color(p[c], x, y, c);
      out[3] = quantise(clamp01(p[3]) * 255.0f);
    }
  }

  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = png_uint_32(width);
  png.height = png_uint_32(height);
  png.format = PNG_FORMAT_RGBA;
  // Encode into memory (an upper bound first; libpng reports the size it needs if that was short),
  // so that the file itself goes through the shared temp-and-rename writer.
  png_alloc_size_t size = PNG_IMAGE_PNG_SIZE_MAX(png);
  std::vector<std::uint8_t> encoded(size);
  int ok = png_image_write_to_memory(&png, encoded.data(), &size, 0, pixels.data(), 0, nullptr);
  if (!ok && size > encoded.size()) {
    png_image_free(&png);
    png.warning_or_error = 0;
    encoded.resize(size);
    ok = png_image_write_to_memory(&png, encoded.data(), &size, 0, pixels.data(), 0, nullptr);
  }
  if (!ok) {
    const std::string reason = png.message;
    png_image_free(&png);
    throw Error(path + ": cannot write PNG: " + reason);
  }
  png_image_free(&png);

  detail::write_file_atomically(path, "PNG", [&](std::ostream& out, const std::string&) {
    out.write(reinterpret_cast<const char*>(encoded.data()), std::streamsize(size));
  });
}

}  // namespace fogcl
