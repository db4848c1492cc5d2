// The demo scene's fog volumes (fogcl/demo_scene.h): shared by `fogcl demo`, the benchmarks and
// the tests, so every figure the project prints is of the same scene.
#include "fogcl/demo_scene.h"

namespace fogcl {

std::vector<FogVolume> demo_fog_volumes(VolumeIntegrator integrator) {
  // Noise tiling 0.1-0.25 per world unit: one noise period spans 4-10 units, a few billows per
  // volume in this ~50-unit scene (the seed's 0.015 suits its 100s-of-units scenes). Fades of a
  // few units (the seed's 20 / 10 would thin these 3-12 unit spheres to nothing), and a cut-off
  // that leaves gaps between the billows. Values chosen by looking at the PNGs.
  FogVolume around;  // the camera (0, 1.6, -6) is inside: a light haze with gaps
  around.center = glm::vec3(0.5f, 1.5f, -4.0f);
  around.radius = 6.0f;
  around.density = 1.2f;
  around.fade_edge = 1.5f;
  around.proximity_fade = 0.5f;
  around.fog_cutoff = 0.5f;
  around.tiling = glm::vec3(0.2f);
  around.detail_tiling = glm::vec3(0.6f);
  around.detail_strength = 0.4f;
  around.speed = glm::vec3(0.6f, -0.1f, 0.3f);
  around.fog_color = glm::vec4(0.9f, 0.92f, 1.0f, 1.0f);

  FogVolume behind = around;  // behind the (2.2, 1, -0.5) sphere, seen past its silhouette
  behind.center = glm::vec3(3.2f, 1.8f, 3.5f);
  behind.radius = 3.5f;
  behind.density = 4.0f;
  behind.fade_edge = 1.0f;
  behind.fog_cutoff = 0.35f;
  behind.tiling = glm::vec3(0.25f);
  behind.detail_tiling = glm::vec3(0.7f);
  behind.fog_color = glm::vec4(1.0f, 0.7f, 0.45f, 1.0f);

  FogVolume ground = around;  // crossing the ground, thinning out with height
  ground.center = glm::vec3(-5.0f, 0.0f, 12.0f);
  ground.radius = 7.0f;
  ground.max_y = 5.0f;
  ground.fade_y = 3.0f;
  ground.density = 6.0f;
  ground.fog_cutoff = 0.25f;
  ground.tiling = glm::vec3(0.15f);
  ground.detail_tiling = glm::vec3(0.5f);
  ground.fog_color = glm::vec4(0.55f, 0.7f, 1.0f, 1.0f);

  FogVolume bank = around;  // a wide bank around the far spheres
  bank.center = glm::vec3(4.0f, 2.0f, 34.0f);
  bank.radius = 12.0f;
  bank.max_y = 7.0f;
  bank.fade_y = 4.0f;
  bank.fade_edge = 3.0f;
  bank.proximity_fade = 1.0f;
  bank.density = 6.0f;
  bank.fog_cutoff = 0.3f;
  bank.tiling = glm::vec3(0.1f);
  bank.detail_tiling = glm::vec3(0.3f);
  bank.fog_color = glm::vec4(0.85f, 0.9f, 1.0f, 1.0f);

  std::vector<FogVolume> volumes{around, behind, ground, bank};
  if (integrator == VolumeIntegrator::physical)
    for (FogVolume& v : volumes) {
      // density is then sigma_t [1/unit]: 0.15 x the stylized alpha scale keeps the thick parts
      // translucent; a sky-coloured ambient (the seed's 0.1 x light leaves thick fog dark grey)
      // and mild forward scattering.
      v.density *= 0.15f;
      v.ambient = glm::vec3(0.6f, 0.65f, 0.75f);
      v.anisotropy = 0.2f;
    }
  return volumes;
}


FogSettings demo_shaft_fog() {
  // A ground haze a few units deep (thins by e per 1/0.3 units of height), thick enough that the
  // spheres' shadows cut dark shafts out of the sun's glow. Values chosen by looking at the PNGs.
  FogSettings f;
  f.mode = FogMode::height;
  f.color = glm::vec3(0.12f, 0.15f, 0.2f);
  f.density = 0.06f;
  f.height.falloff = 0.2f;
  f.height.cutoff = 100.0f;
  f.height.base_height = 0.0f;
  f.fog_skybox = true;
  SunLobe sun;
  sun.direction = demo_low_sun().direction;
  sun.color = glm::vec3(1.8f, 1.45f, 0.95f);
  sun.exponent = 16.0f;
  f.height.sun = sun;
  return f;
}


std::vector<LocalLight> demo_street_lamps() {
  // Three street lamps on 4.5-unit poles along the left of the view and one on the right, spots
  // pointing down with a warm sodium-like color, and two small lanterns (point lights) near the
  // ground. Values chosen by looking at the PNGs.
  std::vector<LocalLight> lamps;
  const auto street = [&](glm::vec3 at) {
    LocalLight l;
    l.kind = LightKind::spot;
    l.position = at;
    l.color = glm::vec3(1.0f, 0.72f, 0.4f);
    l.intensity = 50.0f;
    l.range = 14.0f;
    l.radius = 0.15f;
    l.direction = glm::vec3(0.0f, -1.0f, 0.0f);
    l.inner_angle = 20.0f;
    l.outer_angle = 38.0f;
    lamps.push_back(l);
  };
  street(glm::vec3(-2.6f, 4.5f, 1.0f));
  street(glm::vec3(-2.6f, 4.5f, 10.0f));
  street(glm::vec3(-2.6f, 4.5f, 19.0f));
  street(glm::vec3(4.0f, 4.5f, 6.0f));
  const auto lantern = [&](glm::vec3 at, glm::vec3 color, float intensity) {
    LocalLight l;
    l.position = at;
    l.color = color;
    l.intensity = intensity;
    l.range = 8.0f;
    l.radius = 0.1f;
    lamps.push_back(l);
  };
  lantern(glm::vec3(0.9f, 0.7f, 3.0f), glm::vec3(0.55f, 0.75f, 1.0f), 8.0f);
  lantern(glm::vec3(1.5f, 1.0f, 14.0f), glm::vec3(1.0f, 0.45f, 0.25f), 20.0f);
  return lamps;
}

FogSettings demo_night_fog() {
  // A ground mist at night: the ambient (fog color) is a dim blue sky light, no sun lobe; the
  // lamps' light is what glows in it.
  FogSettings f;
  f.mode = FogMode::height;
  f.color = glm::vec3(0.015f, 0.02f, 0.035f);
  f.density = 0.12f;
  f.height.falloff = 0.25f;
  f.height.cutoff = 60.0f;
  f.fog_skybox = true;
  return f;
}


DemoFrame demo_night_frame(int width, int height) {
  DemoFrame frame = render_demo_scene(width, height);
  for (int y = 0; y < frame.color.height(); ++y)
    for (int x = 0; x < frame.color.width(); ++x) {
      const glm::vec4 c = frame.color.pixel(x, y);
      frame.color.set_pixel(x, y, glm::vec4(glm::vec3(c) * 0.04f, c.a));
    }
  return frame;
}

}  // namespace fogcl
