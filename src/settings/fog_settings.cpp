#include "fogcl/fog_settings.h"

#include <cmath>

#include "fogcl/error.h"
#include "runtime/format.h"

namespace fogcl {

namespace {
using detail::comma_list;
using detail::str;
bool finite(float v) { return std::isfinite(v); }
bool finite_non_negative(const glm::vec3& v) {
  for (int c = 0; c < 3; ++c)
    if (!(finite(v[c]) && v[c] >= 0.0f)) return false;
  return true;
}

// FogMode::height's own parameters (docs/DESIGN.md §6.1).
void validate_height(const FogSettings& s) {
  const HeightFogSettings& h = s.height;
  if (!h.extinction && !(finite(s.density) && s.density >= 0.0f))
    throw Error("height fog density must be finite and >= 0 (got " + str(s.density) + ")");
  if (h.extinction && !finite_non_negative(*h.extinction))
    throw Error("height fog extinction must be finite and >= 0 in each channel (got " + comma_list(*h.extinction) +
                ")");
  if (h.inscattering && !finite_non_negative(*h.inscattering))
    throw Error("height fog in-scattering must be finite and >= 0 in each channel (got " + comma_list(*h.inscattering) +
                ")");
  if (!finite(h.falloff)) throw Error("height fog falloff must be finite (got " + str(h.falloff) + ")");
  if (!finite(h.base_height)) throw Error("height fog base height must be finite (got " + str(h.base_height) + ")");
  if (!(finite(h.start) && h.start >= 0.0f))
    throw Error("height fog start must be finite and >= 0 (got " + str(h.start) + ")");
  if (!(h.cutoff > h.start))
    throw Error("height fog cut-off must be > start (got cut-off " + str(h.cutoff) + ", start " + str(h.start) + ")");
  if (!(h.max_opacity >= 0.0f && h.max_opacity <= 1.0f))
    throw Error("height fog maximum opacity must be in [0, 1] (got " + str(h.max_opacity) + ")");
  if (h.sun) {
    const SunLobe& l = *h.sun;
    if (!(finite(l.direction.x) && finite(l.direction.y) && finite(l.direction.z)) || l.direction == glm::vec3(0.0f))
      throw Error("sun direction must be a finite non-zero vector (got " + comma_list(l.direction) + ")");
    if (!finite_non_negative(l.color))
      throw Error("sun color must be finite and >= 0 in each channel (got " + comma_list(l.color) + ")");
    if (!(finite(l.exponent) && l.exponent > 0.0f))
      throw Error("sun exponent must be finite and > 0 (got " + str(l.exponent) + ")");
    if (!(finite(l.start) && l.start >= 0.0f))
      throw Error("sun start must be finite and >= 0 (got " + str(l.start) + ")");
  }
}
}  // namespace

void validate(const FogSettings& s) {
  if (s.mode != FogMode::off && s.mode != FogMode::linear && s.mode != FogMode::exp &&
      s.mode != FogMode::exp2 && s.mode != FogMode::height)
    throw Error("fog mode " + std::to_string(int(s.mode)) + " is not one of off, linear, exp, exp2, height");
  if (s.mode == FogMode::off) return;
  for (int c = 0; c < 3; ++c)
    if (!finite(s.color[c]) || std::fabs(s.color[c]) > 65504.0f)
      throw Error("fog color component " + std::to_string(c) + " must be finite with |c| <= 65504 (got " +
                  str(s.color[c]) + ")");
  if (s.mode == FogMode::linear) {
    if (!finite(s.start)) throw Error("fog start must be finite (got " + str(s.start) + ")");
    if (!finite(s.end)) throw Error("fog end must be finite (got " + str(s.end) + ")");
    if (s.start > s.end)
      throw Error("fog start must be <= end (got start " + str(s.start) + ", end " + str(s.end) + ")");
  } else if (s.mode == FogMode::height) {
    validate_height(s);
  } else if (!(s.density >= 0.0f) || !finite(s.density)) {
    throw Error("fog density must be finite and >= 0 (got " + str(s.density) + ")");
  }
  if (s.precision != Precision::precise && s.precision != Precision::fast)
    throw Error("precision " + std::to_string(int(s.precision)) + " is not one of precise, fast");
  if (s.metric != FogMetric::depth && s.metric != FogMetric::distance)
    throw Error("fog metric " + std::to_string(int(s.metric)) + " is not one of depth, distance");
  if (s.sky != SkyDistance::far_plane && s.sky != SkyDistance::infinite)
    throw Error("sky distance " + std::to_string(int(s.sky)) + " is not one of far, infinite");
}

const char* to_string(FogMode mode) {
  switch (mode) {
    case FogMode::off: return "off";
    case FogMode::linear: return "linear";
    case FogMode::exp: return "exp";
    case FogMode::exp2: return "exp2";
    case FogMode::height: return "height";
  }
  return "?";
}

const char* to_string(FogMetric metric) { return metric == FogMetric::distance ? "distance" : "depth"; }

const char* to_string(Precision p) { return p == Precision::fast ? "fast" : "precise"; }
const char* to_string(SkyDistance sky) { return sky == SkyDistance::infinite ? "infinite" : "far"; }

}  // namespace fogcl
