// The march on stiff and thin media, the jitter's convergence and the depth-aware upsampling
// (docs/volumetric.md §The march, §Resolution, upsampling, composite).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "volume/volume_formulas.h"
#include "volume_support.h"

namespace fogcl::test {
namespace {

// One volume of constant extinction on a unit chord: the ray from the origin along +z through a
// sphere of radius 1/2 touching the origin; albedo 1, ambient 1, no light: L = 1 everywhere.
// riemann: the textbook left Riemann sum I += T sigma_t d, T *= e^(-sigma_t d) of the shared march
// (VOL_RIEMANN) instead of the exact segment weight.
template <class T>
std::array<T, 2> unit_chord(double sigma_t, int steps, bool riemann = false) {
  std::array<float, VOL_F_COUNT> frame{};
  frame[VOL_F_LIGHT_DIR + 1] = 1.0f;  // light color stays 0
  std::array<float, VOL_V_STRIDE> vol{};
  vol[VOL_V_CENTER + 2] = 0.5f;
  vol[VOL_V_RADIUS] = 0.5f;
  vol[VOL_V_DENSITY] = float(sigma_t);
  for (int k = 0; k < 3; ++k) vol[VOL_V_ALBEDO + k] = vol[VOL_V_AMBIENT + k] = 1.0f;
  const glm::vec<3, T> origin(0), dir(0, 0, 1);
  T coverage[3];
  const glm::vec<4, T> r = volume_formulas::vol_physical<T>(origin, dir, T(INFINITY), T(1), T(0.5), vol.data(), 1,
                                                            frame.data(), nullptr, 0, nullptr, steps, 0, 0,
                                                            int(riemann), coverage);
  return {r.x, r.w};  // I (one channel), A = 1 - T
}

TEST(VolumeStiffness, EnergyConservedFromClearAirToOpaque) {
  int checked = 0;
  double worst_f = 0, worst_d = 0;
  for (int steps : {1, 8, 64}) {
    std::printf("  %d steps:\n  %10s %14s %14s %14s %14s\n", steps, "sigma_t*d", "I+T-1 float", "I+T-1 double",
                "T float", "naive I-(1-T)");
    for (double x : {0.0, 1e-8, 1e-6, 1e-4, 1e-2, 1.0, 1e1, 1e2, 1e3, 1e4, 1e20}) {
      const double sigma = x * steps;  // sigma_t * d = x on the unit chord
      const auto f = unit_chord<float>(sigma, steps);
      const auto d = unit_chord<double>(sigma, steps);
      const double tf = 1.0 - double(f[1]), td = 1.0 - d[1];
      for (double v : {double(f[0]), double(f[1]), d[0], d[1]}) EXPECT_TRUE(std::isfinite(v)) << "sigma_t*d " << x;
      EXPECT_GE(tf, 0.0);
      EXPECT_LE(tf, 1.0);
      // I + T = 1: with T = 1 - A, |I - A|.
      const double ef = std::fabs(double(f[0]) - double(f[1])), ed = std::fabs(d[0] - d[1]);
      worst_f = std::max(worst_f, ef);
      worst_d = std::max(worst_d, ed);
      EXPECT_LE(ef, 1e-6) << "float, sigma_t*d " << x << ", " << steps << " steps";
      EXPECT_LE(ed, 1e-12) << "double, sigma_t*d " << x << ", " << steps << " steps";
      // Thin media keep their digits: A = 1 - e^(-sigma_t L) to a few ulps of itself.
      if (x > 0 && x * steps < 1e-3) {
        EXPECT_NEAR(double(f[1]), -std::expm1(-sigma), 1e-6 * -std::expm1(-sigma)) << "thin, sigma_t*d " << x;
      }
      const double naive = unit_chord<double>(sigma, steps, true)[0] - (1.0 - std::exp(-sigma));
      std::printf("  %10.0e %14.3g %14.3g %14.3g %14.3g\n", x, double(f[0]) + tf - 1.0, d[0] + td - 1.0, tf, naive);
      // The textbook sum overshoots by about sigma_t d once a segment is opaque (fogcl report
      // --volumetric shows it on its dense scene); the exact weight above stays within 1e-6.
      if (x >= 10.0) {
        EXPECT_GT(naive, 0.5 * x) << "Riemann, sigma_t*d " << x;
      }
      ++checked;
    }
  }
  std::printf("  worst |I + T - 1|: float %.3g, double %.3g over %d cases\n", worst_f, worst_d, checked);
}

// Mean over 64 frame indices of the jittered 64-step physical march, noise on, against the
// unjittered 4096-step march: within 0.1 % and closer than the unjittered 64-step march.
TEST(VolumeJitter, MeanOverFramesConvergesToTheFineMarch) {
  VolumeTestScene t = volume_test_scene(48, 27);
  VolumeSettings settings;
  settings.integrator = VolumeIntegrator::physical;
  settings.resolution_divisor = 1;
  settings.steps = 4096;
  settings.jitter = false;
  const VolumeResult<double> fine = volumes_scalar<double>(t.frame.color, t.frame.depth, t.frame.params, t.scene, settings);
  settings.steps = 64;
  const VolumeResult<double> coarse =
      volumes_scalar<double>(t.frame.color, t.frame.depth, t.frame.params, t.scene, settings);
  settings.jitter = true;
  std::vector<double> mean(fine.low.size(), 0.0);
  for (std::uint32_t frame = 0; frame < 64; ++frame) {
    t.scene.frame_index = frame;
    const VolumeResult<double> r = volumes_scalar<double>(t.frame.color, t.frame.depth, t.frame.params, t.scene, settings);
    for (std::size_t i = 0; i < mean.size(); ++i) mean[i] += r.low[i] / 64.0;
  }
  // Relative L1 over the target's in-scattered light and coverage.
  double sum_ref = 0, err_mean = 0, err_coarse = 0;
  for (std::size_t i = 0; i < mean.size(); ++i) {
    sum_ref += std::fabs(fine.low[i]);
    err_mean += std::fabs(mean[i] - fine.low[i]);
    err_coarse += std::fabs(coarse.low[i] - fine.low[i]);
  }
  const double rel_mean = err_mean / sum_ref, rel_coarse = err_coarse / sum_ref;
  std::printf("  relative L1 against 4096 steps: mean of 64 jittered frames %.3g, unjittered 64 steps %.3g\n",
              rel_mean, rel_coarse);
  EXPECT_LE(rel_mean, 1e-3);
  EXPECT_LT(rel_mean, rel_coarse);
}

// A fog volume behind a sphere against the sky: at half and quarter resolution, depth-aware
// upsampling's error against the full-resolution march is smaller than bilinear's.
TEST(VolumeUpsampling, DepthAwareBeatsBilinearAtSilhouettes) {
  VolumeTestScene t = volume_test_scene(128, 72);
  FogVolume v;  // a dense volume around the (2.2, 1, -0.5) sphere, seen against sky and ground
  v.center = glm::vec3(2.2f, 1.5f, 0.5f);
  v.radius = 3.5f;
  v.density = 2.0f;
  v.noise = false;
  v.fade_edge = 0.5f;
  v.proximity_fade = 0.0f;
  t.scene.volumes = {v};
  VolumeSettings settings;
  settings.integrator = VolumeIntegrator::physical;
  settings.jitter = false;
  settings.steps = 32;
  settings.resolution_divisor = 1;
  const VolumeResult<double> full = volumes_scalar<double>(t.frame.color, t.frame.depth, t.frame.params, t.scene, settings);
  for (int divisor : {2, 4}) {
    settings.resolution_divisor = divisor;
    double err[2] = {0, 0};
    for (int mode = 0; mode < 2; ++mode) {
      settings.upsampling = mode == 0 ? VolumeUpsampling::depth_aware : VolumeUpsampling::bilinear;
      const VolumeResult<double> r = volumes_scalar<double>(t.frame.color, t.frame.depth, t.frame.params, t.scene, settings);
      for (std::size_t i = 0; i < r.rgba.size(); ++i)
        if (i % 4 != 3) err[mode] += std::fabs(r.rgba[i] - full.rgba[i]);
      err[mode] /= double(r.rgba.size() / 4);
    }
    std::printf("  1/%d resolution: mean |error| per pixel against full resolution: depth-aware %.4g, bilinear %.4g\n",
                divisor, err[0], err[1]);
    EXPECT_LT(err[0], 0.85 * err[1]);  // measured: 0.799 at 1/2, 0.794 at 1/4
  }
}

}  // namespace
}  // namespace fogcl::test
