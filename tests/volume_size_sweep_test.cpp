// The march and the composite over many frame sizes, for both integrators at full, half and
// quarter resolution: every width 1..400 at heights 1, 3, 90 and 180 (every row count modulo 4),
// and the frame sizes of common formats. Each launch's work-group is the host's choice
// (src/runtime/work_groups.h) and its global size is rounded up to whole groups, so the sizes
// exercise the kernels' range guards and row tails; a work-group too large for the device crashed
// PoCL here (320x180 at full resolution, physical: PoCL's own choice of 3600 work-items). Every
// frame must match the scalar double path within the budget of tests/volume_pass_test.cpp. One or
// two march steps and two volumes keep the sweep short (timed, printed).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "runtime/work_groups.h"
#include "volume/volume_formulas.h"
#include "volume/volume_params.h"
#include "volume_composite_cl.h"
#include "volume_march_cl.h"
#include "volume_support.h"

namespace fogcl::test {
namespace {

VolumePass& sweep_pass() {
  static VolumePass pass(*runtime());
  return pass;
}

const char* resolution_name(int divisor) { return divisor == 1 ? "full" : divisor == 2 ? "half" : "quarter"; }

// The test scene without the volume around the camera: the two others cover part of the frame,
// so the march meets rays that enter a volume and rays that miss both.
VolumeTestScene sweep_scene(int width, int height) {
  VolumeTestScene t = volume_test_scene(width, height);
  t.scene.volumes.erase(t.scene.volumes.begin());
  t.scene.frame_index = unsigned(width * 7 + height);
  return t;
}

// One resolution's tally over the frames of a sweep.
struct Tally {
  int frames = 0;
  std::size_t pixels = 0, fogged = 0, over = 0;
  double worst = 0;
  std::string worst_at;
};

// The pass against the scalar double path: RGB within `tolerance` but for one pixel in 1000 (a
// march sample on the other side of a volume's edge in float), every output finite. Returns
// false (and fails the test) otherwise.
bool check_frame(const VolumeTestScene& t, VolumeIntegrator integrator, int divisor, int steps, bool noise,
                 Tally& tally) {
  constexpr double kTolerance = 2e-4;
  VolumeScene scene = t.scene;
  for (FogVolume& v : scene.volumes) v.noise = noise;
  VolumeSettings settings;
  settings.integrator = integrator;
  settings.resolution_divisor = divisor;
  settings.steps = steps;
  ColorImage out;
  sweep_pass().apply(t.frame.color, t.frame.depth, out, t.frame.params, scene, settings);
  const VolumeResult<double> ref =
      volumes_scalar<double>(t.frame.color, t.frame.depth, t.frame.params, scene, settings);
  const std::size_t pixels = std::size_t(out.width()) * std::size_t(out.height());
  const float* got = out.rgba32f();
  std::size_t over = 0, nonfinite = 0, fogged = 0;
  double worst = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    double d = 0;
    for (int k = 0; k < 3; ++k) {
      const float g = got[4 * i + k];
      nonfinite += !std::isfinite(g);
      d = std::max(d, std::isfinite(g) ? std::fabs(double(g) - ref.rgba[4 * i + k]) : INFINITY);
    }
    worst = std::max(worst, d);
    over += d > kTolerance;
    fogged += ref.coverage[i] > 0;
  }
  const std::string at = std::to_string(out.width()) + "x" + std::to_string(out.height());
  ++tally.frames;
  tally.pixels += pixels;
  tally.fogged += fogged;
  tally.over += over;
  if (worst >= tally.worst) tally.worst = worst, tally.worst_at = at;
  const bool ok = nonfinite == 0 && over <= pixels / 1000;
  EXPECT_TRUE(ok) << to_string(integrator) << " " << resolution_name(divisor) << " " << at << ": max " << worst
                  << ", " << over << " of " << pixels << " pixels over " << kTolerance << ", " << nonfinite
                  << " non-finite";
  return ok;
}

constexpr int kDivisors[] = {1, 2, 4};

void print(const char* sweep, VolumeIntegrator integrator, const Tally (&tallies)[3], double seconds) {
  std::printf("  %s, %s (%.1f s):\n", sweep, to_string(integrator), seconds);
  for (int r = 0; r < 3; ++r) {
    const Tally& t = tallies[r];
    std::printf("    %-7s %4d frames, %9zu pixels (%.0f %% fogged), %zu over 2e-4, worst %.3g at %s\n",
                resolution_name(kDivisors[r]), t.frames, t.pixels, 100.0 * double(t.fogged) / double(t.pixels),
                t.over, t.worst, t.worst_at.c_str());
  }
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

class VolumeSizeSweep : public ::testing::TestWithParam<VolumeIntegrator> {};

TEST_P(VolumeSizeSweep, EveryWidthTo400AtHeights1And3And90And180) {
  FOGCL_REQUIRE_DEVICE();
  const VolumeIntegrator integrator = GetParam();
  const auto start = std::chrono::steady_clock::now();
  Tally tallies[3];
  int failures = 0;
  for (int height : {1, 3, 90, 180})
    for (int width = 1; width <= 400 && failures < 5; ++width) {
      const VolumeTestScene t = sweep_scene(width, height);
      // Noise in the short frames only: it costs the scalar reference more than the sizes gain.
      for (int r = 0; r < 3; ++r) failures += !check_frame(t, integrator, kDivisors[r], 2, height < 90, tallies[r]);
    }
  print("widths 1..400 at heights 1, 3, 90, 180", integrator, tallies, seconds_since(start));
  for (const Tally& t : tallies) EXPECT_GT(t.fogged, t.pixels / 10);  // the volumes are in the frames
}

TEST_P(VolumeSizeSweep, CommonFormats) {
  FOGCL_REQUIRE_DEVICE();
  const VolumeIntegrator integrator = GetParam();
  struct Format {
    const char* name;
    int width, height;
  };
  const Format formats[] = {{"720p", 1280, 720}, {"1080p", 1920, 1080}, {"DCI 2K", 2048, 1080}, {"4K UHD", 3840, 2160}};
  const auto start = std::chrono::steady_clock::now();
  Tally tallies[3];
  for (const Format& f : formats) {
    const VolumeTestScene t = sweep_scene(f.width, f.height);
    // No noise where the target has more than half a million pixels: the sizes are
    // the point here, and the scalar reference runs on one thread.
    for (int r = 0; r < 3; ++r) {
      const bool large = (long long)(f.width / kDivisors[r]) * (f.height / kDivisors[r]) > 500000;
      check_frame(t, integrator, kDivisors[r], 2, !large, tallies[r]);
    }
  }
  print("720p, 1080p, DCI 2K, 4K UHD", integrator, tallies, seconds_since(start));
  for (const Tally& t : tallies) EXPECT_GT(t.fogged, t.pixels / 10);
}

// The shapes the rule gives the march and the composite on this device: within the device's and
// the kernel's limits, and on a CPU device the group's private memory within the stack budget (a
// group of CL_DEVICE_MAX_WORK_GROUP_SIZE physical-march work-items would not be).
TEST(VolumeWorkGroups, FitTheDeviceAndOnCpusTheStack) {
  FOGCL_REQUIRE_DEVICE();
  const cl::Device device = wrap(runtime()->device());
  const DeviceTraits traits = device_traits(device());
  ProgramCache programs(runtime()->context());
  const std::size_t device_max = device.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>();
  const std::size_t budget = detail::cpu_work_group_stack_bytes();
  std::printf("  %s: max work-group %zu; CPU work-group stack budget %zu bytes\n",
              device.getInfo<CL_DEVICE_NAME>().c_str(), device_max, budget);
  for (VolumeIntegrator integrator : {VolumeIntegrator::stylized, VolumeIntegrator::physical}) {
    detail::VolumeVariant v;
    v.integrator = integrator;
    v.features = VOL_FEATURE_NOISE;
    struct Kernel {
      const char *name, *file, *source;
      std::string options;
      std::size_t private_bytes;
    };
    const Kernel kernels[] = {
        {"volume_march", "volume_march.cl", volume_march_cl, detail::volume_march_options(v, traits),
         detail::volume_march_private_bytes(v, traits)},
        {"volume_composite", "volume_composite.cl", volume_composite_cl, detail::volume_composite_options(v, traits),
         detail::volume_composite_private_bytes(v, traits)}};
    for (const Kernel& k : kernels) {
      const cl::Kernel kernel(wrap(programs.get(device(), k.file, k.source, k.options)), k.name);
      const detail::WorkGroupShape s = detail::work_group_shape(kernel, device, k.private_bytes);
      const std::size_t kernel_max = kernel.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device);
      std::printf("    %-16s %-8s %zu x %zu work-items (kernel max %zu, private %zu bytes a work-item, "
                  "reported %llu)\n",
                  k.name, to_string(integrator), s.x, s.y, kernel_max, k.private_bytes,
                  (unsigned long long)kernel.getWorkGroupInfo<CL_KERNEL_PRIVATE_MEM_SIZE>(device));
      EXPECT_GE(s.x * s.y, 1u);
      EXPECT_LE(s.x * s.y, std::min(device_max, kernel_max));
      if (traits.cpu) {
        EXPECT_LE(s.x * s.y * k.private_bytes, budget) << k.name;
      }
    }
    if (traits.cpu && integrator == VolumeIntegrator::physical) {
      EXPECT_GT(device_max * detail::volume_march_private_bytes(v, traits), budget)
          << "the bound would not have refused a group of the device's maximum size";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Volumes, VolumeSizeSweep,
                         ::testing::Values(VolumeIntegrator::stylized, VolumeIntegrator::physical),
                         [](const auto& info) { return std::string(to_string(info.param)); });

}  // namespace
}  // namespace fogcl::test
