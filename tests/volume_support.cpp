#include "volume_support.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

namespace fogcl::test {

CameraPose pose_of(const DemoView& view) {
  CameraPose p;
  p.eye = view.eye;
  p.forward = view.target - view.eye;
  p.up = glm::vec3(0.0f, 1.0f, 0.0f);
  return p;
}

ShadowMap synthetic_shadow_map(bool reversed_z) {
  constexpr int kSize = 128;
  constexpr float kHalf = 15.0f, kCz = 4.0f, kTop = 10.0f, kBottom = -1.0f;
  ShadowMap m;
  glm::mat4& p = m.params.world_to_light_clip;
  p = glm::mat4(0.0f);
  p[0][0] = 1.0f / kHalf;              // clip x from world x
  p[2][1] = 1.0f / kHalf;              // clip y from world z
  p[3][1] = -kCz / kHalf;
  p[1][2] = -1.0f / (kTop - kBottom);  // depth 0 at the top, 1 at the bottom
  p[3][2] = kTop / (kTop - kBottom);
  p[3][3] = 1.0f;
  if (reversed_z) {
    p[1][2] = -p[1][2];
    p[3][2] = 1.0f - p[3][2];
  }
  m.params.reversed_z = reversed_z;
  m.depth = DepthImage(kSize, kSize);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const float wx = ((x + 0.5f) / kSize * 2 - 1) * kHalf, wz = (1 - (y + 0.5f) / kSize * 2) * kHalf + kCz;
      const float height = wx * wx + wz * wz < 9.0f ? 2.0f : 0.0f;
      const float d = (kTop - height) / (kTop - kBottom);
      m.depth.at(x, y) = reversed_z ? 1.0f - d : d;
    }
  return m;
}

VolumeTestScene volume_test_scene(int width, int height, ColorFormat format, bool reversed_z) {
  VolumeTestScene s;
  PerspectiveCamera camera;
  camera.reversed_z = reversed_z;
  camera.far_plane = 200.0f;
  const DemoView view;
  s.frame = render_demo_scene(width, height, camera, view, format);
  s.scene.pose = pose_of(view);
  s.scene.light.direction = glm::vec3(0.35f, 0.8f, -0.5f);
  s.scene.light.color = glm::vec3(1.0f, 0.96f, 0.9f);
  FogVolume around;  // the camera is inside
  around.center = glm::vec3(0.5f, 1.5f, -4.0f);
  around.radius = 5.0f;
  around.density = 0.6f;
  around.fade_edge = 2.0f;
  around.proximity_fade = 1.0f;
  around.tiling = glm::vec3(0.2f);
  around.detail_tiling = glm::vec3(0.5f);
  FogVolume behind = around;  // behind the (2.2, 1, -0.5) sphere
  behind.center = glm::vec3(3.0f, 1.5f, 3.0f);
  behind.radius = 3.0f;
  behind.density = 1.0f;
  behind.fog_color = glm::vec4(0.9f, 0.8f, 0.7f, 1.0f);
  FogVolume ground = around;  // crossing the ground
  ground.center = glm::vec3(-5.0f, 0.0f, 12.0f);
  ground.radius = 6.0f;
  ground.max_y = 3.0f;
  ground.fade_y = 1.0f;
  ground.density = 0.8f;
  ground.fog_color = glm::vec4(0.7f, 0.8f, 1.0f, 1.0f);
  s.scene.volumes = {around, behind, ground};
  return s;
}

VolumeErrorStats compare_volumes(const ColorImage& got, const VolumeResult<double>& ref, double tolerance) {
  VolumeErrorStats s;
  std::vector<double> per_pixel;
  per_pixel.reserve(std::size_t(ref.width) * ref.height);
  for (int y = 0; y < ref.height; ++y)
    for (int x = 0; x < ref.width; ++x) {
      const std::size_t i = std::size_t(y) * ref.width + x;
      const glm::vec4 c = got.pixel(x, y);
      double worst = 0;
      for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(c[k]) && std::isfinite(ref.rgba[4 * i + k])) ++s.nonfinite;
        const double d = std::fabs(double(c[k]) - ref.rgba[4 * i + k]);
        worst = std::isnan(d) ? INFINITY : std::max(worst, d);
      }
      per_pixel.push_back(worst);
      s.max_abs = std::max(s.max_abs, worst);
      if (worst > tolerance) ++s.over;
      if (ref.coverage[i] > 0) ++s.fogged;
    }
  s.pixels = per_pixel.size();
  std::sort(per_pixel.begin(), per_pixel.end());
  s.p999 = per_pixel[std::min(per_pixel.size() - 1, std::size_t(double(per_pixel.size()) * 0.999))];
  return s;
}

std::string describe(const VolumeErrorStats& s) {
  std::ostringstream o;
  o << "max " << s.max_abs << ", p99.9 " << s.p999 << ", " << s.over << " of " << s.pixels
    << " pixels over tolerance, " << s.fogged << " fogged, " << s.nonfinite << " non-finite";
  return o.str();
}

}  // namespace fogcl::test
