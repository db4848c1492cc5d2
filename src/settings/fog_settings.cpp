#include "fogcl/fog_settings.h"

#include <cmath>
#include <sstream>

#include "fogcl/error.h"

namespace fogcl {

namespace {
std::string num(float v) {
  std::ostringstream s;
  s.precision(9);
  s << v;
  return s.str();
}
bool finite(float v) { return std::isfinite(v); }
}  // namespace

void validate(const FogSettings& s) {
  if (s.mode != FogMode::off && s.mode != FogMode::linear && s.mode != FogMode::exp &&
      s.mode != FogMode::exp2)
    throw Error("fog mode " + std::to_string(int(s.mode)) + " is not one of off, linear, exp, exp2");
  if (s.mode == FogMode::off) return;
  for (int c = 0; c < 3; ++c)
    if (!finite(s.color[c]) || std::fabs(s.color[c]) > 65504.0f)
      throw Error("fog color component " + std::to_string(c) + " must be finite with |c| <= 65504 (got " +
                  num(s.color[c]) + ")");
  if (s.mode == FogMode::linear) {
    if (!finite(s.start)) throw Error("fog start must be finite (got " + num(s.start) + ")");
    if (!finite(s.end)) throw Error("fog end must be finite (got " + num(s.end) + ")");
    if (s.start > s.end)
      throw Error("fog start must be <= end (got start " + num(s.start) + ", end " + num(s.end) + ")");
  } else if (!(s.density >= 0.0f) || !finite(s.density)) {
    throw Error("fog density must be finite and >= 0 (got " + num(s.density) + ")");
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
  }
  return "?";
}

const char* to_string(FogMetric metric) { return metric == FogMetric::distance ? "distance" : "depth"; }

const char* to_string(Precision p) { return p == Precision::fast ? "fast" : "precise"; }
const char* to_string(SkyDistance sky) { return sky == SkyDistance::infinite ? "infinite" : "far"; }

}  // namespace fogcl
