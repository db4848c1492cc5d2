// Host images: the frame a renderer hands over (docs/DESIGN.md §1, §2). Rows are stored top row
// first; storage is page-aligned so OpenCL CPU devices can use it in place (CL_MEM_USE_HOST_PTR).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include <glm/vec4.hpp>

namespace fogcl {

enum class ColorFormat {
  rgba32f,  // 4 x float32 per pixel
  rgba16f,  // 4 x IEEE half per pixel (stored as raw 16-bit patterns)
};

std::size_t bytes_per_pixel(ColorFormat format);
const char* to_string(ColorFormat format);

namespace detail {
// Page-aligned, zero-initialised byte storage with value semantics. Or memory from elsewhere
// (pinned host memory of an OpenCL context: FogPass::pinned_color_image), kept alive by `owner`;
// a copy of it is ordinary memory.
class AlignedBytes {
 public:
  AlignedBytes() = default;
  explicit AlignedBytes(std::size_t size);
  AlignedBytes(std::byte* external, std::size_t size, std::shared_ptr<void> owner);
  AlignedBytes(const AlignedBytes& other);
  AlignedBytes& operator=(const AlignedBytes& other);
  AlignedBytes(AlignedBytes&&) noexcept = default;
  AlignedBytes& operator=(AlignedBytes&&) noexcept = default;
  std::byte* data() const { return data_.get(); }
  std::size_t size() const { return size_; }

 private:
  struct Free {
    std::shared_ptr<void> owner;  // external memory: released with it; else std::free
    void operator()(std::byte* p);
  };
  std::unique_ptr<std::byte[], Free> data_;
  std::size_t size_ = 0;
};
}  // namespace detail

// Linear RGBA color, row-major, row 0 = top. Alpha is carried, never modified by the fog pass.
// Threads: a value type; concurrent reads are fine, a write needs the only reference.
class ColorImage {
 public:
  ColorImage() = default;
  // width, height >= 1 (throws fogcl::Error otherwise); pixels start as (0, 0, 0, 0).
  ColorImage(int width, int height, ColorFormat format = ColorFormat::rgba32f);
  // Over `storage` (at least width * height pixels; throws otherwise), as FogPass's pinned images.
  ColorImage(int width, int height, ColorFormat format, detail::AlignedBytes storage);

  int width() const { return width_; }
  int height() const { return height_; }
  ColorFormat format() const { return format_; }
  bool empty() const { return width_ == 0 || height_ == 0; }
  std::size_t pixel_count() const { return std::size_t(width_) * std::size_t(height_); }
  std::size_t size_bytes() const { return pixel_count() * bytes_per_pixel(format_); }

  void* data() { return bytes_.data(); }
  const void* data() const { return bytes_.data(); }
  // Typed access; throws fogcl::Error if the format differs.
  float* rgba32f();
  const float* rgba32f() const;
  std::uint16_t* rgba16f();
  const std::uint16_t* rgba16f() const;

  // Converting accessors (half <-> float round to nearest even).
  glm::vec4 pixel(int x, int y) const;
  void set_pixel(int x, int y, const glm::vec4& rgba);

 private:
  int width_ = 0, height_ = 0;
  ColorFormat format_ = ColorFormat::rgba32f;
  detail::AlignedBytes bytes_;
};

// Raw device depth as a depth buffer stores it: float32 in [0, 1] (docs/DESIGN.md §2).
// Threads: as ColorImage.
class DepthImage {
 public:
  DepthImage() = default;
  // width, height >= 1; pixels start at `fill`.
  DepthImage(int width, int height, float fill = 0.0f);
  // Over `storage` (at least width * height floats; throws otherwise), as FogPass's pinned images.
  DepthImage(int width, int height, detail::AlignedBytes storage);

  int width() const { return width_; }
  int height() const { return height_; }
  bool empty() const { return width_ == 0 || height_ == 0; }
  std::size_t pixel_count() const { return std::size_t(width_) * std::size_t(height_); }
  std::size_t size_bytes() const { return pixel_count() * sizeof(float); }

  float* data() { return reinterpret_cast<float*>(bytes_.data()); }
  const float* data() const { return reinterpret_cast<const float*>(bytes_.data()); }
  float at(int x, int y) const { return data()[std::size_t(y) * std::size_t(width_) + std::size_t(x)]; }
  float& at(int x, int y) { return data()[std::size_t(y) * std::size_t(width_) + std::size_t(x)]; }

 private:
  int width_ = 0, height_ = 0;
  detail::AlignedBytes bytes_;
};

// Throws fogcl::Error unless color and depth are non-empty and of the same size.
void validate_frame(const ColorImage& color, const DepthImage& depth);

// A width x height image with every pixel `rgba` (e.g. the white probe that makes a fogged
// output equal the fog factor).
ColorImage uniform_image(int width, int height, ColorFormat format, const glm::vec4& rgba);

// sRGB transfer function (IEC 61966-2-1:1999, §5.2): linear light in [0, 1] to the encoded value
// in [0, 1]; 12.92 L for L <= 0.0031308, else 1.055 L^(1/2.4) - 0.055.
double srgb_encode(double linear);

// One unit in the last place of the storage format at |x| (half: 2^-24 in the subnormal range;
// float: 2^-149 there).
double ulp_of(double x, ColorFormat format);

// Converts a color image to another storage format (round to nearest even for half).
ColorImage convert(const ColorImage& image, ColorFormat format);

}  // namespace fogcl
