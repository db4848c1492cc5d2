// numpy arrays as the library's views (fogcl/image.h), without copies: the rules an array must
// meet, each refused with a ValueError naming the argument and the rule (docs/python.md).
#pragma once

#include <string>
#include <vector>

#include <pybind11/numpy.h>

#include "fogcl/image.h"

namespace fogcl::python {

// H x W x 4 float32 or float16 whose pixels are packed along each row (rows may be strided).
ConstColorView color_view(const pybind11::array& a, const std::string& name);
ColorView writable_color_view(pybind11::array& a, const std::string& name);
// H x W float32, packed along each row.
ConstDepthView depth_view(const pybind11::array& a, const std::string& name);

// A new C-contiguous array of `shape` and `dtype` on page-aligned memory, which a CPU device reads
// and writes in place (docs/python.md, "Zero copy and alignment").
pybind11::array aligned_empty(const std::vector<pybind11::ssize_t>& shape, const pybind11::dtype& dtype);
// An array of color's shape and dtype, on page-aligned memory.
pybind11::array new_color_like(const pybind11::array& color);
// Arrays over an image's own memory (moved in; freed with the last array over it).
pybind11::array color_array(ColorImage image);
pybind11::array depth_array(DepthImage image);
// An array's memory as a ColorImage for a read-only use while the array lives (its rows packed);
// a copy when they are not.
ColorImage color_image_of(const pybind11::array& a, const std::string& name);

// "depth_channel" -> "depth-channel".
std::string cli_flag_name(const std::string& keyword);

}  // namespace fogcl::python
