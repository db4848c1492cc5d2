// docs/library.md's fog-volume snippet: a volume set up as it says fogs the demo scene visibly
// (the largest pixel change >= 0.1) for every radius from 1 to 10, where the seed's defaults alone
// (tuned for volumes tens of units across: a 20-unit edge fade) barely show. The snippet's values
// are repeated here; DocsVolumeSnippet below checks that the page still holds them.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "fogcl/volume_scalar.h"
#include "volume_support.h"

namespace fogcl::test {
namespace {

// As docs/library.md#fog-volumes sets it up, for a radius.
FogVolume snippet_volume(float radius) {
  FogVolume volume;
  volume.center = {0.0f, 1.0f, 2.0f};
  volume.radius = radius;
  volume.density = 4.0f;
  volume.fade_edge = 0.25f * volume.radius;
  volume.proximity_fade = 1.0f;
  volume.tiling = volume.detail_tiling = glm::vec3(0.25f);
  volume.fog_color = volume.directional_fog_color = {0.9f, 0.55f, 0.3f, 1.0f};
  return volume;
}

struct Change {
  double max = 0;       // the largest change of a channel
  double visible = 0;   // the share of pixels with a channel changed by more than 0.05
};

Change change_of(const FogVolume& volume, const DemoFrame& frame) {
  VolumeScene scene;
  scene.volumes = {volume};
  scene.pose = pose_of(DemoView{});
  scene.light = demo_light();
  ColorImage out;
  apply_volumes_scalar(frame.color, frame.depth, out, frame.params, scene, VolumeSettings{});
  Change change;
  std::size_t visible = 0;
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x) {
      double pixel = 0;
      for (int c = 0; c < 3; ++c)
        pixel = std::max(pixel, double(std::fabs(out.pixel(x, y)[c] - frame.color.pixel(x, y)[c])));
      change.max = std::max(change.max, pixel);
      visible += pixel > 0.05;
    }
  change.visible = double(visible) / double(out.pixel_count());
  return change;
}

TEST(VolumeDefaults, TheDocumentedVolumeFogsTheDemoSceneVisibly) {
  const DemoFrame frame = render_demo_scene(160, 90);
  double weakest_snippet = INFINITY, strongest_defaults = 0;
  for (float radius = 1.0f; radius <= 10.0f; radius += 1.0f) {
    FogVolume defaults;
    defaults.center = snippet_volume(radius).center;
    defaults.radius = radius;
    const Change d = change_of(defaults, frame), s = change_of(snippet_volume(radius), frame);
    std::printf("radius %2.0f: largest pixel change %.4f with the seed's defaults, %.4f as documented "
                "(%.1f %% of the pixels change by more than 0.05)\n",
                radius, d.max, s.max, 100 * s.visible);
    EXPECT_GE(s.max, 0.1) << "radius " << radius;
    EXPECT_GT(s.visible, 0.0) << "radius " << radius;
    weakest_snippet = std::min(weakest_snippet, s.max);
    strongest_defaults = std::max(strongest_defaults, d.max);
  }
  std::printf("weakest documented volume %.4f; strongest defaults-only volume %.4f\n", weakest_snippet,
              strongest_defaults);
}

TEST(VolumeDefaults, DocsVolumeSnippetHoldsTheseValues) {
  std::ifstream f(std::string(FOGCL_SOURCE_DIR) + "/docs/library.md");
  ASSERT_TRUE(f) << "docs/library.md not found";
  std::stringstream text;
  text << f.rdbuf();
  for (const char* line : {"volume.center = {0.0f, 1.0f, 2.0f};", "volume.density = 4.0f;",
                           "volume.fog_color = volume.directional_fog_color = {0.9f, 0.55f, 0.3f, 1.0f};",
                           "volume.fade_edge = 0.25f * volume.radius;", "volume.proximity_fade = 1.0f;",
                           "volume.tiling = volume.detail_tiling = glm::vec3(0.25f);"})
    EXPECT_NE(text.str().find(line), std::string::npos) << "docs/library.md lacks: " << line;
}

}  // namespace
}  // namespace fogcl::test
