#include "cli/frame_memory.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "cli/cli.h"
#include "fogcl/error.h"
#include "fogcl/runtime.h"
#include "runtime/clhpp.h"

namespace fogcl::cli {

namespace {

std::string window_text(const ExrWindows& w) {
  return "(" + std::to_string(w.display_min.x) + ", " + std::to_string(w.display_min.y) + ")-(" +
         std::to_string(w.display_max.x) + ", " + std::to_string(w.display_max.y) + ")";
}

// Pixels lo..hi of a window's side (0 when empty).
std::uint64_t extent(int lo, int hi) { return std::uint64_t(std::max<std::int64_t>(0, std::int64_t(hi) - lo + 1)); }

// The volume pass's march target for a width x height frame: ceil(W / s) x ceil(H / s) pixels.
std::uint64_t volume_target_pixels(std::uint64_t width, std::uint64_t height, int divisor) {
  const std::uint64_t s = std::uint64_t(std::max(divisor, 1));
  return ((width + s - 1) / s) * ((height + s - 1) / s);
}

// The first number in a cgroup file ("max" and unreadable files: 0, no limit).
std::uint64_t cgroup_limit(const char* path) {
  std::ifstream in(path);
  std::string text;
  if (!(in >> text) || text.empty() || !std::isdigit(static_cast<unsigned char>(text[0]))) return 0;
  return std::strtoull(text.c_str(), nullptr, 10);
}

}  // namespace

std::uint64_t parse_memory_size(const std::string& text) {
  const auto bad = [&](const std::string& why) {
    return Error(
        "--max-memory must be a size such as 8G, 512M or 1.5GiB (binary units, K = 1024 bytes; a plain "
        "number is bytes)" +
        why + " (got '" + text + "')");
  };
  std::size_t end = 0;
  while (end < text.size() && (std::isdigit(static_cast<unsigned char>(text[end])) || text[end] == '.')) ++end;
  if (end == 0 || std::count(text.begin(), text.begin() + long(end), '.') > 1 || text[0] == '.' ||
      text[end - 1] == '.' || end > 24)
    throw bad("");
  const double number = std::strtod(text.substr(0, end).c_str(), nullptr);
  std::string unit = text.substr(end);
  for (char& c : unit) c = char(std::toupper(static_cast<unsigned char>(c)));
  static const struct {
    const char* prefix;
    int shift;
  } units[] = {{"", 0}, {"K", 10}, {"M", 20}, {"G", 30}, {"T", 40}};
  int shift = -1;
  for (const auto& u : units) {
    const std::string p = u.prefix;
    if (unit == p || (!p.empty() && (unit == p + "B" || unit == p + "IB")) || (p.empty() && unit == "B"))
      shift = u.shift;
  }
  if (shift < 0) throw bad("");
  const double bytes = std::ldexp(number, shift);
  if (!(bytes >= double(1 << 20))) throw bad(": at least 1M");
  if (bytes > std::ldexp(1.0, 60)) throw bad(": at most 2^60 bytes");
  return std::uint64_t(bytes);
}

std::string memory_text(std::uint64_t bytes) {
  static const char* const units[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  if (bytes < 1024) return std::to_string(bytes) + " bytes";
  double v = double(bytes) / 1024;
  int u = 0;
  while (v >= 1024 && u < 5) v /= 1024, ++u;
  char buf[32];
  std::snprintf(buf, sizeof buf, v < 10 ? "%.2f %s" : "%.1f %s", v, units[u]);
  return buf;
}

std::uint64_t machine_memory(std::string* source) {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  std::uint64_t bytes = pages > 0 && page > 0 ? std::uint64_t(pages) * std::uint64_t(page) : 0;
  *source = "physical memory";
  // A container's limit: cgroup v2, else v1 (whose "no limit" is a huge number, above the physical).
  for (const char* path : {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    const std::uint64_t limit = cgroup_limit(path);
    if (limit > 0 && (bytes == 0 || limit < bytes)) {
      bytes = limit;
      *source = "cgroup memory limit";
      break;
    }
  }
  return bytes;
}

MemoryLimit memory_limit(const std::string& flag) {
  MemoryLimit limit;
  if (!flag.empty()) {
    limit.bytes = parse_memory_size(flag);
    limit.source = "--max-memory " + flag;
    return limit;
  }
  std::string source;
  const std::uint64_t machine = machine_memory(&source);
  if (machine == 0) {  // unknown: no default limit (the header checks still bound what a file can claim)
    limit.bytes = ~std::uint64_t(0);
    limit.source = "no default: this machine's memory is unknown";
    return limit;
  }
  limit.bytes = machine / 2;
  limit.source = "the default --max-memory, half of the " + memory_text(machine) + " of " + source;
  return limit;
}

std::uint64_t FrameMemoryPlan::total() const {
  std::uint64_t sum = 0;
  for (const auto& p : parts) sum += p.second;
  return sum;
}

std::string FrameMemoryPlan::text() const {
  std::string out;
  for (const auto& p : parts) out += (out.empty() ? "" : ", ") + p.first + " " + memory_text(p.second);
  return out;
}

FrameMemoryNeeds frame_memory_needs(const ApplyOptions& o) {
  FrameMemoryNeeds needs;
  needs.half_output = o.pixel_type == "half";
  needs.png = !o.png_path.empty();
  needs.volumes = !o.volumes.volumes_path.empty() || o.volumes.height_fog.has_value();
  const std::string& r = o.volumes.resolution;
  needs.volume_divisor = o.volumes.max_error_given ? 1 : r == "half" ? 2 : r == "quarter" ? 4 : 1;
  needs.volumes_scalar = resolve_device_choice(o.device) == "scalar";
  return needs;
}

FrameMemoryPlan frame_memory(const ExrFrameShape& shape, const FrameMemoryNeeds& needs) {
  const ExrWindows& w = shape.windows;
  const std::uint64_t width = extent(w.display_min.x, w.display_max.x),
                      height = extent(w.display_min.y, w.display_max.y);
  const std::uint64_t pixels = width * height;
  const std::uint64_t data_pixels = extent(w.data_min.x, w.data_max.x) * extent(w.data_min.y, w.data_max.y);
  const std::uint64_t color = pixels * bytes_per_pixel(shape.color_format);
  FrameMemoryPlan plan;
  plan.parts.push_back({"color", color});
  plan.parts.push_back({"depth", pixels * 4});
  plan.parts.push_back({"output", color});
  if (needs.half_output && shape.color_format == ColorFormat::rgba32f) plan.parts.push_back({"conversion", pixels * 8});
  if (needs.png) plan.parts.push_back({"preview", pixels * 8});
  if (shape.deep) plan.parts.push_back({"deep tables", data_pixels * 52});
  if (needs.volumes)
    plan.parts.push_back({"volume target", volume_target_pixels(width, height, needs.volume_divisor) * 20 +
                                               (needs.volumes_scalar ? pixels * 20 : 0)});
  return plan;
}

void check_frame_memory(const std::string& path, const ExrFrameShape& shape, const FrameMemoryNeeds& needs,
                        const MemoryLimit& limit) {
  const FrameMemoryPlan plan = frame_memory(shape, needs);
  if (plan.total() <= limit.bytes) return;
  const ExrWindows& w = shape.windows;
  throw Error(path + ": a " + std::to_string(extent(w.display_min.x, w.display_max.x)) + "x" +
              std::to_string(extent(w.display_min.y, w.display_max.y)) + " frame (display window " +
              window_text(w) + ") needs about " + memory_text(plan.total()) + " (" + plan.text() + "), more than " +
              memory_text(limit.bytes) + " (" + limit.source + ")");
}

void check_shadow_map_memory(const std::string& path, const ExrFrameShape& shape, const MemoryLimit& limit) {
  const ExrWindows& w = shape.windows;
  const std::uint64_t width = extent(w.display_min.x, w.display_max.x), height = extent(w.display_min.y, w.display_max.y);
  const std::uint64_t bytes = width * height * 8;
  if (bytes <= limit.bytes) return;
  throw Error(path + ": a " + std::to_string(width) + "x" + std::to_string(height) + " shadow map (display window " +
              window_text(w) + ") needs about " + memory_text(bytes) + " (the map " + memory_text(bytes / 2) +
              ", its device copy " + memory_text(bytes / 2) + "), more than " + memory_text(limit.bytes) + " (" +
              limit.source + ")");
}

FrameMemoryPlan demo_memory(int width, int height) {
  const std::uint64_t pixels = std::uint64_t(std::max(width, 0)) * std::uint64_t(std::max(height, 0));
  FrameMemoryPlan plan;
  plan.parts.push_back({"scenes", pixels * 40});
  plan.parts.push_back({"float64 references", pixels * 248});
  plan.parts.push_back({"fogged frames", pixels * 32});
  plan.parts.push_back({"volume buffers", pixels * 20 + volume_target_pixels(std::uint64_t(std::max(width, 0)),
                                                                             std::uint64_t(std::max(height, 0)), 2) *
                                                            20});
  plan.parts.push_back({"preview", pixels * 8});
  return plan;
}

void check_demo_memory(int width, int height, const MemoryLimit& limit) {
  const FrameMemoryPlan plan = demo_memory(width, height);
  if (plan.total() <= limit.bytes) return;
  throw Error("a " + std::to_string(width) + "x" + std::to_string(height) + " scene needs about " +
              memory_text(plan.total()) + " (" + plan.text() + "), more than " + memory_text(limit.bytes) + " (" +
              limit.source + "): give a smaller --width / --height or a larger --max-memory");
}

std::string frame_memory_hint(const MemoryLimit& limit) {
  return "the machine had less free memory than " + memory_text(limit.bytes) + " (" + limit.source +
         "); a lower --max-memory refuses such frames before they are read";
}

namespace {
std::atomic<const char*> g_memory_stage{"starting"};
}  // namespace

void set_memory_stage(const char* stage) { g_memory_stage.store(stage); }
const char* memory_stage() { return g_memory_stage.load(); }

void check_device_allocations(const std::string& path, const Runtime& runtime, int width, int height,
                              ColorFormat format, const FrameMemoryNeeds& needs) {
  const cl::Device device(runtime.device(), true);
  const std::uint64_t max_alloc =
      with_cl_errors([&] { return std::uint64_t(device.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>()); });
  const std::uint64_t pixels = std::uint64_t(width) * std::uint64_t(height);
  std::vector<std::pair<std::string, std::uint64_t>> buffers = {{"color", pixels * bytes_per_pixel(format)},
                                                                {"depth", pixels * 4}};
  if (needs.volumes && !needs.volumes_scalar)
    buffers.push_back({"volume target", volume_target_pixels(width, height, needs.volume_divisor) * 16});
  for (const auto& [name, bytes] : buffers)
    if (bytes > max_alloc)
      throw Error(path + ": a " + std::to_string(width) + "x" + std::to_string(height) + " " + to_string(format) +
                  " frame needs a " + memory_text(bytes) + " " + name + " buffer (" + std::to_string(bytes) +
                  " bytes), more than " + runtime.description() +
                  " can allocate at once (CL_DEVICE_MAX_MEM_ALLOC_SIZE " + memory_text(max_alloc) +
                  "); use a smaller frame or another device (--device)");
}

}  // namespace fogcl::cli
