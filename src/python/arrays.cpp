#include "python/arrays.h"

#include <cstdlib>
#include <cstring>
#include <limits>

#include "fogcl/error.h"

namespace py = pybind11;

namespace fogcl::python {

namespace {

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}
std::string strides_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.strides(i));
  return s + ")";
}
std::string dtype_text(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

int dimension(const py::array& a, int axis, const std::string& name) {
  const py::ssize_t n = a.shape(axis);
  if (n < 1 || n > std::numeric_limits<int>::max())
    throw py::value_error(name + " must have at least one row and one column (got shape " + shape_text(a) + ")");
  return int(n);
}

ColorFormat color_format(const py::array& a, const std::string& name) {
  if (a.ndim() != 3 || a.shape(2) != 4 || !(a.dtype().is(py::dtype::of<float>()) || a.dtype().is(py::dtype("float16"))))
    throw py::value_error(name + " must be an H x W x 4 array (RGBA) of float32 or float16 (got shape " +
                          shape_text(a) + ", dtype " + dtype_text(a) + ")");
  return a.itemsize() == 4 ? ColorFormat::rgba32f : ColorFormat::rgba16f;
}

// The row stride in bytes once the pixels are checked packed along the row.
std::size_t color_row_stride(const py::array& a, const std::string& name) {
  const py::ssize_t c = a.itemsize();
  if (a.strides(2) != c || (a.shape(1) > 1 && a.strides(1) != 4 * c) || (a.shape(0) > 1 && a.strides(0) <= 0))
    throw py::value_error(name + "'s pixels must follow one another along each row, rows top first (strides " +
                          std::to_string(4 * c) + ", " + std::to_string(c) + " bytes for the last two axes; got " +
                          strides_text(a) + "): np.ascontiguousarray(" + name + ") makes a copy that is");
  return a.shape(0) > 1 ? std::size_t(a.strides(0)) : std::size_t(a.shape(1) * 4 * c);
}

}  // namespace

ConstColorView color_view(const py::array& a, const std::string& name) {
  const ColorFormat format = color_format(a, name);
  const std::size_t stride = color_row_stride(a, name);
  try {
    return ConstColorView(a.data(), dimension(a, 1, name), dimension(a, 0, name), format, stride);
  } catch (const Error& e) {
    throw py::value_error(name + ": " + e.what());
  }
}

ColorView writable_color_view(py::array& a, const std::string& name) {
  const ColorFormat format = color_format(a, name);
  const std::size_t stride = color_row_stride(a, name);
  if (!a.writeable()) throw py::value_error(name + " is read-only (its writeable flag is off)");
  try {
    return ColorView(a.mutable_data(), dimension(a, 1, name), dimension(a, 0, name), format, stride);
  } catch (const Error& e) {
    throw py::value_error(name + ": " + e.what());
  }
}

ConstDepthView depth_view(const py::array& a, const std::string& name) {
  if (a.ndim() != 2 || !a.dtype().is(py::dtype::of<float>()))
    throw py::value_error(name + " must be an H x W array of float32 (got shape " + shape_text(a) + ", dtype " +
                          dtype_text(a) + ")");
  if ((a.shape(1) > 1 && a.strides(1) != 4) || (a.shape(0) > 1 && a.strides(0) <= 0))
    throw py::value_error(name + "'s values must follow one another along each row, rows top first (stride 4 "
                          "bytes for the last axis; got " + strides_text(a) + "): np.ascontiguousarray(" + name +
                          ") makes a copy that is");
  const std::size_t stride = a.shape(0) > 1 ? std::size_t(a.strides(0)) : std::size_t(a.shape(1) * 4);
  try {
    return ConstDepthView(static_cast<const float*>(a.data()), dimension(a, 1, name), dimension(a, 0, name), stride);
  } catch (const Error& e) {
    throw py::value_error(name + ": " + e.what());
  }
}

py::array aligned_empty(const std::vector<py::ssize_t>& shape, const py::dtype& dtype) {
  constexpr std::size_t kPage = 4096;
  std::size_t bytes = std::size_t(dtype.itemsize());
  for (py::ssize_t n : shape) {
    if (n < 0) throw py::value_error("a shape has no negative sizes");
    if (n > 0 && bytes > std::numeric_limits<std::size_t>::max() / std::size_t(n)) throw std::bad_alloc();
    bytes *= std::size_t(n);
  }
  void* p = std::aligned_alloc(kPage, std::max(kPage, (bytes + kPage - 1) / kPage * kPage));
  if (p == nullptr) throw std::bad_alloc();
  py::capsule owner(p, [](void* q) { std::free(q); });
  return py::array(dtype, shape, {}, p, owner);
}

py::array new_color_like(const py::array& color) {
  return aligned_empty({color.shape(0), color.shape(1), 4}, color.dtype());
}

py::array color_array(ColorImage image) {
  auto* held = new ColorImage(std::move(image));
  py::capsule owner(held, [](void* q) { delete static_cast<ColorImage*>(q); });
  const py::dtype dtype = held->format() == ColorFormat::rgba32f ? py::dtype::of<float>() : py::dtype("float16");
  return py::array(dtype, {py::ssize_t(held->height()), py::ssize_t(held->width()), py::ssize_t(4)}, {},
                   held->data(), owner);
}

py::array depth_array(DepthImage image) {
  auto* held = new DepthImage(std::move(image));
  py::capsule owner(held, [](void* q) { delete static_cast<DepthImage*>(q); });
  return py::array(py::dtype::of<float>(), {py::ssize_t(held->height()), py::ssize_t(held->width())}, {},
                   held->data(), owner);
}

ColorImage color_image_of(const py::array& a, const std::string& name) {
  const ConstColorView v = color_view(a, name);
  if (v.packed())  // the array's own memory, which the caller keeps alive and the use only reads
    return ColorImage(v.width(), v.height(), v.format(),
                      detail::AlignedBytes(const_cast<std::byte*>(static_cast<const std::byte*>(v.data())),
                                           v.span_bytes(), nullptr));
  ColorImage image(v.width(), v.height(), v.format());
  for (int y = 0; y < v.height(); ++y) std::memcpy(image.view().row(y), v.row(y), v.row_bytes());
  return image;
}

std::string cli_flag_name(const std::string& keyword) {
  std::string flag = keyword;
  for (char& c : flag)
    if (c == '_') c = '-';
  return flag;
}

}  // namespace fogcl::python
