// Small inputs that describe large costs, refused before the cost is paid: a display window of
// 20000x20000 around a few pixels (--max-memory), a header claiming more pixels than its file can
// hold (the EXR header check), a --frames range of a billion absent frames, missing frames of a
// sequence (named as ranges), JSON nested 100 000 deep, and a frame larger than the device's largest
// allocation. Each failure must come fast, in bounded memory, as one line.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>

#include "cli/frame_memory.h"
#include "cli/sequence.h"
#include "exr_fixtures.h"
#include "fogcl/exr_io.h"
#include "fogcl/volumes_json.h"
#include "runtime/clhpp.h"
#include "test_support.h"

extern char** environ;

#if defined(__SANITIZE_ADDRESS__)
#define FOGCL_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define FOGCL_TEST_ASAN 1
#endif
#endif

namespace fogcl::test {
namespace {

namespace fs = std::filesystem;
using cli::FrameRange;

const char* kFog = " --near 0.3 --far 1000 --fov 50 --depth-kind eye --mode exp2 --density 0.004 --device scalar";

// A CLI run with its wall time (printed, never asserted: a slow machine is no failure) and peak
// resident memory. The peak is the kernel's own account, not a sample: fogcl runs as the child of
// a small launcher (Python) that reports RUSAGE_CHILDREN's ru_maxrss once fogcl has exited. (The
// test process cannot ask wait4 itself: a child it spawns starts in its address space, whose
// high-water mark the child's ru_maxrss would then carry; the launcher's is about 10 MiB.) Outside
// AddressSanitizer (which reserves terabytes of address space) it runs under a 4 GiB address-space
// limit, so that a regression fails here instead of taking the machine's memory.
struct MeasuredRun {
  int exit_code = -1;
  std::string output;
  double seconds = 0;
  double peak_mib = 0;
  int lines() const { return int(std::count(output.begin(), output.end(), '\n')); }
};

MeasuredRun run_measured(const std::string& args, const std::string& limit_kib = std::to_string(4l << 20)) {
#ifdef FOGCL_TEST_ASAN
  const std::string limit;
  (void)limit_kib;
#else
  const std::string limit = "ulimit -v " + limit_kib + "; ";
#endif
  static int runs = 0;
  const std::string peak_file = temp_dir() + "/peak-" + std::to_string(getpid()) + "-" + std::to_string(++runs);
  fs::remove(peak_file);
  const std::string launcher =
      "/usr/bin/python3 -c 'import resource, subprocess, sys; r = subprocess.call(sys.argv[2:]); "
      "open(sys.argv[1], \"w\").write(str(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)); "
      "sys.exit(r if r >= 0 else 128 - r)' ";
  const std::vector<std::string> argv_text = {"/bin/sh", "-c",
                                              limit + "exec " + launcher + peak_file + " " + cli_path() + " " + args + " 2>&1"};
  std::vector<char*> argv;
  for (const std::string& a : argv_text) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  MeasuredRun r;
  int fds[2];
  if (pipe(fds) != 0) return r;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  posix_spawn_file_actions_addclose(&actions, fds[1]);
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = -1;
  const int spawned = posix_spawn(&pid, "/bin/sh", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(fds[1]);
  if (spawned != 0) {
    close(fds[0]);
    return r;
  }
  char buf[4096];
  for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) != 0;)
    if (n > 0) r.output.append(buf, std::size_t(n));
    else if (errno != EINTR) break;
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  const std::string peak = read_text(peak_file);
  EXPECT_FALSE(peak.empty()) << "the launcher reported no peak: " << r.output;
  r.peak_mib = std::atof(peak.c_str()) / 1024.0;  // ru_maxrss is in KiB
  fs::remove(peak_file);
  return r;
}

Imath::Box2i box(int x0, int y0, int x1, int y1) { return Imath::Box2i(Imath::V2i(x0, y0), Imath::V2i(x1, y1)); }

// Sets a box2i attribute of an EXR header in place (the first part's).
void patch_box(std::vector<char>& bytes, const std::string& name, const Imath::Box2i& b) {
  const std::string key = name + std::string(1, '\0') + "box2i" + std::string(1, '\0');
  const auto at = std::search(bytes.begin(), bytes.end(), key.begin(), key.end());
  ASSERT_NE(at, bytes.end()) << name;
  char* value = &*at + key.size() + 4;  // after the 4-byte size
  const std::int32_t v[4] = {b.min.x, b.min.y, b.max.x, b.max.y};
  std::memcpy(value, v, sizeof v);  // little-endian, as the file (x86)
}

// An RGBA FLOAT file of `w` x `h` pixels in `compression`; random values (they barely compress)
// or one constant (as well as they can).
void write_rgba(const std::string& path, int w, int h, Imf::Compression compression, bool constant,
                Imf::PixelType type = Imf::FLOAT) {
  Imf::Header header(w, h);
  header.compression() = compression;
  std::vector<float> pixels(std::size_t(w) * h * 4, 0.25f);
  std::vector<Imath::half> halves(pixels.size());
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 4.0f);
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    if (!constant) pixels[i] = u(rng);
    halves[i] = Imath::half(pixels[i]);
  }
  const char* names[4] = {"R", "G", "B", "A"};
  Imf::FrameBuffer fb;
  const std::size_t size = type == Imf::HALF ? 2 : 4;
  char* base = type == Imf::HALF ? reinterpret_cast<char*>(halves.data()) : reinterpret_cast<char*>(pixels.data());
  for (int c = 0; c < 4; ++c) {
    header.channels().insert(names[c], Imf::Channel(type));
    fb.insert(names[c], Imf::Slice(type, base + std::size_t(c) * size, 4 * size, 4 * size * std::size_t(w)));
  }
  Imf::OutputFile out(path.c_str(), header);
  out.setFrameBuffer(fb);
  out.writePixels(h);
}

class InputLimits : public testing::Test {
 protected:
  void SetUp() override { dir_ = fresh_dir("input-limits"); }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  // A small renderer frame (RGBA half, eye depth Z) with these windows.
  void write_frame(const std::string& name, const Imath::Box2i& display, const Imath::Box2i& data, unsigned seed = 1) {
    const fixtures::RenderFrame f = fixtures::make_render_frame(display, data, seed);
    std::vector<fixtures::Channel> channels = fixtures::color_channels(f, "", Imf::HALF);
    channels.push_back(fixtures::depth_channel(f, "Z"));
    fixtures::write_flat(path(name), f, {{"", channels, false, false}});
  }
  // A frame refused from its header alone: one line naming `message`, exit 1, little memory and
  // time (nothing of its size allocated), and no output written.
  void expect_refused_before_allocation(const MeasuredRun& r, const std::string& message) const {
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_EQ(r.lines(), 1) << r.output;
    EXPECT_MSG_HAS(r.output, message);
    EXPECT_LT(r.peak_mib, 200.0);
    EXPECT_FALSE(fs::exists(path("out.exr")));
  }
  std::string dir_;
};

// ---- --max-memory: the frame a header describes, before it is allocated -----------------------

TEST(FrameMemory, SizesParseInBinaryUnitsAndBadOnesNameTheFlag) {
  EXPECT_EQ(cli::parse_memory_size("8G"), 8ull << 30);
  EXPECT_EQ(cli::parse_memory_size("512M"), 512ull << 20);
  EXPECT_EQ(cli::parse_memory_size("512m"), 512ull << 20);
  EXPECT_EQ(cli::parse_memory_size("1.5GiB"), 3ull << 29);
  EXPECT_EQ(cli::parse_memory_size("2TB"), 2ull << 40);
  EXPECT_EQ(cli::parse_memory_size("1048576"), 1ull << 20);
  EXPECT_EQ(cli::parse_memory_size("4096K"), 4ull << 20);
  for (const char* bad : {"", "G", "8X", "-1G", "8 G", "1.2.3G", ".5G", "1e9", "0", "1023K", "2000000T"}) {
    const std::string msg = error_of([&] { cli::parse_memory_size(bad); });
    EXPECT_MSG_HAS(msg, "--max-memory must be a size such as 8G");
    EXPECT_MSG_HAS(msg, "(got '" + std::string(bad) + "')");
  }
  EXPECT_EQ(cli::memory_text(1536ull << 20), "1.50 GiB");
  EXPECT_EQ(cli::memory_text(12), "12 bytes");
  std::string source;
  const std::uint64_t machine = cli::machine_memory(&source);
  const cli::MemoryLimit limit = cli::memory_limit("");
  std::printf("[  default ] --max-memory %s: %s\n", cli::memory_text(limit.bytes).c_str(), limit.source.c_str());
  EXPECT_GT(machine, 64ull << 20);
  EXPECT_EQ(limit.bytes, machine / 2);
  EXPECT_MSG_HAS(limit.source, "half of the " + cli::memory_text(machine) + " of " + source);
}

TEST(FrameMemory, ThePlanCountsWhatTheRunAllocates) {
  ExrFrameShape shape;
  shape.windows.display_min = {0, 0};
  shape.windows.display_max = {1999, 999};  // 2e6 pixels
  shape.windows.data_min = {0, 0};
  shape.windows.data_max = {99, 99};  // 1e4 pixels
  cli::FrameMemoryNeeds needs;
  EXPECT_EQ(cli::frame_memory(shape, needs).total(), 2000000ull * (16 + 4 + 16));
  shape.color_format = ColorFormat::rgba16f;
  EXPECT_EQ(cli::frame_memory(shape, needs).total(), 2000000ull * (8 + 4 + 8));
  shape.color_format = ColorFormat::rgba32f;
  needs.half_output = needs.png = true;
  EXPECT_EQ(cli::frame_memory(shape, needs).total(), 2000000ull * (16 + 4 + 16 + 8 + 8));
  needs = {};
  shape.deep = true;
  EXPECT_EQ(cli::frame_memory(shape, needs).total(), 2000000ull * 36 + 10000ull * 52);
  shape.deep = false;
  needs.volumes = true;
  needs.volume_divisor = 2;
  EXPECT_EQ(cli::frame_memory(shape, needs).total(), 2000000ull * 36 + 1000ull * 500 * 20);
  needs.volumes_scalar = true;
  EXPECT_EQ(cli::frame_memory(shape, needs).total(), 2000000ull * (36 + 20) + 1000ull * 500 * 20);
  EXPECT_EQ(cli::frame_memory(shape, needs).text(),
            "color 30.5 MiB, depth 7.63 MiB, output 30.5 MiB, volume target 47.7 MiB");
}

// 492 KB made 14 GB: a 20000x20000 display window around 8x6 pixels of data.
TEST_F(InputLimits, AHugeDisplayWindowIsRefusedBeforeItIsAllocated) {
  write_frame("huge.exr", box(0, 0, 19999, 19999), box(9996, 9997, 10003, 10002));
  const MeasuredRun r =
      run_measured("apply --color " + path("huge.exr") + kFog + " --max-memory 2G --out " + path("out.exr"));
  std::printf("[ 20000^2  ] %zu-byte file: exit %d in %.2f s, peak %.0f MiB: %s", fs::file_size(path("huge.exr")),
              r.exit_code, r.seconds, r.peak_mib, r.output.c_str());
  expect_refused_before_allocation(
      r, "fogcl: error: " + path("huge.exr") +
             ": a 20000x20000 frame (display window (0, 0)-(19999, 19999)) needs about 13.4 GiB "
             "(color 5.96 GiB, depth 1.49 GiB, output 5.96 GiB), more than 2.00 GiB (--max-memory 2G)");
}

// The shadow map is a frame too (loaded once a run): its display window is checked the same way.
TEST_F(InputLimits, AHugeShadowMapIsRefusedBeforeItIsAllocated) {
  write_frame("frame.exr", box(0, 0, 15, 8), box(0, 0, 15, 8));
  const fixtures::RenderFrame map = fixtures::make_render_frame(box(0, 0, 19999, 19999), box(0, 0, 7, 5), 3);
  fixtures::write_flat(path("shadow.exr"), map, {{"", {fixtures::depth_channel(map, "Z")}, false, false}});
  std::ofstream(path("v.json")) << R"({"volumes": [{"center": [0, 1, 0], "radius": 2}]})";
  const MeasuredRun r = run_measured("apply --color " + path("frame.exr") + kFog + " --volumes " + path("v.json") +
                                     " --eye 0,1,-5 --forward 0,0,1 --up 0,1,0 --shadow-map " + path("shadow.exr") +
                                     " --light-view-proj 1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1 --max-memory 1G --out " +
                                     path("out.exr"));
  std::printf("[ shadow   ] exit %d in %.2f s, peak %.0f MiB: %s", r.exit_code, r.seconds, r.peak_mib, r.output.c_str());
  expect_refused_before_allocation(
      r, "fogcl: error: --shadow-map: " + path("shadow.exr") +
             ": a 20000x20000 shadow map (display window (0, 0)-(19999, 19999)) needs about 2.98 GiB "
             "(the map 1.49 GiB, its device copy 1.49 GiB), more than 1.00 GiB (--max-memory 1G)");
}

// The default limit is half of the machine's memory: a 46000x46000 frame (the largest display
// window the reader takes is 2^31 pixels) needs 70.9 GiB.
TEST_F(InputLimits, TheDefaultLimitIsHalfTheMachinesMemory) {
  write_frame("huger.exr", box(0, 0, 45999, 45999), box(0, 0, 7, 5));
  std::string source;
  const std::uint64_t machine = cli::machine_memory(&source);
  ExrFrameShape shape;
  shape.windows.display_max = {45999, 45999};
  if (cli::frame_memory(shape, {}).total() <= machine / 2)
    GTEST_SKIP() << "this machine's " << cli::memory_text(machine) << " would allow the frame";
  const MeasuredRun r = run_measured("apply --color " + path("huger.exr") + kFog + " --out " + path("out.exr"));
  std::printf("[ default  ] exit %d in %.2f s, peak %.0f MiB: %s", r.exit_code, r.seconds, r.peak_mib,
              r.output.c_str());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.lines(), 1) << r.output;
  EXPECT_MSG_HAS(r.output, "display window (0, 0)-(45999, 45999)) needs about 70.9 GiB");
  EXPECT_MSG_HAS(r.output,
                 "(the default --max-memory, half of the " + cli::memory_text(machine) + " of " + source + ")");
  EXPECT_LT(r.peak_mib, 200.0);
}

// The plan is what the run takes: a 2048x2048 frame around a few pixels of data runs under a limit
// just above the plan and is refused just below it, and its peak memory is the plan plus the
// process's own.
TEST_F(InputLimits, TheLimitIsTheFramesMemory) {
  write_frame("frame.exr", box(0, 0, 2047, 2047), box(100, 100, 131, 123));
  ExrFrameShape shape;
  shape.windows.display_max = {2047, 2047};
  const std::uint64_t plan = cli::frame_memory(shape, {}).total();  // float color, depth, output: 144 MiB
  const auto mib = [](std::uint64_t b) { return std::to_string(b >> 20) + "M"; };
  const MeasuredRun below = run_measured("apply --color " + path("frame.exr") + kFog + " --max-memory " +
                                         mib(plan - (1 << 20)) + " --out " + path("below.exr"));
  EXPECT_EQ(below.exit_code, 1) << below.output;
  EXPECT_MSG_HAS(below.output, "needs about 144.0 MiB (color 64.0 MiB, depth 16.0 MiB, output 64.0 MiB)");
  const MeasuredRun above = run_measured("apply --color " + path("frame.exr") + kFog + " --max-memory " +
                                         mib(plan + (1 << 20)) + " --out " + path("above.exr"));
  ASSERT_EQ(above.exit_code, 0) << above.output;
  std::printf("[ 2048^2   ] plan %.0f MiB, peak of the run %.0f MiB (refused at %.0f MiB)\n", double(plan) / (1 << 20),
              above.peak_mib, below.peak_mib);
  EXPECT_GT(above.peak_mib, 0.9 * double(plan) / (1 << 20)) << "the plan counts memory the run does not take";
#ifndef FOGCL_TEST_ASAN
  EXPECT_LT(above.peak_mib, double(plan) / (1 << 20) + 100.0) << "the run takes memory the plan does not count";
#endif
  EXPECT_LT(below.peak_mib, 100.0);
}

// A frame larger than the device can allocate at once: one line naming the limit, never the raw
// CL_INVALID_BUFFER_SIZE (checked without allocating it).
TEST(FrameMemory, AFrameLargerThanTheDevicesLargestAllocationIsNamed) {
  FOGCL_REQUIRE_DEVICE();
  const Runtime& rt = *runtime();
  const std::uint64_t max_alloc = cl::Device(rt.device(), true).getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
  const int width = 16384, rows = int(max_alloc / 16 / width);  // the most rows of rgba32f that fit
  std::printf("[ device   ] %s: CL_DEVICE_MAX_MEM_ALLOC_SIZE %s: %dx%d rgba32f fits\n", rt.description().c_str(),
              cli::memory_text(max_alloc).c_str(), width, rows);
  cli::FrameMemoryNeeds needs;
  EXPECT_NO_THROW(cli::check_device_allocations("f.exr", rt, width, rows, ColorFormat::rgba32f, needs));
  std::string msg =
      error_of([&] { cli::check_device_allocations("f.exr", rt, width, rows + 1, ColorFormat::rgba32f, needs); });
  EXPECT_MSG_HAS(msg, "f.exr: a " + std::to_string(width) + "x" + std::to_string(rows + 1) + " rgba32f frame needs a ");
  EXPECT_MSG_HAS(msg, " color buffer (" + std::to_string(std::uint64_t(width) * std::uint64_t(rows + 1) * 16) +
                          " bytes), more than " + rt.description() +
                          " can allocate at once (CL_DEVICE_MAX_MEM_ALLOC_SIZE " + cli::memory_text(max_alloc) + ")");
  // The volume target at full resolution is RGBA float whatever the frame's storage.
  needs.volumes = true;
  EXPECT_NO_THROW(cli::check_device_allocations("f.exr", rt, width, rows + 1, ColorFormat::rgba16f, {}));
  msg = error_of([&] { cli::check_device_allocations("f.exr", rt, width, rows + 1, ColorFormat::rgba16f, needs); });
  EXPECT_MSG_HAS(msg, " volume target buffer");
  needs.volume_divisor = 2;
  EXPECT_NO_THROW(cli::check_device_allocations("f.exr", rt, width, rows + 1, ColorFormat::rgba16f, needs));
}

// The same through the CLI, on PoCL limited to 1 GB (its largest allocation is then 256 MiB): a
// 4096x4097 float frame (256.06 MiB of color) is refused before the pass allocates anything.
TEST_F(InputLimits, AFrameTheDeviceCannotAllocateIsOneLine) {
  FOGCL_REQUIRE_DEVICE();
  if (!device_is_pocl_cpu(runtime()->device())) GTEST_SKIP() << "POCL_MEMORY_LIMIT is PoCL's";
  write_frame("tall.exr", box(0, 0, 4095, 4096), box(0, 0, 7, 5));
  std::string args = "apply --color " + path("tall.exr") + kFog + " --out " + path("out.exr");
  args.replace(args.find("--device scalar"), 15, "--device cpu");
  const CliRun r = run_cli(args, "POCL_MEMORY_LIMIT=1");
  std::printf("[ device   ] %s", r.output.c_str());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_MSG_HAS(r.output, "fogcl: error: " + path("tall.exr") +
                               ": a 4096x4097 rgba32f frame needs a 256.1 MiB color buffer (268500992 bytes), "
                               "more than ");
  EXPECT_MSG_HAS(r.output, "can allocate at once (CL_DEVICE_MAX_MEM_ALLOC_SIZE 256.0 MiB)");
  EXPECT_EQ(r.output.find("CL_INVALID_BUFFER_SIZE"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("out.exr")));
}

// ---- The EXR header check: pixels the file cannot hold ------------------------------------------

// 16 s and 6.3 GB before "Early end of file": a header claiming 20000x20000 pixels of data. Here a
// 64x64 ZIP file (random floats, about 64 KB) whose windows say 20000x20000: its offset table (1250
// chunks of 16 lines) fits, its pixels cannot, even at deflate's best.
TEST_F(InputLimits, AHeaderClaimingMorePixelsThanTheFileHoldsIsRefused) {
  write_rgba(path("small.exr"), 64, 64, Imf::ZIP_COMPRESSION, false);
  std::vector<char> bytes = file_bytes(path("small.exr"));
  patch_box(bytes, "dataWindow", box(0, 0, 19999, 19999));
  patch_box(bytes, "displayWindow", box(0, 0, 19999, 19999));
  std::ofstream(path("claims.exr"), std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
  ExrReadRequest request;
  const std::string msg = error_of([&] { read_exr(path("claims.exr"), request); });
  std::printf("[ claims   ] %zu-byte file: %s\n", bytes.size(), msg.c_str());
  EXPECT_MSG_HAS(msg, path("claims.exr") +
                          ": cannot read EXR: dataWindow (0, 0)-(19999, 19999) holds 6400000000 "
                          "bytes of pixels; zip compression and 1250 chunks store that in no fewer than 6211551 bytes, "
                          "but the file has ");
  EXPECT_MSG_HAS(msg, "bytes after its headers and offset tables (truncated or corrupt)");

  const MeasuredRun r = run_measured("apply --color " + path("claims.exr") + kFog + " --out " + path("out.exr"));
  std::printf("[ claims   ] CLI: exit %d in %.2f s, peak %.0f MiB\n", r.exit_code, r.seconds, r.peak_mib);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.lines(), 1) << r.output;
  EXPECT_MSG_HAS(r.output, "holds 6400000000 bytes of pixels");
  EXPECT_LT(r.peak_mib, 200.0);
}

// The bound never refuses a real file: each compression's most compressible image (one constant,
// half and float) reads, however small its file.
TEST_F(InputLimits, TheHeaderCheckAcceptsTheMostCompressedFiles) {
  const Imf::Compression all[] = {Imf::NO_COMPRESSION,  Imf::RLE_COMPRESSION,  Imf::ZIPS_COMPRESSION,
                                  Imf::ZIP_COMPRESSION, Imf::PIZ_COMPRESSION,  Imf::PXR24_COMPRESSION,
                                  Imf::B44_COMPRESSION, Imf::B44A_COMPRESSION, Imf::DWAA_COMPRESSION,
                                  Imf::DWAB_COMPRESSION};
  double best = 0;
  for (const Imf::Compression c : all)
    for (const Imf::PixelType type : {Imf::HALF, Imf::FLOAT}) {
      const std::string name = path("c" + std::to_string(int(c)) + "-" + std::to_string(int(type)) + ".exr");
      write_rgba(name, 512, 512, c, true, type);
      const double ratio = 512.0 * 512 * 4 * (type == Imf::HALF ? 2 : 4) / double(fs::file_size(name));
      best = std::max(best, ratio);
      static const char* const names[] = {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"};
      std::printf("[ constant ] %-6s %s: %7zu bytes, %6.0f bytes of pixels per byte of file\n", names[int(c)],
                  type == Imf::HALF ? "half " : "float", std::size_t(fs::file_size(name)), ratio);
      try {
        read_exr(name, ExrReadRequest{});
      } catch (const Error& e) {
        ADD_FAILURE() << e.what();
      }
    }
  EXPECT_GT(best, 100.0) << "no file compressed well: the check was not put to the test";
}

// ---- Sequences: absent frames cost nothing, and are named as ranges ------------------------------

TEST(SequenceFrames, RangesAreNeverExpanded) {
  const FrameRange r = cli::parse_frame_range("1001-999999999");
  EXPECT_EQ(r.count(), 999998999);
  const std::string dir = fresh_dir("sequence-frames");
  for (int f : {3, 4, 7, 20}) std::ofstream(dir + "/s." + std::to_string(f) + ".exr") << "x";
  std::ofstream(dir + "/s.0005.exr") << "x";  // not a name of the pattern "%d"
  const cli::FramePattern p = cli::parse_frame_pattern(dir + "/s.%d.exr");
  cli::SequenceFrames s = cli::find_sequence_frames(p, std::nullopt);
  EXPECT_EQ(s.present, (std::vector<int>{3, 4, 7, 20}));
  EXPECT_EQ(cli::ranges_text(s.missing), "5-6, 8-19");
  EXPECT_EQ(s.missing_count, 14);
  EXPECT_EQ(s.requested, 18);
  s = cli::find_sequence_frames(p, r);
  EXPECT_TRUE(s.present.empty());
  EXPECT_EQ(cli::ranges_text(s.missing), "1001-999999999");
  EXPECT_EQ(s.missing_count, 999998999);
  s = cli::find_sequence_frames(p, FrameRange{0, 999999999});
  EXPECT_EQ(s.present, (std::vector<int>{3, 4, 7, 20}));
  EXPECT_EQ(cli::ranges_text(s.missing), "0-2, 5-6, 8-19, 21-999999999");
  EXPECT_EQ(s.missing_count, 1000000000 - 4);
  s = cli::find_sequence_frames(cli::parse_frame_pattern(dir + "/none/s.%d.exr"), FrameRange{1, 2});
  EXPECT_EQ(cli::ranges_text(s.missing), "1-2");
  std::vector<FrameRange> many;
  for (int i = 0; i < 30; ++i) many.push_back({2 * i, 2 * i});
  EXPECT_EQ(cli::ranges_text(many, 3), "0, 2, 4, ... (27 more ranges)");
}

// 4.2 GB before the first frame, and one line per absent frame with --keep-going (110 000 lines in
// 20 s): --frames 1001-999999999 with three frames on disk.
TEST_F(InputLimits, ABillionAbsentFramesCostNothing) {
  for (int f = 1001; f <= 1003; ++f)
    write_frame("shot." + std::to_string(f) + ".exr", box(0, 0, 15, 8), box(0, 0, 15, 8), unsigned(f));
  const std::string args =
      "apply --color " + path("shot.####.exr") + kFog + " --frames 1001-999999999 --out " + path("out.####.exr");
  MeasuredRun r = run_measured(args);
  std::printf("[ frames   ] exit %d in %.2f s, peak %.0f MiB: %s", r.exit_code, r.seconds, r.peak_mib,
              r.output.c_str());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.lines(), 1) << r.output;
  EXPECT_MSG_HAS(r.output, "fogcl: error: '" + path("shot.####.exr") +
                               "': missing frames 1004-999999999 (999998996 "
                               "of 999998999 frames: no such files); --keep-going fogs the others");
  EXPECT_FALSE(fs::exists(path("out.1001.exr"))) << "nothing is written when frames are missing";
  EXPECT_LT(r.peak_mib, 200.0);

  r = run_measured(args + " --keep-going");
  std::printf("[ frames   ] --keep-going: exit %d in %.2f s, peak %.0f MiB:\n%s", r.exit_code, r.seconds, r.peak_mib,
              r.output.c_str());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_LE(r.lines(), 3) << r.output;
  EXPECT_MSG_HAS(r.output, "fogcl: '" + path("shot.####.exr") +
                               "': missing frames 1004-999999999 (999998996 of "
                               "999998999 frames: no such files); fogging the other 3");
  EXPECT_MSG_HAS(r.output, "fogcl: error: 999998996 of 999998999 frames failed:\n  missing frames 1004-999999999");
  for (int f = 1001; f <= 1003; ++f) EXPECT_TRUE(fs::exists(path("out." + std::to_string(f) + ".exr"))) << f;
  EXPECT_LT(r.peak_mib, 200.0);
}

// A gap in the frames on disk (no --frames) fails as a missing frame of --frames does; with
// --keep-going the others are fogged and the gaps listed. Many gaps stay one short line.
TEST_F(InputLimits, GapsInASequenceOnDiskAreNamed) {
  for (int f : {1, 2, 4, 5, 9})
    write_frame("seq." + std::to_string(f) + ".exr", box(0, 0, 15, 8), box(0, 0, 15, 8), unsigned(f));
  const std::string args = "apply --color " + path("seq.#.exr") + kFog + " --out " + path("out.#.exr");
  CliRun r = run_cli(args);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_MSG_HAS(r.output, "': missing frames 3, 6-8 (4 of 9 frames: no such files); --keep-going fogs the others");
  EXPECT_FALSE(fs::exists(path("out.1.exr")));
  r = run_cli(args + " --keep-going");
  std::printf("[ gaps     ] %s", r.output.c_str());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_MSG_HAS(r.output,
                 "fogcl: error: 4 of 9 frames failed:\n  missing frames 3, 6-8 (4 of 9 frames: no such files)");
  for (int f : {1, 2, 4, 5, 9}) EXPECT_TRUE(fs::exists(path("out." + std::to_string(f) + ".exr"))) << f;

  for (int f = 11; f <= 59; f += 2)
    write_frame("seq." + std::to_string(f) + ".exr", box(0, 0, 3, 2), box(0, 0, 3, 2), unsigned(f));
  r = run_cli(args);
  std::printf("[ gaps     ] %s", r.output.c_str());
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_MSG_HAS(r.output, "missing frames 3, 6-8, 10, 12, 14, 16, 18, 20, ... (19 more ranges) (29 of 59 frames");
}

// ---- VOLUMES.json: a regular file of at most 64 MiB, checked before it is read -----------------------

// /dev/zero grew the text until memory ran out; a 100 MiB (sparse) file was read whole. Both are
// refused from what the file is, in bounded memory, naming the file; a file just under the limit
// is read (and refused by the parser, from its content).
TEST_F(InputLimits, AVolumesFileThatIsNotARegularFileOrTooLargeIsRefusedBeforeItIsRead) {
  write_frame("frame.exr", box(0, 0, 15, 8), box(0, 0, 15, 8));
  const auto run = [&](const std::string& volumes) {
    return run_measured("apply --color " + path("frame.exr") + kFog + " --volumes " + volumes +
                        " --eye 0,1,0 --forward 0,0,1 --up 0,1,0 --out " + path("out.exr"));
  };
  MeasuredRun r = run("/dev/zero");
  std::printf("[ /dev/zero] exit %d, peak %.0f MiB: %s", r.exit_code, r.peak_mib, r.output.c_str());
  expect_refused_before_allocation(r, "fogcl: error: --volumes '/dev/zero': is a character device, not a regular file");

  std::ofstream(path("big.json")) << R"({"volumes": [{"center": [0, 1, 0], "radius": 2}]})";
  fs::resize_file(path("big.json"), std::uintmax_t(100) << 20);  // sparse: 100 MiB that cost no disk
  r = run(path("big.json"));
  std::printf("[ 100 MiB  ] exit %d, peak %.0f MiB: %s", r.exit_code, r.peak_mib, r.output.c_str());
  expect_refused_before_allocation(r, "fogcl: error: " + path("big.json") +
                                          ": the volumes file (--volumes) is 104857600 bytes, more than the 67108864 "
                                          "bytes (64 MiB) a VOLUMES.json may be");
  fs::resize_file(path("big.json"), kMaxVolumesJsonBytes + 1);
  r = run(path("big.json"));
  EXPECT_MSG_HAS(r.output, "is 67108865 bytes, more than the 67108864 bytes (64 MiB)");
  // The limit itself is read: the volume, then spaces up to 64 MiB.
  const std::string volume = R"({"volumes": [{"center": [0, 1, 0], "radius": 2}]})";
  std::ofstream(path("big.json"), std::ios::trunc)
      << volume << std::string(std::size_t(kMaxVolumesJsonBytes) - volume.size(), ' ');
  ASSERT_EQ(fs::file_size(path("big.json")), kMaxVolumesJsonBytes);
  r = run(path("big.json"));
  std::printf("[ 64 MiB   ] exit %d, peak %.0f MiB: %s\n", r.exit_code, r.peak_mib, r.output.c_str());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(path("out.exr")));
}

// ---- fogcl demo: its size against --max-memory, before anything is allocated ------------------------

// 16384x16384 is in --width / --height's range, and took std::bad_alloc before any check: the
// scene's plan is checked first, with --max-memory's grammar and default.
TEST_F(InputLimits, ADemoLargerThanTheMemoryLimitIsRefusedBeforeItRenders) {
  const cli::FrameMemoryPlan plan = cli::demo_memory(16384, 16384);
  EXPECT_EQ(plan.total(), 16384ull * 16384 * 353);
  MeasuredRun r = run_measured("demo --width 16384 --height 16384 --max-memory 8G --out " + path("demo"));
  std::printf("[ demo 16K ] exit %d, peak %.0f MiB: %s", r.exit_code, r.peak_mib, r.output.c_str());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.lines(), 1) << r.output;
  EXPECT_MSG_HAS(r.output, "fogcl: error: a 16384x16384 scene needs about 88.2 GiB (scenes 10.0 GiB, float64 "
                           "references 62.0 GiB, fogged frames 8.00 GiB, volume buffers 6.25 GiB, preview 2.00 GiB), "
                           "more than 8.00 GiB (--max-memory 8G)");
  EXPECT_LT(r.peak_mib, 200.0);
  EXPECT_FALSE(fs::exists(path("demo"))) << "the output folder was made before the check";
  // The default limit: half of the machine's memory.
  std::string source;
  if (plan.total() > cli::machine_memory(&source) / 2) {
    r = run_measured("demo --width 16384 --height 16384 --out " + path("demo"));
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_MSG_HAS(r.output, "(the default --max-memory, half of the ");
    EXPECT_FALSE(fs::exists(path("demo")));
  }
  // The boundary: 64x36 (813 KiB) runs under --max-memory 1M, 64x48 (1.03 MiB) is refused.
  r = run_measured("demo --width 64 --height 48 --device scalar --max-memory 1M --out " + path("demo"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_MSG_HAS(r.output, "a 64x48 scene needs about 1.03 MiB");
  r = run_measured("demo --width 64 --height 36 --device scalar --max-memory 1M --out " + path("demo"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(path("demo/scene.exr")));
  std::printf("[ demo 64  ] plan %s, peak of the run %.0f MiB\n", cli::memory_text(cli::demo_memory(64, 36).total()).c_str(),
              r.peak_mib);
}

// ---- Allocations that fail anyway: one line naming what, never std::bad_alloc ------------------------

// An 8192x8192 frame is within --max-memory 64G but not within the run's 2 GiB of address space:
// reading it takes 1.25 GiB, fogging it another 1 GiB. The failed allocation is named.
TEST_F(InputLimits, AnAllocationThatFailsNamesWhatWasBeingAllocated) {
#ifdef FOGCL_TEST_ASAN
  GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space: no limit to run under";
#endif
  write_frame("frame.exr", box(0, 0, 8191, 8191), box(0, 0, 7, 5));
  const MeasuredRun r = run_measured("apply --color " + path("frame.exr") + kFog + " --max-memory 64G --out " +
                                         path("out.exr"),
                                     std::to_string(2l << 20));
  std::printf("[ 8192^2   ] exit %d, peak %.0f MiB: %s", r.exit_code, r.peak_mib, r.output.c_str());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.lines(), 1) << r.output;
  EXPECT_EQ(r.output.find("bad_alloc"), std::string::npos) << r.output;
  EXPECT_MSG_HAS(r.output, "fogcl: error: out of memory ");
  EXPECT_MSG_HAS(r.output, path("frame.exr"));
  EXPECT_FALSE(fs::exists(path("out.exr")));
}

// ---- VOLUMES.json nested 100 000 deep ---------------------------------------------------------------

TEST_F(InputLimits, DeeplyNestedJsonIsRefusedWithOneLine) {
  write_frame("frame.exr", box(0, 0, 15, 8), box(0, 0, 15, 8));
  const auto run = [&](const std::string& json) {
    std::ofstream(path("v.json")) << json;
    return run_measured("apply --color " + path("frame.exr") + kFog + " --volumes " + path("v.json") +
                        " --eye 0,1,0 --forward 0,0,1 --up 0,1,0 --out " + path("out.exr"));
  };
  const MeasuredRun deep = run(std::string(100000, '[') + std::string(100000, ']'));
  std::printf("[ json     ] exit %d in %.2f s: %s", deep.exit_code, deep.seconds, deep.output.c_str());
  EXPECT_EQ(deep.exit_code, 1);
  EXPECT_EQ(deep.lines(), 1) << deep.output;
  EXPECT_MSG_HAS(deep.output, path("v.json") +
                                  ": JSON nested deeper than 64 levels at line 1, column 65 (a volumes "
                                  "file needs 4");
  // 64 levels pass the check (the schema refuses them); 65 do not; brackets in strings do not count.
  const auto nested = [](int depth) {
    return "{\"volumes\": " + std::string(std::size_t(depth - 1), '[') + std::string(std::size_t(depth - 1), ']') + "}";
  };
  MeasuredRun r = run(nested(64));
  EXPECT_EQ(r.output.find("nested deeper"), std::string::npos) << r.output;
  EXPECT_MSG_HAS(r.output, "volume 0");
  r = run("\n" + nested(65));
  EXPECT_MSG_HAS(r.output, "JSON nested deeper than 64 levels at line 2, column 76");
  r = run("{\"volumes\": [], \"a\\\"[[" + std::string(100, '[') + "\": 1}");
  EXPECT_MSG_HAS(r.output, "top level: unknown key");
  EXPECT_EQ(r.lines(), 1) << r.output;
}

}  // namespace
}  // namespace fogcl::test
