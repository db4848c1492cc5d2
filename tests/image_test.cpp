// Unit tests of the host images (docs/DESIGN.md §1, §2): sizes, alignment, half conversion, typed
// access, value semantics, format conversion and frame validation.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "test_support.h"

#include "fogcl/error.h"
#include "fogcl/image.h"

namespace fogcl {
namespace {

using test::error_of;


bool aligned(const void* p) { return reinterpret_cast<std::uintptr_t>(p) % 4096 == 0; }

std::uint32_t bits(float f) {
  std::uint32_t b;
  std::memcpy(&b, &f, sizeof b);
  return b;
}

TEST(ImageTest, BadSizesThrowWithTheSize) {
  const std::pair<int, int> sizes[] = {{0, 5}, {5, 0}, {0, 0}, {-3, 2}, {4, -7}};
  for (const auto& [w, h] : sizes) {
    const std::string want = std::to_string(w) + "x" + std::to_string(h);
    for (ColorFormat f : {ColorFormat::rgba32f, ColorFormat::rgba16f}) {
      const std::string msg = error_of([&, w = w, h = h] { ColorImage img(w, h, f); });
      EXPECT_MSG_HAS(msg, want);
    }
    const std::string msg = error_of([&, w = w, h = h] { DepthImage img(w, h); });
    EXPECT_MSG_HAS(msg, want);
  }
}

TEST(ImageTest, SizesAndFormats) {
  const ColorImage c(7, 3, ColorFormat::rgba16f);
  EXPECT_EQ(c.width(), 7);
  EXPECT_EQ(c.height(), 3);
  EXPECT_EQ(c.format(), ColorFormat::rgba16f);
  EXPECT_FALSE(c.empty());
  EXPECT_EQ(c.pixel_count(), 21u);
  EXPECT_EQ(c.size_bytes(), 21u * 8u);
  EXPECT_EQ(ColorImage(7, 3).size_bytes(), 21u * 16u);
  EXPECT_EQ(bytes_per_pixel(ColorFormat::rgba32f), 16u);
  EXPECT_EQ(bytes_per_pixel(ColorFormat::rgba16f), 8u);
  EXPECT_STREQ(to_string(ColorFormat::rgba32f), "rgba32f");
  EXPECT_STREQ(to_string(ColorFormat::rgba16f), "rgba16f");
  const DepthImage d(5, 4, 0.25f);
  EXPECT_EQ(d.pixel_count(), 20u);
  EXPECT_EQ(d.size_bytes(), 80u);
  EXPECT_TRUE(ColorImage().empty());
  EXPECT_TRUE(DepthImage().empty());
}

TEST(ImageTest, NewImagesAreZeroOrFilled) {
  for (ColorFormat f : {ColorFormat::rgba32f, ColorFormat::rgba16f}) {
    const ColorImage c(3, 2, f);
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 3; ++x) EXPECT_EQ(c.pixel(x, y), glm::vec4(0.0f));
  }
  const DepthImage d(3, 2, 0.75f);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) EXPECT_EQ(d.at(x, y), 0.75f);
  EXPECT_EQ(DepthImage(2, 2).at(1, 1), 0.0f);
}

TEST(ImageTest, DataIsPageAligned) {
  const std::pair<int, int> sizes[] = {{1, 1}, {3, 7}, {1920, 1}, {257, 129}};
  for (const auto& [w, h] : sizes) {
    for (ColorFormat f : {ColorFormat::rgba32f, ColorFormat::rgba16f}) {
      ColorImage c(w, h, f);
      EXPECT_TRUE(aligned(c.data())) << w << "x" << h << " " << to_string(f);
      const ColorImage copy = c;
      EXPECT_TRUE(aligned(copy.data())) << "copy " << w << "x" << h;
      EXPECT_TRUE(aligned(convert(c, f == ColorFormat::rgba32f ? ColorFormat::rgba16f : ColorFormat::rgba32f).data()));
    }
    DepthImage d(w, h);
    EXPECT_TRUE(aligned(d.data())) << "depth " << w << "x" << h;
    const DepthImage dcopy = d;
    EXPECT_TRUE(aligned(dcopy.data()));
  }
}

TEST(ImageTest, RowMajorTopRowFirstLayout) {
  ColorImage c(4, 3);
  c.set_pixel(2, 1, glm::vec4(1, 2, 3, 4));
  const float* p = c.rgba32f();
  const std::size_t i = 4 * (1 * 4 + 2);
  EXPECT_EQ(p[i + 0], 1.0f);
  EXPECT_EQ(p[i + 1], 2.0f);
  EXPECT_EQ(p[i + 2], 3.0f);
  EXPECT_EQ(p[i + 3], 4.0f);
  DepthImage d(4, 3);
  d.at(3, 2) = 0.5f;
  EXPECT_EQ(d.data()[2 * 4 + 3], 0.5f);
}

TEST(ImageTest, Float32PixelRoundTripIsBitExact) {
  ColorImage c(3, 2);
  const float denorm = std::numeric_limits<float>::denorm_min();
  const glm::vec4 values[] = {glm::vec4(0.1f, -2.5f, 1e30f, 0.333333f),
                              glm::vec4(-0.0f, denorm, std::numeric_limits<float>::max(), 1.0f),
                              glm::vec4(std::numeric_limits<float>::infinity(), 65504.0f, 1e-20f, 0.5f)};
  for (int k = 0; k < 3; ++k) c.set_pixel(k, 1, values[k]);
  for (int k = 0; k < 3; ++k) {
    const glm::vec4 got = c.pixel(k, 1);
    for (int ch = 0; ch < 4; ++ch) EXPECT_EQ(bits(got[ch]), bits(values[k][ch])) << "pixel " << k << " ch " << ch;
  }
  EXPECT_EQ(c.pixel(0, 0), glm::vec4(0.0f)) << "other pixels untouched";
}

TEST(ImageTest, HalfPixelRoundTripOfRepresentableValues) {
  ColorImage c(2, 2, ColorFormat::rgba16f);
  const glm::vec4 values[] = {glm::vec4(1.0f, -2.0f, 0.5f, 0.0f),
                              glm::vec4(65504.0f, -65504.0f, std::ldexp(1.0f, -24), std::ldexp(1.0f, -14)),
                              glm::vec4(1.0f + std::ldexp(1.0f, -10), 3.140625f, 1024.0f, 0.25f),
                              glm::vec4(-0.0f, 2048.0f, std::ldexp(1.0f, -20), 0.75f)};
  for (int k = 0; k < 4; ++k) c.set_pixel(k % 2, k / 2, values[k]);
  for (int k = 0; k < 4; ++k) {
    const glm::vec4 got = c.pixel(k % 2, k / 2);
    for (int ch = 0; ch < 4; ++ch) EXPECT_EQ(bits(got[ch]), bits(values[k][ch])) << "pixel " << k << " ch " << ch;
  }
  // Raw IEEE half patterns.
  ColorImage h(1, 1, ColorFormat::rgba16f);
  h.set_pixel(0, 0, glm::vec4(1.0f, -2.0f, 65504.0f, std::ldexp(1.0f, -24)));
  EXPECT_EQ(h.rgba16f()[0], 0x3C00);
  EXPECT_EQ(h.rgba16f()[1], 0xC000);
  EXPECT_EQ(h.rgba16f()[2], 0x7BFF);
  EXPECT_EQ(h.rgba16f()[3], 0x0001);
}

TEST(ImageTest, HalfRoundsToNearestEven) {
  ColorImage c(1, 1, ColorFormat::rgba16f);
  const float ulp = std::ldexp(1.0f, -10);  // half ulp at [1, 2)
  // Ties: 1 + ulp/2 lies between 1 (even mantissa 0) and 1 + ulp (odd): goes to 1.
  //       1 + 3 ulp/2 lies between 1 + ulp (odd) and 1 + 2 ulp (even mantissa 2): goes to 1 + 2 ulp.
  //       -(1 + ulp/2) is symmetric.
  // Non-ties round to the nearest: 1 + 0.6 ulp -> 1 + ulp, 1 + 1.4 ulp -> 1 + ulp.
  c.set_pixel(0, 0, glm::vec4(1.0f + 0.5f * ulp, 1.0f + 1.5f * ulp, -(1.0f + 0.5f * ulp), 1.0f + 0.6f * ulp));
  glm::vec4 got = c.pixel(0, 0);
  EXPECT_EQ(got[0], 1.0f) << "1 + 2^-11 must round to 1";
  EXPECT_EQ(got[1], 1.0f + 2.0f * ulp) << "1 + 3*2^-11 must round to the even neighbour 1 + 2^-9";
  EXPECT_EQ(got[2], -1.0f);
  EXPECT_EQ(got[3], 1.0f + ulp);
  c.set_pixel(0, 0, glm::vec4(1.0f + 1.4f * ulp, 1.0f + 2.5f * ulp, 2048.0f + 1.0f, 0.1f));
  got = c.pixel(0, 0);
  EXPECT_EQ(got[0], 1.0f + ulp);
  EXPECT_EQ(got[1], 1.0f + 2.0f * ulp) << "1 + 2.5 ulp ties to the even 1 + 2 ulp";
  EXPECT_EQ(got[2], 2048.0f) << "2049 ties to the even 2048";
  EXPECT_EQ(c.rgba16f()[3], 0x2E66) << "0.1 is 0x2E66 in half";
  // Overflow beyond the half range (>= 65520 after rounding) becomes infinity.
  c.set_pixel(0, 0, glm::vec4(65519.0f, 65520.0f, -1e6f, 0.0f));
  got = c.pixel(0, 0);
  EXPECT_EQ(got[0], 65504.0f);
  EXPECT_TRUE(std::isinf(got[1]) && got[1] > 0);
  EXPECT_TRUE(std::isinf(got[2]) && got[2] < 0);
}

TEST(ImageTest, TypedAccessOfTheWrongFormatThrows) {
  ColorImage f32(2, 2, ColorFormat::rgba32f);
  ColorImage f16(2, 2, ColorFormat::rgba16f);
  EXPECT_NO_THROW(f32.rgba32f());
  EXPECT_NO_THROW(f16.rgba16f());
  EXPECT_EQ(static_cast<void*>(f32.rgba32f()), f32.data());
  EXPECT_EQ(static_cast<void*>(f16.rgba16f()), f16.data());
  std::string msg = error_of([&] { f32.rgba16f(); });
  EXPECT_MSG_HAS(msg, "rgba16f");
  EXPECT_MSG_HAS(msg, "rgba32f");
  msg = error_of([&] { f16.rgba32f(); });
  EXPECT_MSG_HAS(msg, "rgba16f");
  const ColorImage& c32 = f32;
  const ColorImage& c16 = f16;
  EXPECT_THROW(c32.rgba16f(), Error);
  EXPECT_THROW(c16.rgba32f(), Error);
}

TEST(ImageTest, CopyIsDeep) {
  for (ColorFormat f : {ColorFormat::rgba32f, ColorFormat::rgba16f}) {
    ColorImage a(3, 3, f);
    a.set_pixel(1, 1, glm::vec4(1, 2, 3, 4));
    ColorImage b = a;
    EXPECT_NE(b.data(), a.data());
    EXPECT_EQ(b.format(), f);
    EXPECT_EQ(b.pixel(1, 1), glm::vec4(1, 2, 3, 4));
    a.set_pixel(1, 1, glm::vec4(5, 6, 7, 8));
    EXPECT_EQ(b.pixel(1, 1), glm::vec4(1, 2, 3, 4)) << "copy constructor shares storage";
    ColorImage c(1, 1);
    c = a;
    EXPECT_EQ(c.width(), 3);
    EXPECT_EQ(c.format(), f);
    EXPECT_NE(c.data(), a.data());
    a.set_pixel(1, 1, glm::vec4(0));
    EXPECT_EQ(c.pixel(1, 1), glm::vec4(5, 6, 7, 8)) << "copy assignment shares storage";
    const ColorImage& alias = c;
    c = alias;  // self-assignment keeps the content
    EXPECT_EQ(c.pixel(1, 1), glm::vec4(5, 6, 7, 8));
  }
  DepthImage d(2, 2, 0.5f);
  DepthImage e = d;
  EXPECT_NE(e.data(), d.data());
  d.at(0, 0) = 1.0f;
  EXPECT_EQ(e.at(0, 0), 0.5f);
  DepthImage g;
  g = d;
  d.at(1, 1) = 0.0f;
  EXPECT_EQ(g.at(1, 1), 0.5f);
  EXPECT_EQ(g.at(0, 0), 1.0f);
}

TEST(ImageTest, MoveTransfersStorage) {
  ColorImage a(2, 2);
  a.set_pixel(0, 1, glm::vec4(9));
  const void* p = a.data();
  ColorImage b = std::move(a);
  EXPECT_EQ(b.data(), p);
  EXPECT_EQ(b.pixel(0, 1), glm::vec4(9));
}

TEST(ImageTest, ConvertFloatHalfFloat) {
  ColorImage src(3, 2);
  src.set_pixel(0, 0, glm::vec4(1.0f, -2.0f, 0.5f, 0.25f));
  src.set_pixel(1, 0, glm::vec4(0.1f, 1.0f + std::ldexp(1.0f, -11), 65504.0f, 1.0f));
  src.set_pixel(2, 1, glm::vec4(3.0f, 1e-3f, -0.0f, 0.75f));
  const ColorImage h = convert(src, ColorFormat::rgba16f);
  EXPECT_EQ(h.format(), ColorFormat::rgba16f);
  EXPECT_EQ(h.width(), 3);
  EXPECT_EQ(h.height(), 2);
  const ColorImage back = convert(h, ColorFormat::rgba32f);
  EXPECT_EQ(back.format(), ColorFormat::rgba32f);
  double worst = 0;
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 3; ++x) {
      const glm::vec4 a = src.pixel(x, y), b = back.pixel(x, y);
      for (int ch = 0; ch < 4; ++ch) {
        const double r = a[ch] == 0 ? std::fabs(b[ch]) : std::fabs(double(b[ch]) - a[ch]) / std::fabs(a[ch]);
        worst = std::max(worst, r);
        EXPECT_LE(r, std::ldexp(1.0, -11)) << "(" << x << "," << y << ") ch " << ch << ": " << a[ch] << " -> " << b[ch];
      }
    }
  }
  std::printf("[ info ] f32 -> f16 -> f32: worst relative error %.3g (bound 2^-11 = %.3g)\n", worst,
              std::ldexp(1.0, -11));
  // Exactly representable values survive; the others are the half rounding.
  EXPECT_EQ(back.pixel(0, 0), glm::vec4(1.0f, -2.0f, 0.5f, 0.25f));
  EXPECT_EQ(back.pixel(1, 0)[1], 1.0f);
  EXPECT_EQ(back.pixel(1, 0)[0], 0.0999755859375f);
  EXPECT_EQ(back.pixel(2, 1)[0], 3.0f);
  EXPECT_EQ(h.pixel(1, 0), back.pixel(1, 0));
  // Same format: a deep copy.
  const ColorImage same = convert(src, ColorFormat::rgba32f);
  EXPECT_NE(same.data(), src.data());
  EXPECT_EQ(std::memcmp(same.data(), src.data(), src.size_bytes()), 0);
  // Half -> half is bit-exact.
  const ColorImage hh = convert(h, ColorFormat::rgba16f);
  EXPECT_EQ(std::memcmp(hh.data(), h.data(), h.size_bytes()), 0);
  // Half -> float -> half is bit-exact (every half is a float).
  const ColorImage h2 = convert(back, ColorFormat::rgba16f);
  EXPECT_EQ(std::memcmp(h2.data(), h.data(), h.size_bytes()), 0);
}

TEST(ImageTest, ValidateFrame) {
  EXPECT_NO_THROW(validate_frame(ColorImage(4, 3), DepthImage(4, 3)));
  EXPECT_NO_THROW(validate_frame(ColorImage(1, 1, ColorFormat::rgba16f), DepthImage(1, 1)));
  {
    const std::string msg = error_of([] { validate_frame(ColorImage(4, 3), DepthImage(3, 4)); });
    EXPECT_MSG_HAS(msg, "4x3");
    EXPECT_MSG_HAS(msg, "3x4");
  }
  {
    const std::string msg = error_of([] { validate_frame(ColorImage(640, 480), DepthImage(640, 479)); });
    EXPECT_MSG_HAS(msg, "640x480");
    EXPECT_MSG_HAS(msg, "640x479");
  }
  {
    const std::string msg = error_of([] { validate_frame(ColorImage(), DepthImage(2, 2)); });
    EXPECT_MSG_HAS(msg, "empty");
  }
  {
    const std::string msg = error_of([] { validate_frame(ColorImage(2, 2), DepthImage()); });
    EXPECT_MSG_HAS(msg, "empty");
  }
  EXPECT_THROW(validate_frame(ColorImage(), DepthImage()), Error);
}

}  // namespace
}  // namespace fogcl
