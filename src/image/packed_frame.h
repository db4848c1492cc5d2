// A convenience call's frame as the kernels and the scalar loops take it: packed rows (no
// padding) starting at a multiple of the device's alignment. Views that are so are used where
// they are; the others are copied once into page-aligned images, the output copied back by
// write_back() (docs/library.md#images-and-views).
#pragma once

#include <cstddef>

#include "fogcl/image.h"

namespace fogcl::detail {

// Whether memory at `data` with these rows can be handed to a kernel as it is.
bool usable_in_place(const void* data, bool packed, std::size_t alignment);

// Rows of `from` into `to` (same size and format; any strides).
void copy_pixels(const ConstColorView& from, const ColorView& to);
void copy_pixels(const ConstDepthView& from, const DepthView& to);

class PackedFrame {
 public:
  // in, depth and out as validate_frame(in, depth, out) accepts them (checked by the caller).
  PackedFrame(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out, std::size_t alignment);
  PackedFrame(PackedFrame&&) noexcept = default;
  PackedFrame& operator=(PackedFrame&&) noexcept = default;

  ConstColorView in;
  ConstDepthView depth;
  ColorView out;          // in's memory when in place
  bool in_place = false;  // out is in (the caller's same view)
  bool copied() const { return copied_; }
  // The result into the caller's output, when it was computed in a copy.
  void write_back() const;

 private:
  ColorView caller_out_;
  bool copied_ = false, out_copied_ = false;
  ColorImage in_copy_, out_copy_;
  DepthImage depth_copy_;
};

// A packed depth view over `depth` or over `copy` (filled from it) when depth has padded rows.
ConstDepthView packed_depth(const ConstDepthView& depth, DepthImage& copy);

}  // namespace fogcl::detail
