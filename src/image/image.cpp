#include "fogcl/image.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <new>
#include <string>
#include <utility>

#include <Imath/half.h>
#if defined(__linux__)
#include <sys/mman.h>
#include <sys/sysinfo.h>
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
  if (std::size_t(width) * std::size_t(height) > std::size_t(-1) / 16)
    throw Error(std::string(what) + " size " + std::to_string(width) + "x" + std::to_string(height) +
                " has more pixels than host memory can address");
}

std::string size_text(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

// The machine's memory and swap in bytes (0: unknown). An image larger than that can never be
// backed: where Linux overcommits memory, its allocation would succeed and the process be killed
// when the pages are touched, so it is refused first.
std::size_t machine_memory_bytes() {
#if defined(__linux__)
  struct sysinfo info {};
  if (sysinfo(&info) == 0) return (std::size_t(info.totalram) + std::size_t(info.totalswap)) * info.mem_unit;
#endif
  return 0;
}

// Page-aligned storage for an image, or fogcl::Error naming the image and the bytes it needed.
detail::AlignedBytes image_storage(const std::string& what, std::size_t bytes) {
  if (const std::size_t machine = machine_memory_bytes(); machine != 0 && bytes > machine)
    throw OutOfMemory(what + ": cannot allocate " + std::to_string(bytes) + " bytes (out of host memory: more than " +
                      "this machine's " + std::to_string(machine) + " bytes of memory and swap)");
  try {
    return detail::AlignedBytes(bytes);
  } catch (const std::bad_alloc&) {
    throw OutOfMemory(what + ": cannot allocate " + std::to_string(bytes) + " bytes (out of host memory)");
  }
}

void check_pixel(const char* what, int x, int y, int width, int height) {
  if (x < 0 || y < 0 || x >= width || y >= height)
    throw Error(std::string(what) + ": pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                ") is outside the " + size_text(width, height) + " image (x in [0, " + std::to_string(width) +
                "), y in [0, " + std::to_string(height) + "))");
}

// A view's checks (image.h); returns the stride in bytes.
std::size_t check_view(const char* what, const void* data, int width, int height, std::size_t row_bytes_per_pixel,
                       std::size_t channel, std::size_t row_stride) {
  check_size(what, width, height);
  if (data == nullptr) throw Error(std::string(what) + ": data is null");
  const std::size_t row = std::size_t(width) * row_bytes_per_pixel;
  const std::size_t stride = row_stride == 0 ? row : row_stride;
  if (stride < row)
    throw Error(std::string(what) + ": row stride " + std::to_string(row_stride) + " bytes is less than a row of " +
                std::to_string(width) + " pixels (" + std::to_string(row) + " bytes)");
  if (reinterpret_cast<std::uintptr_t>(data) % channel != 0 || stride % channel != 0)
    throw Error(std::string(what) + ": data address and row stride (" + std::to_string(stride) +
                " bytes) must be multiples of a channel's size, " + std::to_string(channel) + " bytes");
  return stride;
}

glm::vec4 load_pixel(const std::byte* p, ColorFormat format) {
  glm::vec4 v;
  for (int c = 0; c < 4; ++c) {
    if (format == ColorFormat::rgba32f) {
      float f;
      std::memcpy(&f, p + 4 * c, sizeof f);
      v[c] = f;
    } else {
      std::uint16_t bits;
      std::memcpy(&bits, p + 2 * c, sizeof bits);
      Imath::half h;
      h.setBits(bits);
      v[c] = float(h);
    }
  }
  return v;
}

void store_pixel(std::byte* p, ColorFormat format, const glm::vec4& rgba) {
  for (int c = 0; c < 4; ++c) {
    if (format == ColorFormat::rgba32f) {
      const float f = rgba[c];
      std::memcpy(p + 4 * c, &f, sizeof f);
    } else {
      const std::uint16_t bits = Imath::half(rgba[c]).bits();
      std::memcpy(p + 2 * c, &bits, sizeof bits);
    }
  }
}
}  // namespace

ConstColorView::ConstColorView(const void* data, int width, int height, ColorFormat format, std::size_t row_stride)
    : data_(data), width_(width), height_(height), format_(format) {
  stride_ = check_view("color view", data, width, height, bytes_per_pixel(format),
                       format == ColorFormat::rgba16f ? 2 : 4, row_stride);
}

glm::vec4 ConstColorView::pixel(int x, int y) const {
  check_pixel("color view", x, y, width_, height_);
  return load_pixel(row(y) + std::size_t(x) * bytes_per_pixel(format_), format_);
}

void ColorView::set_pixel(int x, int y, const glm::vec4& rgba) const {
  check_pixel("color view", x, y, width(), height());
  store_pixel(row(y) + std::size_t(x) * bytes_per_pixel(format()), format(), rgba);
}

ConstDepthView::ConstDepthView(const float* data, int width, int height, std::size_t row_stride)
    : data_(data), width_(width), height_(height) {
  stride_ = check_view("depth view", data, width, height, sizeof(float), sizeof(float), row_stride);
}

float ConstDepthView::at(int x, int y) const {
  check_pixel("depth view", x, y, width_, height_);
  return row(y)[x];
}

float& DepthView::at(int x, int y) const {
  check_pixel("depth view", x, y, width(), height());
  return row(y)[x];
}

std::size_t bytes_per_pixel(ColorFormat format) {
  return format == ColorFormat::rgba16f ? 4 * sizeof(std::uint16_t) : 4 * sizeof(float);
}

const char* to_string(ColorFormat format) {
  return format == ColorFormat::rgba16f ? "rgba16f" : "rgba32f";
}

namespace detail {
void AlignedBytes::Free::operator()(std::byte* p) {
  if (external)
    owner.reset();  // memory from elsewhere is never std::free'd, with or without an owner
  else
    std::free(p);
}

AlignedBytes::AlignedBytes(std::byte* external, std::size_t size, std::shared_ptr<void> owner)
    : data_(external, Free{std::move(owner), true}), size_(size) {}

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

AlignedBytes::AlignedBytes(const AlignedBytes& other) : AlignedBytes(image_storage("image copy", other.size_)) {
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
  bytes_ = image_storage("color image " + size_text(width, height) + " " + to_string(format), size_bytes());
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
  check_pixel("color image", x, y, width_, height_);
  return load_pixel(bytes_.data() + (std::size_t(y) * std::size_t(width_) + std::size_t(x)) * bytes_per_pixel(format_),
                    format_);
}

void ColorImage::set_pixel(int x, int y, const glm::vec4& rgba) {
  check_pixel("color image", x, y, width_, height_);
  store_pixel(bytes_.data() + (std::size_t(y) * std::size_t(width_) + std::size_t(x)) * bytes_per_pixel(format_),
              format_, rgba);
}

DepthImage::DepthImage(int width, int height, float fill) : width_(width), height_(height) {
  check_size("depth image", width, height);
  bytes_ = image_storage("depth image " + size_text(width, height), size_bytes());
  std::fill(data(), data() + pixel_count(), fill);
}

DepthImage::DepthImage(int width, int height, detail::AlignedBytes storage) : width_(width), height_(height) {
  check_size("depth image", width, height);
  if (storage.size() < size_bytes())
    throw Error("depth image storage holds " + std::to_string(storage.size()) + " bytes, " +
                std::to_string(size_bytes()) + " needed");
  bytes_ = std::move(storage);
}

std::size_t DepthImage::index(int x, int y) const {
  check_pixel("depth image", x, y, width_, height_);
  return std::size_t(y) * std::size_t(width_) + std::size_t(x);
}

void validate_frame(const ConstColorView& color, const ConstDepthView& depth) {
  if (color.empty()) throw Error("color image is empty (0x0)");
  if (depth.empty()) throw Error("depth image is empty (0x0)");
  if (color.width() != depth.width() || color.height() != depth.height())
    throw Error("color is " + size_text(color.width(), color.height()) + " but depth is " +
                size_text(depth.width(), depth.height()) + ": they must be the same size");
}

namespace {
bool overlap(const void* a, std::size_t a_bytes, const void* b, std::size_t b_bytes) {
  const auto x = reinterpret_cast<std::uintptr_t>(a), y = reinterpret_cast<std::uintptr_t>(b);
  return x < y + b_bytes && y < x + a_bytes;
}
}  // namespace

void validate_frame(const ConstColorView& color, const ConstDepthView& depth, const ConstColorView& out) {
  validate_frame(color, depth);
  if (out.empty()) throw Error("output image is empty (0x0)");
  if (out.width() != color.width() || out.height() != color.height() || out.format() != color.format())
    throw Error("output is " + size_text(out.width(), out.height()) + " " + to_string(out.format()) + " but input is " +
                size_text(color.width(), color.height()) + " " + to_string(color.format()) +
                ": a view cannot be resized, it must match");
  if (overlap(out.data(), out.span_bytes(), depth.data(), depth.span_bytes()))
    throw Error("output memory overlaps the depth image's");
  const bool in_place = out.data() == color.data() && out.row_stride() == color.row_stride();
  if (!in_place && overlap(out.data(), out.span_bytes(), color.data(), color.span_bytes()))
    throw Error("output memory overlaps the input's without being the same view (in place needs the same data "
                "and row stride)");
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
