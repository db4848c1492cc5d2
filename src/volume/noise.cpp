// The volumetric pass's noise texture (fogcl/noise.h; docs/volumetric-noise.md).
//
// Determinism: every value is computed from integer hashes with +, -, *, / and sqrt on doubles,
// which IEEE 754 rounds correctly; this file is compiled with -ffp-contract=off
// (src/CMakeLists.txt) so no compiler fuses a multiply-add differently on another machine. Min /
// max are exact, and each thread writes its own z slices, so the number of threads cannot change a
// byte.
#include "fogcl/noise.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cassert>
#include <cmath>
#include <cstddef>
#include <string>
#include <system_error>
#include <thread>

#include "fogcl/error.h"

namespace fogcl {
namespace {

constexpr int kChannels = 4;
constexpr int kMinSize = 32;
constexpr int kMaxSize = 128;

// Per channel: base frequency [periods per tile] and octave count (lacunarity 2). No octave above
// 16 periods per tile, so that a cell spans >= 2 texels at N = 32 (see fogcl/noise.h).
constexpr std::array<NoiseChannelSpec, kChannels> kSpecs{{
    {4, 3},  // R: gradient fBm 4, 8, 16
    {1, 3},  // G: Worley fBm 1, 2, 4
    {2, 3},  // B: Worley fBm 2, 4, 8
    {4, 3},  // A: Worley fBm 4, 8, 16
}};
constexpr double kPerlinGain = 0.5;                                  // amplitude per octave
constexpr std::array<double, 3> kWorleyWeights{0.625, 0.25, 0.125};  // Schneider & Vos 2015
static_assert(kSpecs[1].octaves <= 3 && kSpecs[2].octaves <= 3 && kSpecs[3].octaves <= 3,
              "one Worley weight per octave");

// "lowbias32" (C. Wellons, hash-prospector, 2018): a 32-bit integer permutation with good
// avalanche. Lattice points hash as h(x + h(y + h(z + salt))).
constexpr std::uint32_t hash32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

std::uint32_t hash_cell(int x, int y, int z, std::uint32_t salt) {
  return hash32(
      static_cast<std::uint32_t>(x) +
      hash32(static_cast<std::uint32_t>(y) + hash32(static_cast<std::uint32_t>(z) + salt)));
}

// One salt per (seed, channel, octave), so octaves and channels are independent noises.
std::uint32_t octave_salt(std::uint32_t seed, int channel, int octave) {
  return hash32(seed ^ hash32(static_cast<std::uint32_t>(channel * 16 + octave) + 0x9e3779b9U));
}

// Perlin 2002's quintic fade: C2 at lattice points, so the sum has no second-derivative creases.
double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

double lerp(double a, double b, double t) { return a + t * (b - a); }

// Perlin 2002's gradient: the 12 cube-edge directions (16 entries, 4 repeated), dotted with the
// offset (x, y, z) from the lattice point.
double grad(std::uint32_t h, double x, double y, double z) {
  const unsigned g = h & 15U;
  const double u = g < 8 ? x : y;
  const double v = g < 4 ? y : (g == 12 || g == 14 ? x : z);
  return ((g & 1U) ? -u : u) + ((g & 2U) ? -v : v);
}

// One octave's lattice: `period` cells per tile on each axis, the hash of every lattice point
// (taken modulo the period, which is what makes the octave tile) precomputed.
struct Lattice {
  int period = 0;
  std::vector<std::uint32_t> hashes;  // period^3, x fastest

  Lattice(int p, std::uint32_t salt) : period(p), hashes(static_cast<std::size_t>(p) * p * p) {
    for (int z = 0; z < p; ++z)
      for (int y = 0; y < p; ++y)
        for (int x = 0; x < p; ++x) hashes[index(x, y, z)] = hash_cell(x, y, z, salt);
  }
  std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * period + y) * period + x;
  }
  // Lattice coordinate i in [0, period] (the texel positions never leave the tile): wraps period
  // to 0. Generating without this wrap is the non-tileable mutation the tiling test catches.
  int wrap(int i) const { return i == period ? 0 : i; }
};

// Improved noise (Perlin 2002) at tile coordinate p * period, p in [0, 1)^3. About [-1, 1].
double gradient_noise(const Lattice& l, double px, double py, double pz) {
  const double fx = px * l.period, fy = py * l.period, fz = pz * l.period;
  const int ix = static_cast<int>(std::floor(fx)), iy = static_cast<int>(std::floor(fy)),
            iz = static_cast<int>(std::floor(fz));
  const double x = fx - ix, y = fy - iy, z = fz - iz;
  const int x0 = l.wrap(ix), x1 = l.wrap(ix + 1), y0 = l.wrap(iy), y1 = l.wrap(iy + 1),
            z0 = l.wrap(iz), z1 = l.wrap(iz + 1);
  const auto h = [&](int a, int b, int c) { return l.hashes[l.index(a, b, c)]; };
  const double u = fade(x), v = fade(y), w = fade(z);
  const double n000 = grad(h(x0, y0, z0), x, y, z), n100 = grad(h(x1, y0, z0), x - 1, y, z);
  const double n010 = grad(h(x0, y1, z0), x, y - 1, z), n110 = grad(h(x1, y1, z0), x - 1, y - 1, z);
  const double n001 = grad(h(x0, y0, z1), x, y, z - 1), n101 = grad(h(x1, y0, z1), x - 1, y, z - 1);
  const double n011 = grad(h(x0, y1, z1), x, y - 1, z - 1);
  const double n111 = grad(h(x1, y1, z1), x - 1, y - 1, z - 1);
  return lerp(lerp(lerp(n000, n100, u), lerp(n010, n110, u), v),
              lerp(lerp(n001, n101, u), lerp(n011, n111, u), v), w);
}

// One Worley octave: `period` cells per tile, one feature point per cell at a hashed position in
// the cell (24 bits per coordinate), precomputed for the cells -1 .. period on each axis: the
// cells outside the tile are copies of the cells `period` apart (the wrap that makes it tile).
struct Cells {
  int period = 0;
  int side = 0;                               // period + 2
  std::vector<std::array<double, 3>> points;  // offset inside the cell, [0, 1)^3, x fastest

  Cells(int p, std::uint32_t salt)
      : period(p), side(p + 2), points(static_cast<std::size_t>(side) * side * side) {
    const auto wrap = [p](int i) { return (i + p) % p; };
    for (int z = -1; z <= p; ++z)
      for (int y = -1; y <= p; ++y)
        for (int x = -1; x <= p; ++x) {
          std::uint32_t h = hash_cell(wrap(x), wrap(y), wrap(z), salt);
          for (double& c : points[index(x, y, z)]) {
            c = static_cast<double>(h >> 8) * (1.0 / 16777216.0);
            h = hash32(h);
          }
        }
  }
  std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z + 1) * side + (y + 1)) * side + (x + 1);
  }
};

// 1 - F1 at tile coordinate p * period, F1 = distance [cells] to the nearest feature point,
// clamped to 1. The 27 cells around p's cell are searched with wrap-around; any point further out
// is at least one cell away, so with the clamp the search is exact. A neighbour whose box is no
// nearer than the best point so far is skipped: it cannot hold a nearer point, so the minimum,
// and every byte, is the same as with all 27.
double worley(const Cells& c, double px, double py, double pz) {
  const int n = c.period;
  const double fx = px * n, fy = py * n, fz = pz * n;
  const int ix = static_cast<int>(std::floor(fx)), iy = static_cast<int>(std::floor(fy)),
            iz = static_cast<int>(std::floor(fz));
  const double rx = fx - ix, ry = fy - iy, rz = fz - iz;
  // Squared distance from p to the neighbour boxes along each axis, offsets -1, 0, +1.
  const double bx[3] = {rx * rx, 0.0, (1 - rx) * (1 - rx)};
  const double by[3] = {ry * ry, 0.0, (1 - ry) * (1 - ry)};
  const double bz[3] = {rz * rz, 0.0, (1 - rz) * (1 - rz)};
  const auto& own = c.points[c.index(ix, iy, iz)];
  const double ox = own[0] - rx, oy = own[1] - ry, oz = own[2] - rz;
  double best = std::min(1.0, ox * ox + oy * oy + oz * oz);  // squared, clamped at 1 cell
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy) {
      const double byz = bz[dz + 1] + by[dy + 1];
      if (byz >= best) continue;
      for (int dx = -1; dx <= 1; ++dx) {
        if ((dx | dy | dz) == 0 || byz + bx[dx + 1] >= best) continue;
        const auto& q = c.points[c.index(ix + dx, iy + dy, iz + dz)];
        const double ex = dx + q[0] - rx, ey = dy + q[1] - ry, ez = dz + q[2] - rz;
        best = std::min(best, ex * ex + ey * ey + ez * ez);
      }
    }
  return 1.0 - std::sqrt(best);
}

void check_size(int size) {
  if (size < kMinSize || size > kMaxSize || (size & (size - 1)) != 0)
    throw Error("noise size " + std::to_string(size) + ": must be a power of two in [" +
                std::to_string(kMinSize) + ", " + std::to_string(kMaxSize) + "]");
}

}  // namespace

float NoiseTexture::value(int x, int y, int z, int channel) const {
  assert(channel >= 0 && channel < kChannels && size > 0);
  const auto wrap = [n = size](int i) { return ((i % n) + n) % n; };
  const std::size_t i =
      ((static_cast<std::size_t>(wrap(z)) * size + wrap(y)) * size + wrap(x)) * kChannels + channel;
  return texels[i] / 255.0f;
}

NoiseChannelSpec noise_channel_spec(int channel) {
  if (channel < 0 || channel >= kChannels)
    throw Error("noise channel " + std::to_string(channel) +
                ": must be 0 (R), 1 (G), 2 (B) or 3 (A)");
  return kSpecs[static_cast<std::size_t>(channel)];
}

NoiseTexture make_noise_texture(int size, std::uint32_t seed) {
  check_size(size);
  const int n = size;
  const std::size_t count = static_cast<std::size_t>(n) * n * n;

  // Every octave's lattice / cells, hashed once.
  std::vector<Lattice> perlin;
  for (int o = 0; o < kSpecs[0].octaves; ++o)
    perlin.emplace_back(kSpecs[0].base_frequency << o, octave_salt(seed, 0, o));
  std::array<std::vector<Cells>, kChannels> cells;
  for (int c = 1; c < kChannels; ++c)
    for (int o = 0; o < kSpecs[c].octaves; ++o)
      cells[c].emplace_back(kSpecs[c].base_frequency << o, octave_salt(seed, c, o));
  // The sum of the octaves' amplitudes: R's fBm divided by it lies in about [-1, 1].
  double perlin_norm = 0.0, amplitude = 1.0;
  for (int o = 0; o < kSpecs[0].octaves; ++o, amplitude *= kPerlinGain) perlin_norm += amplitude;

  // Unnormalised channel values, texel-major like the output.
  std::vector<double> raw(count * kChannels);
  const auto slice = [&](int z) {
    const double pz = (z + 0.5) / n;
    for (int y = 0; y < n; ++y) {
      const double py = (y + 0.5) / n;
      for (int x = 0; x < n; ++x) {
        const double px = (x + 0.5) / n;
        double* out = &raw[((static_cast<std::size_t>(z) * n + y) * n + x) * kChannels];
        double r = 0.0, amplitude = 1.0;
        for (const Lattice& l : perlin) {
          r += amplitude * gradient_noise(l, px, py, pz);
          amplitude *= kPerlinGain;
        }
        out[0] = r / perlin_norm;
        for (int c = 1; c < kChannels; ++c) {
          double w = 0.0;
          for (std::size_t o = 0; o < cells[c].size(); ++o)
            w += kWorleyWeights[o] * worley(cells[c][o], px, py, pz);
          out[c] = w;
        }
      }
    }
  };
  // Workers take z slices from a shared counter; each slice's texels are written by one thread
  // only, so the split cannot change a byte. A thread that cannot be started leaves its share to
  // the others (the calling thread always works).
  std::atomic<int> next_z{0};
  const auto work = [&] {
    for (int z = next_z++; z < n; z = next_z++) slice(z);
  };
  const int threads =
      std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, std::min(n, 16));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) {
    try {
      pool.emplace_back(work);
    } catch (const std::system_error&) {
      break;
    }
  }
  work();
  for (std::thread& th : pool) th.join();

  // Remap each channel so its minimum is byte 0 and its maximum byte 255, rounding to nearest.
  NoiseTexture tex;
  tex.size = n;
  tex.seed = seed;
  tex.texels.resize(count * kChannels);
  for (int c = 0; c < kChannels; ++c) {
    double lo = raw[c], hi = raw[c];
    for (std::size_t i = c; i < raw.size(); i += kChannels) {
      lo = std::min(lo, raw[i]);
      hi = std::max(hi, raw[i]);
    }
    // A constant channel cannot happen with these octaves; guard the division anyway.
    const double scale = hi > lo ? 255.0 / (hi - lo) : 0.0;
    for (std::size_t i = c; i < raw.size(); i += kChannels)
      tex.texels[i] =
          static_cast<std::uint8_t>(std::min(255.0, std::floor((raw[i] - lo) * scale + 0.5)));
  }
  return tex;
}

}  // namespace fogcl
