// EXR and PNG I/O (src/io): round trips, windows (docs/DESIGN.md §2: the display window is the frame),
// bad input, the temp-and-rename writers, and the dithered sRGB PNG preview.
//
// Files that feed the readers are written with OpenEXR directly (write_raw_exr), so the readers
// are not only checked against fogcl's own writer.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <Imath/ImathBox.h>
#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <png.h>

#include "fogcl/error.h"
#include "fogcl/exr_io.h"
#include "fogcl/image.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;
using fogcl::ColorFormat;
using fogcl::ColorImage;
using fogcl::DepthImage;
using fogcl::ExrWindows;

struct RawChannel {
  std::string name;
  Imf::PixelType type;        // as stored in the file: HALF or FLOAT
  std::vector<float> values;  // data window, row-major, top row first
};

// Writes an EXR with OpenEXR itself: any windows, any channel names and types.
void write_raw_exr(const std::string& path, const Imath::Box2i& display, const Imath::Box2i& data,
                   const std::vector<RawChannel>& channels) {
  Imf::Header header(display, data);
  for (const RawChannel& c : channels) header.channels().insert(c.name, Imf::Channel(c.type));
  Imf::OutputFile file(path.c_str(), header);
  Imf::FrameBuffer fb;
  const std::size_t width = std::size_t(data.max.x - data.min.x + 1);
  std::vector<std::vector<Imath::half>> halves;  // the frame buffer's type must match the file's
  halves.reserve(channels.size());
  for (const RawChannel& c : channels) {
    if (c.type == Imf::HALF) {
      halves.emplace_back(c.values.begin(), c.values.end());
      fb.insert(c.name, Imf::Slice::Make(Imf::HALF, halves.back().data(), data, sizeof(Imath::half),
                                         sizeof(Imath::half) * width));
    } else {
      fb.insert(c.name, Imf::Slice::Make(Imf::FLOAT, c.values.data(), data, sizeof(float), sizeof(float) * width));
    }
  }
  file.setFrameBuffer(fb);
  file.writePixels(data.max.y - data.min.y + 1);
}

Imath::Box2i box(int x0, int y0, int x1, int y1) { return Imath::Box2i(Imath::V2i(x0, y0), Imath::V2i(x1, y1)); }

// Deterministic test values (xorshift32), spread over many magnitudes and both signs.
class Values {
 public:
  float next() {
    state_ ^= state_ << 13;
    state_ ^= state_ >> 17;
    state_ ^= state_ << 5;
    const float unit = float(state_ >> 8) / 16777216.0f;                // [0, 1)
    return (unit - 0.25f) * std::ldexp(1.0f, int(state_ % 41u) - 20);  // 2^-20 .. 2^20
  }

 private:
  std::uint32_t state_ = 0x12345678u;
};

double srgb_encode_reference(double linear) {  // IEC 61966-2-1, in double
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

struct Png {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
  int at(int x, int y, int c) const { return rgba[4 * (std::size_t(y) * std::size_t(width) + std::size_t(x)) + c]; }
};

Png read_png(const std::string& path) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str())) {
    ADD_FAILURE() << "libpng cannot read " << path << ": " << image.message;
    return {};
  }
  EXPECT_EQ(image.format, png_uint_32(PNG_FORMAT_RGBA)) << "the preview is 8-bit RGBA";
  image.format = PNG_FORMAT_RGBA;  // 8-bit sRGB in, 8-bit sRGB out: bytes as stored
  Png png;
  png.width = int(image.width);
  png.height = int(image.height);
  png.rgba.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, png.rgba.data(), 0, nullptr)) {
    ADD_FAILURE() << "libpng cannot decode " << path << ": " << image.message;
    png_image_free(&image);
    return {};
  }
  return png;
}

class ExrIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // One folder per test: ctest may run tests in parallel and each checks its folder for leftovers.
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    dir_ = fs::path(fogcl::test::temp_dir()) / ("exrio_" + test);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }

  std::string path(const std::string& name) const { return (dir_ / ("exrio_" + name)).string(); }

  std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

  void expect_no_temp_files() const {
    for (const std::string& name : files()) EXPECT_EQ(name.find(".tmp"), std::string::npos) << "left behind: " << name;
  }

  // `f` must throw a one-line fogcl::Error naming `file` and containing `expected`, and leave the
  // folder as it was.
  void expect_error(const std::string& file, const std::string& expected, const std::function<void()>& f) const {
    const std::vector<std::string> before = files();
    try {
      f();
      ADD_FAILURE() << "no fogcl::Error for " << file;
    } catch (const fogcl::Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(file), std::string::npos) << what;
      EXPECT_NE(what.find(expected), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << "one line: " << what;
      std::cout << "  [error] " << what << "\n";
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a fogcl::Error: " << e.what();
    }
    EXPECT_EQ(files(), before) << "the folder changed";
  }

  fs::path dir_;
};

// ---------------------------------------------------------------------------------------------
// Round trips

TEST_F(ExrIoTest, ColorFloatRoundTripIsBitExact) {
  ColorImage image(7, 5);
  Values values;
  for (std::size_t i = 0; i < 4 * image.pixel_count(); ++i) image.rgba32f()[i] = values.next();
  image.rgba32f()[0] = std::numeric_limits<float>::infinity();
  image.rgba32f()[1] = std::numeric_limits<float>::denorm_min();
  image.rgba32f()[2] = -0.0f;
  const std::string file = path("float.exr");
  fogcl::write_exr_rgba(file, image);

  ExrWindows windows;
  const ColorImage back = fogcl::read_exr_color(file, &windows);
  ASSERT_EQ(back.width(), 7);
  ASSERT_EQ(back.height(), 5);
  EXPECT_EQ(back.format(), ColorFormat::rgba32f);
  EXPECT_EQ(std::memcmp(back.data(), image.data(), image.size_bytes()), 0);
  ExrWindows full;
  full.display_min = full.data_min = {0, 0};
  full.display_max = full.data_max = {6, 4};
  EXPECT_EQ(windows, full);

  Imf::InputFile raw(file.c_str());  // what is in the file: R, G, B, A as FLOAT
  std::vector<std::string> names;
  for (auto it = raw.header().channels().begin(); it != raw.header().channels().end(); ++it) {
    names.push_back(it.name());
    EXPECT_EQ(it.channel().type, Imf::FLOAT) << it.name();
  }
  EXPECT_EQ(names, (std::vector<std::string>{"A", "B", "G", "R"}));
  expect_no_temp_files();
}

TEST_F(ExrIoTest, ColorHalfRoundTripIsBitExact) {
  ColorImage image(6, 4, ColorFormat::rgba16f);
  Values values;
  for (std::size_t i = 0; i < 4 * image.pixel_count(); ++i)
    image.rgba16f()[i] = Imath::half(std::clamp(values.next(), -60000.0f, 60000.0f)).bits();
  const std::string file = path("half.exr");
  fogcl::write_exr_rgba(file, image);  // widened to float: exact

  const ColorImage half_back = fogcl::read_exr_color(file, nullptr, ColorFormat::rgba16f);
  EXPECT_EQ(half_back.format(), ColorFormat::rgba16f);
  EXPECT_EQ(std::memcmp(half_back.data(), image.data(), image.size_bytes()), 0);
  const ColorImage float_back = fogcl::read_exr_color(file);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 6; ++x) EXPECT_EQ(float_back.pixel(x, y), image.pixel(x, y)) << x << "," << y;
  expect_no_temp_files();
}

TEST_F(ExrIoTest, HalfReadRoundsToNearestEven) {
  const float one_ulp = std::ldexp(1.0f, -10);  // half spacing at 1.0
  const std::string file = path("ties.exr");
  // Exactly halfway between two halves: 1 + ulp/2 -> 1.0 (even), 1 + 3ulp/2 -> 1 + 2ulp (even);
  // just above halfway rounds up.
  const std::vector<float> r = {1.0f + one_ulp / 2, 1.0f + 3 * one_ulp / 2, 1.0f + one_ulp / 2 + one_ulp / 64};
  write_raw_exr(file, box(0, 0, 2, 0), box(0, 0, 2, 0),
                {{"R", Imf::FLOAT, r}, {"G", Imf::FLOAT, {0, 0, 0}}, {"B", Imf::FLOAT, {0, 0, 0}}});
  const ColorImage image = fogcl::read_exr_color(file, nullptr, ColorFormat::rgba16f);
  EXPECT_EQ(image.rgba16f()[0], 0x3C00);
  EXPECT_EQ(image.rgba16f()[4], 0x3C02);
  EXPECT_EQ(image.rgba16f()[8], 0x3C01);
  EXPECT_EQ(image.rgba16f()[3], 0x3C00) << "missing A reads as 1";
}

TEST_F(ExrIoTest, RgbWithoutAlphaIsOpaque) {
  const std::string file = path("rgb_half.exr");
  write_raw_exr(file, box(0, 0, 1, 1), box(0, 0, 1, 1),
                {{"R", Imf::HALF, {0.5f, 1, 2, 0.25f}},
                 {"G", Imf::HALF, {0, -1, 8, 0.125f}},
                 {"B", Imf::HALF, {3, 4, 5, 6}}});
  const ColorImage image = fogcl::read_exr_color(file);
  EXPECT_EQ(image.pixel(0, 0), glm::vec4(0.5f, 0, 3, 1));
  EXPECT_EQ(image.pixel(1, 0), glm::vec4(1, -1, 4, 1));
  EXPECT_EQ(image.pixel(0, 1), glm::vec4(2, 8, 5, 1));
  EXPECT_EQ(image.pixel(1, 1), glm::vec4(0.25f, 0.125f, 6, 1));
}

TEST_F(ExrIoTest, DepthRoundTripIsBitExact) {
  DepthImage depth(9, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 9; ++x) depth.at(x, y) = std::nextafter(float(x + 9 * y) / 36.0f, 2.0f);
  depth.at(8, 3) = 1.0f;
  const std::string file = path("depth.exr");
  fogcl::write_exr_depth(file, depth);

  ExrWindows windows;
  const DepthImage back = fogcl::read_exr_depth(file, &windows);
  ASSERT_EQ(back.width(), 9);
  ASSERT_EQ(back.height(), 4);
  EXPECT_EQ(std::memcmp(back.data(), depth.data(), depth.size_bytes()), 0);
  EXPECT_EQ(windows.display_max, glm::ivec2(8, 3));

  Imf::InputFile raw(file.c_str());
  const Imf::ChannelList& channels = raw.header().channels();
  ASSERT_NE(channels.findChannel("Z"), nullptr);
  EXPECT_EQ(channels.findChannel("Z")->type, Imf::FLOAT);
  int channel_count = 0;
  for (auto it = channels.begin(); it != channels.end(); ++it) ++channel_count;
  EXPECT_EQ(channel_count, 1);
  expect_no_temp_files();
}

TEST_F(ExrIoTest, DepthFromTheOnlyChannelWhateverItsName) {
  const std::string file = path("depth_named.exr");
  write_raw_exr(file, box(0, 0, 2, 0), box(0, 0, 2, 0), {{"depth.V", Imf::FLOAT, {0.25f, 0.5f, 0.999f}}});
  const DepthImage depth = fogcl::read_exr_depth(file);
  EXPECT_EQ(depth.at(0, 0), 0.25f);
  EXPECT_EQ(depth.at(1, 0), 0.5f);
  EXPECT_EQ(depth.at(2, 0), 0.999f);
}

TEST_F(ExrIoTest, DepthChannelChosenByName) {
  const std::string file = path("two_channels.exr");
  write_raw_exr(file, box(0, 0, 1, 0), box(0, 0, 1, 0),
                {{"Z", Imf::FLOAT, {0.1f, 0.2f}}, {"depth", Imf::HALF, {0.5f, 0.75f}}});
  EXPECT_EQ(fogcl::read_exr_depth(file).at(1, 0), 0.2f);
  EXPECT_EQ(fogcl::read_exr_depth(file, nullptr, "depth").at(1, 0), 0.75f);
}

TEST_F(ExrIoTest, MissingDepthChannelNamesTheChannelsPresent) {
  const std::string file = path("color_only.exr");
  fogcl::write_exr_rgba(file, ColorImage(2, 2));
  expect_error(file, "no depth channel 'Z' (channels present: A, B, G, R)", [&] { fogcl::read_exr_depth(file); });
  expect_error(file, "no depth channel 'depth'", [&] { fogcl::read_exr_depth(file, nullptr, "depth"); });
}

TEST_F(ExrIoTest, MissingColorChannelNamesTheChannelsPresent) {
  const std::string depth_file = path("depth_only.exr");
  fogcl::write_exr_depth(depth_file, DepthImage(2, 2, 0.5f));
  expect_error(depth_file, "missing channel R (channels present: Z)", [&] { fogcl::read_exr_color(depth_file); });

  const std::string rg_file = path("rg.exr");
  write_raw_exr(rg_file, box(0, 0, 0, 0), box(0, 0, 0, 0), {{"R", Imf::HALF, {1}}, {"G", Imf::HALF, {1}}});
  expect_error(rg_file, "missing channel B (channels present: G, R)", [&] { fogcl::read_exr_color(rg_file); });
}

// ---------------------------------------------------------------------------------------------
// Bad files: one fogcl::Error line naming the file, nothing written.

TEST_F(ExrIoTest, MissingFileIsAnError) {
  const std::string file = path("does_not_exist.exr");
  expect_error(file, "cannot read EXR", [&] { fogcl::read_exr_color(file); });
  expect_error(file, "cannot read EXR", [&] { fogcl::read_exr_depth(file); });
}

TEST_F(ExrIoTest, NotAnExrIsAnError) {
  const std::string file = path("text.exr");
  std::ofstream(file) << "this is a text file, not an OpenEXR image\n";
  expect_error(file, "cannot read EXR", [&] { fogcl::read_exr_color(file); });
  expect_error(file, "cannot read EXR", [&] { fogcl::read_exr_depth(file); });

  const std::string empty = path("empty.exr");
  std::ofstream{empty};
  expect_error(empty, "cannot read EXR", [&] { fogcl::read_exr_color(empty); });
}

TEST_F(ExrIoTest, TruncatedExrIsAnError) {
  ColorImage image(64, 48);
  Values values;  // noise: compresses badly, so half the file is half the pixels
  for (std::size_t i = 0; i < 4 * image.pixel_count(); ++i) image.rgba32f()[i] = values.next();
  const std::string whole = path("whole.exr");
  fogcl::write_exr_rgba(whole, image);
  std::vector<char> bytes;
  {
    std::ifstream in(whole, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  ASSERT_GT(bytes.size(), 1000u);

  for (std::size_t keep : {bytes.size() / 2, std::size_t(40), std::size_t(4)}) {
    const std::string cut = path("cut_" + std::to_string(keep) + ".exr");
    std::ofstream(cut, std::ios::binary).write(bytes.data(), std::streamsize(keep));
    expect_error(cut, "cannot read EXR", [&] { fogcl::read_exr_color(cut); });
    expect_error(cut, "cannot read EXR", [&] { fogcl::read_exr_depth(cut, nullptr, "R"); });
  }
}

TEST_F(ExrIoTest, AbsurdDisplayWindowIsRejectedBeforeAllocating) {
  const std::string file = path("huge.exr");
  // 100000 x 100000 = 10^10 pixels (160 GB as RGBA float); only 2 x 2 are stored.
  write_raw_exr(file, box(0, 0, 99999, 99999), box(0, 0, 1, 1),
                {{"R", Imf::HALF, {0, 0, 0, 0}}, {"G", Imf::HALF, {0, 0, 0, 0}}, {"B", Imf::HALF, {0, 0, 0, 0}}});
  expect_error(file, "more than the limit of 2^31", [&] { fogcl::read_exr_color(file); });
  expect_error(file, "more than the limit of 2^31", [&] { fogcl::read_exr_depth(file, nullptr, "R"); });
}

// ---------------------------------------------------------------------------------------------
// Windows (docs/DESIGN.md §2)

TEST_F(ExrIoTest, DataWindowInsideDisplayWindowKeepsPixelPositions) {
  const Imath::Box2i display = box(-3, -2, 12, 9);  // 16 x 12 frame
  const Imath::Box2i data = box(1, 0, 8, 6);        // 8 x 7 stored
  std::vector<float> r, g, z;
  for (int y = data.min.y; y <= data.max.y; ++y)
    for (int x = data.min.x; x <= data.max.x; ++x) {
      r.push_back(float(x));
      g.push_back(float(y));
      z.push_back(0.01f * float(x + 100 * y));
    }
  const std::vector<float> b(r.size(), 2.0f);
  const std::string color_file = path("windowed_color.exr");
  const std::string depth_file = path("windowed_depth.exr");
  write_raw_exr(color_file, display, data, {{"R", Imf::FLOAT, r}, {"G", Imf::HALF, g}, {"B", Imf::FLOAT, b}});
  write_raw_exr(depth_file, display, data, {{"Z", Imf::FLOAT, z}});

  ExrWindows windows;
  const ColorImage color = fogcl::read_exr_color(color_file, &windows);
  EXPECT_EQ(windows.display_min, glm::ivec2(-3, -2));
  EXPECT_EQ(windows.display_max, glm::ivec2(12, 9));
  EXPECT_EQ(windows.data_min, glm::ivec2(1, 0));
  EXPECT_EQ(windows.data_max, glm::ivec2(8, 6));
  ASSERT_EQ(color.width(), 16);
  ASSERT_EQ(color.height(), 12);
  const DepthImage depth = fogcl::read_exr_depth(depth_file, nullptr, "Z", 0.75f);
  const DepthImage depth_default = fogcl::read_exr_depth(depth_file);
  ASSERT_EQ(depth.width(), 16);
  ASSERT_EQ(depth.height(), 12);

  for (int fy = 0; fy < 12; ++fy)
    for (int fx = 0; fx < 16; ++fx) {
      const int x = fx + display.min.x, y = fy + display.min.y;  // file (absolute) coordinates
      const bool stored = x >= data.min.x && x <= data.max.x && y >= data.min.y && y <= data.max.y;
      if (stored) {
        EXPECT_EQ(color.pixel(fx, fy), glm::vec4(float(x), float(y), 2.0f, 1.0f)) << fx << "," << fy;
        EXPECT_EQ(depth.at(fx, fy), 0.01f * float(x + 100 * y)) << fx << "," << fy;
        EXPECT_EQ(depth_default.at(fx, fy), depth.at(fx, fy));
      } else {
        EXPECT_EQ(color.pixel(fx, fy), glm::vec4(0.0f)) << fx << "," << fy;
        EXPECT_EQ(depth.at(fx, fy), 0.75f) << fx << "," << fy;
        EXPECT_EQ(depth_default.at(fx, fy), 1.0f) << fx << "," << fy;
      }
    }
}

// Reading into a previous frame (ExrReadRequest::color_into / depth_into, as a sequence does)
// gives the bytes of a fresh read and reuses the memory: with a full data window, and with a
// smaller one, whose unstored pixels must come out as a new frame's, not as the old frame's.
TEST_F(ExrIoTest, ReadingIntoAnOldFrameGivesTheFreshBytesAndReusesItsMemory) {
  const Imath::Box2i display = box(0, 0, 15, 11);
  const std::string full_file = path("full.exr"), windowed_file = path("windowed.exr");
  for (const auto& [file, data] : {std::pair{full_file, display}, std::pair{windowed_file, box(2, 1, 9, 8)}}) {
    std::vector<float> r, z;
    for (int y = data.min.y; y <= data.max.y; ++y)
      for (int x = data.min.x; x <= data.max.x; ++x) {
        r.push_back(float(x) + 0.5f);
        z.push_back(0.01f * float(x + 100 * y));
      }
    write_raw_exr(file, display, data,
                  {{"R", Imf::FLOAT, r}, {"G", Imf::HALF, r}, {"B", Imf::FLOAT, r}, {"Z", Imf::FLOAT, z}});
  }
  fogcl::ExrReadRequest request;
  request.depth_channel = "Z";
  request.depth_outside = 0.75f;
  for (const std::string& file : {full_file, windowed_file}) {
    const fogcl::ExrInput fresh = fogcl::read_exr(file, request);
    // An old frame of the same size full of other values (as the previous frame of a shot is).
    ColorImage old_color(16, 12);
    fogcl::DepthImage old_depth(16, 12, -7.0f);
    std::fill(old_color.rgba32f(), old_color.rgba32f() + 4 * old_color.pixel_count(), 42.0f);
    const void* color_memory = old_color.data();
    const float* depth_memory = old_depth.data();
    fogcl::ExrReadRequest into = request;
    into.color_into = &old_color;
    into.depth_into = &old_depth;
    const fogcl::ExrInput reused = fogcl::read_exr(file, into);
    EXPECT_EQ(reused.color.data(), color_memory) << file;
    EXPECT_EQ(reused.depth.data(), depth_memory) << file;
    ASSERT_EQ(reused.color.size_bytes(), fresh.color.size_bytes());
    EXPECT_EQ(std::memcmp(reused.color.data(), fresh.color.data(), fresh.color.size_bytes()), 0) << file;
    EXPECT_EQ(std::memcmp(reused.depth.data(), fresh.depth.data(), 4 * fresh.depth.pixel_count()), 0) << file;
    // A frame of another size (or storage) is left alone and a new one is made.
    ColorImage small(3, 3);
    fogcl::ExrReadRequest other = request;
    other.color_into = &small;
    const fogcl::ExrInput made = fogcl::read_exr(file, other);
    EXPECT_EQ(small.width(), 3);
    EXPECT_EQ(std::memcmp(made.color.data(), fresh.color.data(), fresh.color.size_bytes()), 0) << file;
  }
}

TEST_F(ExrIoTest, DataWindowOutsideDisplayWindowIsAnError) {
  const std::string file = path("data_outside.exr");
  write_raw_exr(file, box(0, 0, 3, 3), box(2, 2, 5, 3),
                {{"R", Imf::HALF, std::vector<float>(8, 0.0f)},
                 {"G", Imf::HALF, std::vector<float>(8, 0.0f)},
                 {"B", Imf::HALF, std::vector<float>(8, 0.0f)},
                 {"Z", Imf::FLOAT, std::vector<float>(8, 0.0f)}});
  expect_error(file, "is not inside the display window", [&] { fogcl::read_exr_color(file); });
  expect_error(file, "is not inside the display window", [&] { fogcl::read_exr_depth(file); });
}

TEST_F(ExrIoTest, WriteRgbaWithWindowsKeepsBothWindows) {
  ExrWindows windows;
  windows.display_min = {-2, -3};
  windows.display_max = {13, 8};  // 16 x 12
  windows.data_min = {1, 0};
  windows.data_max = {9, 6};
  for (ColorFormat format : {ColorFormat::rgba32f, ColorFormat::rgba16f}) {
    ColorImage image(16, 12, format);
    for (int y = 0; y < 12; ++y)
      for (int x = 0; x < 16; ++x) image.set_pixel(x, y, glm::vec4(float(x), float(y), 0.5f, 0.25f));
    const std::string file = path(std::string("windows_") + fogcl::to_string(format) + ".exr");
    fogcl::write_exr_rgba(file, image, &windows);

    ExrWindows back_windows;
    const ColorImage back = fogcl::read_exr_color(file, &back_windows);
    EXPECT_EQ(back_windows, windows);
    ASSERT_EQ(back.width(), 16);
    ASSERT_EQ(back.height(), 12);
    for (int fy = 0; fy < 12; ++fy)
      for (int fx = 0; fx < 16; ++fx) {
        const int x = fx + windows.display_min.x, y = fy + windows.display_min.y;
        const bool stored = x >= windows.data_min.x && x <= windows.data_max.x && y >= windows.data_min.y &&
                            y <= windows.data_max.y;
        EXPECT_EQ(back.pixel(fx, fy), stored ? image.pixel(fx, fy) : glm::vec4(0.0f)) << fx << "," << fy;
      }
  }
  expect_no_temp_files();
}

TEST_F(ExrIoTest, WriteRejectsWindowsThatDoNotFitTheImage) {
  const ColorImage image(8, 6);
  const std::string file = path("bad_windows.exr");
  ExrWindows w;
  w.display_min = {0, 0};
  w.display_max = {7, 6};  // 8 x 7, image is 8 x 6
  w.data_min = {0, 0};
  w.data_max = {7, 5};
  expect_error(file, "display window", [&] { fogcl::write_exr_rgba(file, image, &w); });
  w.display_max = {7, 5};
  w.data_max = {8, 5};  // one column outside
  expect_error(file, "not inside the display window", [&] { fogcl::write_exr_rgba(file, image, &w); });
  w.data_min = {3, 3};
  w.data_max = {2, 5};  // empty
  expect_error(file, "empty data window", [&] { fogcl::write_exr_rgba(file, image, &w); });
  EXPECT_FALSE(fs::exists(file));
}

// ---------------------------------------------------------------------------------------------
// Writers: complete file or none

TEST_F(ExrIoTest, WriteReplacesAnExistingFileAndLeavesNoTempFiles) {
  const std::string file = path("replace.exr");
  ColorImage first(3, 3), second(5, 2);
  first.set_pixel(1, 1, glm::vec4(1, 2, 3, 4));
  second.set_pixel(4, 1, glm::vec4(5, 6, 7, 8));
  fogcl::write_exr_rgba(file, first);
  fogcl::write_exr_rgba(file, second);
  const ColorImage back = fogcl::read_exr_color(file);
  ASSERT_EQ(back.width(), 5);
  EXPECT_EQ(back.pixel(4, 1), glm::vec4(5, 6, 7, 8));
  EXPECT_EQ(files(), std::vector<std::string>{"exrio_replace.exr"});
}

TEST_F(ExrIoTest, FailedWritesLeaveNothingBehind) {
  const std::string no_dir = (dir_ / "no_such_folder" / "exrio_x.exr").string();
  expect_error(no_dir, "cannot write EXR", [&] { fogcl::write_exr_rgba(no_dir, ColorImage(2, 2)); });
  expect_error(no_dir, "cannot write EXR", [&] { fogcl::write_exr_depth(no_dir, DepthImage(2, 2)); });
  const std::string no_dir_png = (dir_ / "no_such_folder" / "exrio_x.png").string();
  expect_error(no_dir_png, "cannot write PNG", [&] { fogcl::write_png_preview(no_dir_png, ColorImage(2, 2)); });

  // The target is a folder: the temp file is written, the rename fails, the temp file must go.
  const std::string folder = path("a_folder.exr");
  fs::create_directories(folder);
  expect_error(folder, "cannot write EXR", [&] { fogcl::write_exr_rgba(folder, ColorImage(2, 2)); });
  expect_error(folder, "cannot write EXR", [&] { fogcl::write_exr_depth(folder, DepthImage(2, 2)); });
  expect_error(folder, "cannot write PNG", [&] { fogcl::write_png_preview(folder, ColorImage(2, 2)); });
  EXPECT_TRUE(fs::is_directory(folder));
  EXPECT_TRUE(fs::is_empty(folder));
  expect_no_temp_files();
}

// ---------------------------------------------------------------------------------------------
// PNG preview

TEST_F(ExrIoTest, PngPreviewIsDitheredSrgbWithoutBias) {
  // A slow gradient: 0.2 .. 0.21 linear over 256 columns is about 3 sRGB codes (123.5 .. 126.5),
  // the case where plain rounding bands.
  const int width = 256, height = 64;
  ColorImage image(width, height);
  std::vector<double> linear(width);
  for (int x = 0; x < width; ++x) {
    linear[x] = 0.2 + 0.01 * double(x) / double(width - 1);
    for (int y = 0; y < height; ++y) image.set_pixel(x, y, glm::vec4(float(linear[x]), float(linear[x]), float(linear[x]), 1.0f));
  }
  const std::string file = path("gradient.png");
  fogcl::write_png_preview(file, image);
  expect_no_temp_files();
  const Png png = read_png(file);
  ASSERT_EQ(png.width, width);
  ASSERT_EQ(png.height, height);

  double worst_code = 0, worst_mean = 0;  // |png - sRGB x 255| per pixel; per column mean
  int worst_rounded = 0;                  // |png - round(sRGB x 255)|
  for (int x = 0; x < width; ++x) {
    const double exact = srgb_encode_reference(double(float(linear[x]))) * 255.0;
    for (int c = 0; c < 3; ++c) {
      double sum = 0;
      for (int y = 0; y < height; ++y) {
        const int code = png.at(x, y, c);
        sum += code;
        worst_code = std::max(worst_code, std::abs(code - exact));
        worst_rounded = std::max(worst_rounded, std::abs(code - int(std::lround(exact))));
      }
      worst_mean = std::max(worst_mean, std::abs(sum / height - exact));
    }
    for (int y = 0; y < height; ++y) EXPECT_EQ(png.at(x, y, 3), 255);
  }
  // Rows differ (dither is present) ...
  int differing_rows = 0;
  for (int y = 1; y < height; ++y)
    differing_rows += !std::equal(&png.rgba[4 * std::size_t(y) * width], &png.rgba[4 * std::size_t(y + 1) * width],
                                  &png.rgba[0]);
  std::cout << "  PNG gradient: worst |code - sRGB*255| = " << worst_code << " (TPDF bound 1.5), worst |code - "
            << "round(sRGB*255)| = " << worst_rounded << ", worst column-mean error = " << worst_mean
            << " codes (budget 0.5), rows differing from row 0: " << differing_rows << "/" << height - 1 << "\n";
  EXPECT_LE(worst_rounded, 1) << "within one code of the undithered value";
  EXPECT_LT(worst_code, 1.5);
  EXPECT_LE(worst_mean, 0.5) << "the dither is unbiased";
  EXPECT_GT(differing_rows, 0) << "no dither";

  // ... and the output is reproducible.
  const std::string again = path("gradient_again.png");
  fogcl::write_png_preview(again, image);
  EXPECT_EQ(read_png(again).rgba, png.rgba);
}

TEST_F(ExrIoTest, PngPreviewClampsAndKeepsAlphaLinear) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  ColorImage image(5, 1);
  image.set_pixel(0, 0, glm::vec4(nan, -1.0f, 0.0f, nan));
  image.set_pixel(1, 0, glm::vec4(2.0f, inf, 1.0f, 2.0f));
  image.set_pixel(2, 0, glm::vec4(-inf, 0.5f, 0.5f, 0.5f));
  image.set_pixel(3, 0, glm::vec4(0.0f, 0.0f, 0.0f, -1.0f));
  image.set_pixel(4, 0, glm::vec4(0.001f, 0.001f, 0.001f, 0.2f));
  const std::string file = path("clamp.png");
  fogcl::write_png_preview(file, image);
  const Png png = read_png(file);
  ASSERT_EQ(png.width, 5);
  // Clamped black and white are exact (not dithered).
  EXPECT_EQ(png.at(0, 0, 0), 0);
  EXPECT_EQ(png.at(0, 0, 1), 0);
  EXPECT_EQ(png.at(0, 0, 2), 0);
  EXPECT_EQ(png.at(1, 0, 0), 255);
  EXPECT_EQ(png.at(1, 0, 1), 255);
  EXPECT_EQ(png.at(1, 0, 2), 255);
  EXPECT_EQ(png.at(2, 0, 0), 0);
  const int half_code = int(std::lround(srgb_encode_reference(0.5) * 255.0));  // 188
  EXPECT_NEAR(png.at(2, 0, 1), half_code, 1);
  EXPECT_NEAR(png.at(2, 0, 2), half_code, 1);
  const double dark = srgb_encode_reference(double(0.001f)) * 255.0;  // 3.29: the linear segment
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(png.at(4, 0, c), dark, 1.5);
  // Alpha: clamped and rounded, not sRGB-encoded.
  EXPECT_EQ(png.at(0, 0, 3), 0);    // NaN
  EXPECT_EQ(png.at(1, 0, 3), 255);  // 2
  EXPECT_EQ(png.at(2, 0, 3), 128);  // 0.5 -> 127.5 -> 128
  EXPECT_EQ(png.at(3, 0, 3), 0);    // -1
  EXPECT_EQ(png.at(4, 0, 3), 51);   // 0.2 -> 51
  expect_no_temp_files();
}

TEST_F(ExrIoTest, PngPreviewOfHalfImageMatchesFloat) {
  ColorImage image(32, 8, ColorFormat::rgba16f);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 32; ++x) image.set_pixel(x, y, glm::vec4(float(x) / 32.0f, 0.3f, float(y) / 8.0f, 1.0f));
  const std::string half_file = path("half.png"), float_file = path("float.png");
  fogcl::write_png_preview(half_file, image);
  fogcl::write_png_preview(float_file, fogcl::convert(image, ColorFormat::rgba32f));
  EXPECT_EQ(read_png(half_file).rgba, read_png(float_file).rgba);
}

}  // namespace
