// The volumetric pass's noise texture (fogcl/noise.h, docs/volumetric-noise.md): it tiles (opposite faces
// continue each other), fills [0, 1] in every channel, each channel has the frequency it claims,
// and it is deterministic from (size, seed). Every test prints what it measured, passing or not.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "fogcl/error.h"
#include "fogcl/noise.h"

namespace fogcl {
namespace {

constexpr std::array<const char*, 4> kChannelName{"R", "G", "B", "A"};
constexpr std::array<const char*, 3> kAxisName{"x", "y", "z"};

// The textures the tests share (generation is the slow part), built once; a deque keeps the
// references stable.
const NoiseTexture& texture(int size, std::uint32_t seed = 1) {
  static std::deque<NoiseTexture> cache;
  for (const NoiseTexture& t : cache)
    if (t.size == size && t.seed == seed) return t;
  cache.push_back(make_noise_texture(size, seed));
  return cache.back();
}

int byte_at(const NoiseTexture& t, int x, int y, int z, int c) {
  return t.texels[((static_cast<std::size_t>(z) * t.size + y) * t.size + x) * 4 + c];
}

// Texel (i, j, k) with `axis` along i: the texel whose coordinate on `axis` is i.
int byte_on_axis(const NoiseTexture& t, int axis, int i, int j, int k, int c) {
  switch (axis) {
    case 0:
      return byte_at(t, i, j, k, c);
    case 1:
      return byte_at(t, j, i, k, c);
    default:
      return byte_at(t, j, k, i, c);
  }
}

struct FaceJump {
  double mean = 0;  // mean |byte difference| over the N^2 texel pairs of two neighbouring faces
  int max = 0;      // max |byte difference|
};

// The jump between face a and face b (coordinate on `axis`), over all N^2 texel pairs.
FaceJump face_jump(const NoiseTexture& t, int c, int axis, int a, int b) {
  FaceJump f;
  long sum = 0;
  for (int k = 0; k < t.size; ++k)
    for (int j = 0; j < t.size; ++j) {
      const int d = std::abs(byte_on_axis(t, axis, a, j, k, c) - byte_on_axis(t, axis, b, j, k, c));
      sum += d;
      f.max = std::max(f.max, d);
    }
  f.mean = static_cast<double>(sum) / (static_cast<double>(t.size) * t.size);
  return f;
}

// Tiling: the wrap (face N-1 next to face 0) must look like any interior pair of neighbouring
// faces. Budget: its mean |byte difference| at most 1.15 x the largest interior face's mean and
// 2 x the average interior one, its max at most 1.25 x the interior max + 1. Over seeds 1..12 at
// N = 32 and 64 (288 channel-axis cases) the tileable noise stayed within 1.03 x the largest face,
// 1.53 x the average and the interior max + 2 bytes. Generated without the modulo on the lattice
// and the cells, every case fails: the wrap's mean is 2.6..32 x the interior's, 2.2..22 x the
// largest face's, its max 95..205 bytes against 9..75 (checked by hand, see the commit message).
TEST(NoiseTiling, OppositeFacesContinueEachOther) {
  for (int size : {32, 64}) {
    const NoiseTexture& t = texture(size);
    const int n = t.size;
    for (int c = 0; c < 4; ++c)
      for (int axis = 0; axis < 3; ++axis) {
        double interior_sum = 0, interior_max_mean = 0;
        int interior_max = 0;
        for (int i = 0; i + 1 < n; ++i) {
          const FaceJump f = face_jump(t, c, axis, i, i + 1);
          interior_sum += f.mean;
          interior_max_mean = std::max(interior_max_mean, f.mean);
          interior_max = std::max(interior_max, f.max);
        }
        const double interior_mean = interior_sum / (n - 1);
        const FaceJump wrap = face_jump(t, c, axis, n - 1, 0);
        std::printf(
            "N=%3d %s along %s: wrap mean %6.3f max %3d | interior mean %6.3f (largest face %6.3f) "
            "max %3d | wrap/interior mean %.3f\n",
            n, kChannelName[c], kAxisName[axis], wrap.mean, wrap.max, interior_mean,
            interior_max_mean, interior_max, wrap.mean / interior_mean);
        const std::string where =
            "N=" + std::to_string(n) + " " + kChannelName[c] + " along " + kAxisName[axis];
        EXPECT_LE(wrap.mean, 1.15 * interior_max_mean) << where;
        EXPECT_LE(wrap.mean, 2.0 * interior_mean) << where;
        EXPECT_LE(wrap.max, 1.25 * interior_max + 1) << where;
      }
  }
}

// Range: every channel spans bytes 0..255 exactly; value() is byte / 255 in [0, 1] and wraps.
TEST(NoiseRange, EveryChannelFillsZeroToOne) {
  for (int size : {32, 64, 128}) {
    const NoiseTexture& t = texture(size);
    ASSERT_EQ(t.texels.size(), static_cast<std::size_t>(size) * size * size * 4);
    for (int c = 0; c < 4; ++c) {
      int lo = 255, hi = 0;
      double mean = 0;
      for (std::size_t i = c; i < t.texels.size(); i += 4) {
        lo = std::min<int>(lo, t.texels[i]);
        hi = std::max<int>(hi, t.texels[i]);
        mean += t.texels[i];
      }
      mean /= static_cast<double>(t.texels.size() / 4) * 255.0;
      std::printf("N=%3d %s: min byte %3d, max byte %3d, mean value %.3f\n", size, kChannelName[c],
                  lo, hi, mean);
      EXPECT_EQ(lo, 0) << kChannelName[c];
      EXPECT_EQ(hi, 255) << kChannelName[c];
    }
    const int n = t.size;
    for (int c = 0; c < 4; ++c)
      for (int i = -n - 1; i <= 2 * n; i += 7) {
        const float v = t.value(i, 3, 5, c);
        EXPECT_GE(v, 0.0f);
        EXPECT_LE(v, 1.0f);
        const int w = ((i % n) + n) % n;
        EXPECT_EQ(v, byte_at(t, w, 3, 5, c) / 255.0f) << "x " << i;
        EXPECT_EQ(t.value(2, i, 5, c), byte_at(t, 2, w, 5, c) / 255.0f) << "y " << i;
        EXPECT_EQ(t.value(2, 3, i, c), byte_at(t, 2, 3, w, c) / 255.0f) << "z " << i;
      }
    EXPECT_EQ(t.value(0, 0, 0, 0), 0.0f + byte_at(t, 0, 0, 0, 0) / 255.0f);
  }
}

// One-sided 1D power spectrum along x, averaged over all N^2 lines: power[k] for k = 1 .. N/2
// (DC dropped) in cycles per tile, by direct DFT. (A line through an isotropic 3D field has a
// spectrum that falls from k = 1 whatever the field's scale, so its peak says nothing; its
// moments do.)
std::vector<double> x_power_spectrum(const NoiseTexture& t, int c) {
  const int n = t.size;
  const double two_pi = 6.283185307179586;
  std::vector<double> cs(static_cast<std::size_t>(n)), sn(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    cs[i] = std::cos(two_pi * i / n);
    sn[i] = std::sin(two_pi * i / n);
  }
  std::vector<double> power(static_cast<std::size_t>(n / 2 + 1), 0.0),
      line(static_cast<std::size_t>(n));
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) line[x] = byte_at(t, x, y, z, c) / 255.0;
      for (int k = 1; k <= n / 2; ++k) {
        double re = 0, im = 0;
        for (int x = 0; x < n; ++x) {
          const int m = (k * x) % n;
          re += line[x] * cs[m];
          im -= line[x] * sn[m];
        }
        // Bins 1 .. N/2 - 1 stand for +k and -k; the Nyquist bin only for itself.
        power[k] += (k == n / 2 ? 1.0 : 2.0) * (re * re + im * im);
      }
    }
  return power;
}

// Power of the 3D DFT summed over shells of radius |K| (rounded to the nearest integer, cycles
// per tile): shell[s] for s = 1 .. N/2 (DC and corners beyond N/2 dropped). Separable direct DFT.
std::vector<double> shell_power_spectrum(const NoiseTexture& t, int c) {
  const int n = t.size;
  const double two_pi = 6.283185307179586;
  std::vector<double> cs(static_cast<std::size_t>(n)), sn(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    cs[i] = std::cos(two_pi * i / n);
    sn[i] = std::sin(two_pi * i / n);
  }
  const std::size_t count = static_cast<std::size_t>(n) * n * n;
  std::vector<double> re(count), im(count, 0.0);
  for (std::size_t i = 0; i < count; ++i)
    re[i] = t.texels[i * 4 + static_cast<std::size_t>(c)] / 255.0;
  std::vector<double> lr(static_cast<std::size_t>(n)), li(static_cast<std::size_t>(n));
  const std::size_t strides[3] = {1, static_cast<std::size_t>(n), static_cast<std::size_t>(n) * n};
  for (int axis = 0; axis < 3; ++axis) {
    const std::size_t s = strides[axis];
    for (std::size_t base = 0; base < count; ++base) {
      if ((base / s) % static_cast<std::size_t>(n) != 0) continue;  // one line per start point
      for (int i = 0; i < n; ++i) {
        lr[i] = re[base + i * s];
        li[i] = im[base + i * s];
      }
      for (int k = 0; k < n; ++k) {
        double ar = 0, ai = 0;
        for (int i = 0; i < n; ++i) {
          const int m = (k * i) % n;
          ar += lr[i] * cs[m] + li[i] * sn[m];
          ai += li[i] * cs[m] - lr[i] * sn[m];
        }
        re[base + k * s] = ar;
        im[base + k * s] = ai;
      }
    }
  }
  std::vector<double> shell(static_cast<std::size_t>(n / 2 + 1), 0.0);
  const auto freq = [n](int k) { return k <= n / 2 ? k : k - n; };
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double r =
            std::sqrt(double(freq(x) * freq(x) + freq(y) * freq(y) + freq(z) * freq(z)));
        const int b = static_cast<int>(std::lround(r));
        if (b < 1 || b > n / 2) continue;
        const std::size_t i = (static_cast<std::size_t>(z) * n + y) * n + x;
        shell[static_cast<std::size_t>(b)] += re[i] * re[i] + im[i] * im[i];
      }
  return shell;
}

struct SpectrumFigures {
  double centroid = 0;  // sum k P(k) / sum P(k) [cycles per tile]
  double rms = 0;       // sqrt(sum k^2 P(k) / sum P(k)) [cycles per tile]
  int peak = 0;         // the bin of largest power
  double in_band = 0;   // fraction of the power in [base / 2, 2 base]
};

SpectrumFigures figures(const std::vector<double>& power, int base) {
  SpectrumFigures f;
  double total = 0, moment = 0, moment2 = 0, band = 0;
  f.peak = 1;
  for (std::size_t k = 1; k < power.size(); ++k) {
    const double kk = static_cast<double>(k);
    total += power[k];
    moment += kk * power[k];
    moment2 += kk * kk * power[k];
    if (2 * static_cast<int>(k) >= base && static_cast<int>(k) <= 2 * base) band += power[k];
    if (power[k] > power[static_cast<std::size_t>(f.peak)]) f.peak = static_cast<int>(k);
  }
  f.centroid = moment / total;
  f.rms = std::sqrt(moment2 / total);
  f.in_band = band / total;
  return f;
}

// Frequency: each channel has the frequency noise_channel_spec() claims, measured on the 3D power
// spectrum summed over shells |K| (cycles per tile) at N = 32 and 64:
// - Worley G, B, A: the spectral rms frequency rises G < B < A, each ratio within 25 % of the
//   ratio of the base frequencies (2); swapping any two channels fails this. The x-line spectra
//   must rise in the same order (their figures are printed: a line's own mean takes much of a
//   low-frequency channel's variance, which compresses their ratios, so they are not held to 2).
// - R: the shell spectrum peaks within [base/2, base] (gradient noise's energy sits just below its
//   lattice frequency) and holds >= 75 % of its power within [base/2, 2 base].
TEST(NoiseFrequency, EachChannelHasTheFrequencyItClaims) {
  for (int size : {32, 64}) {
    const NoiseTexture& t = texture(size);
    std::array<SpectrumFigures, 4> line, shell;
    for (int c = 0; c < 4; ++c) {
      const NoiseChannelSpec spec = noise_channel_spec(c);
      const std::vector<double> shells = shell_power_spectrum(t, c);
      line[c] = figures(x_power_spectrum(t, c), spec.base_frequency);
      shell[c] = figures(shells, spec.base_frequency);
      std::printf(
          "N=%d %s (base %d, %d octaves): 3D shells: rms %.3f centroid %.3f peak %d, "
          "%.1f %% of power in [base/2, 2 base] | x lines: rms %.3f centroid %.3f\n"
          "  shell power / peak, |K| = 1..12:",
          size, kChannelName[c], spec.base_frequency, spec.octaves, shell[c].rms, shell[c].centroid,
          shell[c].peak, 100.0 * shell[c].in_band, line[c].rms, line[c].centroid);
      for (int k = 1; k <= 12; ++k) std::printf(" %.3f", shells[k] / shells[shell[c].peak]);
      std::printf("\n");
    }
    for (int c = 2; c < 4; ++c) {
      const double claimed = static_cast<double>(noise_channel_spec(c).base_frequency) /
                             noise_channel_spec(c - 1).base_frequency;
      const double measured = shell[c].rms / shell[c - 1].rms;
      std::printf(
          "N=%d %s/%s: shell rms ratio %.3f (centroid ratio %.3f, x-line rms ratio %.3f), "
          "claimed %.3f\n",
          size, kChannelName[c], kChannelName[c - 1], measured,
          shell[c].centroid / shell[c - 1].centroid, line[c].rms / line[c - 1].rms, claimed);
      EXPECT_NEAR(measured, claimed, 0.25 * claimed)
          << "N=" << size << " " << kChannelName[c] << "/" << kChannelName[c - 1];
      EXPECT_GT(line[c].rms, line[c - 1].rms) << "N=" << size << " x lines " << kChannelName[c];
      EXPECT_GT(line[c].centroid, line[c - 1].centroid)
          << "N=" << size << " x lines " << kChannelName[c];
    }
    const int r_base = noise_channel_spec(0).base_frequency;
    EXPECT_GE(2 * shell[0].peak, r_base) << "N=" << size;
    EXPECT_LE(shell[0].peak, r_base) << "N=" << size;
    EXPECT_GE(shell[0].in_band, 0.75) << "N=" << size;
  }
}

TEST(NoiseFrequency, ChannelSpecs) {
  for (int c = 0; c < 4; ++c) {
    const NoiseChannelSpec s = noise_channel_spec(c);
    const int highest = s.base_frequency << (s.octaves - 1);
    std::printf("%s: base %d, %d octaves, highest %d periods per tile (N=32 Nyquist 16)\n",
                kChannelName[c], s.base_frequency, s.octaves, highest);
    EXPECT_GE(s.base_frequency, 1);
    EXPECT_GE(s.octaves, 1);
    EXPECT_LE(highest, 16) << "a cell must span >= 2 texels at N = 32";
    EXPECT_EQ(32 % highest, 0) << "every period must divide the tile";
  }
  EXPECT_THROW(noise_channel_spec(4), Error);
  EXPECT_THROW(noise_channel_spec(-1), Error);
}

// FNV-1a 64 of the bytes: a fingerprint for the determinism checks.
std::uint64_t fingerprint(const std::vector<std::uint8_t>& bytes) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (std::uint8_t b : bytes) {
    h ^= b;
    h *= 0x100000001b3ULL;
  }
  return h;
}

TEST(NoiseDeterminism, SameSeedSameBytesOtherSeedOtherBytes) {
  const NoiseTexture a = make_noise_texture(32, 1), b = make_noise_texture(32, 1);
  const NoiseTexture c = make_noise_texture(32, 2);
  EXPECT_EQ(a.size, 32);
  EXPECT_EQ(a.seed, 1U);
  EXPECT_EQ(c.seed, 2U);
  EXPECT_TRUE(a.texels == b.texels);
  std::size_t differing = 0;
  for (std::size_t i = 0; i < a.texels.size(); ++i) differing += a.texels[i] != c.texels[i];
  std::printf("seed 1 vs seed 1: %s; seed 1 vs seed 2: %zu of %zu bytes differ (%.1f %%)\n",
              a.texels == b.texels ? "identical" : "DIFFERENT", differing, a.texels.size(),
              100.0 * differing / a.texels.size());
  EXPECT_GT(differing, a.texels.size() * 9 / 10);
}

// The same bytes on every machine and compiler. These fingerprints were taken on x86-64 with
// GCC 12 and clang, -O0 to -O3 -march=native, with and without FMA contraction, 1, 2 and 7
// threads (docs/volumetric-noise.md). A change of the algorithm changes them on purpose (update
// them and say why); a change of platform or compiler must not.
TEST(NoiseDeterminism, BytesMatchTheRecordedFingerprints) {
  const std::array<std::pair<int, std::uint64_t>, 2> expected{
      {{32, 0xa3e1bda590bda05aULL}, {64, 0xf5c59e54d01436cdULL}}};
  for (const auto& [size, want] : expected) {
    const std::uint64_t got = fingerprint(texture(size, 1).texels);
    std::printf("N=%d seed 1: FNV-1a 64 of the bytes 0x%016llx (recorded 0x%016llx)\n", size,
                static_cast<unsigned long long>(got), static_cast<unsigned long long>(want));
    EXPECT_EQ(got, want) << "N=" << size;
  }
}

TEST(NoiseDeterminism, SizesArePowersOfTwoFrom32To128) {
  for (int size : {32, 64, 128}) {
    const NoiseTexture& t = texture(size);
    std::printf("N=%3d accepted, %zu bytes\n", size, t.texels.size());
    EXPECT_EQ(t.size, size);
    EXPECT_EQ(t.texels.size(), static_cast<std::size_t>(size) * size * size * 4);
  }
  for (int size : {48, 16, 256, 0, -64, 33, 127}) {
    try {
      (void)make_noise_texture(size, 1);
      ADD_FAILURE() << "size " << size << " accepted";
    } catch (const Error& e) {
      const std::string what = e.what();
      std::printf("N=%d rejected: %s\n", size, what.c_str());
      EXPECT_NE(what.find(std::to_string(size)), std::string::npos) << what;
      EXPECT_NE(what.find("power of two in [32, 128]"), std::string::npos) << what;
    }
  }
}

// Generation time per size (printed, not asserted: fogcl/noise.h states the expectation).
TEST(NoiseTiming, GenerationTimePerSize) {
  for (int size : {32, 64, 128}) {
    double best = 1e30;
    const int runs = size == 128 ? 1 : 3;
    for (int r = 0; r < runs; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      const NoiseTexture t = make_noise_texture(size, 7);
      best = std::min(
          best,
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      EXPECT_EQ(t.size, size);
    }
    std::printf("N=%3d: generated in %.1f ms (best of %d, all hardware threads)\n", size, best,
                runs);
  }
}

}  // namespace
}  // namespace fogcl
