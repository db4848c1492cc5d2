#include "independent_reference.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace fogcl::test::independent {
namespace {

using Vec = std::array<double, 3>;

Vec normalized(const Vec& v) {
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return {v[0] / n, v[1] / n, v[2] / n};
}
Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec vec(const glm::vec3& v) { return {double(v.x), double(v.y), double(v.z)}; }

// §2: the pixel's ray, the bilinear interpolation of the corners (bottom-left, bottom-right,
// top-left, top-right) at the pixel centre's u = (x + 0.5) / W, v = 1 - (y + 0.5) / H.
Vec pixel_ray(const CameraParams& cam, int x, int y, int w, int h) {
  const double u = (x + 0.5) / w, v = 1.0 - (y + 0.5) / h;
  const auto& c = cam.frustum_corners;
  Vec r;
  for (int k = 0; k < 3; ++k) {
    const double bottom = c[kBottomLeft][k] + (double(c[kBottomRight][k]) - c[kBottomLeft][k]) * u;
    const double top = c[kTopLeft][k] + (double(c[kTopRight][k]) - c[kTopLeft][k]) * u;
    r[k] = bottom + (top - bottom) * v;
  }
  return r;
}

// What a raw depth sample means (§2, §2.2): eye depth relative to the far plane and the sky flag.
struct Depth {
  double linear01;  // Linear01Depth; infinite far plane: eye depth itself (corners at z = 1)
  bool sky;
};
Depth read_depth(float sample, const CameraParams& cam) {
  double raw = sample;
  if (std::isnan(raw)) raw = cam.reversed_z ? 0.0 : 1.0;  // NaN is the far plane
  raw = std::min(std::max(raw, 0.0), 1.0);
  const double n = cam.near_plane();
  switch (cam.projection) {
    case Projection::perspective_infinite_far:
      return {raw == 0.0 ? INFINITY : n / raw, raw == 0.0};
    case Projection::orthographic: {
      const double l01 = double(cam.zbuffer_params.x) * raw + double(cam.zbuffer_params.y);
      return {l01, l01 > 0.9999};
    }
    case Projection::perspective:
      break;
  }
  // Linear01Depth = 1 / (x raw + y); conventional x = 1 - y, written so in double.
  const double zx = cam.zbuffer_params.x, zy = cam.zbuffer_params.y;
  const double l01 = 1.0 / (cam.reversed_z ? zx * raw + zy : zy * (1.0 - raw) + raw);
  return {l01, l01 > 0.9999};
}

// §2's view distance d: depth-based Linear01Depth * far - near (eye depth - near), distance-based
// |ray| * Linear01Depth (the ray at the far plane; at z = 1 for the infinite far plane).
double view_distance(const Depth& depth, const Vec& ray, const CameraParams& cam, FogMetric metric) {
  const double n = cam.near_plane(), f = cam.far_plane();
  const double eye = cam.projection == Projection::perspective_infinite_far ? depth.linear01 : depth.linear01 * f;
  if (metric == FogMetric::depth || cam.projection == Projection::orthographic) return eye - n;
  return std::sqrt(dot(ray, ray)) * depth.linear01;
}

double clamp01(double x) { return std::min(std::max(x, 0.0), 1.0); }

// Unity's fog factors (1: no fog).
double unity_factor(const FogSettings& s, double d) {
  const double start = s.start, end = s.end, rho = s.density;
  switch (s.mode) {
    case FogMode::linear:
      if (start == end) return d < start ? 1.0 : 0.0;
      return clamp01((end - d) / (end - start));
    case FogMode::exp:
      return std::exp(-rho * d);
    case FogMode::exp2:
      return std::exp(-(rho * d) * (rho * d));
    case FogMode::off:
    case FogMode::height:
      break;
  }
  throw std::logic_error("unity_factor: not a factor mode");
}

// §2's blend: f == 1 keeps the color, f == 0 is the fog color.
double blend(double c, double fog, double f) { return f == 1.0 ? c : (f == 0.0 ? fog : fog + f * (c - fog)); }

long double legendre_node_weight(int n, int i, long double* weight) {
  const long double pi = 3.141592653589793238462643383279502884L;
  long double x = std::cos(pi * (i + 0.75L) / (n + 0.5L));
  long double dp = 0;
  for (int it = 0; it < 100; ++it) {
    long double p0 = 1, p1 = x;
    for (int k = 2; k <= n; ++k) {
      const long double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
      p0 = p1;
      p1 = p2;
    }
    dp = n * (x * p1 - p0) / (x * x - 1);
    const long double dx = p1 / dp;
    x -= dx;
    if (std::fabs(dx) < 1e-19L) break;
  }
  *weight = 2 / ((1 - x * x) * dp * dp);
  return x;
}

struct Nodes {
  long double x[8], w[8];
  Nodes() {
    for (int i = 0; i < 8; ++i) x[i] = legendre_node_weight(8, i, &w[i]);
  }
};

}  // namespace

long double gauss_legendre(const std::function<long double(long double)>& g, long double a, long double b,
                           long long panels) {
  static const Nodes nodes;
  const long double width = (b - a) / panels;
  long double sum = 0;
  for (long long p = 0; p < panels; ++p) {
    const long double lo = a + width * p, half = width / 2, mid = lo + half;
    long double panel = 0;
    for (int i = 0; i < 8; ++i) panel += nodes.w[i] * g(mid + half * nodes.x[i]);
    sum += panel * half;
  }
  return sum;
}

long double height_integral(long double s0, long double s1, long double y0, long double wy, long double k,
                            long double b) {
  const long double rate = k * wy;  // the integrand is e^(-k (y0 - b)) e^(-rate s)
  if (std::isinf(s1)) {
    if (!(rate > 0)) return INFINITY;
    s1 = s0 + 80 / rate;
  }
  const long double change = std::fabs(rate) * (s1 - s0);
  const long long panels = std::max<long long>(1, (long long)std::ceil(change / 2));
  return gauss_legendre([&](long double s) { return std::exp(-k * (y0 + s * wy - b)); }, s0, s1, panels);
}

Reference deferred_fog(const ColorImage& color, const DepthImage& depth, const CameraParams& cam,
                       const FogSettings& s) {
  Reference r;
  r.width = color.width();
  r.height = color.height();
  r.rgb.resize(3 * color.pixel_count());
  r.factor.resize(color.pixel_count());
  const bool sky_infinite = s.sky == SkyDistance::infinite;
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x) {
      const std::size_t i = std::size_t(y) * r.width + x;
      const Depth dep = read_depth(depth.at(x, y), cam);
      double f = dep.sky && sky_infinite ? 0.0 : unity_factor(s, view_distance(dep, pixel_ray(cam, x, y, r.width, r.height), cam, s.metric));
      if (dep.sky && !sky_infinite && !s.fog_skybox) f = 1.0;
      r.factor[i] = f;
      const glm::vec4 c = color.pixel(x, y);
      for (int ch = 0; ch < 3; ++ch) r.rgb[3 * i + ch] = blend(c[ch], s.color[ch], f);
    }
  return r;
}

Reference height_fog(const ColorImage& color, const DepthImage& depth, const CameraParams& cam,
                     const FogSettings& s) {
  if (s.mode != FogMode::height || !cam.pose) throw std::logic_error("height_fog: height mode and a pose");
  const HeightFogSettings& h = s.height;
  const Vec beta_ext = h.extinction ? vec(*h.extinction) : Vec{s.density, s.density, s.density};
  const Vec beta_in = h.inscattering ? vec(*h.inscattering) : beta_ext;
  const double m = h.max_opacity;
  // §6.1 / docs/volumetric.md "World and rays": view space to world by the columns (right, up', forward).
  const Vec fwd = normalized(vec(cam.pose->forward));
  const Vec right = normalized(cross(vec(cam.pose->up), fwd));
  const Vec up = cross(fwd, right);
  const double eye_y = cam.pose->eye.y;
  const Vec light = h.sun ? normalized(vec(h.sun->direction)) : Vec{0, 1, 0};

  Reference r;
  r.width = color.width();
  r.height = color.height();
  r.rgb.resize(3 * color.pixel_count());
  r.factor.resize(color.pixel_count());
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x) {
      const std::size_t i = std::size_t(y) * r.width + x;
      const glm::vec4 c = color.pixel(x, y);
      for (int ch = 0; ch < 3; ++ch) r.rgb[3 * i + ch] = c[ch];
      r.factor[i] = 1;
      const Vec ray = pixel_ray(cam, x, y, r.width, r.height);
      const Depth dep = read_depth(depth.at(x, y), cam);
      // The distance along the ray: §2's distance-based metric.
      const double s_hit = std::sqrt(dot(ray, ray)) * dep.linear01;
      if (dep.sky && !s.fog_skybox) continue;
      const double s0 = h.start;
      const double s1 = dep.sky ? double(h.cutoff) : std::min(s_hit, double(h.cutoff));
      if (!(s1 > s0)) continue;
      const Vec world = {right[0] * ray[0] + up[0] * ray[1] + fwd[0] * ray[2],
                         right[1] * ray[0] + up[1] * ray[1] + fwd[1] * ray[2],
                         right[2] * ray[0] + up[2] * ray[1] + fwd[2] * ray[2]};
      const Vec omega = normalized(world);
      const double H = double(height_integral(s0, s1, eye_y, omega[1], h.falloff, h.base_height));
      double lobe = 0, H_sun = 0;
      if (h.sun) {
        lobe = std::pow(std::max(dot(omega, light), 0.0), double(h.sun->exponent));
        const double s0_sun = std::max(s0, double(h.sun->start));
        if (s1 > s0_sun) H_sun = double(height_integral(s0_sun, s1, eye_y, omega[1], h.falloff, h.base_height));
      }
      for (int ch = 0; ch < 3; ++ch) {
        // 0 * inf = 0: a zero coefficient is no fog in its channel.
        const double tau_ext = beta_ext[ch] == 0 ? 0.0 : beta_ext[ch] * H;
        const double tau_in = beta_in[ch] == 0 ? 0.0 : beta_in[ch] * H;
        const double tau_sun = beta_in[ch] == 0 ? 0.0 : beta_in[ch] * H_sun;
        const double T = std::max(std::exp(-tau_ext), 1 - m);
        const double J = std::min(-std::expm1(-tau_in), m);
        const double J_sun = std::min(-std::expm1(-tau_sun), m);
        const double sun = h.sun ? double(h.sun->color[ch]) * lobe * J_sun : 0.0;
        r.rgb[3 * i + ch] = (T == 0 ? 0.0 : c[ch] * T) + s.color[ch] * J + sun;
        if (ch == 0) r.factor[i] = T;
      }
    }
  return r;
}

VolumeReference stylized_volumes(const ColorImage& color, const DepthImage& depth, const CameraParams& cam,
                                 const VolumeScene& scene, const VolumeSettings& settings) {
  VolumeReference out;
  Reference& r = out.frame;
  r.width = color.width();
  r.height = color.height();
  r.rgb.resize(3 * color.pixel_count());
  r.factor.resize(color.pixel_count());
  out.certain.assign(color.pixel_count(), 1);
  const Vec fwd = normalized(vec(scene.pose.forward));
  const Vec right = normalized(cross(vec(scene.pose.up), fwd));
  const Vec up = cross(fwd, right);
  const Vec eye = vec(scene.pose.eye);
  const Vec light = normalized(vec(scene.light.direction));
  const double n = cam.near_plane(), f = cam.far_plane();
  // The march with adaptive steps skips its first sample and marches the rest at 0.2 steps after
  // going back 4 of them: accumulated / marched = (steps - 1) / steps.
  const double ratio = settings.adaptive_steps ? double(settings.steps - 1) / settings.steps : 1.0;
  for (int y = 0; y < r.height; ++y)
    for (int x = 0; x < r.width; ++x) {
      const std::size_t i = std::size_t(y) * r.width + x;
      const Vec c = pixel_ray(cam, x, y, r.width, r.height);
      const Vec world = {right[0] * c[0] + up[0] * c[1] + fwd[0] * c[2], right[1] * c[0] + up[1] * c[1] + fwd[1] * c[2],
                         right[2] * c[0] + up[2] * c[1] + fwd[2] * c[2]};
      const Vec dir = normalized(world);
      // The ray starts on the near plane: eye + R c near / c.z.
      const double to_near = n / c[2] * std::sqrt(dot(world, world));
      const Vec origin = {eye[0] + dir[0] * to_near, eye[1] + dir[1] * to_near, eye[2] + dir[2] * to_near};
      const Depth dep = read_depth(depth.at(x, y), cam);
      const double t_scene = dep.sky ? INFINITY : (dep.linear01 * f - n) * std::sqrt(dot(c, c)) / c[2];
      double P[3] = {0, 0, 0}, A = 0;
      for (const FogVolume& v : scene.volumes) {
        // |origin + t dir - center|^2 = r^2: t = tc -+ sqrt(r^2 - d^2), d the ray's distance to the centre.
        const Vec oc = {vec(v.center)[0] - origin[0], vec(v.center)[1] - origin[1], vec(v.center)[2] - origin[2]};
        const double tc = dot(oc, dir), d2 = dot(oc, oc) - tc * tc, r2 = double(v.radius) * v.radius;
        if (std::fabs(std::sqrt(std::max(d2, 0.0)) - v.radius) < 1e-4 * v.radius) out.certain[i] = 0;
        if (d2 >= r2) continue;
        const double half = std::sqrt(r2 - d2);
        const double front = std::max(tc - half, 0.0), back = tc + half;
        if (std::fabs(front - t_scene) < 1e-4 * std::max(1.0, t_scene) || std::fabs(back) < 1e-4 * v.radius)
          out.certain[i] = 0;
        if (!(back > 0) || !(front < t_scene)) continue;
        const double reach = std::min((t_scene - front) * v.occluder_overshoot, back - front);
        if (!(reach > 0)) continue;
        const double k = std::pow(clamp01(dot(dir, light)), double(v.directional_falloff));
        double rgb[3];
        for (int ch = 0; ch < 3; ++ch) {
          const double L = scene.light.color[ch];
          const double base = 1 + (L - 1) * v.light_contribution, lobe = 1 + (L - 1) * v.directional_light_contribution;
          const double light_color = base + (lobe - base) * k;
          const double fog = v.fog_color[ch] + (double(v.directional_fog_color[ch]) - v.fog_color[ch]) * k;
          rgb[ch] = fog * std::max(light_color, 0.1 * light_color);
        }
        const double fog_a = v.fog_color.a + (double(v.directional_fog_color.a) - v.fog_color.a) * k;
        const double a = fog_a * clamp01(clamp01(ratio) * v.density);
        // The seed's blend: SrcAlpha, OneMinusSrcAlpha (color); One, OneMinusSrcAlpha (alpha).
        for (int ch = 0; ch < 3; ++ch) P[ch] = rgb[ch] * a + P[ch] * (1 - a);
        A = a + A * (1 - a);
      }
      const glm::vec4 in = color.pixel(x, y);
      for (int ch = 0; ch < 3; ++ch) r.rgb[3 * i + ch] = A == 0 ? double(in[ch]) : P[ch] + in[ch] * (1 - A);
      r.factor[i] = 1 - A;
    }
  return out;
}

}  // namespace fogcl::test::independent
