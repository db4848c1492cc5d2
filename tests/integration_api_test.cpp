// The integration API (docs/DESIGN.md §1.1): the caller's context, queue and buffers as raw
// handles; wait list in, owned event out; no hidden host synchronisation and no hidden build;
// exact-size packed buffers (sub-buffers for regions); in place; fog off as a marker or a copy.
#include <chrono>
#include <cstring>
#include <memory>

#include "test_support.h"

namespace fogcl::test {
namespace {

class IntegrationApi : public ::testing::Test {
 protected:
  void SetUp() override {
    FOGCL_REQUIRE_DEVICE();
    ctx = wrap(runtime()->context());
    device = wrap(runtime()->device());
    queue = cl::CommandQueue(ctx, device);  // the caller's own queue
    frame = make_test_frame(97, 61, false, ColorFormat::rgba32f, 3);
    settings.mode = FogMode::exp2;
    settings.density = 0.004f;
    settings.metric = FogMetric::distance;
  }
  // Buffers the test keeps alive; FrameBuffers borrows their handles.
  FrameBuffers buffers(bool in_place) {
    color_in = cl::Buffer(ctx, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, frame.color.size_bytes(),
                          const_cast<void*>(frame.color.data()));
    depth = cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, frame.depth.size_bytes(),
                       const_cast<float*>(frame.depth.data()));
    color_out = in_place ? color_in : cl::Buffer(ctx, CL_MEM_READ_WRITE, frame.color.size_bytes());
    FrameBuffers fb;
    fb.width = frame.color.width();
    fb.height = frame.color.height();
    fb.color_in = color_in();
    fb.depth = depth();
    fb.color_out = color_out();
    return fb;
  }
  ColorImage read(cl_mem b) {
    ColorImage out(frame.color.width(), frame.color.height());
    queue.enqueueReadBuffer(wrap(b), CL_TRUE, 0, out.size_bytes(), out.data());
    return out;
  }
  ColorImage expected() {
    ColorImage out;
    apply_fog_scalar(frame.color, frame.depth, out, frame.params, settings);
    return out;
  }
  FogPass prepared_pass(std::shared_ptr<ProgramCache> cache = nullptr) {
    FogPass pass(ctx(), device(), std::move(cache));
    pass.prepare(settings, frame.params, frame.color.format());
    return pass;
  }
  cl_event enqueue(FogPass& pass, const FrameBuffers& fb, const std::vector<cl_event>& waits = {}) {
    return pass.enqueue(queue(), fb, frame.params, settings, waits);
  }

  cl::Context ctx;
  cl::Device device;
  cl::CommandQueue queue;
  cl::Buffer color_in, depth, color_out;
  TestFrame frame;
  FogSettings settings;
};

double worst_abs(const ColorImage& a, const ColorImage& b) {
  double worst = 0;
  for (std::size_t i = 0; i < 4 * a.pixel_count(); ++i)
    worst = std::max(worst, double(std::fabs(a.rgba32f()[i] - b.rgba32f()[i])));
  return worst;
}

TEST_F(IntegrationApi, WaitsOnCallerEventsAndNeverBlocks) {
  FogPass pass = prepared_pass();
  const FrameBuffers fb = buffers(false);
  cl::UserEvent gate(ctx);
  // If enqueue waited for its work (a hidden finish), this call would never return: the gate
  // opens only below. ctest's timeout turns that into a failure.
  const cl::Event done = adopt(enqueue(pass, fb, {gate()}));
  EXPECT_NE(done.getInfo<CL_EVENT_COMMAND_EXECUTION_STATUS>(), CL_COMPLETE);
  EXPECT_EQ(pass.stats().kernel_dispatches, 1u);
  gate.setStatus(CL_COMPLETE);
  done.wait();
  const double worst = worst_abs(read(fb.color_out), expected());
  std::printf("[ worst    ] integration vs scalar<float>: %.2e\n", worst);
  EXPECT_LE(worst, 1e-5);
}

TEST_F(IntegrationApi, ReturnedEventIsTheCallersReference) {
  auto pass = std::make_unique<FogPass>(prepared_pass());
  const FrameBuffers fb = buffers(true);
  const cl_event e = enqueue(*pass, fb);
  ASSERT_NE(e, nullptr);
  // Once the command and the queue are done the count no longer moves on its own (the runtime may
  // keep references of its own: PoCL keeps 2). The pass keeps none: destroying it leaves the count
  // as it was; the caller's retain and release move it by exactly one.
  ASSERT_EQ(clWaitForEvents(1, &e), CL_SUCCESS);
  ASSERT_EQ(clFinish(queue()), CL_SUCCESS);
  const auto refs = [&] {
    cl_uint n = 0;
    EXPECT_EQ(clGetEventInfo(e, CL_EVENT_REFERENCE_COUNT, sizeof n, &n, nullptr), CL_SUCCESS);
    return n;
  };
  const cl_uint with_pass = refs();
  pass.reset();
  const cl_uint without_pass = refs();
  std::printf("[ info     ] reference count of the returned event: %u with the pass, %u after it\n", with_pass,
              without_pass);
  EXPECT_EQ(without_pass, with_pass);
  EXPECT_GE(without_pass, 1u);
  ASSERT_EQ(clRetainEvent(e), CL_SUCCESS);
  EXPECT_EQ(refs(), without_pass + 1);
  ASSERT_EQ(clReleaseEvent(e), CL_SUCCESS);
  EXPECT_EQ(refs(), without_pass);
  EXPECT_EQ(clReleaseEvent(e), CL_SUCCESS);  // the caller's release
}

TEST_F(IntegrationApi, InPlace) {
  FogPass pass = prepared_pass();
  const FrameBuffers fb = buffers(true);
  adopt(enqueue(pass, fb)).wait();
  const double worst = worst_abs(read(fb.color_out), expected());
  std::printf("[ worst    ] in place vs scalar<float>: %.2e\n", worst);
  EXPECT_LE(worst, 1e-5);
}

TEST_F(IntegrationApi, EnqueueNeverBuildsAndNamesTheUnpreparedVariant) {
  FogPass pass(ctx(), device());
  const FrameBuffers fb = buffers(true);
  const Variant v = select_variant(settings, frame.params, ColorFormat::rgba32f);
  EXPECT_FALSE(pass.is_prepared(v));
  const std::string msg = error_of([&] { enqueue(pass, fb); });
  std::printf("[ info     ] %s\n", msg.c_str());
  EXPECT_MSG_HAS(msg, describe(v));
  EXPECT_MSG_HAS(msg, "prepare(");
  EXPECT_EQ(pass.programs().builds(), 0u) << "enqueue built a program";
  EXPECT_EQ(pass.stats().kernel_dispatches, 0u);
  pass.prepare(settings, frame.params, ColorFormat::rgba32f);
  EXPECT_TRUE(pass.is_prepared(v));
  const std::size_t builds = pass.programs().builds();
  adopt(enqueue(pass, fb)).wait();
  EXPECT_EQ(pass.programs().builds(), builds);
  EXPECT_EQ(pass.stats().kernel_dispatches, 1u);
}

TEST_F(IntegrationApi, PassesShareOneProgramCache) {
  auto cache = std::make_shared<ProgramCache>(ctx());
  FogPass first = prepared_pass(cache);
  EXPECT_EQ(cache->builds(), 1u);
  // A second pass on the same cache runs the variant without preparing it: no build.
  FogPass second(ctx(), device(), cache);
  EXPECT_TRUE(second.is_prepared(select_variant(settings, frame.params, ColorFormat::rgba32f)));
  const FrameBuffers fb = buffers(false);
  adopt(enqueue(second, fb)).wait();
  EXPECT_EQ(cache->builds(), 1u);
  EXPECT_EQ(&second.programs(), cache.get());
  const double worst = worst_abs(read(fb.color_out), expected());
  std::printf("[ worst    ] second pass on a shared cache vs scalar<float>: %.2e\n", worst);
  EXPECT_LE(worst, 1e-5);
  // A cache of another context is refused.
  const cl::Context other_ctx(device);
  const std::string msg = error_of([&] { FogPass p(other_ctx(), device(), cache); });
  EXPECT_MSG_HAS(msg, "another OpenCL context");
}

TEST_F(IntegrationApi, FogOffIsAMarkerInPlaceAndACopyOtherwise) {
  FogPass pass(ctx(), device());
  settings.mode = FogMode::off;
  const FrameBuffers same = buffers(true);
  adopt(enqueue(pass, same)).wait();  // fog off needs no prepare(): there is no program
  EXPECT_EQ(pass.stats().kernel_dispatches, 0u);
  EXPECT_EQ(pass.stats().buffer_copies, 0u);
  const FrameBuffers other = buffers(false);
  adopt(enqueue(pass, other)).wait();
  EXPECT_EQ(pass.stats().kernel_dispatches, 0u);
  EXPECT_EQ(pass.stats().buffer_copies, 1u);
  const ColorImage out = read(other.color_out);
  EXPECT_EQ(std::memcmp(out.data(), frame.color.data(), out.size_bytes()), 0);
  EXPECT_EQ(pass.programs().builds(), 0u) << "fog off built a program";
}

TEST_F(IntegrationApi, RejectsBuffersOfTheWrongSizeAndBadSizes) {
  FogPass pass = prepared_pass();
  FrameBuffers fb = buffers(false);
  const cl::Buffer small(ctx, CL_MEM_READ_ONLY, 16);
  fb.depth = small();
  std::string msg = error_of([&] { enqueue(pass, fb); });
  EXPECT_MSG_HAS(msg, "depth");
  EXPECT_MSG_HAS(msg, "16 bytes");
  // Larger than the frame is refused as well (exact-size policy).
  const cl::Buffer large(ctx, CL_MEM_READ_ONLY, frame.depth.size_bytes() + 4);
  fb = buffers(false);
  fb.depth = large();
  msg = error_of([&] { enqueue(pass, fb); });
  EXPECT_MSG_HAS(msg, "exactly " + std::to_string(frame.depth.size_bytes()));
  fb = buffers(false);
  fb.width = 0;
  EXPECT_THROW(enqueue(pass, fb), Error);
  fb = buffers(false);
  fb.color_out = nullptr;
  msg = error_of([&] { enqueue(pass, fb); });
  EXPECT_MSG_HAS(msg, "color_out");
  EXPECT_EQ(pass.stats().kernel_dispatches, 0u);
}

// A frame on the wrong buffers: an RGBA16F frame on buffers sized for RGBA32F (and the reverse) is refused,
// and the message says which format the buffer's size fits.
TEST_F(IntegrationApi, RejectsAFormatThatDoesNotMatchTheBuffers) {
  FogPass pass(ctx(), device());
  FrameBuffers fb = buffers(false);  // rgba32f-sized
  fb.format = ColorFormat::rgba16f;
  pass.prepare(settings, frame.params, ColorFormat::rgba16f);
  std::string msg = error_of([&] { enqueue(pass, fb); });
  std::printf("[ info     ] %s\n", msg.c_str());
  EXPECT_MSG_HAS(msg, "color_in");
  EXPECT_MSG_HAS(msg, "97x61 rgba16f");
  EXPECT_MSG_HAS(msg, "size of a rgba32f frame");
  const cl::Buffer half_sized(ctx, CL_MEM_READ_WRITE, color_buffer_bytes(97, 61, ColorFormat::rgba16f));
  fb = buffers(false);
  fb.color_out = half_sized();  // a 32f frame whose output buffer is sized for 16f
  msg = error_of([&] { enqueue(pass, fb); });
  EXPECT_MSG_HAS(msg, "color_out");
  EXPECT_MSG_HAS(msg, "size of a rgba16f frame");
  EXPECT_EQ(pass.stats().kernel_dispatches, 0u);
}

TEST_F(IntegrationApi, RejectsQueuesAndBuffersOfAnotherContext) {
  FogPass pass = prepared_pass();
  const FrameBuffers fb = buffers(false);
  const cl::Context other_ctx(device);
  const cl::CommandQueue other_queue(other_ctx, device);
  std::string msg = error_of([&] { pass.enqueue(other_queue(), fb, frame.params, settings); });
  EXPECT_MSG_HAS(msg, "queue belongs to another OpenCL context");
  FrameBuffers foreign = fb;
  const cl::Buffer other_depth(other_ctx, CL_MEM_READ_ONLY, frame.depth.size_bytes());
  foreign.depth = other_depth();
  msg = error_of([&] { enqueue(pass, foreign); });
  EXPECT_MSG_HAS(msg, "depth belongs to another OpenCL context");
  EXPECT_EQ(pass.stats().kernel_dispatches, 0u);
}

// A frame inside a larger allocation: the caller passes sub-buffers (the documented way to give
// byte offsets), which the pass treats as any other buffer.
TEST_F(IntegrationApi, SubBuffersGiveFramesAtAnOffset) {
  FogPass pass = prepared_pass();
  cl_uint align_bits = 0;
  ASSERT_EQ(clGetDeviceInfo(device(), CL_DEVICE_MEM_BASE_ADDR_ALIGN, sizeof align_bits, &align_bits, nullptr),
            CL_SUCCESS);
  const std::size_t align = std::max<std::size_t>(align_bits / 8, 4);
  const std::size_t color_bytes = frame.color.size_bytes(), depth_bytes = frame.depth.size_bytes();
  const std::size_t color_at = 3 * align, depth_at = ((color_at + color_bytes + align - 1) / align + 1) * align;
  cl::Buffer pool(ctx, CL_MEM_READ_WRITE, depth_at + depth_bytes + align);
  queue.enqueueWriteBuffer(pool, CL_TRUE, color_at, color_bytes, frame.color.data());
  queue.enqueueWriteBuffer(pool, CL_TRUE, depth_at, depth_bytes, frame.depth.data());
  const cl_buffer_region color_region{color_at, color_bytes}, depth_region{depth_at, depth_bytes};
  const cl::Buffer color_sub = pool.createSubBuffer(CL_MEM_READ_WRITE, CL_BUFFER_CREATE_TYPE_REGION, &color_region);
  const cl::Buffer depth_sub = pool.createSubBuffer(CL_MEM_READ_WRITE, CL_BUFFER_CREATE_TYPE_REGION, &depth_region);
  FrameBuffers fb;
  fb.width = frame.color.width();
  fb.height = frame.color.height();
  fb.color_in = fb.color_out = color_sub();
  fb.depth = depth_sub();
  adopt(enqueue(pass, fb)).wait();
  ColorImage out(fb.width, fb.height);
  queue.enqueueReadBuffer(pool, CL_TRUE, color_at, color_bytes, out.data());
  const double worst = worst_abs(out, expected());
  std::printf("[ worst    ] sub-buffers at offsets %zu / %zu vs scalar<float>: %.2e\n", color_at, depth_at, worst);
  EXPECT_LE(worst, 1e-5);
}

TEST_F(IntegrationApi, ConvenienceUsesHostMemoryOnCpuDevices) {
  if (!device_is_cpu(device())) GTEST_SKIP() << "not a CPU device";
  FogPass pass(*runtime());
  ColorImage out;
  pass.apply(frame.color, frame.depth, out, frame.params, settings);  // prepares implicitly
  EXPECT_EQ(pass.stats().zero_copy_frames, 1u);
  EXPECT_EQ(pass.stats().copied_frames, 0u);
  // In place on the caller's image.
  ColorImage image = frame.color;
  pass.apply(image, frame.depth, image, frame.params, settings);
  EXPECT_EQ(std::memcmp(image.data(), out.data(), out.size_bytes()), 0);
}

// stats().last_kernel_ms: the kernel's own device time, inside the call's wall time, and 0 after a
// call that ran no kernel (fog off: a copy).
TEST_F(IntegrationApi, LastKernelTimeIsTheCallsKernel) {
  FogPass pass(*runtime());
  ColorImage out;
  pass.apply(frame.color, frame.depth, out, frame.params, settings);  // the build, not timed below
  const auto start = std::chrono::steady_clock::now();
  pass.apply(frame.color, frame.depth, out, frame.params, settings);
  const double call_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("[ kernel   ] %.3f ms of a %.3f ms call\n", pass.stats().last_kernel_ms, call_ms);
  EXPECT_GT(pass.stats().last_kernel_ms, 0.0);
  EXPECT_LE(pass.stats().last_kernel_ms, call_ms);
  FogSettings off = settings;
  off.mode = FogMode::off;
  pass.apply(frame.color, frame.depth, out, frame.params, off);
  EXPECT_EQ(pass.stats().last_kernel_ms, 0.0);
  // The caller's queue without profiling (a Runtime from its handles): the call works, no figure.
  const Runtime theirs(ctx(), device(), queue());
  FogPass on_their_queue(theirs);
  ColorImage out2;
  on_their_queue.apply(frame.color, frame.depth, out2, frame.params, settings);
  EXPECT_EQ(on_their_queue.stats().last_kernel_ms, 0.0);
  pass.apply(frame.color, frame.depth, out, frame.params, settings);
  EXPECT_EQ(std::memcmp(out2.data(), out.data(), out.size_bytes()), 0);
}

// apply() on images the caller keeps and changes between calls, as a renderer does every frame:
// new contents at the same addresses, `out` reused as the next input and in place, images freed
// and allocated again (often at the same address and size), another size in between, both
// storages. Each output must be the one a new pass gives on fresh copies of the same inputs, bit
// for bit: no call may see the buffers, contents or results of an earlier one.
TEST_F(IntegrationApi, ConvenienceFollowsReusedAndReallocatedImages) {
  for (ColorFormat format : {ColorFormat::rgba32f, ColorFormat::rgba16f}) {
    SCOPED_TRACE(to_string(format));
    const TestFrame a = make_test_frame(97, 61, false, format, 3);
    const TestFrame b = make_test_frame(97, 61, false, format, 11);
    const TestFrame small = make_test_frame(40, 24, false, format, 5);
    CameraParams params = a.params;
    params.non_square_pixels = true;  // one camera for both frame sizes
    // The reference: a pass of its own on images of its own.
    const auto fresh = [&](const ColorImage& in, const DepthImage& depth) {
      const ColorImage in_copy = in;
      const DepthImage depth_copy = depth;
      ColorImage out;
      FogPass(*runtime()).apply(in_copy, depth_copy, out, params, settings);
      return out;
    };
    const auto same = [](const ColorImage& x, const ColorImage& y) {
      return x.width() == y.width() && x.height() == y.height() && x.format() == y.format() &&
             std::memcmp(x.data(), y.data(), x.size_bytes()) == 0;
    };
    ASSERT_FALSE(same(fresh(a.color, a.depth), fresh(b.color, b.depth)));  // the frames tell calls apart

    FogPass pass(*runtime());
    ColorImage in = a.color, out;
    DepthImage depth = a.depth;
    pass.apply(in, depth, out, params, settings);
    EXPECT_TRUE(same(out, fresh(a.color, a.depth))) << "first call";
    const void* in_at = in.data();
    const void* out_at = out.data();

    // New contents at the same addresses (the same images, written by the caller).
    std::memcpy(in.data(), b.color.data(), in.size_bytes());
    std::memcpy(depth.data(), b.depth.data(), depth.size_bytes());
    pass.apply(in, depth, out, params, settings);
    ASSERT_EQ(in.data(), in_at);
    ASSERT_EQ(out.data(), out_at);
    EXPECT_TRUE(same(out, fresh(b.color, b.depth))) << "same images, new contents";

    // The output as the next input (fog applied twice), then in place on the caller's image.
    ColorImage twice;
    pass.apply(out, depth, twice, params, settings);
    EXPECT_TRUE(same(twice, fresh(fresh(b.color, b.depth), b.depth))) << "output as input";
    ColorImage image = a.color;
    pass.apply(image, a.depth, image, params, settings);
    EXPECT_TRUE(same(image, fresh(a.color, a.depth))) << "in place";

    // Images freed and allocated again: the allocator often returns the same address and size.
    for (int round = 0; round < 3; ++round) {
      const TestFrame& src = round % 2 ? a : b;
      in = ColorImage();
      out = ColorImage();
      depth = DepthImage();
      in = src.color;
      depth = src.depth;
      pass.apply(in, depth, out, params, settings);
      EXPECT_TRUE(same(out, fresh(src.color, src.depth))) << "reallocated, round " << round;
    }

    // Another size in between, into the same `out` (apply reallocates it), then back.
    pass.apply(small.color, small.depth, out, params, settings);
    EXPECT_TRUE(same(out, fresh(small.color, small.depth))) << "smaller frame";
    pass.apply(a.color, a.depth, out, params, settings);
    EXPECT_TRUE(same(out, fresh(a.color, a.depth))) << "back to the first size";
  }
}

TEST_F(IntegrationApi, ConvenienceRejectsMismatchedImagesBeforeAnyWork) {
  FogPass pass(*runtime());
  ColorImage out;
  const DepthImage small(5, 5);
  const std::string msg = error_of([&] { pass.apply(frame.color, small, out, frame.params, settings); });
  EXPECT_MSG_HAS(msg, "97x61");
  EXPECT_MSG_HAS(msg, "5x5");
  EXPECT_THROW(pass.apply(ColorImage(), frame.depth, out, frame.params, settings), Error);
  FogSettings bad = settings;
  bad.density = -1.0f;
  EXPECT_THROW(pass.apply(frame.color, frame.depth, out, frame.params, bad), Error);
  EXPECT_EQ(pass.stats().kernel_dispatches, 0u);
  EXPECT_EQ(pass.programs().builds(), 0u);
}

}  // namespace
}  // namespace fogcl::test
