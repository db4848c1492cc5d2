// Tests that only mean something on a GPU; CI's CPU runs skip them with the reason.
// scripts/gpu-run.sh runs the whole suite with FOGCL_DEVICE=gpu on the GPU machine, these included.
#include <cstdio>

#include "fogcl/fogcl.h"
#include "volume_support.h"

namespace fogcl::test {
namespace {

#define FOGCL_REQUIRE_GPU()                                                                             \
  do {                                                                                                  \
    if (resolve_device_choice() != "gpu")                                                              \
      GTEST_SKIP() << "FOGCL_DEVICE=" << resolve_device_choice()                                       \
                   << ": GPU tests run with FOGCL_DEVICE=gpu (scripts/gpu-run.sh on the GPU machine)"; \
    ASSERT_NE(runtime(), nullptr) << "FOGCL_DEVICE=gpu found no GPU: " << runtime_error();              \
  } while (0)

// A GPU run must not pass by skipping: with FOGCL_DEVICE=gpu every kernel test would skip if the
// ICD were not registered, so this one fails instead.
TEST(GpuDevice, FogclDeviceGpuOpensAGpu) {
  FOGCL_REQUIRE_GPU();
  EXPECT_FALSE(runtime()->is_cpu()) << runtime()->description();
  std::printf("[ info ] device: %s\n", runtime()->description().c_str());
}

// GPUs run one pixel per work-item; the 16-pixel float16 blocks are the CPU device's layout.
TEST(GpuDevice, DeferredPassRunsOnePixelPerWorkItem) {
  FOGCL_REQUIRE_GPU();
  FogSettings s;
  s.mode = FogMode::exp2;
  const std::string options =
      shared_pass().build_options_for(select_variant(s, make_camera_params(PerspectiveCamera{}), ColorFormat::rgba32f));
  EXPECT_NE(options.find("-D FOG_VECTOR_WIDTH=1"), std::string::npos) << options;
  EXPECT_EQ(options.find("-D FOG_VECTOR_WIDTH=16"), std::string::npos) << options;
}

// The noise as a buffer (manual trilinear in float) and as an image (the texture unit's linear
// filter) on the same frame, both against the scalar double march. The buffer keeps the kernel
// budget of every other device (2e-4). The texture unit interpolates with 8-bit fractional
// weights (NVIDIA's CUDA C Programming Guide, "Texture Fetching": 9-bit fixed point), and the
// OpenCL C spec sets no precision for CL_FILTER_LINEAR: a weight off by up to 2^-9 per axis moves
// a sample by up to 3 * 2^-9 = 5.9e-3 of the noise's range, which the density exponents and the
// march can amplify a few times: 2e-2, the image budget of VolumeKernelFeatures too.
TEST(GpuDevice, NoiseImageAgainstBufferSideBySide) {
  FOGCL_REQUIRE_GPU();
  if (wrap(runtime()->device()).getInfo<CL_DEVICE_IMAGE_SUPPORT>() != CL_TRUE) GTEST_FAIL() << "a GPU without images";
  for (const VolumeIntegrator integrator : {VolumeIntegrator::stylized, VolumeIntegrator::physical}) {
    const VolumeTestScene t = volume_test_scene(240, 135);
    VolumeSettings settings;
    settings.integrator = integrator;
    settings.steps = 64;
    const VolumeResult<double> ref =
        volumes_scalar<double>(t.frame.color, t.frame.depth, t.frame.params, t.scene, settings);
    for (const NoiseSampling sampling : {NoiseSampling::buffer, NoiseSampling::image}) {
      settings.noise_sampling = sampling;
      ColorImage out;
      VolumePass(*runtime()).apply(t.frame.color, t.frame.depth, out, t.frame.params, t.scene, settings);
      const double budget = sampling == NoiseSampling::image ? 2e-2 : 2e-4;
      const VolumeErrorStats s = compare_volumes(out, ref, budget);
      std::printf("  %s, noise %s: %s\n", to_string(integrator), to_string(sampling), describe(s).c_str());
      EXPECT_EQ(s.nonfinite, 0u);
      EXPECT_LE(s.max_abs, budget) << to_string(sampling) << ": " << describe(s);
    }
  }
}

}  // namespace
}  // namespace fogcl::test
