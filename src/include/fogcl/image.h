// Host images: the frame a renderer hands over (docs/DESIGN.md §1, §2). Rows are stored top row
// first; storage is page-aligned so OpenCL CPU devices can use it in place (CL_MEM_USE_HOST_PTR).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>

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
    Free() noexcept : external(false) {}
    Free(std::shared_ptr<void> o, bool e) noexcept : owner(std::move(o)), external(e) {}
    std::shared_ptr<void> owner;  // external memory: released with it (may be empty)
    bool external;                // else the memory is std::free'd
    void operator()(std::byte* p);
  };
  std::unique_ptr<std::byte[], Free> data_;
  std::size_t size_ = 0;
};
}  // namespace detail

// Views: the caller's own memory as a frame, not owned (docs/library.md#images-and-views). Row 0 =
// top; row y starts row_stride bytes after row y - 1 (0 = tight: width * bytes per pixel). The
// constructor throws fogcl::Error naming the rule when data is null, width or height < 1, the
// stride is below a row's bytes, or data or stride are not multiples of a channel's size (4 bytes
// for float, 2 for half). The memory must stay alive (and, for an input, unchanged) for the call
// that takes the view, and an asynchronous call's output until its wait().
class ConstColorView {
 public:
  ConstColorView() = default;
  ConstColorView(const void* data, int width, int height, ColorFormat format = ColorFormat::rgba32f,
                 std::size_t row_stride = 0);
  const void* data() const { return data_; }
  int width() const { return width_; }
  int height() const { return height_; }
  ColorFormat format() const { return format_; }
  std::size_t row_stride() const { return stride_; }  // bytes, never 0 once constructed
  bool empty() const { return width_ == 0 || height_ == 0; }
  std::size_t pixel_count() const { return std::size_t(width_) * std::size_t(height_); }
  std::size_t row_bytes() const { return std::size_t(width_) * bytes_per_pixel(format_); }
  // Rows without padding: the memory is one run of pixel_count() pixels.
  bool packed() const { return stride_ == row_bytes(); }
  // From the first byte to the last row's end.
  std::size_t span_bytes() const { return empty() ? 0 : stride_ * std::size_t(height_ - 1) + row_bytes(); }
  const std::byte* row(int y) const { return static_cast<const std::byte*>(data_) + std::size_t(y) * stride_; }
  // Converting read (half -> float); throws fogcl::Error outside [0, width) x [0, height).
  glm::vec4 pixel(int x, int y) const;

 private:
  const void* data_ = nullptr;
  int width_ = 0, height_ = 0;
  ColorFormat format_ = ColorFormat::rgba32f;
  std::size_t stride_ = 0;
};

class ColorView {
 public:
  ColorView() = default;
  ColorView(void* data, int width, int height, ColorFormat format = ColorFormat::rgba32f,
            std::size_t row_stride = 0)
      : view_(data, width, height, format, row_stride) {}
  operator const ConstColorView&() const { return view_; }
  void* data() const { return const_cast<void*>(view_.data()); }
  int width() const { return view_.width(); }
  int height() const { return view_.height(); }
  ColorFormat format() const { return view_.format(); }
  std::size_t row_stride() const { return view_.row_stride(); }
  bool empty() const { return view_.empty(); }
  std::size_t pixel_count() const { return view_.pixel_count(); }
  std::size_t row_bytes() const { return view_.row_bytes(); }
  bool packed() const { return view_.packed(); }
  std::size_t span_bytes() const { return view_.span_bytes(); }
  std::byte* row(int y) const { return const_cast<std::byte*>(view_.row(y)); }
  glm::vec4 pixel(int x, int y) const { return view_.pixel(x, y); }
  // Converting write (float -> half rounds to nearest even); throws fogcl::Error out of range.
  void set_pixel(int x, int y, const glm::vec4& rgba) const;

 private:
  ConstColorView view_;
};

// float32 depth (DepthImage's contents) in the caller's memory; rules as ConstColorView.
class ConstDepthView {
 public:
  ConstDepthView() = default;
  ConstDepthView(const float* data, int width, int height, std::size_t row_stride = 0);
  const float* data() const { return data_; }
  int width() const { return width_; }
  int height() const { return height_; }
  std::size_t row_stride() const { return stride_; }  // bytes
  bool empty() const { return width_ == 0 || height_ == 0; }
  std::size_t pixel_count() const { return std::size_t(width_) * std::size_t(height_); }
  std::size_t row_bytes() const { return std::size_t(width_) * sizeof(float); }
  bool packed() const { return stride_ == row_bytes(); }
  std::size_t span_bytes() const { return empty() ? 0 : stride_ * std::size_t(height_ - 1) + row_bytes(); }
  const float* row(int y) const {
    return reinterpret_cast<const float*>(reinterpret_cast<const std::byte*>(data_) + std::size_t(y) * stride_);
  }
  // Throws fogcl::Error outside [0, width) x [0, height).
  float at(int x, int y) const;

 private:
  const float* data_ = nullptr;
  int width_ = 0, height_ = 0;
  std::size_t stride_ = 0;
};

class DepthView {
 public:
  DepthView() = default;
  DepthView(float* data, int width, int height, std::size_t row_stride = 0) : view_(data, width, height, row_stride) {}
  operator const ConstDepthView&() const { return view_; }
  float* data() const { return const_cast<float*>(view_.data()); }
  int width() const { return view_.width(); }
  int height() const { return view_.height(); }
  std::size_t row_stride() const { return view_.row_stride(); }
  bool empty() const { return view_.empty(); }
  std::size_t pixel_count() const { return view_.pixel_count(); }
  std::size_t row_bytes() const { return view_.row_bytes(); }
  bool packed() const { return view_.packed(); }
  std::size_t span_bytes() const { return view_.span_bytes(); }
  float* row(int y) const { return const_cast<float*>(view_.row(y)); }
  float& at(int x, int y) const;  // throws fogcl::Error out of range

 private:
  ConstDepthView view_;
};

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

  // Converting accessors (half <-> float round to nearest even). Checked: a pixel outside
  // [0, width) x [0, height) throws fogcl::Error (bulk access: data(), rgba32f(), rgba16f()).
  glm::vec4 pixel(int x, int y) const;
  void set_pixel(int x, int y, const glm::vec4& rgba);

  // The image as a view (packed rows; an empty image gives an empty view, which the calls
  // reject as empty); valid while the image lives and is not reassigned.
  ColorView view() { return empty() ? ColorView() : ColorView(data(), width_, height_, format_); }
  ConstColorView view() const { return empty() ? ConstColorView() : ConstColorView(data(), width_, height_, format_); }
  operator ColorView() { return view(); }
  operator ConstColorView() const { return view(); }

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
  // Checked: outside [0, width) x [0, height) throws fogcl::Error (bulk access: data()).
  float at(int x, int y) const { return data()[index(x, y)]; }
  float& at(int x, int y) { return data()[index(x, y)]; }

  DepthView view() { return empty() ? DepthView() : DepthView(data(), width_, height_); }
  ConstDepthView view() const { return empty() ? ConstDepthView() : ConstDepthView(data(), width_, height_); }
  operator DepthView() { return view(); }
  operator ConstDepthView() const { return view(); }

 private:
  std::size_t index(int x, int y) const;
  int width_ = 0, height_ = 0;
  detail::AlignedBytes bytes_;
};

// Throws fogcl::Error unless color and depth are non-empty and of the same size.
void validate_frame(const ConstColorView& color, const ConstDepthView& depth);
// The same, and `out` of color's size and format, either color itself (the same memory and
// stride: in place) or memory that overlaps neither color nor depth.
void validate_frame(const ConstColorView& color, const ConstDepthView& depth, const ConstColorView& out);

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
