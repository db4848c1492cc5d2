// `fogcl apply` on sequences: the bounded pipeline (order, failures, frames in flight,
// interrupts), the progress bar's rate and ETA, --pixel-type / --compression / --threads, and
// outputs that a killed run (SIGKILL mid-write, SIGINT) never leaves partial or as temporaries.
#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <regex>
#include <thread>
#include <vector>

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>

#include "cli/frame_pipeline.h"
#include "cli/sequence.h"
#include "fogcl/demo_scene.h"
#include "fogcl/exr_io.h"
#include "test_support.h"

namespace fogcl::test {
namespace {

namespace fs = std::filesystem;
using cli::FramePipeline;
using cli::progress_text;

// ---- The pipeline, with stand-in stages ----------------------------------------------------------

struct FakeJob {
  static inline std::atomic<int> alive{0}, max_alive{0};
  FakeJob() {
    const int now = ++alive;
    int seen = max_alive.load();
    while (now > seen && !max_alive.compare_exchange_weak(seen, now)) {
    }
  }
  ~FakeJob() { --alive; }
  int frame = 0;
  std::string error;
  std::vector<std::string> trail;  // the stages this frame went through
};

std::vector<int> range(int first, int last) {
  std::vector<int> v;
  for (int f = first; f <= last; ++f) v.push_back(f);
  return v;
}

TEST(FramePipeline, WritesInOrderWithAFewFramesInFlight) {
  FakeJob::max_alive = 0;
  std::vector<int> written;
  FramePipeline<FakeJob>::Stages s;
  s.read = [](FakeJob& j) { j.trail.push_back("read"); };
  s.fog = [](FakeJob& j) { j.trail.push_back("fog"); };
  s.write = [&](FakeJob& j) {
    // A slow first write: an unbounded reader would load every frame meanwhile.
    if (written.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(300));
    j.trail.push_back("write");
    written.push_back(j.frame);
  };
  s.done = [](const FakeJob& j) {
    EXPECT_EQ(j.trail, (std::vector<std::string>{"read", "fog", "write"})) << j.frame;
    return true;
  };
  const auto outcome = FramePipeline<FakeJob>::run(range(1, 40), s, nullptr);
  EXPECT_EQ(outcome.finished, 40);
  EXPECT_FALSE(outcome.interrupted);
  EXPECT_EQ(written, range(1, 40));
  std::printf("[ in flight] at most %d frames alive\n", FakeJob::max_alive.load());
  EXPECT_LE(FakeJob::max_alive.load(), 5);
  EXPECT_EQ(FakeJob::alive.load(), 0);
}

// A condition the stages wait for: set() by one stage, wait() by another. wait() gives up after a
// minute, a hang guard only: in a correct pipeline the condition always comes, so the test's outcome
// never depends on how fast the machine is.
class Gate {
 public:
  void set() {
    std::lock_guard<std::mutex> lock(m_);
    open_ = true;
    cv_.notify_all();
  }
  bool wait() {
    std::unique_lock<std::mutex> lock(m_);
    return cv_.wait_for(lock, std::chrono::minutes(1), [&] { return open_; });
  }

 private:
  std::mutex m_;
  std::condition_variable cv_;
  bool open_ = false;
};

// A clock per thread that moves only when its thread says it worked (work()), as a thread's CPU
// clock does, by whole seconds: the times the pipeline sums are exact.
struct WorkClock {
  using duration = std::chrono::seconds;
  using rep = duration::rep;
  using period = duration::period;
  using time_point = std::chrono::time_point<WorkClock>;
  static constexpr bool is_steady = true;
  static time_point now() { return time_point(elapsed); }
  static void work(int seconds) { elapsed += duration(seconds); }
  static inline thread_local duration elapsed{0};
};

// The stage times --verbose prints: each stage's own work, not the rest of its thread's. Reading a
// frame takes 1 s, fogging 2 s, writing 4 s (WorkClock's); done() takes 8 s on the writer's thread
// and start() 16 s on the caller's, which no stage counts, nor the stages a failed frame skips. In
// the threaded run reading also overlaps writing: frame 1's write waits until frame 3 has been read
// (frame 2 is then between the stages), which stages run in turn never get to.
TEST(FramePipeline, ReportsEachStagesBusyTime) {
  for (const bool serial : {false, true}) {
    SCOPED_TRACE(serial ? "serial" : "threads");
    using Pipeline = FramePipeline<FakeJob, WorkClock>;
    Pipeline::Stages s;
    Gate third_read;
    bool overlapped = true;
    s.read = [&](FakeJob& j) {
      WorkClock::work(1);
      if (j.frame == 3) third_read.set();
      if (j.frame == 5) throw Error("frame five is truncated");
    };
    s.fog = [](FakeJob&) { WorkClock::work(2); };
    s.write = [&](FakeJob& j) {
      if (j.frame == 1 && !serial) overlapped = third_read.wait();
      WorkClock::work(4);
    };
    s.done = [](const FakeJob&) {
      WorkClock::work(8);
      return true;
    };
    s.start = [] { WorkClock::work(16); };
    const auto outcome = Pipeline::run(range(1, 10), s, nullptr, serial);
    std::printf("[   stages] %s: read %.0f s, fog %.0f s, write %.0f s, the caller's thread %.0f s\n",
                serial ? "serial" : "threads", outcome.read_s, outcome.fog_s, outcome.write_s, outcome.total_s);
    EXPECT_EQ(outcome.finished, 10);
    EXPECT_TRUE(overlapped) << "frame 3 was not read while frame 1 was being written";
    EXPECT_EQ(outcome.read_s, 10.0);
    EXPECT_EQ(outcome.fog_s, 9 * 2.0);  // frame 5 failed to read: neither fogged nor written
    EXPECT_EQ(outcome.write_s, 9 * 4.0);
    // The whole run on the caller's thread: serial, everything; threaded, start() alone.
    EXPECT_EQ(outcome.total_s, serial ? 16 + 10 + 9 * 2 + 9 * 4 + 10 * 8.0 : 16.0);
  }
}

// Stages::start: once, on the caller's thread, while frames are read, fogged and written (apply.cpp
// opens the device there and fogs the first frames on the scalar path meanwhile); run() returns
// after both.
TEST(FramePipeline, StartRunsOnceOnTheCallersThreadWhileFramesAreWritten) {
  FramePipeline<FakeJob>::Stages s;
  std::atomic<int> starts{0}, writes{0};
  int writes_during_start = 0;
  std::atomic<bool> start_returned{false};
  std::thread::id start_thread, write_thread;
  Gate all_written;
  s.read = [](FakeJob&) {};
  s.fog = [](FakeJob&) {};
  s.write = [&](FakeJob&) {
    write_thread = std::this_thread::get_id();
    if (++writes == 6) all_written.set();
  };
  s.done = [](const FakeJob&) { return true; };
  s.start = [&] {
    ++starts;
    start_thread = std::this_thread::get_id();
    // start() returns only once every frame has been written: possible only if the frames go
    // through while it runs.
    all_written.wait();
    writes_during_start = writes.load();
    start_returned = true;
  };
  const auto outcome = FramePipeline<FakeJob>::run(range(1, 6), s, nullptr);
  EXPECT_TRUE(start_returned.load());
  EXPECT_EQ(outcome.finished, 6);
  EXPECT_EQ(starts.load(), 1);
  EXPECT_EQ(start_thread, std::this_thread::get_id());
  EXPECT_NE(write_thread, std::this_thread::get_id());
  EXPECT_EQ(writes_during_start, 6);  // every frame went through while start() ran
}

class FramePipelineModes : public testing::TestWithParam<bool> {};  // serial (one core) or threaded
INSTANTIATE_TEST_SUITE_P(Serial, FramePipelineModes, testing::Bool(),
                         [](const auto& info) { return info.param ? std::string("serial") : std::string("threads"); });

TEST_P(FramePipelineModes, AFailedFrameSkipsItsLaterStagesAndCanStopTheRun) {
  const bool serial = GetParam();
  FramePipeline<FakeJob>::Stages s;
  std::vector<int> fogged, written, reported;
  s.read = [](FakeJob& j) {
    if (j.frame == 3) throw Error("frame three is truncated");
  };
  s.fog = [&](FakeJob& j) {
    fogged.push_back(j.frame);
    if (j.frame == 5) throw Error("the device is lost");
  };
  s.write = [&](FakeJob& j) { written.push_back(j.frame); };
  s.done = [&](const FakeJob& j) {
    reported.push_back(j.frame);
    if (j.frame == 3) {
      EXPECT_EQ(j.error, "frame three is truncated");
    }
    if (j.frame == 5) {
      EXPECT_EQ(j.error, "the device is lost");
    }
    return true;  // --keep-going
  };
  auto outcome = FramePipeline<FakeJob>::run(range(1, 6), s, nullptr, serial);
  EXPECT_EQ(outcome.finished, 6);
  EXPECT_EQ(reported, range(1, 6));
  EXPECT_EQ(written, (std::vector<int>{1, 2, 4, 6}));
  EXPECT_EQ(std::count(fogged.begin(), fogged.end(), 3), 0);

  // Without --keep-going the run stops at the first failure: nothing after it is written.
  written.clear();
  reported.clear();
  s.done = [&](const FakeJob& j) {
    reported.push_back(j.frame);
    return j.error.empty();
  };
  outcome = FramePipeline<FakeJob>::run(range(1, 30), s, nullptr, serial);
  EXPECT_EQ(written, (std::vector<int>{1, 2}));
  EXPECT_EQ(reported, (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(FakeJob::alive.load(), 0);
}

// One core: start() first, then each frame's read, fog and write in turn, all on the caller's
// thread (nothing could overlap; interleaved stages would evict each other's caches).
TEST(FramePipeline, SerialRunsStartThenEachFrameInTurnOnTheCallersThread) {
  FramePipeline<FakeJob>::Stages s;
  std::vector<std::string> order;
  bool other_thread = false;
  const std::thread::id caller = std::this_thread::get_id();
  const auto here = [&](const char* what, int frame) {
    other_thread |= std::this_thread::get_id() != caller;
    order.push_back(std::string(what) + std::to_string(frame));
  };
  const auto stage = [&](const char* what) {
    return [&, what](FakeJob& j) { here(what, j.frame); };
  };
  s.read = stage("r");
  s.fog = stage("f");
  s.write = stage("w");
  s.start = [&] { here("start", 0); };
  s.done = [&](const FakeJob& j) {
    here("done", j.frame);
    return true;
  };
  const auto outcome = FramePipeline<FakeJob>::run(range(1, 2), s, nullptr, true);
  EXPECT_EQ(outcome.finished, 2);
  EXPECT_FALSE(other_thread);
  EXPECT_EQ(order, (std::vector<std::string>{"start0", "r1", "f1", "w1", "done1", "r2", "f2", "w2", "done2"}));
  EXPECT_EQ(FakeJob::alive.load(), 0);
}

TEST(FramePipeline, AnInterruptFinishesTheWriteInProgressAndStartsNothing) {
  std::atomic<int> interrupt{0};
  std::vector<int> written;
  FramePipeline<FakeJob>::Stages s;
  s.read = [](FakeJob&) {};
  s.fog = [](FakeJob&) {};
  s.write = [&](FakeJob& j) {
    if (j.frame == 4) interrupt = SIGINT;  // arrives during frame 4's write
    written.push_back(j.frame);
  };
  s.done = [](const FakeJob&) { return true; };
  const auto outcome = FramePipeline<FakeJob>::run(range(1, 20), s, &interrupt);
  EXPECT_TRUE(outcome.interrupted);
  EXPECT_EQ(outcome.finished, 4);
  EXPECT_EQ(written, range(1, 4));
  EXPECT_EQ(FakeJob::alive.load(), 0);
}

// ---- The progress bar ----------------------------------------------------------------------------

TEST(ProgressText, RateAndEtaComeFromFinishedFramesNotThePipelineFill) {
  // First frame after 3 s (the pipeline filling), then one every 0.5 s: 2 frames/s, not 5/4.
  const std::string t = progress_text(5, 25, 3.0, 5.0);
  EXPECT_NE(t.find("5/25 frames"), std::string::npos) << t;
  EXPECT_NE(t.find("2.00 frames/s"), std::string::npos) << t;
  EXPECT_NE(t.find("ETA 0:10"), std::string::npos) << t;  // 20 frames left at 2 frames/s
  EXPECT_NE(progress_text(1, 200, 2.0, 2.0).find("0.50 frames/s  ETA 6:38"), std::string::npos)
      << progress_text(1, 200, 2.0, 2.0);
  const std::string end = progress_text(25, 25, 3.0, 15.0);
  EXPECT_EQ(end.find("ETA"), std::string::npos) << end;
  EXPECT_NE(end.find("[==============================]"), std::string::npos) << end;
  EXPECT_NE(progress_text(0, 10, -1, 0.5).find("0.00 frames/s"), std::string::npos);
}

// ---- The CLI on sequences ------------------------------------------------------------------------

const char* kFog = " --near 0.3 --far 1000 --fov 60 --mode exp2 --density 0.03 --fog-color 0.6,0.7,0.8";

class Sequence : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = temp_dir() + "/sequence-" + info->name() + "-" + std::to_string(::getpid());
    fs::remove_all(dir_);
    fs::create_directories(dir_ + "/in");
    fs::create_directories(dir_ + "/out");
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  static std::string frame_name(const std::string& stem, int frame) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s.%04d.exr", stem.c_str(), frame);
    return buf;
  }
  // Demo-scene frames in/color.NNNN.exr (RGBA float, ZIP) and in/depth.NNNN.exr.
  void make_frames(int count, int width, int height) {
    for (int f = 1; f <= count; ++f) {
      DemoView view;
      view.eye.z += 0.1f * float(f);
      PerspectiveCamera camera;
      camera.fov_y_deg = 60.0f;
      const DemoFrame frame = render_demo_scene(width, height, camera, view);
      write_exr_rgba(path("in/" + frame_name("color", f)), frame.color);
      write_exr_depth(path("in/" + frame_name("depth", f)), frame.depth);
    }
  }
  std::string inputs() const {
    return "apply --color " + path("in/color.####.exr") + " --depth " + path("in/depth.####.exr") + kFog;
  }
  std::vector<std::string> out_files() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(path("out"))) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }
  std::string dir_;
};

TEST_F(Sequence, ThreadCountsAndThePipelineChangeNoByte) {
  make_frames(5, 64, 36);
  std::vector<std::string> devices{"scalar"};  // --threads 3: the scalar pass runs in row bands
  if (runtime() != nullptr) devices.push_back("cpu");
  for (const std::string& device : devices) {
    const std::string fog = std::string(kFog) + " --distance --device " + device;
    CliRun r = run_cli(inputs() + " --distance --out " + path("out/one.####.exr") + " --threads 1 --device " + device);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = run_cli(inputs() + " --distance --out " + path("out/three.####.exr") + " --threads 3 --device " + device);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (int f = 1; f <= 5; ++f) {
      // The same frame fogged on its own, outside any pipeline.
      const std::string single = path("out/single." + std::to_string(f) + ".exr");
      r = run_cli("apply --color " + path("in/" + frame_name("color", f)) + " --depth " +
                  path("in/" + frame_name("depth", f)) + fog + " --threads 1 --out " + single);
      ASSERT_EQ(r.exit_code, 0) << r.output;
      const std::vector<char> one = file_bytes(path("out/" + frame_name("one", f)));
      EXPECT_FALSE(one.empty());
      EXPECT_EQ(one, file_bytes(path("out/" + frame_name("three", f)))) << device << " frame " << f;
      EXPECT_EQ(one, file_bytes(single)) << device << " frame " << f;
    }
  }
}

// Staged transfers (the GPU default, --host-transfer staged here on the suite's device): frames
// overlap (a frame's download is waited for by the writer while the next one uploads), through
// a size change and a frame that fails to read; the files are those of direct transfers, byte
// for byte, with and without the volumes.
TEST_F(Sequence, StagedTransfersWriteTheBytesOfDirectOnes) {
  FOGCL_REQUIRE_DEVICE();
  make_frames(6, 64, 36);
  // Frame 4 at another size, frame 5 unreadable: a new slot size, then a frame without one.
  {
    DemoView view;
    PerspectiveCamera camera;
    camera.fov_y_deg = 60.0f;
    const DemoFrame frame = render_demo_scene(80, 45, camera, view);
    write_exr_rgba(path("in/" + frame_name("color", 4)), frame.color);
    write_exr_depth(path("in/" + frame_name("depth", 4)), frame.depth);
  }
  std::ofstream(path("in/" + frame_name("color", 5)), std::ios::trunc) << "not an EXR file";
  write_text(path("in/volumes.json"), R"({"volumes": [
    {"center": [0.5, 1.5, -4], "radius": 5, "density": 0.6, "tiling": [0.2, 0.2, 0.2]},
    {"center": [3, 1.5, 3], "radius": 3, "density": 1.0, "noise": false}]})");
  // The demo view's pose (DemoView's eye, looking at its target): the volumes are in sight.
  const DemoView view;
  const glm::vec3 forward = view.target - view.eye;
  char pose[200];
  std::snprintf(pose, sizeof pose, " --eye %g,%g,%g --forward %g,%g,%g --up 0,1,0", double(view.eye.x),
                double(view.eye.y), double(view.eye.z), double(forward.x), double(forward.y), double(forward.z));
  for (const std::string& volumes : {std::string(), " --volumes " + path("in/volumes.json") + pose}) {
    const std::string tag = volumes.empty() ? "" : "-volumes";
    const std::string args = inputs() + volumes + " --keep-going --device cpu --host-transfer ";
    const CliRun direct = run_cli(args + "direct --out " + path("out/direct" + tag + ".####.exr"));
    const CliRun staged =
        run_cli(args + "staged --verbose --out " + path("out/staged" + tag + ".####.exr"), "FOGCL_TIERING=off");
    EXPECT_NE(staged.output.find("host transfers: staged"), std::string::npos) << staged.output;
    EXPECT_EQ(direct.exit_code, 1) << direct.output;  // frame 5 failed, the others were written
    EXPECT_EQ(staged.exit_code, 1) << staged.output;
    EXPECT_NE(staged.output.find("1 of 6 frames failed"), std::string::npos) << staged.output;
    for (int f : {1, 2, 3, 4, 6}) {
      const std::vector<char> bytes = file_bytes(path("out/" + frame_name("direct" + tag, f)));
      EXPECT_FALSE(bytes.empty()) << tag << " frame " << f;
      EXPECT_EQ(bytes, file_bytes(path("out/" + frame_name("staged" + tag, f)))) << tag << " frame " << f;
    }
    EXPECT_FALSE(fs::exists(path("out/" + frame_name("staged" + tag, 5))));
  }
  // The volumes changed the frames: the comparison above covered their pass too.
  EXPECT_NE(file_bytes(path("out/" + frame_name("staged", 1))), file_bytes(path("out/" + frame_name("staged-volumes", 1))));
  const CliRun scalar = run_cli(inputs() + " --device scalar --host-transfer staged --out " + path("out/s.####.exr"));
  EXPECT_EQ(scalar.exit_code, 1) << scalar.output;
  EXPECT_NE(scalar.output.find("fogcl: error: --host-transfer staged moves frames to an OpenCL device; the scalar "
                               "path (--device scalar) has none"),
            std::string::npos)
      << scalar.output;
  EXPECT_FALSE(fs::exists(path("out/" + frame_name("s", 1))));
  const CliRun bad = run_cli(inputs() + " --host-transfer pinned --out " + path("out/bad.####.exr"));
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(bad.output.find("--host-transfer must be one of auto, direct or staged (got 'pinned')"), std::string::npos) << bad.output;
}

// The pieces the CLI runs on its threads give the bits of one call (float and half storage,
// distance-based: the rays depend on the row).
TEST(ScalarRows, BandsGiveTheBitsOfOneCall) {
  for (const ColorFormat format : {ColorFormat::rgba32f, ColorFormat::rgba16f}) {
    const TestFrame t = make_test_frame(37, 29, false, format, 7);
    FogSettings s;
    s.mode = FogMode::exp2;
    s.density = 0.01f;
    s.metric = FogMetric::distance;
    ColorImage whole, bands(t.color.width(), t.color.height(), format);
    apply_fog_scalar(t.color, t.depth, whole, t.params, s);
    for (int y = 0; y < t.color.height();) {
      const int end = std::min(t.color.height(), y + 1 + y % 5);
      apply_fog_scalar_rows(t.color, t.depth, bands, t.params, s, y, end);
      y = end;
    }
    EXPECT_EQ(std::memcmp(whole.data(), bands.data(), whole.size_bytes()), 0) << to_string(format);
  }
  const TestFrame t = make_test_frame(8, 8, false, ColorFormat::rgba32f);
  ColorImage small(4, 4);
  EXPECT_MSG_HAS(error_of([&] { apply_fog_scalar_rows(t.color, t.depth, small, t.params, FogSettings{}, 0, 4); }),
                 "must have the input's size and format");
  ColorImage out(8, 8);
  EXPECT_MSG_HAS(error_of([&] { apply_fog_scalar_rows(t.color, t.depth, out, t.params, FogSettings{}, 6, 9); }),
                 "rows [6, 9) are not inside [0, 8)");
}

// Half in, half out: every pixel with f == 1 (sky, unfogged) keeps its 16 bits, NaN payloads,
// signalling NaNs, -0 and subnormals included; alpha keeps its bits everywhere (docs/DESIGN.md §2).
TEST_F(Sequence, HalfOutputOfHalfInputKeepsUnfoggedPixelsBitForBit) {
  const int w = 16, h = 8;
  const std::uint16_t specials[] = {0x7c01, 0x7e2a, 0xfe01, 0x8000, 0x0001, 0x83ff, 0x7c00, 0xfc00, 0x7bff, 0x3c00};
  std::vector<std::uint16_t> rgba(std::size_t(w * h * 4));
  std::vector<float> z(std::size_t(w * h));
  for (int i = 0; i < w * h; ++i) {
    const bool sky = i % 3 == 0;
    for (int c = 0; c < 4; ++c)
      rgba[std::size_t(4 * i + c)] = sky ? specials[(i + c) % 10] : Imath::half(1.5f + 0.01f * float((i * 7 + c) % 50)).bits();
    z[std::size_t(i)] = sky ? 1.0f : 0.995f + 0.00004f * float(i % 100);  // 60 to 230 units away
  }
  const Imath::Box2i window(Imath::V2i(0, 0), Imath::V2i(w - 1, h - 1));
  {
    Imf::Header header(window, window);
    header.compression() = Imf::PIZ_COMPRESSION;
    for (const char* c : {"R", "G", "B", "A"}) header.channels().insert(c, Imf::Channel(Imf::HALF));
    header.channels().insert("Z", Imf::Channel(Imf::FLOAT));
    Imf::OutputFile file(path("in/half.0001.exr").c_str(), header);
    Imf::FrameBuffer fb;
    const char* names[4] = {"R", "G", "B", "A"};
    for (int c = 0; c < 4; ++c)
      fb.insert(names[c], Imf::Slice(Imf::HALF, (char*)(rgba.data() + c), 8, 8 * std::size_t(w)));
    fb.insert("Z", Imf::Slice(Imf::FLOAT, (char*)z.data(), 4, 4 * std::size_t(w)));
    file.setFrameBuffer(fb);
    file.writePixels(h);
  }
  const auto read_half = [&](const std::string& p, Imf::Compression* compression) {
    Imf::InputFile file(p.c_str());
    *compression = file.header().compression();
    for (const char* c : {"R", "G", "B", "A"})
      EXPECT_EQ(file.header().channels().findChannel(c)->type, Imf::HALF) << p << " " << c;
    std::vector<std::uint16_t> got(rgba.size());
    Imf::FrameBuffer fb;
    const char* names[4] = {"R", "G", "B", "A"};
    for (int c = 0; c < 4; ++c)
      fb.insert(names[c], Imf::Slice(Imf::HALF, (char*)(got.data() + c), 8, 8 * std::size_t(w)));
    file.setFrameBuffer(fb);
    file.readPixels(0, h - 1);
    return got;
  };
  std::vector<std::string> devices{"scalar"};
  if (runtime() != nullptr) devices.push_back("cpu");
  for (const std::string& device : devices) {
    const std::string base = "apply --color " + path("in/half.####.exr") + kFog + " --device " + device;
    CliRun r = run_cli(base + " --pixel-type half --out " + path("out/" + device + "-half.####.exr"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    r = run_cli(base + " --out " + path("out/" + device + "-float.####.exr") + " --compression zip");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    Imf::Compression compression{};
    const std::vector<std::uint16_t> got = read_half(path("out/" + device + "-half.0001.exr"), &compression);
    EXPECT_EQ(compression, Imf::PIZ_COMPRESSION) << "default: the input's";
    const ColorImage as_float = read_exr_color(path("out/" + device + "-float.0001.exr"));
    Imf::InputFile float_file(path("out/" + device + "-float.0001.exr").c_str());
    EXPECT_EQ(float_file.header().compression(), Imf::ZIP_COMPRESSION);
    EXPECT_EQ(float_file.header().channels().findChannel("R")->type, Imf::FLOAT);
    int sky_checked = 0, fogged_checked = 0;
    for (int i = 0; i < w * h; ++i) {
      const bool sky = i % 3 == 0;
      for (int c = 0; c < 4; ++c) {
        const std::uint16_t in = rgba[std::size_t(4 * i + c)], out = got[std::size_t(4 * i + c)];
        if (sky || c == 3) {
          EXPECT_EQ(out, in) << device << " pixel " << i << " channel " << c;
          ++sky_checked;
        } else {
          // Fogged: the pass ran on half storage; within one half ulp of the float output.
          const float f = as_float.pixel(i % w, i / w)[c];
          Imath::half value;
          value.setBits(out);
          EXPECT_LE(std::fabs(float(value) - f), half_ulp(f)) << device << " pixel " << i;
          EXPECT_NE(out, in) << "fogged";
          ++fogged_checked;
        }
      }
    }
    EXPECT_GT(sky_checked, 100);
    EXPECT_GT(fogged_checked, 100);
  }
}

TEST_F(Sequence, BadOutputChoicesNameTheValueAndWriteNothing) {
  make_frames(1, 16, 9);
  const struct {
    const char* args;
    const char* expect;
  } cases[] = {
      {" --pixel-type double", "--pixel-type must be one of float or half (got 'double')"},
      {" --compression lzma", "--compression must be one of none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa or dwab (got 'lzma')"},
      {" --compression ZIP", "(got 'ZIP'; keywords are lowercase: zip)"},
      {" --threads 0", "--threads must be between 1 and 4096 (got 0)"},
      {" --threads 5000", "--threads must be between 1 and 4096 (got 5000)"},
  };
  for (const auto& c : cases) {
    const CliRun r = run_cli(inputs() + c.args + " --device scalar --out " + path("out/o.####.exr"));
    EXPECT_EQ(r.exit_code, 1) << c.args << ": " << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.args << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_TRUE(out_files().empty()) << c.args;
  }
  for (const char* compression : {"none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab"}) {
    const CliRun r = run_cli(inputs() + " --device scalar --pixel-type half --compression " + compression +
                             " --out " + path(std::string("out/") + compression + ".####.exr"));
    ASSERT_EQ(r.exit_code, 0) << compression << ": " << r.output;
    Imf::InputFile file(path(std::string("out/") + compression + ".0001.exr").c_str());
    EXPECT_STREQ(exr_compression_name(int(file.header().compression())), compression);
  }
}

// The device opens while the first frame is read (apply.cpp, Devices): one that cannot open is
// still one error for the run, never a failure per frame, and nothing is written.
TEST_F(Sequence, ADeviceThatCannotOpenStopsTheRunWithOneError) {
  make_frames(3, 16, 9);
  for (const char* keep_going : {"", " --keep-going"}) {
    const CliRun r = run_cli(inputs() + keep_going + " --device no-such-device-xyz --out " + path("out/o.####.exr"));
    EXPECT_EQ(r.exit_code, 1) << keep_going << ": " << r.output;
    EXPECT_NE(r.output.find("no OpenCL device matches 'no-such-device-xyz'"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("frame 2"), std::string::npos) << keep_going << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << keep_going << ": " << r.output;
    EXPECT_TRUE(out_files().empty()) << keep_going;
  }
  // A single file: a bad input is named whether or not the device opens.
  const CliRun r = run_cli("apply --color " + path("in/missing.exr") + " --depth " + path("in/depth.0001.exr") + kFog +
                           " --device no-such-device-xyz --out " + path("out/one.exr"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("missing.exr"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("no OpenCL device"), std::string::npos) << r.output;
}

// ---- Tiering: the first frames on the scalar path while PoCL opens ---------------------------------

// The frames --verbose says were fogged on the scalar path while the device opened (0 when it
// says nothing about it), and the first frame on the device (-1: none).
struct TierSplit {
  int scalar_frames = 0, first_on_device = -1;
};
TierSplit tier_split(const std::string& output) {
  TierSplit split;
  std::smatch m;
  if (std::regex_search(output, m, std::regex(R"((\d+) frame\(s\) fogged on the scalar path meanwhile \(1-(\d+)\); from frame (\d+) on the device)"))) {
    split.scalar_frames = std::stoi(m[1]);
    EXPECT_EQ(std::stoi(m[2]), split.scalar_frames) << "the scalar frames are the first ones";
    split.first_on_device = std::stoi(m[3]);
  } else if (std::regex_search(output, m, std::regex(R"(all (\d+) frames were fogged on the scalar path)"))) {
    split.scalar_frames = std::stoi(m[1]);
  }
  return split;
}

// The cores this process may run on, as `fogcl apply` counts them.
std::vector<int> allowed_cores() {
  cpu_set_t set;
  std::vector<int> cores;
  if (sched_getaffinity(0, sizeof set, &set) == 0)
    for (int c = 0; c < CPU_SETSIZE; ++c)
      if (CPU_ISSET(c, &set)) cores.push_back(c);
  return cores;
}

bool tiering_applies() {
  return runtime() != nullptr && cli_device() == "cpu" && device_is_pocl_cpu(runtime()->device()) &&
         allowed_cores().size() > 1;
}
#define SKIP_UNLESS_TIERING()                                                                          \
  if (!tiering_applies())                                                                             \
  GTEST_SKIP() << "tiering is PoCL's CPU device's, with more than one core (FOGCL_DEVICE=" << cli_device() \
               << ", " << allowed_cores().size() << " core(s))"


// A tiered run (PoCL's CPU device, the default) fogs its first frames on the scalar path and the
// rest on the device: its files are those of a run on the device alone (FOGCL_TIERING=off) and
// of one on the scalar path alone, byte for byte, and --verbose counts the scalar frames.
TEST_F(Sequence, TieredRunWritesTheBytesOfDeviceOnlyAndScalarOnlyRuns) {
  SKIP_UNLESS_TIERING();
  // Frames slow enough (one thread) that the device, opening in 0.1-0.4 s, takes over midway.
  const int n = 16;
  make_frames(n, 640, 360);
  const std::string args = inputs() + " --distance --threads 1 --verbose";
  const CliRun tiered = run_cli(args + " --device cpu --out " + path("out/tiered.####.exr"));
  ASSERT_EQ(tiered.exit_code, 0) << tiered.output;
  const CliRun device = run_cli(args + " --device cpu --out " + path("out/device.####.exr"), "FOGCL_TIERING=off");
  ASSERT_EQ(device.exit_code, 0) << device.output;
  const CliRun scalar = run_cli(args + " --device scalar --out " + path("out/scalar.####.exr"));
  ASSERT_EQ(scalar.exit_code, 0) << scalar.output;

  const TierSplit split = tier_split(tiered.output);
  std::printf("[    split] %d of %d frames fogged on the scalar path, from frame %d on the device\n",
              split.scalar_frames, n, split.first_on_device);
  EXPECT_NE(tiered.output.find("tiering: frames that reach the fog stage while the device opens"), std::string::npos)
      << tiered.output;
  EXPECT_GT(split.scalar_frames, 0) << tiered.output;
  EXPECT_EQ(split.first_on_device, split.scalar_frames + 1) << "the device takes over midway: " << tiered.output;
  EXPECT_EQ(device.output.find("tiering"), std::string::npos) << device.output;
  EXPECT_EQ(tier_split(device.output).scalar_frames, 0) << device.output;
  EXPECT_NE(device.output.find("device: " + device_name(runtime()->device())), std::string::npos)
      << "the first frame on the device: " << device.output;

  for (int f = 1; f <= n; ++f) {
    const std::vector<char> bytes = file_bytes(path("out/" + frame_name("tiered", f)));
    ASSERT_FALSE(bytes.empty()) << f;
    EXPECT_EQ(bytes, file_bytes(path("out/" + frame_name("device", f)))) << "frame " << f;
    EXPECT_EQ(bytes, file_bytes(path("out/" + frame_name("scalar", f)))) << "frame " << f;
  }

  const CliRun bad = run_cli(inputs() + " --device cpu --out " + path("out/bad.####.exr"), "FOGCL_TIERING=maybe");
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(bad.output.find("FOGCL_TIERING must be on or off (got 'maybe')"), std::string::npos) << bad.output;
}

// Only PoCL's CPU kernel gives the scalar path's bits: a device named by text and --precision fast
// wait for the device as before (tiers() leaves out a GPU and --volumes the same way). So does a
// run on one core, where nothing overlaps the opening.
TEST_F(Sequence, TieringIsOnlyForPoclsCpuDeviceAtThePrecisePrecisionOnSeveralCores) {
  SKIP_UNLESS_TIERING();
  make_frames(2, 16, 9);
  const std::string one_core = "taskset -c " + std::to_string(allowed_cores().front());
  const struct {
    const char* extra;
    std::string env;
  } runs[] = {{" --device portable", ""},  // PoCL's platform name: a device named by text
              {" --device cpu --precision fast", ""},
              {" --device scalar", ""},
              {" --device cpu", one_core}};
  for (const auto& [extra, env] : runs) {
    const CliRun r = run_cli(inputs() + extra + " --verbose --out " + path("out/o.####.exr"), env);
    ASSERT_EQ(r.exit_code, 0) << extra << ": " << r.output;
    EXPECT_EQ(r.output.find("tiering"), std::string::npos) << extra << ": " << r.output;
    EXPECT_EQ(tier_split(r.output).scalar_frames, 0) << extra << ": " << r.output;
  }
}

// On one core the CLI runs each frame's stages in turn on one thread (FramePipeline's serial run):
// the same files, byte for byte, as the pipelined run on every core, failures listed the same.
TEST_F(Sequence, OneCoreRunsTheStagesInTurnWithTheSameBytes) {
  const std::vector<int> cores = allowed_cores();
  const std::string one_core = "taskset -c " + std::to_string(cores.front());
  if (cores.size() < 2 || std::system((one_core + " true >/dev/null 2>&1").c_str()) != 0)
    GTEST_SKIP() << "needs taskset and two cores to compare with";
  make_frames(4, 64, 36);
  std::ofstream(path("in/" + frame_name("color", 3)), std::ios::trunc) << "not an EXR file";
  std::vector<std::string> devices{"scalar"};
  if (runtime() != nullptr) devices.push_back("cpu");
  for (const std::string& device : devices) {
    const std::string args = inputs() + " --keep-going --verbose --device " + device;
    const CliRun serial = run_cli(args + " --out " + path("out/serial.####.exr"), one_core);
    const CliRun threads = run_cli(args + " --out " + path("out/threads.####.exr"));
    EXPECT_EQ(serial.exit_code, 1) << serial.output;  // frame 3 failed, the others were written
    EXPECT_EQ(threads.exit_code, 1) << threads.output;
    EXPECT_NE(serial.output.find("pipeline: one core available"), std::string::npos) << serial.output;
    EXPECT_EQ(threads.output.find("pipeline: one core available"), std::string::npos) << threads.output;
    EXPECT_NE(serial.output.find("1 of 4 frames failed"), std::string::npos) << serial.output;
    for (int f : {1, 2, 4}) {
      const std::vector<char> bytes = file_bytes(path("out/" + frame_name("serial", f)));
      EXPECT_FALSE(bytes.empty()) << device << " frame " << f;
      EXPECT_EQ(bytes, file_bytes(path("out/" + frame_name("threads", f)))) << device << " frame " << f;
    }
    EXPECT_FALSE(fs::exists(path("out/" + frame_name("serial", 3))));
  }
}

// A device that fails to open is one error for the run also when frames were fogged on the scalar
// path meanwhile (here PoCL loads, then finds no device): exit 1, one line, nothing after it. The
// frames written before it stay (complete, the bits PoCL's kernel would give), and the line says
// how many; none when the failure came first.
TEST_F(Sequence, ADeviceThatFailsToOpenAfterTieredFramesStillFailsTheRun) {
  SKIP_UNLESS_TIERING();
  const int n = 40;
  make_frames(n, 64, 36);
  const CliRun scalar = run_cli(inputs() + " --device scalar --out " + path("out/scalar.####.exr"));
  ASSERT_EQ(scalar.exit_code, 0) << scalar.output;
  for (const char* keep_going : {"", " --keep-going"}) {
    for (int f = 1; f <= n; ++f) fs::remove(path("out/" + frame_name("o", f)));
    const CliRun r = run_cli(inputs() + keep_going + " --device cpu --out " + path("out/o.####.exr"),
                             "POCL_DEVICES=no-such-driver");
    EXPECT_EQ(r.exit_code, 1) << keep_going << ": " << r.output;
    EXPECT_NE(r.output.find("fogcl: error: --device: no OpenCL device matches 'cpu'"), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << keep_going << ": " << r.output;
    int written = 0;
    while (written < n && fs::exists(path("out/" + frame_name("o", written + 1)))) ++written;
    std::printf("[  written] %d of %d frames before the device failed%s\n", written, n, keep_going);
    for (int f = written + 1; f <= n; ++f) EXPECT_FALSE(fs::exists(path("out/" + frame_name("o", f)))) << f;
    for (int f = 1; f <= written; ++f)
      EXPECT_EQ(file_bytes(path("out/" + frame_name("o", f))), file_bytes(path("out/" + frame_name("scalar", f)))) << f;
    if (written == 0) {
      EXPECT_EQ(r.output.find("fogged on the scalar path"), std::string::npos) << r.output;
    } else {
      char says[160];
      std::snprintf(says, sizeof says, "(the device failed to open after %d of %d frames were fogged on the scalar path "
                    "and written, the last: frame %d)", written, n, written);
      EXPECT_NE(r.output.find(says), std::string::npos) << r.output;
    }
  }
}

// ---- Killed runs -----------------------------------------------------------------------------------

// Frames 1 to 3 written, frame 4 held (tests/support/call_gate.c) at the call that names its
// output: a rename from a named temporary, or a link of the unnamed O_TMPFILE inode.
TEST_F(Sequence, KillDashNineMidWriteLeavesOnlyCompleteFrames) {
  make_frames(10, 96, 54);
  const std::string args = inputs() + " --device scalar --threads 1 --out " + path("out/fogged.####.exr");
  for (const bool named : {false, true}) {
    SCOPED_TRACE(named ? "named temporaries (FOGCL_TEMP_FILES=named)" : "O_TMPFILE where the file system has it");
    for (const std::string& f : out_files()) fs::remove(path("out/" + f));
    GatedCli run(args, path("log.txt"), named, kNamingCalls, "/out/fogged.0004.exr", 0);
    ASSERT_EQ(run.next_line(), (named ? "held rename " : "held linkat ") + path("out/fogged.0004.exr"))
        << read_text(path("log.txt"));
    // Frame 4 is written, not yet named: unnamed, its inode is open in out/ and has no name there.
    if (!named) {
      EXPECT_TRUE(writing_in(run.pid(), path("out"), true));
    }
    run.signal(SIGKILL);
    EXPECT_EQ(ending(run.wait()), "signal 9");
    std::vector<std::string> temporaries, frames;
    for (const std::string& f : out_files()) (f.find(".tmp-") != std::string::npos ? temporaries : frames).push_back(f);
    EXPECT_EQ(frames, (std::vector<std::string>{frame_name("fogged", 1), frame_name("fogged", 2),
                                                frame_name("fogged", 3)}));
    for (const std::string& f : frames) EXPECT_NO_THROW(read_exr_color(path("out/" + f))) << f << " is not a complete frame";
    std::printf("[ killed   ] %s: %zu complete frame(s), %zu temporary file(s) left\n",
                named ? "named" : "unnamed", frames.size(), temporaries.size());
    if (named) {
      // A named temporary stays after a kill -9 (frame 4's, complete); the next run on the
      // sequence sweeps it.
      ASSERT_EQ(temporaries.size(), 1u);
      EXPECT_EQ(temporaries[0].rfind(frame_name("fogged", 4) + ".tmp-", 0), 0u) << temporaries[0];
      const CliRun r = run_cli(args + " --verbose", "FOGCL_TEMP_FILES=named");
      ASSERT_EQ(r.exit_code, 0) << r.output;
      EXPECT_NE(r.output.find("removed 1 stale temporary file(s)"), std::string::npos) << r.output;
      EXPECT_EQ(out_files().size(), 10u);
      for (const std::string& f : out_files()) EXPECT_EQ(f.find(".tmp-"), std::string::npos) << f;
    } else {
      EXPECT_TRUE(temporaries.empty());
    }
  }
}

TEST_F(Sequence, SweepLeavesOtherFilesAndLiveWritersAlone) {
  make_frames(1, 16, 9);
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  // A dead writer of ours (pid 2^22 + 1 is above Linux's pid_max default), a live one (this test
  // process, not a fogcl: swept), another machine's, and files that only look alike.
  const std::string dead = "o.0001.exr.tmp-" + std::string(host) + "-4194305-0";
  const std::string live_other = "o.0002.exr.tmp-" + std::string(host) + "-" + std::to_string(::getpid()) + "-0";
  const std::string remote = "o.0003.exr.tmp-some-other-host-4194305-0";
  const std::string foreign = "notes.txt.tmp-" + std::string(host) + "-4194305-0";
  for (const std::string& f : {dead, live_other, remote, foreign}) std::ofstream(path("out/" + f)) << "partial";
  const CliRun r = run_cli(inputs() + " --device scalar --verbose --out " + path("out/o.####.exr"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("removed 2 stale temporary file(s)"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("out/" + dead)));
  EXPECT_FALSE(fs::exists(path("out/" + live_other)));  // its pid runs, but not a fogcl
  EXPECT_TRUE(fs::exists(path("out/" + remote)));       // another machine's: maybe still writing
  EXPECT_TRUE(fs::exists(path("out/" + foreign)));      // not one of this sequence's outputs
}

// Ctrl-C while frame 4's output is being named (held by tests/support/call_gate.c until the
// handler has returned): frame 4 completes, frame 5 never starts.
TEST_F(Sequence, CtrlCSaysHowManyFramesWereWrittenAndLeavesNoPartialFile) {
  make_frames(10, 96, 54);
  const std::string args = inputs() + " --device scalar --threads 1 --out " + path("out/fogged.####.exr");
  GatedCli run(args, path("log.txt"), false, kNamingCalls, "/out/fogged.0004.exr", 1);
  ASSERT_EQ(run.next_line().rfind("held ", 0), 0u) << read_text(path("log.txt"));
  run.signal(SIGINT);
  EXPECT_EQ(run.next_line(), "handled " + std::to_string(SIGINT));
  EXPECT_EQ(ending(run.wait()), "exit " + std::to_string(128 + SIGINT));
  const std::string log = read_text(path("log.txt"));
  EXPECT_NE(log.find("fogcl: interrupted: 4 of 10 frames written (the last: frame 4); no partial file left"),
            std::string::npos) << log;
  std::vector<std::string> four;
  for (int f = 1; f <= 4; ++f) four.push_back(frame_name("fogged", f));
  EXPECT_EQ(out_files(), four) << log;
  for (const std::string& f : out_files()) EXPECT_NO_THROW(read_exr_color(path("out/" + f))) << f;
}

}  // namespace
}  // namespace fogcl::test
