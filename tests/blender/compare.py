"""fogcl apply's results against Cycles' own, for tests/blender/run_blender_test.sh.

    python3 tests/blender/compare.py SCRATCH

reads from SCRATCH what run_blender_test.sh and scene.py wrote (scene.json with Blender's camera,
Cycles' surfaces.exr and absorber.exr, fogcl's fogcl-*.exr), prints each comparison with its tolerance,
and exits 1 if a check fails or a negative control passes. Standard library only.

Why the tolerances can be this small: the scene is emission only and Cycles takes one sample per
pixel, whose ray Cycles sends through the pixel centre (the first sample lands on the middle of the
pixel filter's importance table: within one table step, 2 w / 1023 px for a filter of width w, of
the centre). The colour, the Z pass and the Mist pass of a pixel all come from that one ray, so a
pixel is compared wherever it is, silhouettes included, and what is left is rounding plus the
renderers' geometry:
  - Mist: Cycles maps the hit point's distance from the camera, len(P - camera), to
    (d - start) / depth; fogcl gets the same hit's eye depth (Z, the view-axis component of
    P - camera) and multiplies it by the length of its pixel-centre ray at unit eye depth. Both
    work in float32 on coordinates as large as d + |camera|, so a few units in the last place of
    that, over the mist depth.
  - Absorber: Cycles renders a mesh, fogcl a sphere. The mesh (an icosphere with its vertices on
    radius R) lies between the sphere through its vertices and the sphere touching its nearest face
    plane, so Cycles' chord through it lies between those two spheres' chords; fogcl's sphere has
    the mid radius. With the sample's offset from the centre (as a shift of the ray's distance p
    from the sphere's centre), that brackets Cycles' transmittance exp(-sigma * chord) per pixel.
"""

import json
import math
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import exr  # noqa: E402

U = 2.0 ** -24  # float32 unit roundoff
FOG_BUDGET = 2e-7  # the deferred pass's fog factor against float64, given the same inputs (docs/accuracy.md)
FILTER_TABLE_SIZE = 1024  # Cycles' pixel filter importance table


class Camera:
    """Blender's camera as scene.py read it (scene.json), in Blender's world."""

    def __init__(self, camera, width, height):
        self.rotation = camera["rotation"]  # columns: the camera's x, y, z axes in the world
        self.origin = camera["location"]
        self.tan_h = camera["tan_half_width"]
        self.tan_v = camera["tan_half_height"]
        self.near, self.far = camera["clip"]
        self.width, self.height = width, height

    def ray(self, x, y):
        """The ray through pixel (x, y)'s centre (row 0 on top): unit direction in the world and
        the ray's length per unit of eye depth (radial distance = eye depth * k)."""
        cx = (2.0 * (x + 0.5) / self.width - 1.0) * self.tan_h
        cy = (1.0 - 2.0 * (y + 0.5) / self.height) * self.tan_v
        k = math.sqrt(cx * cx + cy * cy + 1.0)
        d = [(r[0] * cx + r[1] * cy - r[2]) / k for r in self.rotation]  # the camera looks along its -z
        return d, k


def summary(errors, tolerances):
    over = [i for i, (e, t) in enumerate(zip(errors, tolerances)) if e > t]
    worst = max(range(len(errors)), key=lambda i: errors[i] / tolerances[i])
    return {"n": len(errors), "max": max(errors), "median": statistics.median(errors),
            "tol_min": min(tolerances), "tol_max": max(tolerances), "over": len(over),
            "worst_ratio": errors[worst] / tolerances[worst], "worst": worst}


def report(name, s, where):
    x, y = where(s["worst"])
    print("  %-34s %6d px  max %.3g  median %.3g  tolerance %.3g..%.3g  worst/tolerance %.3g at (%d, %d)"
          "  over: %d" % (name, s["n"], s["max"], s["median"], s["tol_min"], s["tol_max"], s["worst_ratio"],
                          x, y, s["over"]))


def main():
    scratch = sys.argv[1]
    with open(os.path.join(scratch, "scene.json")) as f:
        scene = json.load(f)
    width, height, surfaces = exr.read(os.path.join(scratch, "surfaces.exr"))
    cam = Camera(scene["camera"], width, height)
    n = width * height

    def where(i):
        return i % width, i // width

    def colour_sum(planes):
        r, g, b = (planes["ViewLayer.Combined." + c] for c in "RGB")
        return [r[i] + g[i] + b[i] for i in range(n)]

    def fogcl(name):
        w, h, planes = exr.read(os.path.join(scratch, name))
        if (w, h) != (width, height):
            raise SystemExit("%s is %dx%d, the render %dx%d" % (name, w, h, width, height))
        return colour_sum(planes)

    z = surfaces["ViewLayer.Depth.Z"]
    mist = surfaces["ViewLayer.Mist.Z"]
    colour = colour_sum(surfaces)
    rays = [cam.ray(i % width, i // width) for i in range(n)]
    sky = [not (0.0 < z[i] < cam.far) for i in range(n)]
    cam_size = math.sqrt(sum(c * c for c in cam.origin))
    # The first sample's offset from the pixel centre, per axis [px].
    offset = 2.0 * scene["filter_width"] / (FILTER_TABLE_SIZE - 1)
    print("Cycles %d sample(s) per pixel, pixel filter %g px: ray within %.2g px of the pixel centre; %dx%d, "
          "%d sky pixels" % (scene["samples"], scene["filter_width"], offset, width, height, sum(sky)))
    failed = []

    # ---- 1. Linear distance fog against the Mist pass ------------------------------------------
    start = scene["mist_start"]
    depth = scene["mist_depth"]
    end = start + depth
    print("\n1. fogcl --mode linear --distance --start %g --end %g --sky infinite against Cycles' Mist "
          "(start %g, depth %g, linear)" % (start, end, start, depth))

    # The Z pass is eye depth, not radial distance: the Mist pass's distance (start + mist * depth,
    # where 0 < mist < 1) against Z times the ray length k, and against Z itself.
    ramp = [i for i in range(n) if not sky[i] and 0.0 < mist[i] < 1.0]
    as_eye = max(abs(start + mist[i] * depth - z[i] * rays[i][1]) / (z[i] * rays[i][1]) for i in ramp)
    as_radial = max(abs(start + mist[i] * depth - z[i]) / z[i] for i in ramp)
    print("  Z pass: Mist's distance / (Z * ray length) - 1 within %.2g; Mist's distance / Z - 1 up to %.3g "
          "(%d px): Z is eye depth (--depth-kind eye)" % (as_eye, as_radial, len(ramp)))
    if not as_eye < 1e-5 < as_radial:
        failed.append("the Z pass is not eye depth")

    # Tolerance per pixel: fogcl's own budget; Cycles' float32 hit point P and its two readings
    # (|P - camera| for Mist, the view-axis component for Z: 6 ulps of d + |camera| between them),
    # the mist mapping, 1 - x and the colour ratio (4 ulps of 1); the ray length fogcl takes at the
    # pixel centre for the sample's (k's change over the offset).
    tolerance = []
    for i in range(n):
        if sky[i]:
            tolerance.append(FOG_BUDGET + 4 * U)
            continue
        x, y = where(i)
        k = rays[i][1]
        dk = max(abs(cam.ray(x + dx, y + dy)[1] - k) for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1)))
        d = z[i] * k
        tolerance.append(FOG_BUDGET + U * (6 * (d + cam_size) / depth + 4) + z[i] * dk * offset * math.sqrt(2) / depth)

    def fog_errors(name):
        out = fogcl(name)
        return [abs((1.0 - out[i] / colour[i]) - mist[i]) for i in range(n)]

    s = summary(fog_errors("fogcl-fog.exr"), tolerance)
    report("fogcl against Mist", s, where)
    print("    (%d px on the ramp, %d clamped to 0 or 1 on surfaces, %d sky)"
          % (len(ramp), n - len(ramp) - sum(sky), sum(sky)))
    if s["over"]:
        failed.append("fog against Mist: %d pixels over the tolerance" % s["over"])
    for name, label in (("fogcl-fog-end-off.exr", "control: --end 1 % long"),
                        ("fogcl-fog-radial.exr", "control: Z read as radial distance"),
                        ("fogcl-fog-lens-off.exr", "control: focal length 0.1 % long")):
        s = summary(fog_errors(name), tolerance)
        report(label, s, where)
        if s["over"] == 0:
            failed.append("negative control passed: " + label)

    # ---- 2. The absorber against Volume Absorption ---------------------------------------------
    sigma = scene["sigma"]
    centre = scene["absorber_center"]
    r_v, r_in, r_mid = (scene["absorber_radius_" + k] for k in ("vertices", "faces", "fogcl"))
    print("\n2. fogcl --integrator physical, a homogeneous absorber (albedo 0) of density %g, radius %.7g, against "
          "Cycles' Volume Absorption (black, density %g) in an icosphere of radius %.7g..%.7g"
          % (sigma, r_mid, sigma, r_in, r_v))
    absorbed = colour_sum(exr.read(os.path.join(scratch, "absorber.exr"))[2])
    cycles_t = [absorbed[i] / colour[i] for i in range(n)]
    pixel_angle = 2.0 * cam.tan_v / height  # [rad / px], the largest (at the centre)

    def chord(rho, b, p2, t_near, t_scene):
        h2 = rho * rho - p2
        if h2 <= 0.0:
            return 0.0
        h = math.sqrt(h2)
        return max(0.0, min(b + h, t_scene) - max(b - h, t_near))

    tolerance, exact, inside, clipped, core_ray = [], [], [], [], []
    for i in range(n):
        d, k = rays[i]
        rel = [centre[j] - cam.origin[j] for j in range(3)]
        b = sum(rel[j] * d[j] for j in range(3))  # the ray's closest approach to the centre
        dist2 = sum(c * c for c in rel)
        p = math.sqrt(max(dist2 - b * b, 0.0))
        t_scene = math.inf if sky[i] else z[i] * k
        t_near = cam.near * k
        # The ray's distance from the centre moves with the sample's offset and with each renderer's
        # float32 ray direction (8 ulps each).
        dp = math.sqrt(dist2) * (offset * math.sqrt(2) * pixel_angle + 16 * U)
        lo = chord(r_in, b, (p + dp) ** 2, t_near, t_scene * (1 - 4 * U))
        hi = chord(r_v, b, max(p - dp, 0.0) ** 2, t_near, t_scene * (1 + 4 * U))
        mid = chord(r_mid, b, p * p, t_near, t_scene)
        t_mid = math.exp(-sigma * mid)
        geometry = max(math.exp(-sigma * lo) - t_mid, t_mid - math.exp(-sigma * hi))
        # Rounding: each renderer's float32 chord (8 ulps of the exit distance), the colour sums and ratios.
        rounding = t_mid * sigma * 16 * U * min(b + r_v, t_scene) + 8 * U if hi > 0 else 8 * U
        tolerance.append(geometry + rounding)
        exact.append(t_mid)
        inside.append(hi > 0)
        clipped.append(hi > 0 and t_scene < b + math.sqrt(max(r_v * r_v - p * p, 0.0)))
        core_ray.append(p < 0.9 * r_mid)

    def volume_errors(name):
        out = fogcl(name)
        return [abs(out[i] / colour[i] - cycles_t[i]) for i in range(n)]

    errors = volume_errors("fogcl-absorber.exr")
    s = summary(errors, tolerance)
    report("fogcl against Cycles", s, where)
    through = [i for i in range(n) if inside[i]]
    t_through = [cycles_t[i] for i in through]
    sub = summary([errors[i] for i in through], [tolerance[i] for i in through])
    report("  rays through the sphere", sub, lambda j: where(through[j]))
    core = [i for i in through if core_ray[i]]
    sub = summary([errors[i] for i in core], [tolerance[i] for i in core])
    report("  of which p < 0.9 r", sub, lambda j: where(core[j]))
    print("    (%d px through the sphere: %d against the sky, %d ending on a surface inside it)"
          % (len(through), sum(1 for i in through if sky[i]), sum(1 for i in through if clipped[i])))
    # fogcl against its own sphere in float64: near the rim the chord's slope in p magnifies the
    # float32 ray direction (and so does the tolerance above).
    fogcl_t = [v / colour[i] for i, v in enumerate(fogcl("fogcl-absorber.exr"))]
    print("    transmittance %.4g..%.4g; fogcl against exp(-sigma * chord) of its sphere in float64: max %.3g "
          "where p < 0.9 r (%d px), %.3g over the whole disc"
          % (min(t_through), max(t_through), max(abs(fogcl_t[i] - exact[i]) for i in core), len(core),
             max(abs(fogcl_t[i] - exact[i]) for i in through)))
    if s["over"]:
        failed.append("absorber against Volume Absorption: %d pixels over the tolerance" % s["over"])
    s = summary(volume_errors("fogcl-absorber-off.exr"), tolerance)
    report("control: density 1 % high", s, where)
    if s["over"] == 0:
        failed.append("negative control passed: density 1 % high")

    print()
    if failed:
        for f in failed:
            print("FAIL: " + f)
        return 1
    print("fogcl agrees with Cycles within the derived tolerances; every negative control fails")
    return 0


if __name__ == "__main__":
    sys.exit(main())
