// Views over the caller's memory (fogcl/image.h): every host call of both passes and of the scalar
// paths gives through a view exactly the bits it gives through owning images, whatever the row
// stride, alignment, format and in-place-ness; memory the device can take is used in place.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "fogcl/volume_pass.h"
#include "fogcl/volume_scalar.h"
#include "test_support.h"
#include "volume_support.h"

namespace fogcl::test {
namespace {

constexpr unsigned char kSentinel = 0xA5;

// Caller-side memory for a frame: page-aligned, then offset by `misalign` bytes; padding bytes
// (and the bytes around the frame) hold kSentinel so that a write outside the pixels shows.
struct CallerMemory {
  std::size_t stride = 0, misalign = 0, bytes = 0;
  std::unique_ptr<unsigned char, decltype(&std::free)> block{nullptr, &std::free};
  unsigned char* base() const { return block.get() + misalign; }
  CallerMemory(std::size_t row_bytes, int height, std::size_t pad, std::size_t offset)
      : stride(row_bytes + pad), misalign(offset), bytes(stride * std::size_t(height)) {
    const std::size_t total = (bytes + misalign + 64 + 4095) / 4096 * 4096;
    block.reset(static_cast<unsigned char*>(std::aligned_alloc(4096, total)));
    std::memset(block.get(), kSentinel, total);
  }
  // Bytes outside [row y, row y + row_bytes) that are not kSentinel.
  std::size_t padding_touched(std::size_t row_bytes, int height) const {
    std::size_t touched = 0;
    for (std::size_t i = 0; i < misalign; ++i) touched += block.get()[i] != kSentinel;
    for (int y = 0; y < height; ++y)
      for (std::size_t i = row_bytes; i < stride; ++i) touched += base()[std::size_t(y) * stride + i] != kSentinel;
    for (std::size_t i = 0; i < 64; ++i) touched += base()[bytes + i] != kSentinel;
    return touched;
  }
};

ColorView color_view_of(CallerMemory& m, const ColorImage& like) {
  return ColorView(m.base(), like.width(), like.height(), like.format(), m.stride);
}

void fill(const ColorView& v, const ColorImage& from) {
  for (int y = 0; y < from.height(); ++y)
    std::memcpy(v.row(y), static_cast<const std::byte*>(from.data()) + std::size_t(y) * v.row_bytes(), v.row_bytes());
}

DepthView depth_view_of(CallerMemory& m, const DepthImage& from) {
  DepthView v(reinterpret_cast<float*>(m.base()), from.width(), from.height(), m.stride);
  for (int y = 0; y < from.height(); ++y) std::memcpy(v.row(y), from.data() + std::size_t(y) * from.width(), v.row_bytes());
  return v;
}

// Pixels whose bytes differ between a view and a packed image.
std::size_t differing_pixels(const ConstColorView& got, const ColorImage& want) {
  std::size_t n = 0;
  const std::size_t px = bytes_per_pixel(want.format());
  for (int y = 0; y < want.height(); ++y)
    for (int x = 0; x < want.width(); ++x)
      n += std::memcmp(got.row(y) + std::size_t(x) * px,
                       static_cast<const std::byte*>(want.data()) + (std::size_t(y) * want.width() + x) * px, px) != 0;
  return n;
}

// One randomly drawn layout of the caller's memory.
struct Layout {
  std::size_t color_pad, depth_pad, color_offset, depth_offset, out_pad, out_offset;
  bool in_place;
  bool device_takes_it(std::size_t alignment, std::size_t) const {
    const bool color = color_pad == 0 && color_offset % alignment == 0;
    const bool depth = depth_pad == 0 && depth_offset % alignment == 0;
    const bool out = in_place || (out_pad == 0 && out_offset % alignment == 0);
    return color && depth && out;
  }
};

Layout draw_layout(std::mt19937& rng, std::size_t channel) {
  std::uniform_int_distribution<int> coin(0, 1), pads(1, 9);
  Layout l{};
  l.in_place = coin(rng) != 0;
  if (std::uniform_int_distribution<int>(0, 2)(rng) == 0) return l;  // packed and page-aligned
  const auto pad = [&] { return coin(rng) ? 0 : std::size_t(pads(rng)) * 4 * channel; };
  const auto offset = [&] { return coin(rng) ? 0 : std::size_t(pads(rng)) * channel; };
  l.color_pad = pad();
  l.depth_pad = coin(rng) ? 0 : std::size_t(pads(rng)) * 4;
  l.out_pad = pad();
  l.color_offset = offset();
  l.depth_offset = coin(rng) ? 0 : std::size_t(pads(rng)) * 4;
  l.out_offset = offset();
  return l;
}

std::size_t host_alignment() {
  const cl_uint bits = cl::Device(runtime()->device(), true).getInfo<CL_DEVICE_MEM_BASE_ADDR_ALIGN>();
  return std::max<std::size_t>(bits / 8, 1);
}

TEST(Views, FogPassThroughViewsGivesTheImagesBits) {
  FOGCL_REQUIRE_DEVICE();
  const std::size_t alignment = host_alignment();
  std::printf("device base address alignment: %zu bytes\n", alignment);
  FogPass direct(*runtime(), {}, shared_pass().program_cache());
  FogPass staged(*runtime(), {}, shared_pass().program_cache());
  direct.set_host_transfer(HostTransfer::direct);
  staged.set_host_transfer(HostTransfer::staged);
  const bool cpu = device_traits(runtime()->device()).cpu;
  FogSettings fog;
  fog.mode = FogMode::exp2;
  fog.density = 0.05f;
  fog.metric = FogMetric::distance;
  fog.color = {0.5f, 0.6f, 0.7f};
  std::mt19937 rng(20261128);
  std::uniform_int_distribution<int> side(1, 90);
  std::size_t cases = 0, worst_pixels = 0, worst_padding = 0, zero_copy_seen = 0, copied_seen = 0;
  for (int trial = 0; trial < 48; ++trial) {
    const ColorFormat format = trial % 2 ? ColorFormat::rgba16f : ColorFormat::rgba32f;
    const TestFrame t = make_test_frame(side(rng), side(rng), trial % 3 == 0, format, std::uint32_t(trial + 1));
    const std::size_t channel = format == ColorFormat::rgba16f ? 2 : 4;
    ColorImage want;
    shared_pass().apply(t.color, t.depth, want, t.params, fog);
    const Layout l = draw_layout(rng, channel);
    for (FogPass* pass : {&direct, &staged}) {
      CallerMemory cm(t.color.width() * bytes_per_pixel(format), t.color.height(), l.color_pad, l.color_offset);
      CallerMemory dm(t.depth.width() * sizeof(float), t.depth.height(), l.depth_pad, l.depth_offset);
      CallerMemory om(t.color.width() * bytes_per_pixel(format), t.color.height(), l.out_pad, l.out_offset);
      const ColorView in = color_view_of(cm, t.color);
      fill(in, t.color);
      const DepthView depth = depth_view_of(dm, t.depth);
      const ColorView out = l.in_place ? in : color_view_of(om, t.color);
      const PassStats before = pass->stats();
      if (trial % 4 == 3) {
        PendingFrame frame = pass->apply_async(in, depth, out, t.params, fog);
        frame.wait();
      } else {
        pass->apply(in, depth, out, t.params, fog);
      }
      const std::size_t differ = differing_pixels(out, want);
      const std::size_t touched = cm.padding_touched(in.row_bytes(), in.height()) +
                                  dm.padding_touched(depth.row_bytes(), depth.height()) +
                                  (l.in_place ? 0 : om.padding_touched(out.row_bytes(), out.height()));
      EXPECT_EQ(differ, 0u) << t.color.width() << "x" << t.color.height() << " " << to_string(format)
                            << (pass == &direct ? " direct" : " staged") << " pads " << l.color_pad << "/"
                            << l.depth_pad << "/" << l.out_pad << " offsets " << l.color_offset << "/"
                            << l.depth_offset << "/" << l.out_offset << (l.in_place ? " in place" : "");
      EXPECT_EQ(touched, 0u) << "bytes outside the pixels were written";
      if (!l.in_place) {
        EXPECT_EQ(differing_pixels(in, t.color), 0u) << "the input changed";
      }
      worst_pixels = std::max(worst_pixels, differ);
      worst_padding = std::max(worst_padding, touched);
      // The kernel works in the caller's memory exactly when the device can take it there.
      if (pass == &direct && cpu) {
        const bool in_place_use = l.device_takes_it(alignment, channel);
        EXPECT_EQ(pass->stats().zero_copy_frames - before.zero_copy_frames, in_place_use ? 1u : 0u);
        EXPECT_EQ(pass->stats().copied_frames - before.copied_frames, in_place_use ? 0u : 1u);
        (in_place_use ? zero_copy_seen : copied_seen) += 1;
      }
      ++cases;
    }
  }
  std::printf("%zu cases: worst differing pixels %zu, worst bytes written outside the pixels %zu; "
              "direct CPU frames in place %zu, copied %zu\n",
              cases, worst_pixels, worst_padding, zero_copy_seen, copied_seen);
  if (cpu) {
    EXPECT_GT(zero_copy_seen, 0u);
    EXPECT_GT(copied_seen, 0u);
  }
}

TEST(Views, InPlaceApplyWritesTheCallersAlignedMemoryWithoutACopy) {
  FOGCL_REQUIRE_DEVICE();
  FogPass pass(*runtime(), {}, shared_pass().program_cache());
  pass.set_host_transfer(HostTransfer::direct);
  if (!device_traits(runtime()->device()).cpu) GTEST_SKIP() << "in-place use of host memory is for CPU devices";
  const TestFrame t = make_test_frame(64, 36, false, ColorFormat::rgba32f, 7);
  FogSettings fog;
  fog.density = 0.2f;
  ColorImage want;
  shared_pass().apply(t.color, t.depth, want, t.params, fog);
  // The renderer's own buffers: page-aligned std::vector-free memory the kernel can map.
  CallerMemory cm(t.color.width() * 16, t.color.height(), 0, 0);
  CallerMemory dm(t.depth.width() * 4, t.depth.height(), 0, 0);
  const ColorView color = color_view_of(cm, t.color);
  fill(color, t.color);
  const DepthView depth = depth_view_of(dm, t.depth);
  const std::size_t copied_before = pass.stats().copied_frames, zero_before = pass.stats().zero_copy_frames;
  pass.apply(color, depth, color, t.params, fog);
  const std::size_t differ = differing_pixels(color, want);
  std::printf("in place over the caller's memory: %zu pixels differ from the image path; frames in place %zu, "
              "copied %zu\n",
              differ, pass.stats().zero_copy_frames - zero_before, pass.stats().copied_frames - copied_before);
  EXPECT_EQ(differ, 0u);
  EXPECT_EQ(pass.stats().zero_copy_frames - zero_before, 1u);
  EXPECT_EQ(pass.stats().copied_frames - copied_before, 0u);
}

TEST(Views, VolumePassThroughViewsGivesTheImagesBits) {
  FOGCL_REQUIRE_DEVICE();
  const std::size_t alignment = host_alignment();
  VolumePass direct(*runtime(), shared_pass().program_cache());
  VolumePass staged(*runtime(), shared_pass().program_cache());
  VolumePass reference(*runtime(), shared_pass().program_cache());
  direct.set_host_transfer(HostTransfer::direct);
  staged.set_host_transfer(HostTransfer::staged);
  const bool cpu = device_traits(runtime()->device()).cpu;
  VolumeSettings settings;
  settings.steps = 12;
  std::mt19937 rng(42);
  std::uniform_int_distribution<int> side(8, 60);
  std::size_t cases = 0, worst = 0;
  for (int trial = 0; trial < 8; ++trial) {
    const ColorFormat format = trial % 2 ? ColorFormat::rgba16f : ColorFormat::rgba32f;
    const VolumeTestScene s = volume_test_scene(side(rng), side(rng), format, trial % 3 == 1);
    const ColorImage& color_image = s.frame.color;
    ColorImage want;
    reference.apply(color_image, s.frame.depth, want, s.frame.params, s.scene, settings);
    const Layout l = draw_layout(rng, format == ColorFormat::rgba16f ? 2 : 4);
    for (VolumePass* pass : {&direct, &staged}) {
      CallerMemory cm(color_image.width() * bytes_per_pixel(format), color_image.height(), l.color_pad,
                      l.color_offset);
      CallerMemory dm(color_image.width() * sizeof(float), color_image.height(), l.depth_pad, l.depth_offset);
      CallerMemory om(color_image.width() * bytes_per_pixel(format), color_image.height(), l.out_pad, l.out_offset);
      const ColorView in = color_view_of(cm, color_image);
      fill(in, color_image);
      const DepthView depth = depth_view_of(dm, s.frame.depth);
      const ColorView out = l.in_place ? in : color_view_of(om, color_image);
      const VolumePassStats before = pass->stats();
      pass->apply(in, depth, out, s.frame.params, s.scene, settings);
      const std::size_t differ = differing_pixels(out, want);
      EXPECT_EQ(differ, 0u) << color_image.width() << "x" << color_image.height() << " " << to_string(format)
                            << (pass == &direct ? " direct" : " staged") << (l.in_place ? " in place" : "");
      EXPECT_EQ(cm.padding_touched(in.row_bytes(), in.height()) +
                    (l.in_place ? 0 : om.padding_touched(out.row_bytes(), out.height())),
                0u);
      if (pass == &direct && cpu && pass->stats().frames_without_volumes == before.frames_without_volumes) {
        EXPECT_EQ(pass->stats().zero_copy_frames - before.zero_copy_frames,
                  l.device_takes_it(alignment, 0) ? 1u : 0u);
      }
      worst = std::max(worst, differ);
      ++cases;
    }
  }
  std::printf("%zu volume cases: worst differing pixels %zu\n", cases, worst);
}

TEST(Views, ScalarPathsThroughViewsGiveTheImagesBits) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> side(1, 50);
  std::size_t worst = 0, cases = 0;
  FogSettings fog;
  fog.mode = FogMode::linear;
  fog.start = 2.0f;
  fog.end = 40.0f;
  for (int trial = 0; trial < 24; ++trial) {
    const ColorFormat format = trial % 2 ? ColorFormat::rgba16f : ColorFormat::rgba32f;
    const TestFrame t = make_test_frame(side(rng), side(rng), trial % 2 == 0, format, std::uint32_t(trial + 3));
    ColorImage want;
    apply_fog_scalar(t.color, t.depth, want, t.params, fog);
    const Layout l = draw_layout(rng, format == ColorFormat::rgba16f ? 2 : 4);
    CallerMemory cm(t.color.width() * bytes_per_pixel(format), t.color.height(), l.color_pad, l.color_offset);
    CallerMemory dm(t.depth.width() * sizeof(float), t.depth.height(), l.depth_pad, l.depth_offset);
    CallerMemory om(t.color.width() * bytes_per_pixel(format), t.color.height(), l.out_pad, l.out_offset);
    const ColorView in = color_view_of(cm, t.color);
    fill(in, t.color);
    const DepthView depth = depth_view_of(dm, t.depth);
    const ColorView out = l.in_place ? in : color_view_of(om, t.color);
    apply_fog_scalar(in, depth, out, t.params, fog);
    const std::size_t differ = differing_pixels(out, want);
    EXPECT_EQ(differ, 0u) << "apply_fog_scalar " << t.color.width() << "x" << t.color.height();
    const FogResult<double> a = fog_scalar<double>(t.color, t.depth, t.params, fog);
    fill(in, t.color);
    const FogResult<double> b = fog_scalar<double>(in, depth, t.params, fog);
    EXPECT_EQ(a.rgba, b.rgba);
    worst = std::max(worst, differ);
    ++cases;
  }
  for (int trial = 0; trial < 4; ++trial) {
    const ColorFormat format = trial % 2 ? ColorFormat::rgba16f : ColorFormat::rgba32f;
    const VolumeTestScene s = volume_test_scene(24 + 7 * trial, 16 + 3 * trial, format);
    VolumeSettings settings;
    settings.steps = 8;
    ColorImage want;
    apply_volumes_scalar(s.frame.color, s.frame.depth, want, s.frame.params, s.scene, settings);
    const Layout l = draw_layout(rng, format == ColorFormat::rgba16f ? 2 : 4);
    CallerMemory cm(s.frame.color.width() * bytes_per_pixel(format), s.frame.color.height(), l.color_pad,
                    l.color_offset);
    CallerMemory dm(s.frame.color.width() * sizeof(float), s.frame.color.height(), l.depth_pad, l.depth_offset);
    CallerMemory om(s.frame.color.width() * bytes_per_pixel(format), s.frame.color.height(), l.out_pad, l.out_offset);
    const ColorView in = color_view_of(cm, s.frame.color);
    fill(in, s.frame.color);
    const DepthView depth = depth_view_of(dm, s.frame.depth);
    const ColorView out = l.in_place ? in : color_view_of(om, s.frame.color);
    apply_volumes_scalar(in, depth, out, s.frame.params, s.scene, settings);
    const std::size_t differ = differing_pixels(out, want);
    EXPECT_EQ(differ, 0u) << "apply_volumes_scalar " << s.frame.color.width() << "x" << s.frame.color.height();
    worst = std::max(worst, differ);
    ++cases;
  }
  std::printf("%zu scalar cases: worst differing pixels %zu\n", cases, worst);
}

// Each wrong view is an Error naming the rule.
TEST(Views, InvalidViewsAreErrorsNamingTheRule) {
  alignas(64) static float memory[4096];
  const auto expect_error = [](auto&& make, const char* needle) {
    try {
      make();
      ADD_FAILURE() << "no error for: " << needle;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error([] { ColorView(nullptr, 4, 4); }, "data is null");
  expect_error([&] { ColorView(memory, 0, 4); }, "at least 1x1");
  expect_error([&] { ColorView(memory, 4, 4, ColorFormat::rgba32f, 32); }, "less than a row");
  expect_error([&] { ColorView(reinterpret_cast<char*>(memory) + 2, 4, 4); }, "multiples of a channel");
  expect_error([&] { ColorView(memory, 4, 4, ColorFormat::rgba32f, 66); }, "multiples of a channel");
  expect_error([&] { ConstDepthView(memory, 4, 4, 8); }, "less than a row");
  expect_error([&] { ColorView(memory, 4, 4).pixel(4, 0); }, "outside");
  expect_error([&] { DepthView(memory, 4, 4).at(0, -1); }, "outside");
  // Outputs: a wrong size, and memory overlapping the input without being it.
  const ColorView in(memory, 8, 8);                 // floats [0, 256)
  const ConstDepthView depth(memory + 1024, 8, 8);  // floats [1024, 1088)
  expect_error([&] { validate_frame(in, depth, ColorView(memory + 2048, 8, 4)); }, "cannot be resized");
  expect_error([&] { validate_frame(in, depth, ColorView(memory + 4, 8, 8)); }, "overlaps the input");
  expect_error([&] { validate_frame(in, depth, ColorView(memory + 1024 - 200, 8, 8)); }, "overlaps the depth");
  validate_frame(in, depth, in);  // in place
  validate_frame(in, depth, ColorView(memory + 2048, 8, 8));
}

}  // namespace
}  // namespace fogcl::test
