// The scalar C++ path: one thread, the formulas of kernels/fog_math.h instantiated on the float
// type. float is the benchmark baseline and the no-OpenCL fallback; double is the reference every
// other path's error is measured against (docs/DESIGN.md §4).
#pragma once

#include <vector>

#include "fogcl/camera.h"
#include "fogcl/fog_settings.h"
#include "fogcl/image.h"

namespace fogcl {

// Fogs `in` into `out` in float, the same storage format as `in` (out is reallocated unless it
// already has in's size and format; out may be in). Same rules as the OpenCL pass: fog off or
// density 0 copies the input bit for bit; f == 1 pixels keep their bits; alpha passes through.
// Throws fogcl::Error for invalid settings, camera constants or mismatched/empty images.
void apply_fog_scalar(const ColorImage& in, const DepthImage& depth, ColorImage& out,
                      const CameraParams& camera, const FogSettings& settings);
// The same over the caller's memory (views, image.h; any row stride): out must have in's size
// and format and be in itself or memory apart from in and depth.
void apply_fog_scalar(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                      const CameraParams& camera, const FogSettings& settings);

// apply_fog_scalar on rows [first_row, end_row) of the frame only, for callers that spread a frame
// over their own threads: every pixel gets the bits apply_fog_scalar gives it, rows outside the
// range are not touched. `out` must already have in's size and format (else fogcl::Error).
void apply_fog_scalar_rows(const ConstColorView& in, const ConstDepthView& depth, const ColorView& out,
                           const CameraParams& camera, const FogSettings& settings, int first_row, int end_row);

// The fog evaluated in T (float or double), unrounded to the storage format: rgba has
// 4 * width * height values; factor the fog factors f and amount the fog amounts 1 - f
// (computed with expm1 for exp/exp2, so a thin fog's amount keeps its relative precision even
// where f rounds to 1), width * height each. Height fog (FogMode::height): factor is the red
// channel's transmittance T and amount its fog amount J (docs/DESIGN.md §6.2); 1 and 0 where the
// pixel passes through.
template <class T>
struct FogResult {
  int width = 0, height = 0;
  std::vector<T> rgba;
  std::vector<T> factor;
  std::vector<T> amount;
};

template <class T>
FogResult<T> fog_scalar(const ConstColorView& in, const ConstDepthView& depth, const CameraParams& camera,
                        const FogSettings& settings);

// max over pixels and R, G, B of |image - reference.rgba| (a NaN difference counts as +inf):
// the "max error against the float64 path" every tool of the project reports.
double max_abs_rgb_error(const ConstColorView& image, const FogResult<double>& reference);

// The same for the fog factor, from a probe run (color (1, 1, 1, 1), fog color 0: every output
// channel is f): max |probe RGB - reference.factor|.
double max_abs_factor_error(const ConstColorView& probe, const FogResult<double>& reference);

extern template FogResult<float> fog_scalar<float>(const ConstColorView&, const ConstDepthView&,
                                                   const CameraParams&, const FogSettings&);
extern template FogResult<double> fog_scalar<double>(const ConstColorView&, const ConstDepthView&,
                                                     const CameraParams&, const FogSettings&);

}  // namespace fogcl
