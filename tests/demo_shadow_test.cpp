// The demo scene's shadow map (render_demo_shadow_map): its matrix follows ShadowMapParams'
// convention and its texels agree with rays cast here, independently, through the inverse matrix
// against the spheres the header documents; ground points in a sphere's shadow are shadowed and
// points in the open are lit, by the comparison the volumetric pass makes.
#include <cmath>
#include <cstdio>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/matrix.hpp>

#include "fogcl/demo_scene.h"
#include "test_support.h"

namespace fogcl::test {
namespace {

// The scene of fogcl/demo_scene.h's comment: centre and radius of each sphere, the ground y = 0.
const glm::dvec4 kSpheres[] = {{-0.9, 0.5, -3.5, 0.5}, {2.2, 1, -0.5, 1}, {-3.8, 1.5, 7, 1.5}, {-12, 2, 16, 2},
                               {-3, 3, 27, 3},         {5, 4, 42, 4},     {34, 5, 56, 5}};

// First hit t >= 0 of o + t d with the spheres and the ground, +inf when none.
double cast(const glm::dvec3& o, const glm::dvec3& d) {
  double best = std::numeric_limits<double>::infinity();
  for (const glm::dvec4& s : kSpheres) {
    const glm::dvec3 oc = o - glm::dvec3(s);
    const double b = glm::dot(oc, d), c = glm::dot(oc, oc) - s.w * s.w, a = glm::dot(d, d);
    const double disc = b * b - a * c;
    if (disc < 0) continue;
    const double t = (-b - std::sqrt(disc)) / a;
    if (t >= 0) best = std::min(best, t);
  }
  if (o.y < 0) return 0.0;  // under the ground: it is solid
  if (d.y < 0) best = std::min(best, -o.y / d.y);
  return best;
}

struct Projected {
  int x, y;     // texel
  double z;     // clip z / w
  bool inside;  // on the map
};
Projected project(const ShadowMap& m, const glm::dvec3& p) {
  const glm::dvec4 c = glm::dmat4(m.params.world_to_light_clip) * glm::dvec4(p, 1.0);
  const double u = c.x / c.w * 0.5 + 0.5, v = c.y / c.w * 0.5 + 0.5;  // v = 0 at the bottom row
  Projected r{int(std::floor(u * m.depth.width())), int(std::floor((1.0 - v) * m.depth.height())), c.z / c.w, false};
  r.inside = u >= 0 && u < 1 && v >= 0 && v < 1;
  return r;
}
bool lit(const ShadowMap& m, const glm::dvec3& p) {  // the volumetric pass's test (conventional Z)
  const Projected q = project(m, p);
  return !q.inside || !(q.z > double(m.depth.at(q.x, q.y)) + double(m.params.bias));
}

TEST(DemoShadowMap, TexelsMatchRaysCastThroughTheInverseMatrix) {
  const ShadowMap m = render_demo_shadow_map(256, 192);
  ASSERT_EQ(m.depth.width(), 256);
  ASSERT_EQ(m.depth.height(), 192);
  EXPECT_FALSE(m.params.reversed_z);
  validate(m.params);
  const glm::dmat4 inv = glm::inverse(glm::dmat4(m.params.world_to_light_clip));
  double worst = 0;
  int far_texels = 0;
  for (int y = 0; y < m.depth.height(); y += 7)
    for (int x = 0; x < m.depth.width(); x += 5) {
      const double cx = (x + 0.5) / m.depth.width() * 2 - 1, cy = (1 - (y + 0.5) / m.depth.height()) * 2 - 1;
      const glm::dvec4 a = inv * glm::dvec4(cx, cy, 0, 1), b = inv * glm::dvec4(cx, cy, 1, 1);
      const glm::dvec3 o = glm::dvec3(a) / a.w, e = glm::dvec3(b) / b.w;
      const double t = cast(o, e - o);  // t in [0, 1] is the depth (linear along the ray)
      const double want = t <= 1 ? t : 1.0;
      far_texels += want == 1.0;
      worst = std::max(worst, std::fabs(double(m.depth.at(x, y)) - want));
    }
  std::printf("[ measured ] shadow map vs rays through the inverse matrix: max |depth diff| %.3g, %d far texels\n",
              worst, far_texels);
  EXPECT_LE(worst, 1e-5);
  // The region lies inside the light's view volume (far texels are corners of the map outside it).
  const DemoShadowRegion region;
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 p((c & 1) ? region.max.x : region.min.x, (c & 2) ? region.max.y : region.min.y,
                       (c & 4) ? region.max.z : region.min.z);
    const Projected q = project(m, p);
    EXPECT_TRUE(q.inside && q.z > 0 && q.z < 1) << "region corner " << c << ": z " << q.z;
  }
}

TEST(DemoShadowMap, GroundInASpheresShadowIsShadowedAndTheOpenIsLit) {
  const ShadowMap m = render_demo_shadow_map();
  const glm::dvec3 to_light = glm::normalize(glm::dvec3(demo_light().direction));
  EXPECT_LT(glm::length(to_light - glm::normalize(glm::dvec3(0.35, 0.8, -0.5))), 1e-6);
  int shadowed = 0, lit_open = 0, tested_shadow = 0, tested_open = 0;
  for (const glm::dvec4& s : kSpheres) {
    const glm::dvec3 c(s);
    const glm::dvec3 ground = c - to_light * (c.y / to_light.y);  // under the centre, seen from the light
    if (!project(m, ground).inside) continue;
    ++tested_shadow;
    shadowed += !lit(m, ground);
    // The sphere's point nearest the light is lit, and the map holds its depth there.
    const glm::dvec3 top = c + to_light * s.w;
    const Projected q = project(m, top);
    EXPECT_TRUE(lit(m, top)) << "sphere at " << c.x << ", " << c.z;
    EXPECT_NEAR(double(m.depth.at(q.x, q.y)), q.z, 2e-4) << "sphere at " << c.x << ", " << c.z;
  }
  for (const glm::dvec3& p : {glm::dvec3(0, 0, -10), glm::dvec3(10, 0, 20), glm::dvec3(-20, 0, 40), glm::dvec3(6, 0, 0),
                              glm::dvec3(0, 4, 0), glm::dvec3(-5, 1, 12)}) {
    ASSERT_TRUE(std::isinf(cast(p + to_light * 1e-6, to_light))) << "test point in shadow: fix the test";
    ++tested_open;
    lit_open += lit(m, p);
  }
  std::printf("[ measured ] ground under %d of %d spheres shadowed; %d of %d open points lit\n", shadowed,
              tested_shadow, lit_open, tested_open);
  EXPECT_EQ(tested_shadow, 7);
  EXPECT_EQ(shadowed, tested_shadow);
  EXPECT_EQ(lit_open, tested_open);
}

}  // namespace
}  // namespace fogcl::test
