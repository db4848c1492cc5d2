// The fog factors' exp2 (fog_exp2_poly in kernels/fog_math.h): the same text runs in the kernel
// and in the scalar float path, so its error is measured here on the C++ instance, against the C
// library's exp2 in double. The full sweep over every float in [-126, 0] (1.1e9 values) measured
// 0.992 ulp; this test walks every 16th float to stay within a second.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include <gtest/gtest.h>

#include "pass/formulas.h"

namespace fogcl::test {
namespace {

using formulas::fog_exp2;

// Distance in units of the float's last place at the reference value.
double ulps(float value, double reference) {
  const float r = float(reference);
  return std::fabs(double(value) - reference) / double(std::nextafter(r, INFINITY) - r);
}

TEST(FogExp2, WithinOneUlpOverItsDomain) {
  double worst_ulp = 0, worst_rel = 0;
  float worst_x = 0;
  long count = 0;
  for (float x = -126.0f; x <= 0.0f; ++count) {
    const double reference = std::exp2(double(x));
    const float y = fog_exp2(x);
    const double u = ulps(y, reference);
    if (u > worst_ulp) {
      worst_ulp = u;
      worst_x = x;
    }
    worst_rel = std::fmax(worst_rel, std::fabs(double(y) - reference) / reference);
    // Every 16th float: step the bit pattern (x < 0, so decreasing bits move towards 0).
    std::uint32_t bits;
    std::memcpy(&bits, &x, 4);
    if (bits <= 0x80000010u) break;
    bits -= 16;
    std::memcpy(&x, &bits, 4);
  }
  std::printf("[ worst    ] fog_exp2 over %ld floats in [-126, 0]: %.3f ulp (rel %.2e) at x = %a\n",
              count, worst_ulp, worst_rel, double(worst_x));
  EXPECT_GT(count, 60000000);
  EXPECT_LT(worst_ulp, 1.0);
}

TEST(FogExp2, ExactWhereTheFactorsNeedIt) {
  // f = 1 at distance 0 (x = -0 or +0) and beyond: fog_blend then copies the color's bits.
  EXPECT_EQ(fog_exp2(0.0f), 1.0f);
  EXPECT_EQ(fog_exp2(-0.0f), 1.0f);
  EXPECT_EQ(fog_exp2(1e-30f), 1.0f);
  EXPECT_EQ(fog_exp2(1e30f), 1.0f);
  EXPECT_EQ(fog_exp2(INFINITY), 1.0f);
  // Integer powers are exact (r = 0, p(0) = 1).
  for (int n = 0; n <= 126; ++n) EXPECT_EQ(fog_exp2(float(-n)), std::ldexp(1.0f, -n)) << n;
  // Below 2^-126 the factor is flushed to exactly 0: the fog color, with no NaN leaking through.
  for (float x : {-126.0001f, -126.5f, -127.0f, -149.0f, -150.0f, -1e3f, -1e30f, -INFINITY})
    EXPECT_EQ(fog_exp2(x), 0.0f) << x;
  // Never above 1 or below 0 on the fog factors' domain.
  for (float x = -130.0f; x <= 1.0f; x += 0.013f) {
    const float y = fog_exp2(x);
    EXPECT_GE(y, 0.0f) << x;
    EXPECT_LE(y, 1.0f) << x;
  }
}

}  // namespace
}  // namespace fogcl::test
