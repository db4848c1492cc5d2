// The volumetric pass's noise (docs/volumetric.md §A volume; docs/volumetric-noise.md): one tileable 3D texture
// of N^3 texels, 4 channels, generated on the host from (size, seed) and uploaded once per device.
//
//   R  gradient-noise fBm (Perlin 2002, "Improving Noise": 12 cube-edge gradients, quintic fade
//      6t^5 - 15t^4 + 10t^3), lattice 4, 8, 16 periods per tile, gain 0.5, lacunarity 2.
//   G  Worley fBm of 1 - F1 (Worley 1996, "A Cellular Texture Basis Function"), 1, 2, 4 cells
//   B  the same at 2, 4, 8 cells per tile
//   A  the same at 4, 8, 16 cells per tile; each Worley fBm weights its octaves 0.625, 0.25,
//      0.125 as Schneider & Vos 2015 ("The Real-time Volumetric Cloudscapes of Horizon Zero
//      Dawn") do.
//
// No octave of any channel goes above 16 periods per tile: at the smallest size (N = 32) a lattice
// cell then spans at least 2 texels, at the default 64 at least 4. The frequencies do not depend
// on N, so the sizes sample one and the same function of the tile coordinate (texel centres at
// (i + 0.5) / N): a larger N is a finer sampling of the same noise, not a different pattern.
//
// Tileable: every octave's lattice / cell grid has an integer period that divides the tile and is
// hashed modulo that period, so texel N (= texel 0) continues texel N - 1 on every axis.
// Each channel is then remapped so that its minimum is byte 0 and its maximum byte 255 exactly.
#pragma once

#include <cstdint>
#include <vector>

namespace fogcl {

// Texel (x, y, z) channel c is texels[((z * size + y) * size + x) * 4 + c], unorm8:
// value = byte / 255 (the scalar path and the kernel's CL_UNORM_INT8 image read convert the same
// byte to the same float). unorm8 keeps the default 64^3 texture at 1 MiB instead of 4 MiB of
// float; one byte step (1/255) is below the resolution any density remap needs.
struct NoiseTexture {
  int size = 0;                      // N texels per side: a power of two in [32, 128], default 64
  std::uint32_t seed = 0;            // the seed it was generated from
  std::vector<std::uint8_t> texels;  // N^3 * 4 bytes, x fastest, then y, z; RGBA per texel
  // byte / 255.0f of texel (x, y, z) channel `channel` (0..3); coordinates wrap modulo N (any
  // int, negative included). No range check on `channel` beyond debug assertions.
  float value(int x, int y, int z, int channel) const;
};

// Deterministic from (size, seed): the same inputs give the same bytes on every machine and
// compiler (integer hashing; only +, -, *, / and sqrt on doubles, all correctly rounded by IEEE
// 754, with floating-point contraction off for this file; no std:: random distributions, no
// unordered iteration; the threads over z slices write disjoint texels, so the thread count
// cannot change a byte).
// Throws fogcl::Error naming the value and the rule for a size that is not a power of two in
// [32, 128]. Takes ~0.25 s at 64^3 and ~2 s at 128^3 on one core, split over the hardware threads
// by z slices (NoiseTiming prints the times).
NoiseTexture make_noise_texture(int size = 64, std::uint32_t seed = 1);

// The frequencies a channel is built from, in periods (lattice cells) per tile: octave i has
// base_frequency * 2^i, i < octaves. R: {4, 3}; G: {1, 3}; B: {2, 3}; A: {4, 3}.
// Throws fogcl::Error for a channel outside 0..3.
struct NoiseChannelSpec {
  int base_frequency;  // periods per tile of the first octave
  int octaves;         // each next octave doubles the frequency (lacunarity 2)
};
NoiseChannelSpec noise_channel_spec(int channel);

}  // namespace fogcl
