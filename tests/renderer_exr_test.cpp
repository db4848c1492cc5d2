// `fogcl apply` on files that mimic renderer output (tests/exr_fixtures.h): multi-part with Z in
// its own part, layered channels, a data window inside the display window, deep scanline, half and
// float, linear Z with background 0 and +inf, camera attributes; each fogged by the CLI and
// compared against the library's double path. Then corrupt and truncated files cut from real ones,
// and sequences with a bad frame.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include "exr_fixtures.h"
#include "fogcl/depth_kinds.h"
#include "fogcl/exr_io.h"
#include "test_support.h"

namespace fogcl::test {
namespace {

namespace fs = std::filesystem;
using fixtures::RenderFrame;


int channel_count(const Imf::Header& h) {
  int n = 0;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it) ++n;
  return n;
}

Imath::Box2i box(int x0, int y0, int x1, int y1) { return Imath::Box2i(Imath::V2i(x0, y0), Imath::V2i(x1, y1)); }

const char* kFog = " --near 0.3 --far 1000 --mode exp2 --density 0.004 --fog-color 0.6,0.7,0.8";

FogSettings fog_settings(bool distance, bool skybox) {
  FogSettings s;
  s.fog_skybox = skybox;
  s.mode = FogMode::exp2;
  s.density = 0.004f;
  s.color = glm::vec3(0.6f, 0.7f, 0.8f);
  s.metric = distance ? FogMetric::distance : FogMetric::depth;
  return s;
}

// The display-window frame of `rgba` / `eye` (data-window arrays): color 0 and depth `outside`
// outside the data window.
ColorImage color_frame(const RenderFrame& f, const std::vector<float>& rgba) {
  ColorImage c(f.display.max.x - f.display.min.x + 1, f.display.max.y - f.display.min.y + 1);
  for (int y = 0; y < f.height(); ++y)
    for (int x = 0; x < f.width(); ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(f.width()) + std::size_t(x);
      c.set_pixel(x + f.data.min.x - f.display.min.x, y + f.data.min.y - f.display.min.y,
                  glm::vec4(rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2], rgba[4 * i + 3]));
    }
  return c;
}
DepthImage depth_frame(const RenderFrame& f, const std::vector<float>& eye, float outside) {
  DepthImage d(f.display.max.x - f.display.min.x + 1, f.display.max.y - f.display.min.y + 1, outside);
  for (int y = 0; y < f.height(); ++y)
    for (int x = 0; x < f.width(); ++x)
      d.at(x + f.data.min.x - f.display.min.x, y + f.data.min.y - f.display.min.y) =
          eye[std::size_t(y) * std::size_t(f.width()) + std::size_t(x)];
  return d;
}

class RendererExr : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = temp_dir() + "/renderer-" + info->name() + "-" + std::to_string(::getpid());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }

  // Runs `fogcl apply ARGS --out OUT` and compares OUT's layer against the double path on the
  // expected color and eye depth (display frames).
  void expect_fogged(const std::string& args, const std::string& out, const std::string& layer,
                     const ColorImage& color, DepthImage eye, DepthKind kind, const PerspectiveCamera& camera,
                     bool distance = false, bool skybox = false) {
    const CliRun r = run_cli("apply " + args + " --out " + out + " --device scalar");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    CameraParams params = make_camera_params(camera);
    params.non_square_pixels = true;  // as the CLI takes the file's camera: its frustum, whatever the frame
    params.depth_kind = kind;  // linear depth reaches the formulas as it is, in the reference too
    const FogSettings s = fog_settings(distance, skybox);
    const FogResult<double> ref = fog_scalar<double>(color, eye, params, s);
    ExrReadRequest request;
    request.layer = layer;
    const ExrInput got = read_exr(out, request);
    // Only the data window is stored: compare there (positions are the display window's).
    const ExrWindows& w = got.windows;
    const int x0 = w.data_min.x - w.display_min.x, y0 = w.data_min.y - w.display_min.y;
    const int cw = w.data_max.x - w.data_min.x + 1, ch = w.data_max.y - w.data_min.y + 1;
    ColorImage got_crop(cw, ch), in_crop(cw, ch);
    FogResult<double> ref_crop;
    ref_crop.width = cw;
    ref_crop.height = ch;
    for (int y = 0; y < ch; ++y)
      for (int x = 0; x < cw; ++x) {
        got_crop.set_pixel(x, y, got.color.pixel(x0 + x, y0 + y));
        in_crop.set_pixel(x, y, color.pixel(x0 + x, y0 + y));
        for (int c = 0; c < 4; ++c)
          ref_crop.rgba.push_back(ref.rgba[4 * (std::size_t(y0 + y) * std::size_t(color.width()) + std::size_t(x0 + x)) +
                                           std::size_t(c)]);
      }
    const ErrorStats e = compare_color(got_crop, ref_crop, in_crop, s.color);
    std::printf("[ worst    ] %s: rel %.2e over %zu pixels\n", args.substr(0, 60).c_str(), e.max_rel, e.pixels);
    EXPECT_LE(e.max_rel, 1e-5);
    EXPECT_EQ(e.nonfinite_from_finite, 0u);
    EXPECT_EQ(e.alpha_changed, 0u);
    // Not a no-op: the fog changed the frame.
    double changed = 0;
    for (int y = 0; y < color.height(); ++y)
      for (int x = 0; x < color.width(); ++x) changed += std::fabs(got.color.pixel(x, y).r - color.pixel(x, y).r);
    EXPECT_GT(changed, 0.0);
  }

  std::string dir_;
};

TEST_F(RendererExr, MultiPartWithZInItsOwnPartHalfAndFloat) {
  for (Imf::PixelType type : {Imf::HALF, Imf::FLOAT}) {
    const RenderFrame f = fixtures::make_render_frame(box(0, 0, 47, 31), box(0, 0, 47, 31), 7);
    const std::string in = path(std::string("multipart-") + (type == Imf::HALF ? "half" : "float") + ".exr");
    fixtures::write_flat(in, f, {{"rgba", fixtures::color_channels(f, "", type), false, false},
                                 {"depth", {fixtures::depth_channel(f, "Z", type)}, false, false}});
    const std::vector<float> rgba = type == Imf::HALF ? fixtures::to_half_values(f.rgba) : f.rgba;
    const std::vector<float> eye = type == Imf::HALF ? fixtures::to_half_values(f.eye) : f.eye;
    expect_fogged("--color " + in + " --fov 50 --depth-kind eye" + kFog, path("out.exr"), "", color_frame(f, rgba),
                  depth_frame(f, eye, 0.0f), DepthKind::eye, f.camera);
    // The output keeps both parts: the depth part is copied as stored.
    Imf::MultiPartInputFile out(path("out.exr").c_str());
    ASSERT_EQ(out.parts(), 2);
    EXPECT_NE(out.header(1).channels().findChannel("Z"), nullptr);
    EXPECT_EQ(out.header(0).channels().findChannel("R")->type, Imf::FLOAT);
  }
}

TEST_F(RendererExr, LayeredChannelsKeepOtherChannelsAndAttributes) {
  const RenderFrame f = fixtures::make_render_frame(box(0, 0, 39, 29), box(0, 0, 39, 29), 11);
  std::vector<fixtures::Channel> channels = fixtures::color_channels(f, "beauty.", Imf::FLOAT);
  for (fixtures::Channel& c : fixtures::color_channels(f, "diffuse.", Imf::HALF)) channels.push_back(c);
  channels.push_back(fixtures::depth_channel(f, "depth.Z"));
  // Radial distance instead of eye depth: distance = eye * |ray| / far.
  RenderFrame dist = f;
  for (int y = 0; y < f.height(); ++y)
    for (int x = 0; x < f.width(); ++x) {
      const double u = (x + 0.5) / f.width(), v = 1.0 - (y + 0.5) / f.height();
      const double tv = std::tan(double(f.camera.fov_y_deg) * 3.14159265358979323846 / 360.0);
      const double rx = (2 * u - 1) * tv * f.camera.aspect, ry = (2 * v - 1) * tv;
      float& e = dist.eye[std::size_t(y) * std::size_t(f.width()) + std::size_t(x)];
      e = float(double(e) * std::sqrt(rx * rx + ry * ry + 1.0));
    }
  channels.back().values = dist.eye;
  const std::string in = path("layered.exr");
  fixtures::write_flat(in, f, {{"", channels, false, false}});
  expect_fogged("--color " + in + " --layer beauty --depth-channel depth.Z --depth-kind distance --distance --fov 50" +
                    kFog,
                path("out.exr"), "beauty", color_frame(f, f.rgba), depth_frame(f, dist.eye, 0.0f),
                DepthKind::distance, f.camera, true);
  Imf::MultiPartInputFile out(path("out.exr").c_str());
  const Imf::Header& h = out.header(0);
  for (const char* c : {"beauty.R", "beauty.A", "diffuse.R", "diffuse.A", "depth.Z"})
    EXPECT_NE(h.channels().findChannel(c), nullptr) << c;
  EXPECT_EQ(h.channels().findChannel("R"), nullptr);
  EXPECT_EQ(h.channels().findChannel("diffuse.G")->type, Imf::HALF);
  ASSERT_NE(h.findTypedAttribute<Imf::StringAttribute>("renderer"), nullptr);
  EXPECT_EQ(h.findTypedAttribute<Imf::StringAttribute>("renderer")->value(), "fogcl fixtures");
  // The other layers are kept bit for bit.
  ExrReadRequest diffuse;
  diffuse.layer = "diffuse";
  const ColorImage kept = read_exr(path("out.exr"), diffuse).color;
  const std::vector<float> halves = fixtures::to_half_values(f.rgba);
  EXPECT_EQ(kept.pixel(5, 7).g, halves[4 * (7 * 40 + 5) + 1]);

  // --rgba-only: the fogged layer as plain R, G, B, A and nothing else.
  const CliRun r = run_cli("apply --color " + in + " --layer beauty --depth-channel depth.Z --depth-kind distance "
                           "--distance --fov 50 --rgba-only --device scalar --out " + path("rgba.exr") + kFog);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  Imf::MultiPartInputFile rgba(path("rgba.exr").c_str());
  EXPECT_EQ(channel_count(rgba.header(0)), 4);
  EXPECT_EQ(rgba.header(0).findTypedAttribute<Imf::StringAttribute>("renderer"), nullptr);
}

TEST_F(RendererExr, DataWindowInsideTheDisplayWindowKeepsPositionsAndWindows) {
  // Linear Z with background 0 and +inf; pixels outside the data window are background too.
  const RenderFrame f = fixtures::make_render_frame(box(-4, -3, 43, 28), box(3, 2, 30, 20), 13);
  const std::string in = path("window.exr");
  std::vector<fixtures::Channel> channels = fixtures::color_channels(f, "", Imf::HALF);
  channels.push_back(fixtures::depth_channel(f, "Z", Imf::FLOAT));
  fixtures::write_flat(in, f, {{"", channels, false, false}});
  expect_fogged("--color " + in + " --fov 50 --depth-kind eye --fog-skybox" + kFog, path("out.exr"), "",
                color_frame(f, fixtures::to_half_values(f.rgba)),
                depth_frame(f, f.eye, std::numeric_limits<float>::infinity()), DepthKind::eye, f.camera, false, true);
  ExrWindows w;
  read_exr_color(path("out.exr"), &w);
  EXPECT_EQ(w.display_min, glm::ivec2(-4, -3));
  EXPECT_EQ(w.display_max, glm::ivec2(43, 28));
  EXPECT_EQ(w.data_min, glm::ivec2(3, 2));
  EXPECT_EQ(w.data_max, glm::ivec2(30, 20));
}

TEST_F(RendererExr, DeepFileIsFlattenedFrontToBack) {
  const RenderFrame f = fixtures::make_render_frame(box(0, 0, 31, 23), box(0, 0, 31, 23), 17);
  const std::string in = path("deep.exr");
  std::vector<float> flat, nearest;
  fixtures::write_deep(in, f, &flat, &nearest);
  // The flattening itself, against the fixture's own compositing in double.
  ExrReadRequest request;
  request.depth_channel = "Z";
  request.depth_outside = std::numeric_limits<float>::infinity();
  const ExrInput read = read_exr(in, request);
  EXPECT_TRUE(read.deep);
  double worst = 0;
  for (int y = 0; y < f.height(); ++y)
    for (int x = 0; x < f.width(); ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(f.width()) + std::size_t(x);
      for (int c = 0; c < 4; ++c)
        worst = std::max(worst, double(std::fabs(read.color.pixel(x, y)[c] - flat[4 * i + std::size_t(c)])));
      EXPECT_EQ(read.depth.at(x, y), nearest[i]) << x << "," << y;
    }
  std::printf("[ worst    ] deep flatten: abs %.2e\n", worst);
  EXPECT_LE(worst, 1e-6);
  // And fogged through the CLI (eye depth: Z of a deep file is the distance along the view axis).
  expect_fogged("--color " + in + " --fov 50 --depth-kind eye" + kFog, path("out.exr"), "", color_frame(f, flat),
                depth_frame(f, nearest, 0.0f), DepthKind::eye, f.camera);
}

TEST_F(RendererExr, CameraFromTheFileAttributesAndFlagsWin) {
  RenderFrame f = fixtures::make_render_frame(box(0, 0, 39, 19), box(0, 0, 39, 19), 19);
  f.camera.fov_y_deg = 35.0f;
  f.camera.aspect = 2.5f;  // not the display window's 2.0: the matrices carry it
  std::vector<fixtures::Channel> channels = fixtures::color_channels(f, "", Imf::FLOAT);
  channels.push_back(fixtures::depth_channel(f, "Z"));
  const std::string in = path("camera.exr");
  fixtures::write_flat(in, f, {{"", channels, true, true}});  // tiled, with camera attributes
  ExrReadRequest request;
  const ExrInput read = read_exr(in, request);
  ASSERT_TRUE(read.camera.present) << read.camera.note;
  EXPECT_NEAR(read.camera.fov_y_deg, 35.0f, 1e-3f);
  EXPECT_NEAR(read.camera.aspect, 2.5f, 1e-4f);
  PerspectiveCamera from_file = f.camera;
  from_file.fov_y_deg = read.camera.fov_y_deg;
  from_file.aspect = read.camera.aspect;
  expect_fogged("--color " + in + " --depth-kind distance --distance" + kFog, path("file.exr"), "",
                color_frame(f, f.rgba), depth_frame(f, f.eye, 0.0f), DepthKind::distance, from_file, true);
  PerspectiveCamera flags = f.camera;
  flags.fov_y_deg = 70.0f;
  flags.aspect = 2.0f;  // no --aspect: the display window's, as without a camera
  expect_fogged("--color " + in + " --fov 70 --depth-kind distance --distance" + kFog, path("flags.exr"), "",
                color_frame(f, f.rgba), depth_frame(f, f.eye, 0.0f), DepthKind::distance, flags, true);
  // Without the attributes and without --fov: one line saying so.
  const std::string bare = path("bare.exr");
  fixtures::write_flat(bare, f, {{"", channels, false, false}});
  const CliRun r = run_cli("apply --color " + bare + " --device scalar --out " + path("x.exr") + kFog);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("has no usable camera (no worldToNDC and worldToCamera attributes)"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("x.exr")));
}

void put_bytes(const std::string& path, const std::vector<char>& bytes, std::size_t size) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(std::min(size, bytes.size())));
}

TEST_F(RendererExr, TruncatedAndCorruptFilesNeverCrashTheReader) {
  // Every prefix of real files, and each byte of their headers and offset tables flipped: the
  // reader either reads something or throws fogcl::Error naming the file; never anything else.
  const RenderFrame f = fixtures::make_render_frame(box(-2, -1, 17, 12), box(0, 0, 15, 9), 23);
  std::vector<fixtures::Channel> layered = fixtures::color_channels(f, "beauty.", Imf::HALF);
  layered.push_back(fixtures::depth_channel(f, "Z"));
  fixtures::write_flat(path("multipart.exr"), f,
                       {{"rgba", fixtures::color_channels(f, "", Imf::HALF), true, true},
                        {"depth", {fixtures::depth_channel(f, "Z")}, false, false},
                        {"layers", layered, false, false}});
  std::vector<float> flat, nearest;
  fixtures::write_deep(path("deep.exr"), f, &flat, &nearest);
  std::size_t errors = 0, reads = 0;
  for (const char* name : {"multipart.exr", "deep.exr"}) {
    const std::vector<char> bytes = file_bytes(path(name));
    ExrReadRequest request;
    request.depth_channel = "Z";
    request.max_pixels = 1 << 16;  // corrupt sizes fail fast instead of allocating gigabytes
    request.max_deep_samples = 1 << 16;
    const auto attempt = [&](const std::vector<char>& data, std::size_t size) {
      try {
        read_exr_memory(data.data(), size, name, request);
        ++reads;
      } catch (const Error& e) {
        ++errors;
        EXPECT_EQ(std::string(e.what()).rfind(name, 0), 0u) << e.what();
        EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      }
    };
    for (std::size_t size = 0; size < bytes.size(); size += size < 600 ? 1 : 37) attempt(bytes, size);
    for (std::size_t at = 0; at < std::min<std::size_t>(bytes.size(), 900); ++at) {
      std::vector<char> corrupt = bytes;
      corrupt[at] = char(corrupt[at] ^ 0x5a);
      attempt(corrupt, corrupt.size());
    }
  }
  std::printf("[ corrupt  ] %zu inputs rejected with one line, %zu read\n", errors, reads);
  EXPECT_GT(errors, 1000u);
}

// A header the fuzzer made: a dataWindow of ~3.4e9 x 3.3e9 pixels, whose pixel count overflowed
// a 64-bit multiply in the header pre-check (UBSan). It must be refused with one line.
TEST_F(RendererExr, HugeWindowHeaderFromTheFuzzer) {
  const unsigned char bytes[] = {
      0x76, 0x2f, 0x31, 0x01, 0x02, 0x10, 0x00, 0x00, 0x63, 0x68, 0x61, 0x6e, 0x6e, 0x65, 0x6c, 0x6e,
      0x74, 0x00, 0x69, 0x6e, 0x74, 0x00, 0x04, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x63, 0x6f,
      0x6d, 0x70, 0x72, 0x65, 0x73, 0x73, 0x69, 0x6f, 0x6e, 0x00, 0x63, 0x6f, 0x6d, 0x70, 0x72, 0x65,
      0x73, 0x73, 0x69, 0x6f, 0x6e, 0x00, 0x01, 0x00, 0x00, 0x00, 0x03, 0x64, 0x61, 0x74, 0x61, 0x56,
      0x69, 0x6e, 0x64, 0x6f, 0x77, 0x00, 0x62, 0x6f, 0x78, 0x32, 0x69, 0x00, 0x10, 0x00, 0x00, 0x00,
      0xa6, 0xa6, 0xa6, 0xa6, 0xa6, 0xa6, 0xa6, 0xa6, 0x67, 0x62, 0x61, 0x70, 0x69, 0x78, 0x65, 0x6c,
      0x41, 0x73, 0x70, 0x65, 0x63, 0x74, 0x52, 0x61, 0x74, 0x69, 0x6f, 0x40, 0x67, 0x51, 0x67, 0x40,
      0x63, 0xb0, 0x71, 0x40, 0x9c, 0x41, 0x42, 0x40, 0xbd, 0x2c, 0x65, 0x40, 0xce, 0xe3, 0x06, 0x40,
      0x26, 0xc0, 0x33, 0x40, 0x90, 0x35, 0x7c, 0x40, 0xae, 0x0c, 0x91, 0x3f, 0x42, 0xc7, 0x89, 0x43,
      0x3d, 0x6a, 0xaf, 0x43, 0x2a, 0x55, 0x03, 0x43, 0x00, 0x00, 0x80, 0x7f, 0xe2, 0x26, 0x1c, 0x43,
      0x55, 0x6e, 0xe0, 0x43, 0x09, 0x12, 0xc2, 0x2d, 0x44};
  ExrReadRequest request;
  request.depth_channel = "Z";
  const std::string message = error_of([&] { read_exr_memory(bytes, sizeof bytes, "fuzz.exr", request); });
  EXPECT_NE(message.find("fuzz.exr"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST_F(RendererExr, BadFilesExitNonZeroWithOneLineAndNoOutput) {
  const RenderFrame f = fixtures::make_render_frame(box(0, 0, 23, 15), box(0, 0, 23, 15), 29);
  std::vector<fixtures::Channel> rgbz = fixtures::color_channels(f, "", Imf::HALF);
  rgbz.push_back(fixtures::depth_channel(f, "Z"));
  fixtures::write_flat(path("good.exr"), f, {{"", rgbz, false, false}});
  const std::vector<char> good = file_bytes(path("good.exr"));
  put_bytes(path("truncated.exr"), good, good.size() * 2 / 3);
  std::vector<char> corrupt = good;
  for (std::size_t i = good.size() - 200; i < good.size(); ++i) corrupt[i] = char(i * 7);
  put_bytes(path("corrupt.exr"), corrupt, corrupt.size());
  put_bytes(path("text.exr"), std::vector<char>{'h', 'e', 'l', 'l', 'o'}, 5);
  std::vector<fixtures::Channel> uint_rgb = rgbz;
  uint_rgb[0].type = Imf::UINT;
  fixtures::write_flat(path("uint.exr"), f, {{"", uint_rgb, false, false}});
  const RenderFrame other = fixtures::make_render_frame(box(0, 0, 23, 15), box(1, 1, 20, 12), 29);
  fixtures::write_flat(path("window.exr"), other, {{"", {fixtures::depth_channel(other, "Z")}, false, false}});
  const RenderFrame bigger = fixtures::make_render_frame(box(0, 0, 24, 15), box(0, 0, 24, 15), 29);
  fixtures::write_flat(path("size.exr"), bigger, {{"", {fixtures::depth_channel(bigger, "Z")}, false, false}});

  const struct {
    std::string args, expect;
  } cases[] = {
      {"--color " + path("missing.exr"), "missing.exr: cannot read EXR: cannot open the file"},
      {"--color " + path("text.exr"), "text.exr: cannot read EXR"},
      {"--color " + path("truncated.exr"), "truncated.exr: cannot read EXR"},
      {"--color " + path("corrupt.exr"), "corrupt.exr: cannot read EXR"},
      {"--color " + path("uint.exr"), "channel R has pixel type UINT"},
      {"--color " + path("good.exr") + " --layer beauty", "missing channel beauty.R"},
      {"--color " + path("good.exr") + " --depth-channel depth.Z", "no depth channel 'depth.Z'"},
      {"--color " + path("good.exr") + " --depth " + path("window.exr"), "window differs"},
      {"--color " + path("good.exr") + " --depth " + path("size.exr"), "window differs"},
      {"--color " + path("good.exr") + " --depth-kind linear", "--depth-kind must be one of raw, eye or distance (got 'linear')"},
  };
  for (const auto& c : cases) {
    const CliRun r = run_cli("apply " + c.args + " --fov 50 --device scalar --out " + path("out.exr") +
                             " --png " + path("out.png") + kFog);
    EXPECT_NE(r.exit_code, 0) << c.args;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.args << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(fs::exists(path("out.exr"))) << c.args;
    EXPECT_FALSE(fs::exists(path("out.png"))) << c.args;
  }
  for (const auto& entry : fs::directory_iterator(dir_))  // no temporary file left either
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
}

TEST_F(RendererExr, SequenceWithABadFrame) {
  std::vector<std::vector<float>> eyes;
  for (int frame = 1; frame <= 4; ++frame) {
    const RenderFrame f = fixtures::make_render_frame(box(0, 0, 19, 11), box(0, 0, 19, 11), 100u + unsigned(frame));
    std::vector<fixtures::Channel> rgbz = fixtures::color_channels(f, "", Imf::FLOAT);
    rgbz.push_back(fixtures::depth_channel(f, "Z"));
    char name[32];
    std::snprintf(name, sizeof name, "shot.%04d.exr", frame);
    fixtures::write_flat(path(name), f, {{"", rgbz, false, false}});
  }
  const std::vector<char> good = file_bytes(path("shot.0003.exr"));
  put_bytes(path("shot.0003.exr"), good, good.size() / 2);  // frame 3 is truncated

  const std::string device = cli_device();
  const std::string base = "apply --color " + path("shot.####.exr") + " --fov 50 --depth-kind eye --device " + device +
                           kFog + " --verbose";
  // Without --keep-going: stops at frame 3 with one line naming it; frames 1 and 2 are written.
  CliRun r = run_cli(base + " --out " + path("stop.%04d.exr"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("fogcl: error: frame 3: " + path("shot.0003.exr") + ": cannot read EXR"), std::string::npos)
      << r.output;
  EXPECT_TRUE(fs::exists(path("stop.0001.exr")));
  EXPECT_TRUE(fs::exists(path("stop.0002.exr")));
  EXPECT_FALSE(fs::exists(path("stop.0003.exr")));
  EXPECT_FALSE(fs::exists(path("stop.0004.exr")));

  // With --keep-going: every good frame is written, the failure is listed, the exit code is 1.
  r = run_cli(base + " --keep-going --out " + path("go.####.exr") + " --png " + path("go.####.png"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("1 of 4 frames failed"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("  frame 3: "), std::string::npos) << r.output;
  for (int frame : {1, 2, 4}) {
    char name[32];
    std::snprintf(name, sizeof name, "go.%04d.exr", frame);
    EXPECT_TRUE(fs::exists(path(name))) << name;
    std::snprintf(name, sizeof name, "go.%04d.png", frame);
    EXPECT_TRUE(fs::exists(path(name))) << name;
  }
  EXPECT_FALSE(fs::exists(path("go.0003.exr")));
  // Not a terminal: no progress bar.
  EXPECT_EQ(r.output.find("frames/s"), std::string::npos) << r.output;

  // A range of good frames, %04d: all succeed with one device setup and one program build.
  r = run_cli(base + " --frames 1-2 --out " + path("ok.%04d.exr"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("fogged 2 frames"), std::string::npos) << r.output;
  if (device != "scalar") {
    EXPECT_NE(r.output.find("1 program build(s)"), std::string::npos) << r.output;
  }
  EXPECT_EQ(r.output.find("device:"), r.output.rfind("device:")) << "one device setup: " << r.output;

  // Output without a placeholder for a sequence is refused before anything is read.
  r = run_cli(base + " --out " + path("single.exr"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("needs a frame placeholder"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace fogcl::test
