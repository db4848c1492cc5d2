// The integration API (DESIGN.md §1): the caller's context, queue and buffers; wait list in,
// event out; no hidden host synchronisation; in place; fog off as a marker or a copy.
#include <cstring>

#include "test_support.h"

namespace fogcl::test {
namespace {

class IntegrationApi : public ::testing::Test {
 protected:
  void SetUp() override {
    FOGCL_REQUIRE_DEVICE();
    ctx = runtime()->context();
    device = runtime()->device();
    queue = cl::CommandQueue(ctx, device);  // the caller's own queue
    frame = make_test_frame(97, 61, false, ColorFormat::rgba32f, 3);
    settings.mode = FogMode::exp2;
    settings.density = 0.004f;
    settings.metric = FogMetric::distance;
  }
  FrameBuffers buffers(bool in_place) {
    FrameBuffers fb;
    fb.width = frame.color.width();
    fb.height = frame.color.height();
    fb.color_in = cl::Buffer(ctx, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, frame.color.size_bytes(),
                             const_cast<void*>(frame.color.data()));
    fb.depth = cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, frame.depth.size_bytes(),
                          const_cast<float*>(frame.depth.data()));
    fb.color_out = in_place ? fb.color_in : cl::Buffer(ctx, CL_MEM_READ_WRITE, frame.color.size_bytes());
    return fb;
  }
  ColorImage read(const cl::Buffer& b) {
    ColorImage out(frame.color.width(), frame.color.height());
    queue.enqueueReadBuffer(b, CL_TRUE, 0, out.size_bytes(), out.data());
    return out;
  }
  ColorImage expected() {
    ColorImage out;
    apply_fog_scalar(frame.color, frame.depth, out, frame.params, settings);
    return out;
  }

  cl::Context ctx;
  cl::Device device;
  cl::CommandQueue queue;
  TestFrame frame;
  FogSettings settings;
};

TEST_F(IntegrationApi, WaitsOnCallerEventsAndNeverBlocks) {
  FogPass pass(ctx, device);
  const FrameBuffers fb = buffers(false);
  cl::UserEvent gate(ctx);
  // If enqueue waited for its work (a hidden finish), this call would never return: the gate
  // opens only below. ctest's timeout turns that into a failure.
  const cl::Event done = pass.enqueue(queue, fb, frame.params, settings, {gate});
  EXPECT_NE(done.getInfo<CL_EVENT_COMMAND_EXECUTION_STATUS>(), CL_COMPLETE);
  EXPECT_EQ(pass.stats().kernel_dispatches, 1u);
  gate.setStatus(CL_COMPLETE);
  done.wait();
  const ColorImage out = read(fb.color_out);
  const ColorImage ref = expected();
  double worst = 0;
  for (std::size_t i = 0; i < 4 * out.pixel_count(); ++i)
    worst = std::max(worst, double(std::fabs(out.rgba32f()[i] - ref.rgba32f()[i])));
  std::printf("[ worst    ] integration vs scalar<float>: %.2e\n", worst);
  EXPECT_LE(worst, 1e-5);
}

TEST_F(IntegrationApi, InPlace) {
  FogPass pass(ctx, device);
  const FrameBuffers fb = buffers(true);
  pass.enqueue(queue, fb, frame.params, settings).wait();
  const ColorImage out = read(fb.color_out);
  const ColorImage ref = expected();
  for (std::size_t i = 0; i < 4 * out.pixel_count(); ++i) ASSERT_NEAR(out.rgba32f()[i], ref.rgba32f()[i], 1e-5);
}

TEST_F(IntegrationApi, FogOffIsAMarkerInPlaceAndACopyOtherwise) {
  FogPass pass(ctx, device);
  settings.mode = FogMode::off;
  const FrameBuffers same = buffers(true);
  pass.enqueue(queue, same, frame.params, settings).wait();
  EXPECT_EQ(pass.stats().kernel_dispatches, 0u);
  EXPECT_EQ(pass.stats().buffer_copies, 0u);
  const FrameBuffers other = buffers(false);
  pass.enqueue(queue, other, frame.params, settings).wait();
  EXPECT_EQ(pass.stats().kernel_dispatches, 0u);
  EXPECT_EQ(pass.stats().buffer_copies, 1u);
  const ColorImage out = read(other.color_out);
  EXPECT_EQ(std::memcmp(out.data(), frame.color.data(), out.size_bytes()), 0);
  EXPECT_EQ(pass.programs().builds(), 0u) << "fog off built a program";
}

TEST_F(IntegrationApi, RejectsBuffersTooSmallAndBadSizes) {
  FogPass pass(ctx, device);
  FrameBuffers fb = buffers(false);
  fb.depth = cl::Buffer(ctx, CL_MEM_READ_ONLY, 16);
  try {
    pass.enqueue(queue, fb, frame.params, settings);
    FAIL() << "no error for a small depth buffer";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("depth"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("16 bytes"), std::string::npos) << e.what();
  }
  fb = buffers(false);
  fb.width = 0;
  EXPECT_THROW(pass.enqueue(queue, fb, frame.params, settings), Error);
  fb = buffers(false);
  fb.color_out = cl::Buffer();
  EXPECT_THROW(pass.enqueue(queue, fb, frame.params, settings), Error);
  EXPECT_EQ(pass.stats().kernel_dispatches, 0u);
}

TEST_F(IntegrationApi, ConvenienceUsesHostMemoryOnCpuDevices) {
  if (!device_is_cpu(device)) GTEST_SKIP() << "not a CPU device";
  FogPass pass(*runtime());
  ColorImage out;
  pass.apply(frame.color, frame.depth, out, frame.params, settings);
  EXPECT_EQ(pass.stats().zero_copy_frames, 1u);
  EXPECT_EQ(pass.stats().copied_frames, 0u);
  // In place on the caller's image.
  ColorImage image = frame.color;
  pass.apply(image, frame.depth, image, frame.params, settings);
  EXPECT_EQ(std::memcmp(image.data(), out.data(), out.size_bytes()), 0);
}

TEST_F(IntegrationApi, ConvenienceRejectsMismatchedImagesBeforeAnyWork) {
  FogPass pass(*runtime());
  ColorImage out;
  const DepthImage small(5, 5);
  try {
    pass.apply(frame.color, small, out, frame.params, settings);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("97x61"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("5x5"), std::string::npos) << e.what();
  }
  EXPECT_THROW(pass.apply(ColorImage(), frame.depth, out, frame.params, settings), Error);
  FogSettings bad = settings;
  bad.density = -1.0f;
  EXPECT_THROW(pass.apply(frame.color, frame.depth, out, frame.params, bad), Error);
  EXPECT_EQ(pass.stats().kernel_dispatches, 0u);
}

}  // namespace
}  // namespace fogcl::test
