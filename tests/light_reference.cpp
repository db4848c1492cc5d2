#include "light_reference.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace fogcl::test::light_reference {
namespace {

using Real = long double;
constexpr Real kPi = 3.141592653589793238462643383279502884L;

// 8-point Gauss-Legendre nodes and weights on [-1, 1] (Abramowitz & Stegun, table 25.4).
constexpr Real kNode[4] = {0.183434642495649804939476142360184L, 0.525532409916328985817739049189246L,
                           0.796666477413626739591553936475830L, 0.960289856497536231683560868569473L};
constexpr Real kWeight[4] = {0.362683783378361982965150449277196L, 0.313706645877887287337962201986601L,
                             0.222381034453374470544355994426241L, 0.101228536290376259152531354309861L};

// [t0, t1] of the ray inside the sphere, clipped to [0, t_end]; false where it misses.
bool chord(const glm::dvec3& o, const glm::dvec3& d, const glm::dvec3& c, double r, double t_end, Real& t0, Real& t1) {
  const Real b = Real(glm::dot(o - c, d));
  const glm::dvec3 f = o - c;
  const Real cc = Real(glm::dot(f, f)) - Real(r) * r;
  const Real disc = b * b - cc;
  if (!(disc > 0)) return false;
  t0 = std::max<Real>(-b - std::sqrt(disc), 0);
  t1 = std::min<Real>(-b + std::sqrt(disc), t_end);
  return t1 > t0;
}

Real optical_depth(const glm::dvec3& o, const glm::dvec3& d, Real t, const std::vector<Medium>& media) {
  Real depth = 0;
  for (const Medium& m : media) {
    Real a, b;
    if (chord(o, d, m.center, m.radius, double(t), a, b)) depth += Real(m.sigma_t) * (b - a);
  }
  return depth;
}

Real henyey_greenstein(Real cos_theta, Real g) {
  const Real denom = 1 + g * g - 2 * g * cos_theta;
  return (1 - g * g) / (4 * kPi * denom * std::sqrt(denom));
}

// The documented spot factor: saturate((cos a - cos outer) / max(cos inner - cos outer, 1e-4))^2.
Real cone(const LocalLight& l, Real cos_axis) {
  if (l.kind != LightKind::spot) return 1;
  const Real ci = std::cos(Real(l.inner_angle) * kPi / 180), co = std::cos(Real(l.outer_angle) * kPi / 180);
  const Real x = std::clamp<Real>((cos_axis - co) / std::max<Real>(ci - co, 1e-4L), 0, 1);
  return x * x;
}

}  // namespace

double transmittance(const glm::dvec3& origin, const glm::dvec3& dir, double t_end, const std::vector<Medium>& media) {
  return double(std::exp(-optical_depth(origin, dir, t_end, media)));
}

glm::dvec3 inscattered(const glm::dvec3& o, const glm::dvec3& d, double t_end, const std::vector<Medium>& media,
                       const std::vector<LocalLight>& lights, long panels) {
  std::vector<Real> cuts = {0, Real(t_end)};
  for (const Medium& m : media) {
    Real a, b;
    if (chord(o, d, m.center, m.radius, t_end, a, b)) cuts.insert(cuts.end(), {a, b});
  }
  for (const LocalLight& l : lights) {
    Real a, b;
    if (chord(o, d, glm::dvec3(l.position), l.range, t_end, a, b)) cuts.insert(cuts.end(), {a, b});
    const Real closest = Real(glm::dot(glm::dvec3(l.position) - o, d));
    if (closest > 0 && closest < Real(t_end)) cuts.push_back(closest);
  }
  std::sort(cuts.begin(), cuts.end());
  const auto integrand = [&](Real t, Real out[3]) {
    out[0] = out[1] = out[2] = 0;
    const glm::dvec3 p = o + d * double(t);
    const Real transmit = std::exp(-optical_depth(o, d, t, media));
    for (const LocalLight& l : lights) {
      const glm::dvec3 to_light = glm::dvec3(l.position) - p;
      const Real d2 = Real(glm::dot(to_light, to_light)), dist = std::sqrt(d2);
      if (!(dist < Real(l.range))) continue;
      const Real window = (1 - d2 / (Real(l.range) * l.range)) * (1 - d2 / (Real(l.range) * l.range));
      const Real cos_theta = dist > 0 ? Real(glm::dot(d, to_light)) / dist : 0;
      const glm::dvec3 axis = glm::normalize(glm::dvec3(l.direction));
      const Real cos_axis = dist > 0 ? -Real(glm::dot(to_light, axis)) / dist : 1;
      const Real falloff = Real(l.intensity) * window * cone(l, cos_axis) / (d2 + Real(l.radius) * l.radius);
      for (const Medium& m : media) {
        if (!(glm::length(p - m.center) < m.radius)) continue;
        const Real s = Real(m.sigma_t) * henyey_greenstein(cos_theta, m.g) * falloff * transmit;
        for (int c = 0; c < 3; ++c) out[c] += s * Real(m.albedo[c]) * Real(l.color[c]);
      }
    }
  };
  // Each piece's panels are graded geometrically toward both ends (from 1e-12 of its length to the
  // middle): a light's peak, 1 / radius^2 wide radius, sits at a cut and is resolved at any radius.
  Real sum[3] = {0, 0, 0};
  const long half_panels = std::max(1L, panels / 2);
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const Real a = cuts[k], b = cuts[k + 1];
    if (!(b > a)) continue;
    for (int side = 0; side < 2; ++side)
      for (long j = 0; j < half_panels; ++j) {
        // x in [0, 1/2] from the end: 0, then 1e-12 .. 1/2 log-spaced.
        const auto at = [&](long i) {
          return i == 0 ? Real(0) : 0.5L * std::pow(10.0L, -12.0L * Real(half_panels - i) / Real(half_panels - 1));
        };
        const Real x0 = at(j), x1 = at(j + 1);
        const Real lo = side == 0 ? a + (b - a) * x0 : b - (b - a) * x1;
        const Real hi = side == 0 ? a + (b - a) * x1 : b - (b - a) * x0;
        const Real mid = (lo + hi) / 2, half = (hi - lo) / 2;
        for (int q = 0; q < 8; ++q) {
          const Real x = q < 4 ? -kNode[q] : kNode[q - 4], w = kWeight[q < 4 ? q : q - 4];
          Real f[3];
          integrand(mid + half * x, f);
          for (int c = 0; c < 3; ++c) sum[c] += w * half * f[c];
        }
      }
  }
  return glm::dvec3(double(sum[0]), double(sum[1]), double(sum[2]));
}

}  // namespace fogcl::test::light_reference
