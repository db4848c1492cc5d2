// Staged host transfers (runtime/host_staging.h): the GPU default, run here on the suite's device
// whatever it is. They must give the bytes of the direct path (on a CPU device: the kernel on the
// images' own memory), for odd sizes, both storages, in place, with frames in flight and waited
// for on another thread, and for the volumetric pass.
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <future>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "fogcl/fog_pass.h"
#include "fogcl/volume_pass.h"
#include "runtime/host_staging.h"
#include "runtime/pinned_memory.h"
#include "test_support.h"
#include "volume_support.h"

namespace fogcl::test {
namespace {

FogSettings exp2_fog() {
  FogSettings s;
  s.mode = FogMode::exp2;
  s.density = 0.02f;
  s.color = {0.4f, 0.5f, 0.6f};
  return s;
}

// Bytes that differ between two images of the same size and format (all of them if they do not match).
std::size_t differing_bytes(const ColorImage& a, const ColorImage& b) {
  if (a.size_bytes() != b.size_bytes() || a.format() != b.format()) return std::max(a.size_bytes(), b.size_bytes());
  const auto* x = static_cast<const unsigned char*>(a.data());
  const auto* y = static_cast<const unsigned char*>(b.data());
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size_bytes(); ++i) n += x[i] != y[i];
  return n;
}

struct Passes {
  FogPass direct{*runtime()};
  FogPass staged{*runtime()};
  Passes() {
    direct.set_host_transfer(HostTransfer::direct);
    staged.set_host_transfer(HostTransfer::staged);
  }
};

TEST(HostStaging, SameBytesAsDirectForEverySizeAndStorage) {
  FOGCL_REQUIRE_DEVICE();
  Passes p;
  EXPECT_EQ(p.staged.host_transfer(), HostTransfer::staged);
  EXPECT_EQ(p.direct.host_transfer(), HostTransfer::direct);
  // 1x1, a width that is no multiple of 16, a frame of several 2 MiB bands with a short last one.
  const int sizes[][2] = {{1, 1}, {17, 3}, {320, 180}, {1000, 1333}};
  std::size_t worst = 0;
  for (const auto& wh : sizes)
    for (ColorFormat format : {ColorFormat::rgba32f, ColorFormat::rgba16f}) {
      const TestFrame f = make_test_frame(wh[0], wh[1], false, format, 11);
      ColorImage direct, staged;
      p.direct.apply(f.color, f.depth, direct, f.params, exp2_fog());
      p.staged.apply(f.color, f.depth, staged, f.params, exp2_fog());
      const std::size_t d = differing_bytes(direct, staged);
      worst = std::max(worst, d);
      EXPECT_EQ(d, 0u) << wh[0] << "x" << wh[1] << " " << to_string(format);
      EXPECT_GT(differing_bytes(staged, f.color), 0u) << "the fog changed nothing: the check could not fail";
    }
  std::printf("staged vs direct: worst %zu differing bytes over 8 frames\n", worst);
  EXPECT_EQ(p.staged.stats().copied_frames, 8u);
}

TEST(HostStaging, InPlaceAndFogOff) {
  FOGCL_REQUIRE_DEVICE();
  Passes p;
  const TestFrame f = make_test_frame(64, 37, true, ColorFormat::rgba32f, 5);
  ColorImage want;
  p.direct.apply(f.color, f.depth, want, f.params, exp2_fog());
  ColorImage frame = f.color;
  p.staged.apply(frame, f.depth, frame, f.params, exp2_fog());
  EXPECT_EQ(differing_bytes(frame, want), 0u);
  FogSettings off = exp2_fog();
  off.density = 0;  // no pass: the input, copied on the host
  ColorImage out;
  p.staged.apply(f.color, f.depth, out, f.params, off);
  EXPECT_EQ(differing_bytes(out, f.color), 0u);
}

// Frames in flight: three started before any is waited for, waited for on another thread in
// the sequence pipeline's way, with a size change in the middle; each gives its own frame's bytes.
TEST(HostStaging, FramesInFlightWaitedForOnAnotherThread) {
  FOGCL_REQUIRE_DEVICE();
  Passes p;
  std::vector<TestFrame> frames;
  std::vector<ColorImage> want(6), got(6);
  for (int i = 0; i < 6; ++i) {
    frames.push_back(make_test_frame(i == 3 ? 200 : 160, 90, false, ColorFormat::rgba16f, 100 + i));
    p.direct.apply(frames[i].color, frames[i].depth, want[i], frames[i].params, exp2_fog());
  }
  std::vector<PendingFrame> pending;
  for (int i = 0; i < 3; ++i)
    pending.push_back(p.staged.apply_async(frames[i].color, frames[i].depth, got[i], frames[i].params, exp2_fog()));
  // The inputs are no longer needed once apply_async returns: overwrite them.
  for (int i = 0; i < 3; ++i) std::memset(frames[i].color.data(), 0xff, frames[i].color.size_bytes());
  auto waiter = std::async(std::launch::async, [&] {
    for (int i = 0; i < 3; ++i) pending[i].wait();
  });
  waiter.get();
  for (int i = 3; i < 6; ++i) {
    PendingFrame f = p.staged.apply_async(frames[i].color, frames[i].depth, got[i], frames[i].params, exp2_fog());
    EXPECT_FALSE(f.done());
    f.wait();
    EXPECT_TRUE(f.done());
    f.wait();  // a second wait returns at once
  }
  for (int i = 0; i < 6; ++i) EXPECT_EQ(differing_bytes(got[i], want[i]), 0u) << "frame " << i;
}

// A frame in flight holds the staging it uses: its pass may go first.
TEST(HostStaging, AFrameInFlightOutlivesItsPass) {
  FOGCL_REQUIRE_DEVICE();
  const TestFrame f = make_test_frame(96, 54, false, ColorFormat::rgba32f, 8);
  ColorImage want, got;
  PendingFrame pending;
  {
    Passes p;
    p.direct.apply(f.color, f.depth, want, f.params, exp2_fog());
    pending = p.staged.apply_async(f.color, f.depth, got, f.params, exp2_fog());
  }
  pending.wait();
  EXPECT_EQ(differing_bytes(got, want), 0u);
}

TEST(HostStaging, TooManyFramesInFlightIsAnErrorNotAHang) {
  FOGCL_REQUIRE_DEVICE();
  Passes p;
  const TestFrame f = make_test_frame(8, 8, false, ColorFormat::rgba32f, 3);
  std::vector<ColorImage> outs(17);
  std::vector<PendingFrame> pending;
  for (int i = 0; i < 16; ++i) pending.push_back(p.staged.apply_async(f.color, f.depth, outs[i], f.params, exp2_fog()));
  try {
    pending.push_back(p.staged.apply_async(f.color, f.depth, outs[16], f.params, exp2_fog()));
    ADD_FAILURE() << "a 17th frame in flight was accepted";
  } catch (const Error& e) {
    std::printf("17th frame in flight: %s\n", e.what());
    EXPECT_NE(std::string(e.what()).find("wait()"), std::string::npos);
  }
  for (PendingFrame& x : pending) x.wait();
  // After the waits the slots are free again.
  ColorImage out;
  p.staged.apply_async(f.color, f.depth, out, f.params, exp2_fog()).wait();
  EXPECT_EQ(differing_bytes(out, outs[0]), 0u);
}

// Pinned images cross the bus from where they are (no staging copy): the same bytes, in place
// too, and the images are ordinary images otherwise (copies, pixel access, lifetime past the pass).
TEST(HostStaging, PinnedImagesGoOverTheBusUncopiedWithTheSameBytes) {
  FOGCL_REQUIRE_DEVICE();
  const cl_context ctx = runtime()->context();
  const cl_device_id dev = runtime()->device();
  const TestFrame f = make_test_frame(333, 177, false, ColorFormat::rgba32f, 21);
  ColorImage in = pinned_color_image(ctx, dev, f.color.width(), f.color.height(), f.color.format());
  DepthImage depth = pinned_depth_image(ctx, dev, f.depth.width(), f.depth.height());
  EXPECT_EQ(in.pixel(5, 5), glm::vec4(0.0f)) << "pinned pixels start zeroed";
  // What the staging looks up: these images are pinned memory of this context, a copy is not.
  EXPECT_TRUE(detail::is_pinned(in.data(), in.size_bytes(), ctx));
  EXPECT_TRUE(detail::is_pinned(depth.data(), depth.size_bytes(), ctx));
  EXPECT_FALSE(detail::is_pinned(in.data(), in.size_bytes() + 1, ctx));
  EXPECT_FALSE(detail::is_pinned(f.color.data(), f.color.size_bytes(), ctx));
  std::memcpy(in.data(), f.color.data(), f.color.size_bytes());
  std::memcpy(depth.data(), f.depth.data(), f.depth.size_bytes());
  ColorImage out = pinned_color_image(ctx, dev, in.width(), in.height(), in.format());
  ColorImage want;
  {
    Passes p;
    p.direct.apply(f.color, f.depth, want, f.params, exp2_fog());
    p.staged.apply(in, depth, out, f.params, exp2_fog());
    EXPECT_EQ(differing_bytes(out, want), 0u);
    // Pinned input, ordinary output, and in place.
    ColorImage plain;
    p.staged.apply(in, depth, plain, f.params, exp2_fog());
    EXPECT_EQ(differing_bytes(plain, want), 0u);
    ColorImage frame = in;  // a copy is ordinary memory with the same pixels
    EXPECT_EQ(differing_bytes(frame, in), 0u);
    EXPECT_FALSE(detail::is_pinned(frame.data(), frame.size_bytes(), ctx));
    p.staged.apply(in, depth, in, f.params, exp2_fog());
    EXPECT_EQ(differing_bytes(in, want), 0u);
    // The direct path (the CPU default) takes pinned images as any others.
    ColorImage direct;
    p.direct.apply(frame, depth, direct, f.params, exp2_fog());
    EXPECT_EQ(differing_bytes(direct, want), 0u);
  }
  // The pass is gone; the images stay valid (they keep their buffers and context).
  EXPECT_EQ(differing_bytes(out, want), 0u);
  EXPECT_THROW(pinned_color_image(ctx, dev, 0, 4), Error);
}

TEST(HostStaging, VolumesSameBytesAsDirect) {
  FOGCL_REQUIRE_DEVICE();
  VolumePass direct(*runtime()), staged(*runtime());
  direct.set_host_transfer(HostTransfer::direct);
  staged.set_host_transfer(HostTransfer::staged);
  for (ColorFormat format : {ColorFormat::rgba32f, ColorFormat::rgba16f}) {
    VolumeTestScene t = volume_test_scene(123, 71, format);
    VolumeSettings settings;
    settings.steps = 16;
    ColorImage a, b;
    direct.apply(t.frame.color, t.frame.depth, a, t.frame.params, t.scene, settings);
    staged.apply(t.frame.color, t.frame.depth, b, t.frame.params, t.scene, settings);
    EXPECT_EQ(differing_bytes(a, b), 0u) << to_string(format);
    EXPECT_GT(differing_bytes(b, t.frame.color), 0u) << "no volume visible: the check could not fail";
    // From pinned images: the depth, on which the march starts, and the color cross uncopied.
    const cl_context ctx = runtime()->context();
    const cl_device_id dev = runtime()->device();
    ColorImage color = pinned_color_image(ctx, dev, t.frame.color.width(), t.frame.color.height(), format);
    DepthImage depth = pinned_depth_image(ctx, dev, t.frame.depth.width(), t.frame.depth.height());
    std::memcpy(color.data(), t.frame.color.data(), color.size_bytes());
    std::memcpy(depth.data(), t.frame.depth.data(), depth.size_bytes());
    ColorImage c;
    staged.apply(color, depth, c, t.frame.params, t.scene, settings);
    EXPECT_EQ(differing_bytes(a, c), 0u) << to_string(format) << " from pinned images";
  }
}

// A begun batch runs on the threads while the caller works; wait() joins in, runs every task
// once and rethrows the first exception; a batch dropped unwaited waits for its tasks; one task
// or no threads run inline.
TEST(CopyWorkers, BegunBatchesRunWhileTheCallerWorks) {
  detail::CopyWorkers workers(4);
  std::vector<std::atomic<int>> runs(64);
  std::atomic<bool> caller_went_on{false}, task_saw_it{false};
  {
    detail::CopyWorkers::Batch batch = workers.begin(int(runs.size()), [&](int i) {
      ++runs[i];
      if (i != 0) return;
      // Task 0 waits for the caller's work after begin(): a begin() that ran the batch itself
      // would leave it waiting out the deadline.
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      while (!caller_went_on.load() && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
      task_saw_it = caller_went_on.load();
    });
    caller_went_on = true;
    batch.wait();
  }
  EXPECT_TRUE(task_saw_it.load()) << "begin() returned only after its tasks";
  for (std::size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(runs[i].load(), 1) << "task " << i;
  {
    detail::CopyWorkers::Batch batch = workers.begin(16, [](int i) {
      if (i == 5) throw Error("task 5");
    });
    EXPECT_THROW(batch.wait(), Error);
  }
  std::atomic<int> dropped{0};
  { detail::CopyWorkers::Batch batch = workers.begin(32, [&](int) { ++dropped; }); }
  EXPECT_EQ(dropped.load(), 32) << "a dropped batch returned before its tasks ran";
  int inline_runs = 0;
  detail::CopyWorkers none(1);
  detail::CopyWorkers::Batch a = none.begin(3, [&](int) { ++inline_runs; });
  EXPECT_EQ(inline_runs, 3) << "without threads, begin runs the tasks";
  workers.run(8, [&](int) { ++inline_runs; });  // the next batch after the others ended
  EXPECT_EQ(inline_runs, 11);
}

// What a band of rows waits for: every transfer up to the first that completes its rows (an
// upload's bands may complete out of order), all of them past the last.
TEST(HostStaging, RowsEventsCoverEveryBandUpToTheRows) {
  FOGCL_REQUIRE_DEVICE();
  const cl::Context context = wrap(runtime()->context());
  using detail::HostStaging;
  std::vector<HostStaging::RowsReady> ready;
  for (int rows_end : {3, 3, 7, 10}) ready.push_back({rows_end, cl::UserEvent(context)});
  const auto events = [&](int rows) {
    std::vector<cl_event> handles;
    for (const cl::Event& e : HostStaging::rows_events(ready, rows)) handles.push_back(e());
    return handles;
  };
  const auto first = [&](std::size_t n) {
    std::vector<cl_event> handles;
    for (std::size_t i = 0; i < n; ++i) handles.push_back(ready[i].event());
    return handles;
  };
  EXPECT_EQ(events(1), first(1));
  EXPECT_EQ(events(3), first(1));
  EXPECT_EQ(events(4), first(3));  // row 3 ends in the third band: the second holds part of it
  EXPECT_EQ(events(7), first(3));
  EXPECT_EQ(events(8), first(4));
  EXPECT_EQ(events(10), first(4));
  EXPECT_EQ(events(11), first(4));
  for (HostStaging::RowsReady& r : ready) clSetUserEventStatus(r.event(), CL_COMPLETE);
}

// upload_depth(rows) of a staged call: the entries it returns cover the rows asked for, a first
// call for one row returns before the depth's last band (the march's first band goes while the
// rest is copied), later calls cover more, the call for every row covers all, and what crossed the
// bus is the depth and color given. 1024 x 1536: the depth is 6 MiB, several staging bands.
TEST(HostStaging, DepthRowsComeInTheOrderAskedAndWhole) {
  FOGCL_REQUIRE_DEVICE();
  const cl::Context context = wrap(runtime()->context());
  const cl::Device device = wrap(runtime()->device());
  const int w = 1024, h = 1536;
  ColorImage in(w, h, ColorFormat::rgba32f), out(w, h, ColorFormat::rgba32f);
  DepthImage depth(w, h);
  for (std::size_t i = 0; i < depth.pixel_count(); ++i) depth.data()[i] = float(i % 9973) / 9973.0f;
  for (std::size_t i = 0; i < in.pixel_count() * 4; ++i) static_cast<float*>(in.data())[i] = float(i % 7919);
  const std::shared_ptr<detail::HostStaging> staging = detail::HostStaging::shared(context, device);
  const cl::CommandQueue queue(context, device);
  std::vector<float> depth_back(depth.pixel_count());
  std::vector<int> covered;
  detail::StagedFrame frame = staging->start(
      in, depth, out,
      [&](const FrameBuffers& fb, const detail::HostStaging::UploadDepth& upload_depth,
          const detail::HostStaging::UploadColor& upload_color) {
        for (const int rows : {1, h / 2, h - 1, h}) {
          const std::vector<detail::HostStaging::RowsReady> ready = upload_depth(rows);
          EXPECT_FALSE(ready.empty());
          if (ready.empty()) continue;
          covered.push_back(ready.back().rows_end);
          EXPECT_GE(ready.back().rows_end, rows) << "asked for " << rows << " rows";
          for (std::size_t i = 1; i < ready.size(); ++i) EXPECT_GT(ready[i].rows_end, ready[i - 1].rows_end);
        }
        std::vector<cl::Event> all = detail::HostStaging::rows_events(upload_depth(h), h);
        queue.enqueueReadBuffer(wrap(fb.depth), CL_TRUE, 0, depth.size_bytes(), depth_back.data(), &all);
        const std::vector<cl::Event> color{upload_color()};
        cl::Event copied;
        queue.enqueueCopyBuffer(wrap(fb.color_in), wrap(fb.color_out), 0, 0, in.size_bytes(), &color, &copied);
        queue.flush();
        return std::vector<detail::HostStaging::RowsReady>{{h, copied}};
      });
  staging->finish(frame, out);
  ASSERT_EQ(covered.size(), 4u);
  EXPECT_LT(covered[0], h) << "the first band's rows waited for the whole depth";
  EXPECT_EQ(covered[3], h);
  std::printf("[ rows     ] asked 1, %d, %d, %d: covered %d, %d, %d, %d\n", h / 2, h - 1, h, covered[0], covered[1],
              covered[2], covered[3]);
  EXPECT_EQ(std::memcmp(depth_back.data(), depth.data(), depth.size_bytes()), 0) << "the depth that crossed the bus";
  EXPECT_EQ(differing_bytes(in, out), 0u) << "the color that went up and down";
}

// Staged calls on devices of one pixel per work-item march and composite in bands of rows, each
// band's download following its composite: the same bytes as the direct call at every
// resolution, in place or not, for frames of one band up to several, and stats that count the
// bands' dispatches.
TEST(HostStaging, VolumeBandsSameBytesAsDirect) {
  FOGCL_REQUIRE_DEVICE();
  // On CPU devices, the GPUs' kernels (one pixel per work-item): their composite at half and
  // quarter resolution reads the next band's first target row.
  CpuCodegen one_pixel;
  one_pixel.one_pixel_per_work_item = true;
  VolumePass direct(*runtime(), nullptr, one_pixel), staged(*runtime(), nullptr, one_pixel);
  direct.set_host_transfer(HostTransfer::direct);
  staged.set_host_transfer(HostTransfer::staged);
  std::size_t banded = 0;
  // 768x720: the depth and the color cross the bus in several staging bands each.
  for (const auto& [w, h] : {std::pair{160, 9}, std::pair{97, 130}, std::pair{240, 203}, std::pair{768, 720}}) {
    for (int divisor : {1, 2, 4}) {
      VolumeTestScene t = volume_test_scene(w, h, divisor == 2 ? ColorFormat::rgba16f : ColorFormat::rgba32f);
      VolumeSettings settings;
      settings.steps = 8;
      settings.resolution_divisor = divisor;
      ColorImage a, b;
      direct.apply(t.frame.color, t.frame.depth, a, t.frame.params, t.scene, settings);
      const std::size_t before = staged.stats().march_dispatches;
      staged.apply(t.frame.color, t.frame.depth, b, t.frame.params, t.scene, settings);
      const std::size_t marches = staged.stats().march_dispatches - before;
      banded += marches > 1;
      std::printf("[ bands    ] %dx%d divisor %d: %zu\n", w, h, divisor, marches);
      EXPECT_EQ(differing_bytes(a, b), 0u) << w << "x" << h << " divisor " << divisor << ", " << marches << " bands";
      EXPECT_EQ(staged.stats().composite_dispatches, staged.stats().march_dispatches);
      ColorImage in_place = t.frame.color;
      staged.apply(in_place, t.frame.depth, in_place, t.frame.params, t.scene, settings);
      EXPECT_EQ(differing_bytes(a, in_place), 0u) << w << "x" << h << " divisor " << divisor << " in place";
      EXPECT_GT(differing_bytes(a, t.frame.color), 0u) << "no volume visible: the check could not fail";
    }
  }
  std::printf("[ bands    ] %zu of 12 staged calls marched in more than one band\n", banded);
  EXPECT_GT(banded, 0u) << "no call was banded: the check could not fail";
}

}  // namespace
}  // namespace fogcl::test
