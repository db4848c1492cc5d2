#include "fogcl/image.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>

#include <Imath/half.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "fogcl/error.h"

namespace fogcl {

namespace {
constexpr std::size_t kAlignment = 4096;  // page: satisfies every device's CL_DEVICE_MEM_BASE_ADDR_ALIGN
// Frames of 2 MiB and more sit on 2 MiB boundaries and ask Linux for transparent huge pages: a
// 1080p RGBA32F frame is then 16 page faults instead of 8100 (on a VM, 80 ms of a warm start's
// 200 ms to the first frame was faulting in the output), and 16 TLB entries when the pass
// streams through it.
constexpr std::size_t kHugePage = std::size_t(2) << 20;

void check_size(const char* what, int width, int height) {
  if (width < 1 || height < 1)
    throw Error(std::string(what) + " size must be at least 1x1 (got " + std::to_string(width) +
                "x" + std::to_string(height) + ")");
}
}  // namespace

std::size_t bytes_per_pixel(ColorFormat format) {
  return format == ColorFormat::rgba16f ? 4 * sizeof(std::uint16_t) : 4 * sizeof(float);
}

const char* to_string(ColorFormat format) {
  return format == ColorFormat::rgba16f ? "rgba16f" : "rgba32f";
}

namespace detail {
void AlignedBytes::Free::operator()(std::byte* p) {
  if (owner)
    owner.reset();
  else
    std::free(p);
}

AlignedBytes::AlignedBytes(std::byte* external, std::size_t size, std::shared_ptr<void> owner)
    : data_(external, Free{std::move(owner)}), size_(size) {}

AlignedBytes::AlignedBytes(std::size_t size) : size_(size) {
  const std::size_t alignment = size >= kHugePage ? kHugePage : kAlignment;
  const std::size_t rounded = (size + alignment - 1) / alignment * alignment;
  auto* p = static_cast<std::byte*>(std::aligned_alloc(alignment, rounded == 0 ? alignment : rounded));
  if (p == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (alignment == kHugePage) madvise(p, rounded, MADV_HUGEPAGE);  // advice only: failure is harmless
#endif
  std::memset(p, 0, rounded);
  data_.reset(p);
}

AlignedBytes::AlignedBytes(const AlignedBytes& other) : AlignedBytes(other.size_) {
  if (size_ != 0) std::memcpy(data_.get(), other.data_.get(), size_);
}

AlignedBytes& AlignedBytes::operator=(const AlignedBytes& other) {
  if (this != &other) *this = AlignedBytes(other);
  return *this;
}
}  // namespace detail

ColorImage::ColorImage(int width, int height, ColorFormat format)
    : width_(width), height_(height), format_(format) {
  check_size("color image", width, height);
  bytes_ = detail::AlignedBytes(size_bytes());
}

ColorImage::ColorImage(int width, int height, ColorFormat format, detail::AlignedBytes storage)
    : width_(width), height_(height), format_(format) {
  check_size("color image", width, height);
  if (storage.size() < size_bytes())
    throw Error("color image storage holds " + std::to_string(storage.size()) + " bytes, " +
                std::to_string(size_bytes()) + " needed");
  bytes_ = std::move(storage);
}

float* ColorImage::rgba32f() { return const_cast<float*>(std::as_const(*this).rgba32f()); }
const float* ColorImage::rgba32f() const {
  if (format_ != ColorFormat::rgba32f)
    throw Error(std::string("color image is ") + to_string(format_) + ", rgba32f access asked");
  return reinterpret_cast<const float*>(bytes_.data());
}
std::uint16_t* ColorImage::rgba16f() {
  return const_cast<std::uint16_t*>(std::as_const(*this).rgba16f());
}
const std::uint16_t* ColorImage::rgba16f() const {
  if (format_ != ColorFormat::rgba16f)
    throw Error(std::string("color image is ") + to_string(format_) + ", rgba16f access asked");
  return reinterpret_cast<const std::uint16_t*>(bytes_.data());
}

glm::vec4 ColorImage::pixel(int x, int y) const {
  const std::size_t i = 4 * (std::size_t(y) * std::size_t(width_) + std::size_t(x));
  glm::vec4 v;
  for (int c = 0; c < 4; ++c) {
    if (format_ == ColorFormat::rgba32f) {
      v[c] = rgba32f()[i + c];
    } else {
      Imath::half h;
      h.setBits(rgba16f()[i + c]);
      v[c] = float(h);
    }
  }
  return v;
}

void ColorImage::set_pixel(int x, int y, const glm::vec4& rgba) {
  const std::size_t i = 4 * (std::size_t(y) * std::size_t(width_) + std::size_t(x));
  for (int c = 0; c < 4; ++c) {
    if (format_ == ColorFormat::rgba32f)
      rgba32f()[i + c] = rgba[c];
    else
      rgba16f()[i + c] = Imath::half(rgba[c]).bits();
  }
}

DepthImage::DepthImage(int width, int height, float fill) : width_(width), height_(height) {
  check_size("depth image", width, height);
  bytes_ = detail::AlignedBytes(size_bytes());
  std::fill(data(), data() + pixel_count(), fill);
}

DepthImage::DepthImage(int width, int height, detail::AlignedBytes storage) : width_(width), height_(height) {
  check_size("depth image", width, height);
  if (storage.size() < size_bytes())
    throw Error("depth image storage holds " + std::to_string(storage.size()) + " bytes, " +
                std::to_string(size_bytes()) + " needed");
  bytes_ = std::move(storage);
}

void validate_frame(const ColorImage& color, const DepthImage& depth) {
  if (color.empty()) throw Error("color image is empty (0x0)");
  if (depth.empty()) throw Error("depth image is empty (0x0)");
  if (color.width() != depth.width() || color.height() != depth.height())
    throw Error("color is " + std::to_string(color.width()) + "x" + std::to_string(color.height()) +
                " but depth is " + std::to_string(depth.width()) + "x" + std::to_string(depth.height()) +
                ": they must be the same size");
}

double srgb_encode(double linear) {
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

double ulp_of(double x, ColorFormat format) {
  x = std::fabs(x);
  if (!std::isfinite(x)) return x;  // NaN has no ulp; infinity's is infinite
  if (format == ColorFormat::rgba16f)
    return x < 6.103515625e-05 ? std::ldexp(1.0, -24) : std::ldexp(1.0, int(std::floor(std::log2(x))) - 10);
  if (x < 1.1754943508222875e-38) return std::ldexp(1.0, -149);
  return std::ldexp(1.0, int(std::floor(std::log2(x))) - 23);
}

ColorImage uniform_image(int width, int height, ColorFormat format, const glm::vec4& rgba) {
  ColorImage image(width, height, format);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) image.set_pixel(x, y, rgba);
  return image;
}

ColorImage convert(const ColorImage& image, ColorFormat format) {
  if (image.format() == format) return image;
  ColorImage out(image.width(), image.height(), format);
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) out.set_pixel(x, y, image.pixel(x, y));
  return out;
}

}  // namespace fogcl
