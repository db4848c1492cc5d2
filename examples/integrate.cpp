// fogcl inside a renderer's own OpenCL pipeline (docs/library.md, "Integrating fogcl into a renderer"):
//  - the renderer owns the context, the queue and the frame's buffers, and configures CLHPP its
//    own way (here: OpenCL 3.0 target, exceptions off; see CMakeLists.txt);
//  - its own kernel renders color (RGBA16F) and raw depth into those buffers;
//  - fogcl's fog volumes and then its deferred fog run in place on them, chained by events, the
//    two passes sharing one program cache: no host round trip;
//  - one read-back at the end.
// Then, as a check (not part of the pattern), the same frame goes through fogcl's convenience API
// (host images) and the two results must be equal bit for bit. Exit status 0 when they are.
//
// Usage: integrate [WIDTH HEIGHT]. The device is FOGCL_DEVICE's choice (default: PoCL's CPU).
#include <CL/opencl.hpp>
#include <fogcl/fogcl.h>
#include <fogcl/version.h>
#include <fogcl/volume_pass.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

// The renderer's own scene: a ground plane and two spheres, ray cast per pixel along the same
// corner rays fogcl uses, written as RGBA16F color and conventional-Z raw depth (sky: 1).
const char* kSceneSource = R"CL(
float hit_sphere(float3 dir, float3 centre, float radius) {
  float b = dot(dir, centre), c = dot(centre, centre) - radius * radius, h = b * b - c;
  return h < 0.0f ? INFINITY : b - sqrt(h);
}
__kernel void render_scene(__global half* color, __global float* depth, int width, int height,
                           float4 bl, float4 br, float4 tl, float4 tr, float2 zbuffer_xy, float far_plane) {
  int x = get_global_id(0), y = get_global_id(1);
  if (x >= width || y >= height) return;
  float u = (x + 0.5f) / width, v = 1.0f - (y + 0.5f) / height;
  float3 ray = mix(mix(bl.xyz, br.xyz, u), mix(tl.xyz, tr.xyz, u), v);  /* view space, z = far */
  float3 dir = normalize(ray);
  const float3 c1 = (float3)(-1.5f, 0.0f, 9.0f), c2 = (float3)(4.0f, 1.0f, 30.0f);
  float t1 = hit_sphere(dir, c1, 1.5f), t2 = hit_sphere(dir, c2, 2.5f);
  float tg = dir.y < -1e-6f ? -1.5f / dir.y : INFINITY;  /* ground: y = -1.5 */
  float t = fmin(fmin(t1, t2), tg);
  float3 albedo = (float3)(0.3f, 0.5f, 0.9f), n = (float3)(0.0f, 1.0f, 0.0f);
  if (t == t1) { albedo = (float3)(0.9f, 0.3f, 0.2f); n = normalize(dir * t - c1); }
  else if (t == t2) { albedo = (float3)(0.8f, 0.8f, 0.7f); n = normalize(dir * t - c2); }
  else if (t == tg) { albedo = (float3)(0.5f, 0.55f, 0.45f); }
  float eye = t * dir.z;  /* eye depth along the view axis */
  bool sky = !(eye < far_plane);
  float lambert = sky ? 1.0f : 0.25f + 0.75f * fmax(dot(n, normalize((float3)(0.4f, 0.8f, -0.45f))), 0.0f);
  size_t i = (size_t)y * width + x;
  vstore_half4((float4)(albedo * lambert, 1.0f), i, color);
  /* Raw depth from Linear01Depth = eye / far = 1 / (x raw + y). */
  depth[i] = sky ? 1.0f : clamp((far_plane / eye - zbuffer_xy.y) / zbuffer_xy.x, 0.0f, 1.0f);
}
)CL";

bool ok(cl_int err, const char* what) {
  if (err != CL_SUCCESS) std::fprintf(stderr, "integrate: %s failed: %s (%d)\n", what, fogcl::cl_error_name(err), err);
  return err == CL_SUCCESS;
}

// What a Unity renderer would hand over for a 60 degree camera: _ZBufferParams, _ProjectionParams
// and Camera.CalculateFrustumCorners' rays, in Unity's order (bottom-left, top-left, top-right,
// bottom-right). fogcl checks them against each other (fogcl::camera_params_from_unity).
fogcl::UnityCameraConstants unity_camera(int width, int height) {
  const float near_plane = 0.3f, far_plane = 1000.0f, fov_y = 60.0f;
  const float half_h = std::tan(fov_y * 0.5f * 3.14159265f / 180.0f) * far_plane;
  const float half_w = half_h * float(width) / float(height);
  fogcl::UnityCameraConstants u;
  u.zbuffer_params = {1.0f - far_plane / near_plane, far_plane / near_plane,
                      (1.0f - far_plane / near_plane) / far_plane, (far_plane / near_plane) / far_plane};
  u.projection_params = {1.0f, near_plane, far_plane, 1.0f / far_plane};
  u.frustum_corners = {{{-half_w, -half_h, far_plane}, {-half_w, half_h, far_plane},
                        {half_w, half_h, far_plane}, {half_w, -half_h, far_plane}}};
  return u;
}

cl_float4 f4(const glm::vec3& v) { return cl_float4{{v.x, v.y, v.z, 0.0f}}; }

// Fog volumes in the renderer's world, which is its view space here (camera at the origin looking
// along +z): a noisy bank around the red sphere and a thin haze over the ground.
fogcl::VolumeScene fog_volumes() {
  fogcl::VolumeScene scene;  // pose: eye (0, 0, 0), forward +z, up +y
  scene.light.direction = {0.4f, 0.8f, -0.45f};
  fogcl::FogVolume bank;
  bank.center = {-1.0f, 0.5f, 10.0f};
  bank.radius = 4.0f;
  bank.density = 3.0f;
  bank.fade_edge = 1.5f;
  bank.proximity_fade = 0.0f;
  bank.tiling = glm::vec3(0.2f);
  bank.detail_tiling = glm::vec3(0.6f);
  bank.fog_color = {0.85f, 0.9f, 1.0f, 1.0f};
  fogcl::FogVolume haze = bank;
  haze.center = {3.0f, -2.5f, 25.0f};
  haze.radius = 9.0f;
  haze.max_y = 0.0f;
  haze.fade_y = 1.5f;
  haze.density = 1.5f;
  scene.volumes = {bank, haze};
  return scene;
}

// The renderer's scene pass: enqueued, returns its event (no wait).
bool render_scene(cl::CommandQueue& queue, cl::Kernel& kernel, const cl::Buffer& color, const cl::Buffer& depth,
                  int width, int height, const fogcl::CameraParams& camera, cl::Event* done) {
  const auto& c = camera.frustum_corners;
  cl_int err = CL_SUCCESS;
  err |= kernel.setArg(0, color);
  err |= kernel.setArg(1, depth);
  err |= kernel.setArg(2, cl_int(width));
  err |= kernel.setArg(3, cl_int(height));
  err |= kernel.setArg(4, f4(c[fogcl::kBottomLeft]));
  err |= kernel.setArg(5, f4(c[fogcl::kBottomRight]));
  err |= kernel.setArg(6, f4(c[fogcl::kTopLeft]));
  err |= kernel.setArg(7, f4(c[fogcl::kTopRight]));
  err |= kernel.setArg(8, cl_float2{{camera.zbuffer_params.x, camera.zbuffer_params.y}});
  err |= kernel.setArg(9, camera.far_plane());
  if (!ok(err, "clSetKernelArg(render_scene)")) return false;
  return ok(queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(width, height), cl::NullRange, nullptr, done),
            "clEnqueueNDRangeKernel(render_scene)");
}

}  // namespace

int main(int argc, char** argv) try {
  const int width = argc > 2 ? std::atoi(argv[1]) : 640, height = argc > 2 ? std::atoi(argv[2]) : 360;
  std::printf("fogcl %s (headers %s), %dx%d RGBA16F, in place\n", fogcl::library_version(), FOGCL_VERSION_STRING,
              width, height);

  // ---- The renderer's own OpenCL objects (CLHPP, exceptions off) ----
  cl_int err = CL_SUCCESS;
  const cl::Device device(fogcl::find_device(fogcl::resolve_device_choice()));
  const cl::Context context(device, nullptr, nullptr, nullptr, &err);
  if (!ok(err, "clCreateContext")) return 1;
  cl::CommandQueue queue(context, device, cl::QueueProperties::None, &err);
  if (!ok(err, "clCreateCommandQueue")) return 1;
  cl::Program scene_program(context, std::string(kSceneSource), false, &err);
  if (!ok(err, "clCreateProgramWithSource") || !ok(scene_program.build(std::vector<cl::Device>{device}), "clBuildProgram"))
    return 1;
  cl::Kernel scene_kernel(scene_program, "render_scene", &err);
  if (!ok(err, "clCreateKernel")) return 1;
  const std::size_t pixels = std::size_t(width) * std::size_t(height);
  const cl::Buffer color(context, CL_MEM_READ_WRITE, fogcl::color_buffer_bytes(width, height, fogcl::ColorFormat::rgba16f));
  const cl::Buffer depth(context, CL_MEM_READ_WRITE, fogcl::depth_buffer_bytes(width, height));
  const fogcl::CameraParams camera = fogcl::camera_params_from_unity(unity_camera(width, height));
  fogcl::FogSettings settings;
  settings.mode = fogcl::FogMode::exp2;
  settings.density = 0.02f;
  settings.color = {0.6f, 0.65f, 0.7f};
  settings.metric = fogcl::FogMetric::distance;
  const fogcl::VolumeScene volumes = fog_volumes();
  const fogcl::VolumeSettings volume_settings;  // stylized, 50 steps, half resolution

  // [integration-core]
  // Load time: the passes share one program cache; programs are built now (enqueue never builds).
  fogcl::FogPass fog(context(), device());
  fogcl::VolumePass volume_pass(context(), device(), fog.program_cache());
  fog.prepare(settings, camera, fogcl::ColorFormat::rgba16f);
  volume_pass.prepare(camera, volumes, volume_settings, fogcl::ColorFormat::rgba16f);

  // Each frame: the scene writes color + depth; the volumes, then the fog, run in place after it.
  cl::Event scene_done;
  if (!render_scene(queue, scene_kernel, color, depth, width, height, camera, &scene_done)) return 1;
  fogcl::FrameBuffers frame;
  frame.color_in = frame.color_out = color();  // in place
  frame.depth = depth();
  frame.width = width;
  frame.height = height;
  frame.format = fogcl::ColorFormat::rgba16f;
  cl_event volumes_done = volume_pass.enqueue(queue(), frame, camera, volumes, volume_settings, nullptr, {scene_done()});
  cl_event last = fog.enqueue(queue(), frame, camera, settings, {volumes_done});
  clReleaseEvent(volumes_done);  // each enqueue's event is ours to release
  std::vector<std::uint16_t> result(4 * pixels);
  err = clEnqueueReadBuffer(queue(), color(), CL_TRUE, 0, result.size() * 2, result.data(), 1, &last, nullptr);
  clReleaseEvent(last);
  // [integration-core-end]
  if (!ok(err, "clEnqueueReadBuffer")) return 1;

  // ---- Check: the convenience API on the same device and the same scene ----
  const cl::Buffer color2(context, CL_MEM_READ_WRITE, fogcl::color_buffer_bytes(width, height, fogcl::ColorFormat::rgba16f));
  const cl::Buffer depth2(context, CL_MEM_READ_WRITE, fogcl::depth_buffer_bytes(width, height));
  cl::Event again;
  if (!render_scene(queue, scene_kernel, color2, depth2, width, height, camera, &again)) return 1;
  fogcl::ColorImage image(width, height, fogcl::ColorFormat::rgba16f);
  fogcl::DepthImage depth_image(width, height);
  if (!ok(queue.enqueueReadBuffer(color2, CL_TRUE, 0, image.size_bytes(), image.data()), "read color") ||
      !ok(queue.enqueueReadBuffer(depth2, CL_TRUE, 0, depth_image.size_bytes(), depth_image.data()), "read depth"))
    return 1;
  const fogcl::ColorImage unfogged = image;
  const fogcl::Runtime runtime(context(), device(), queue());
  fogcl::VolumePass(runtime).apply(image, depth_image, image, camera, volumes, volume_settings);
  fogcl::FogPass(runtime).apply(image, depth_image, image, camera, settings);

  // The read-back as it lies in the renderer's memory: a view, no copy into an image.
  const fogcl::ConstColorView integrated(result.data(), width, height, fogcl::ColorFormat::rgba16f);
  std::size_t differ = 0, fogged = 0;
  double worst = 0.0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const glm::vec4 a = integrated.pixel(x, y), b = image.pixel(x, y), before = unfogged.pixel(x, y);
      for (int ch = 0; ch < 4; ++ch) {
        const std::size_t i = 4 * (std::size_t(y) * width + x) + ch;
        differ += result[i] != image.rgba16f()[i];
        fogged += b[ch] != before[ch];
        worst = std::fmax(worst, std::fabs(double(a[ch]) - double(b[ch])));
      }
    }
  std::printf("device: %s\n", fogcl::Runtime(context(), device(), queue()).description().c_str());
  std::printf("fog volumes + fog changed %zu of %zu half values (the scene is fogged)\n", fogged, 4 * pixels);
  std::printf("integration vs convenience API: max |difference| = %g, %zu of %zu half values differ\n", worst, differ,
              4 * pixels);
  if (fogged == 0) {
    std::fprintf(stderr, "integrate: the fog changed nothing: the check would prove nothing\n");
    return 1;
  }
  return differ == 0 ? 0 : 1;
} catch (const fogcl::Error& e) {
  std::fprintf(stderr, "integrate: %s\n", e.what());
  return 1;
}
