// Fog on a frame of the renderer's own (docs/library.md, "From your own renderer"): its color is
// linear RGBA float and its depth raw Z, each in a buffer of its own, row 0 at the top. Exit
// status 0 when the fog changed the frame and the OpenCL pass agrees with the scalar path.
#include <fogcl/fogcl.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

int main() try {
  // The renderer's camera and frame: a ground plane 1.5 units below the eye, under a blue sky.
  const int width = 320, height = 180;
  const float near_plane = 0.3f, far_plane = 500.0f, fov_y_deg = 60.0f, aspect = float(width) / float(height);
  const fogcl::PerspectiveCamera lens{fov_y_deg, aspect, near_plane, far_plane, /*reversed_z=*/false};
  const fogcl::CameraParams camera = fogcl::make_camera_params(lens);
  std::vector<float> rgba(4 * std::size_t(width) * height), depth_buffer(std::size_t(width) * height);
  const float tan_half = std::tan(fov_y_deg * 0.5f * 3.14159265f / 180.0f);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const float u = (x + 0.5f) / width, v = 1.0f - (y + 0.5f) / height;  // fogcl's pixel centres
      const float ray_y = (2.0f * v - 1.0f) * tan_half;                      // at eye depth 1
      const float eye = ray_y < 0.0f ? -1.5f / ray_y : INFINITY;             // the ground's eye depth
      const bool sky = !(eye < far_plane);
      float* p = &rgba[4 * (std::size_t(y) * width + x)];
      p[0] = sky ? 0.3f : 0.35f + 0.3f * u, p[1] = sky ? 0.5f : 0.4f, p[2] = sky ? 0.9f : 0.3f, p[3] = 1.0f;
      depth_buffer[std::size_t(y) * width + x] = float(fogcl::raw_from_eye_depth(eye, camera));  // sky: 1
    }

  fogcl::FogSettings fog;  // exp2 with Unity's defaults
  fog.density = 0.03f;
  fog.color = {0.6f, 0.65f, 0.7f};
  fog.metric = fogcl::FogMetric::distance;  // along the ray, not the view axis

  // The frame in fogcl's images (a copy), fogged on the OpenCL device, read back into the buffer.
  fogcl::ColorImage color(width, height, fogcl::ColorFormat::rgba32f), out(width, height);
  fogcl::DepthImage depth(width, height);
  std::memcpy(color.data(), rgba.data(), color.size_bytes());
  std::memcpy(depth.data(), depth_buffer.data(), depth.size_bytes());
  const fogcl::Runtime runtime;  // FOGCL_DEVICE's choice, or PoCL's CPU device
  fogcl::FogPass pass(runtime);  // builds its kernel on the first apply
  pass.apply(color, depth, out, camera, fog);
  std::memcpy(rgba.data(), out.data(), out.size_bytes());

  // The same frame on the scalar path (no OpenCL): the two agree to float rounding.
  fogcl::ColorImage scalar(width, height);
  fogcl::apply_fog_scalar(color, depth, scalar, camera, fog);
  double worst = 0.0;
  std::size_t changed = 0;
  for (std::size_t i = 0; i < rgba.size(); ++i) {
    worst = std::fmax(worst, std::fabs(double(rgba[i]) - double(scalar.rgba32f()[i])));
    changed += rgba[i] != color.rgba32f()[i];
  }
  std::printf("%s: fog changed %zu of %zu values; OpenCL vs scalar max |difference| %.3g\n",
              runtime.description().c_str(), changed, rgba.size(), worst);
  return changed > 0 && worst <= 1e-5 ? 0 : 1;
} catch (const fogcl::Error& e) {  // every fogcl failure: a message naming the value and the rule
  std::fprintf(stderr, "own_renderer: %s\n", e.what());
  return 1;
}
