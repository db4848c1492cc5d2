#include "image/packed_frame.h"

#include <cstdint>
#include <cstring>

namespace fogcl::detail {

bool usable_in_place(const void* data, bool packed, std::size_t alignment) {
  return packed && reinterpret_cast<std::uintptr_t>(data) % alignment == 0;
}

void copy_pixels(const ConstColorView& from, const ColorView& to) {
  if (from.data() == to.data()) return;  // in place
  if (from.packed() && to.packed()) {
    std::memcpy(to.data(), from.data(), from.span_bytes());
    return;
  }
  for (int y = 0; y < from.height(); ++y) std::memcpy(to.row(y), from.row(y), from.row_bytes());
}

void copy_pixels(const ConstDepthView& from, const DepthView& to) {
  if (from.packed() && to.packed()) {
    std::memcpy(to.data(), from.data(), from.span_bytes());
    return;
  }
  for (int y = 0; y < from.height(); ++y) std::memcpy(to.row(y), from.row(y), from.row_bytes());
}

PackedFrame::PackedFrame(const ConstColorView& in_view, const ConstDepthView& depth_view, const ColorView& out_view,
                         std::size_t alignment)
    : in(in_view), depth(depth_view), out(out_view), caller_out_(out_view) {
  in_place = out_view.data() == in_view.data();
  if (!usable_in_place(in.data(), in.packed(), alignment)) {
    in_copy_ = ColorImage(in.width(), in.height(), in.format());
    copy_pixels(in_view, in_copy_.view());
    in = in_copy_.view();
    copied_ = true;
    if (in_place) {
      out = in_copy_.view();
      out_copied_ = true;
    }
  }
  if (!in_place && !usable_in_place(out.data(), out.packed(), alignment)) {
    out_copy_ = ColorImage(out.width(), out.height(), out.format());
    out = out_copy_.view();
    copied_ = out_copied_ = true;
  }
  if (!usable_in_place(depth.data(), depth.packed(), alignment)) {
    depth_copy_ = DepthImage(depth.width(), depth.height());
    copy_pixels(depth_view, depth_copy_.view());
    depth = depth_copy_.view();
    copied_ = true;
  }
}

void PackedFrame::write_back() const {
  if (out_copied_) copy_pixels(out, caller_out_);
}

ConstDepthView packed_depth(const ConstDepthView& depth, DepthImage& copy) {
  if (depth.packed()) return depth;
  copy = DepthImage(depth.width(), depth.height());
  copy_pixels(depth, copy.view());
  return copy.view();
}

}  // namespace fogcl::detail
