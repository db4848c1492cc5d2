// What every public entry point of the passes does around its work: only fogcl::Error (and
// ClError) leave the library (fogcl/error.h), the checks of a call's arguments that both passes
// share, and the sizing of a ColorImage output.
#pragma once

#include <exception>
#include <new>
#include <string>
#include <vector>

#include "fogcl/camera.h"
#include "fogcl/error.h"
#include "fogcl/image.h"
#include "fogcl/opencl_types.h"

namespace fogcl::detail {

// fn(), with a failed allocation (std::bad_alloc) or any other standard exception turned into
// fogcl::Error naming `who`. fogcl::Error passes as it is.
template <class Fn>
auto host_call(const char* who, Fn&& fn) -> decltype(fn()) {
  try {
    return fn();
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw OutOfMemory(std::string(who) + ": out of host memory (an allocation for the frame failed)");
  } catch (const std::exception& e) {
    throw Error(std::string(who) + ": " + e.what());
  }
}

// Throws fogcl::Error naming the index of a null event in `wait_list`.
inline void check_wait_list(const std::vector<cl_event>& wait_list, const char* who) {
  for (std::size_t i = 0; i < wait_list.size(); ++i)
    if (wait_list[i] == nullptr)
      throw Error(std::string(who) + ": wait_list[" + std::to_string(i) +
                  "] is a null event (every event in a wait list must be a valid cl_event)");
}

// A ColorImage call's checks, then `out` given in's size and format unless it is in or has them
// already: a call that throws leaves `out` as it was.
inline void size_output(const ColorImage& in, const DepthImage& depth, ColorImage& out, const CameraParams& camera) {
  validate_frame(in, depth);
  validate(camera, in.width(), in.height());
  if (&out != &in && (out.width() != in.width() || out.height() != in.height() || out.format() != in.format()))
    out = ColorImage(in.width(), in.height(), in.format());
}

}  // namespace fogcl::detail
