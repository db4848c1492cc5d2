// What a frame of `fogcl apply` costs in memory, known from its header before anything is
// allocated: the --max-memory limit (default: half of the machine's memory) and the OpenCL device's
// largest allocation (CL_DEVICE_MAX_MEM_ALLOC_SIZE). A small file can describe a frame of
// gigabytes (a 20000x20000 display window around a few pixels of data): it is refused with one
// line naming the window and the size, not read until the machine runs out of memory.
#pragma once

#include <cstdint>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "fogcl/error.h"
#include "fogcl/exr_io.h"
#include "fogcl/image.h"

namespace fogcl {
class Runtime;
}

namespace fogcl::cli {

struct ApplyOptions;

// "8G", "512M", "1.5GiB", "2T", "65536" (bytes): binary units (K = 1024), case-insensitive, with
// an optional "B" or "iB". Throws fogcl::Error naming --max-memory for anything else, and for
// less than 1 MiB or more than 2^60 bytes.
std::uint64_t parse_memory_size(const std::string& text);

// "13.4 GiB", "512.0 MiB", "900.0 KiB", "12 bytes".
std::string memory_text(std::uint64_t bytes);

// The machine's memory: the physical memory, or the memory limit of this process's cgroup when
// that is lower (a container). *source says which ("physical memory", "cgroup limit").
std::uint64_t machine_memory(std::string* source);

struct MemoryLimit {
  std::uint64_t bytes = 0;
  std::string source;  // "--max-memory 8G", "default: half of the 23.5 GiB of physical memory"
};
// --max-memory's value; when empty, half of machine_memory().
MemoryLimit memory_limit(const std::string& flag);

// The run's choices that change what a frame allocates.
struct FrameMemoryNeeds {
  bool half_output = false;     // --pixel-type half: a float frame is converted for writing
  bool png = false;             // --png: an 8-bit copy and its encoding
  bool volumes = false;         // --volumes
  int volume_divisor = 1;       // --volume-resolution: 1 full, 2 half, 4 quarter (1 with --max-error)
  bool volumes_scalar = false;  // the volumes' scalar path (--device scalar): its own result frames
};

// The choices of a `fogcl apply` run (--max-error picks the volumes' resolution later: full is
// assumed, the most).
FrameMemoryNeeds frame_memory_needs(const ApplyOptions& options);

// The memory one frame needs, part by part, as `fogcl apply` allocates it for a frame of `shape`
// (P display-window pixels, D data-window pixels, L volume target pixels):
//   color      P x 16 bytes (RGBA float; 8 for half kept as half)
//   depth      P x 4
//   output     P x the color's bytes (the fogged frame)
//   conversion P x 8 when a float frame is written as half
//   preview    P x 8 with --png (the 8-bit pixels and their encoding, at most)
//   deep       D x 52 for a deep part: sample counts and per-channel sample pointers (the samples
//              themselves are bounded by ExrReadRequest::max_deep_samples)
//   volumes    L x 20: the march target (RGBA float) and its depth key; the scalar path adds its
//              result frame and coverage, P x 20
// On a CPU device the pass's buffers are these frames (CL_MEM_USE_HOST_PTR); on a GPU the copies
// live in the device's memory, bounded by check_device_allocations.
struct FrameMemoryPlan {
  std::vector<std::pair<std::string, std::uint64_t>> parts;
  std::uint64_t total() const;
  std::string text() const;  // "color 5.96 GiB, depth 1.49 GiB, output 5.96 GiB"
};
FrameMemoryPlan frame_memory(const ExrFrameShape& shape, const FrameMemoryNeeds& needs);

// Throws fogcl::Error "PATH: a WxH frame (display window (x0, y0)-(x1, y1)) needs about SIZE
// (parts), more than --max-memory LIMIT (source)" when the plan exceeds the limit.
void check_frame_memory(const std::string& path, const ExrFrameShape& shape, const FrameMemoryNeeds& needs,
                        const MemoryLimit& limit);

// The same for --shadow-map: "PATH: a WxH shadow map (display window ...) needs about SIZE (the map,
// its device copy), more than LIMIT (source)"; the map costs 8 bytes a pixel, loaded once a run.
void check_shadow_map_memory(const std::string& path, const ExrFrameShape& shape, const MemoryLimit& limit);

// What `fogcl demo` holds at its peak for a width x height scene (P pixels), the volumetric rows':
//   scenes              P x 40: the deferred rows' frame and the volumetric rows' (RGBA float, depth)
//   float64 references  P x 248: four volumetric ones (RGBA, coverage, the half-resolution target
//                       and its depth key: 50 a pixel) and the deferred fog's on one (48)
//   fogged frames       P x 32: a row's output and the reference's frame in float
//   volume buffers      P x 25: the scalar path's result frame and coverage, the march target
//   preview             P x 8: the 8-bit pixels and their encoding, at most
FrameMemoryPlan demo_memory(int width, int height);
// Throws fogcl::Error "a WxH scene needs about SIZE (parts), more than LIMIT (source): ..." when
// demo_memory exceeds the limit (--max-memory's, as fogcl apply's).
void check_demo_memory(int width, int height, const MemoryLimit& limit);

// Runs fn; an allocation that fails in it becomes one line naming what was being allocated,
// "out of memory WHAT (HINT)", instead of "std::bad_alloc". For the places that allocate frames,
// whose sizes --max-memory bounds but the machine's free memory may not cover.
template <class Fn>
auto naming_allocations(const std::string& what, const std::string& hint, Fn&& fn) -> decltype(fn()) {
  try {
    return fn();
  } catch (const std::bad_alloc&) {
    throw Error("out of memory " + what + (hint.empty() ? std::string() : " (" + hint + ")"));
  } catch (const OutOfMemory& e) {  // the library's, naming the buffer
    throw Error("out of memory " + what + " (" + e.what() + (hint.empty() ? std::string() : "; " + hint) + ")");
  }
}
// The hint for a frame's buffers: the machine had less free memory than the limit allows.
std::string frame_memory_hint(const MemoryLimit& limit);

// What the main thread is doing (a string literal), for main's last resort when an allocation fails
// where nothing nearer names it: "fogcl: error: out of memory while STAGE".
void set_memory_stage(const char* stage);
const char* memory_stage();

// Throws fogcl::Error "PATH: a WxH FORMAT frame needs a SIZE NAME buffer ..." when one of the frame's device buffers
// (color, depth, output; the volume target) is larger than the device's CL_DEVICE_MAX_MEM_ALLOC_SIZE, which the OpenCL
// call would refuse as CL_INVALID_BUFFER_SIZE.
void check_device_allocations(const std::string& path, const Runtime& runtime, int width, int height,
                              ColorFormat format, const FrameMemoryNeeds& needs);

}  // namespace fogcl::cli
