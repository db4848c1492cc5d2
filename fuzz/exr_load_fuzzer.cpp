// libFuzzer target over fogcl's EXR loading path (src/io/exr_read.cpp, exr_precheck.cpp): the
// bytes go through read_exr_memory, the very code `fogcl apply` runs on a file. The contract under
// test: any input either reads or throws fogcl::Error; no crash, no other exception, no
// sanitizer report, no runaway allocation. Built with clang (-fsanitize=fuzzer,address,undefined)
// by `make fuzz`, which runs it on the seed corpus fuzz/make_seeds writes.
#include <cstddef>
#include <cstdint>

#include "fogcl/error.h"
#include "fogcl/exr_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fogcl::ExrReadRequest request;
  // Small limits keep corrupt sizes from allocating the fuzzer's memory budget (the tool's own
  // limits are larger; the code paths are the same).
  request.max_pixels = 1 << 16;
  request.max_deep_samples = 1 << 18;
  request.depth_channel = "Z";
  request.depth_outside = 1.0f;
  try {
    fogcl::read_exr_memory(data, size, "fuzz.exr", request);
  } catch (const fogcl::Error&) {
  }
  // The --depth FILE path: depth only, a single channel's name whatever it is; and a layer.
  request.read_color = false;
  request.depth_single_channel_fallback = true;
  try {
    fogcl::read_exr_memory(data, size, "fuzz.exr", request);
  } catch (const fogcl::Error&) {
  }
  request.read_color = true;
  request.depth_channel.clear();
  request.layer = "beauty";
  try {
    fogcl::read_exr_memory(data, size, "fuzz.exr", request);
  } catch (const fogcl::Error&) {
  }
  return 0;
}
