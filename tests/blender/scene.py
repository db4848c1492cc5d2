"""The test scene of tests/blender/run_blender_test.sh, built and rendered by Blender's Cycles.

    blender -b --factory-startup -noaudio --python-exit-code 1 --python tests/blender/scene.py -- \
        OUT MIST_START MIST_DEPTH SIGMA

writes into OUT:
  scene.blend        the scene (examples/blender_camera.py reads its camera from it);
  surfaces.exr       Cycles' render of the planes and spheres: multilayer EXR, float, uncompressed,
                     layer ViewLayer with Combined (RGBA), Depth (Z) and Mist (Z);
  absorber.exr       the same with a Volume Absorption sphere (colour black, density SIGMA) added;
  absorber.json      that sphere as a fogcl VOLUMES.json medium (centre in Blender's axes);
  absorber-off.json  the same with the density 1 % high (the negative control);
  scene.json         the render settings, the absorber's radii and Blender's own camera, from which
                     the comparison takes its rays and derives its tolerances.

Every surface is an Emission shader (and the world a constant colour), so a pixel's colour is
exact: the only light is what the camera sees directly, and the only attenuation the absorber's,
which Cycles computes in closed form for a homogeneous volume (one step, exp(-sigma * length)).
There is no noise to average, so Cycles takes one sample per pixel. That sample's ray goes through
the centre of the pixel filter (the middle of the filter's importance table: within 2 w / 1023 px of
the pixel centre for a filter of width w, 2e-5 px with the 0.01 px filter here), and the colour,
the Z pass and the Mist pass all come from it, silhouettes included. More samples would only
average in rays from elsewhere in the pixel: with this filter and 16 samples some land up to
0.5 px away (measured with Blender 3.4.1; the Mist pass then moves by up to 0.03 px of its ramp),
which is Cycles' antialiasing, not what the test is about.
"""

import json
import math
import os
import sys

import bpy
from mathutils import Euler, Vector

RESOLUTION = (192, 128)
SAMPLES = 1  # one ray per pixel, through its centre (above)
FILTER_WIDTH = 0.01  # [px], Blender's smallest
CLIP = (0.1, 200.0)

# The absorber: an icosphere (Blender's subdivision 8: 327680 triangles) with its vertices on radius R.
ABSORBER_CENTER = (-2.0, 6.0, 2.9)
ABSORBER_RADIUS = 1.5
ABSORBER_SUBDIVISIONS = 8


def emission_material(name, rgb):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes = m.node_tree.nodes
    nodes.clear()
    emit = nodes.new("ShaderNodeEmission")
    emit.inputs["Color"].default_value = (rgb[0], rgb[1], rgb[2], 1.0)
    emit.inputs["Strength"].default_value = 1.0
    out = nodes.new("ShaderNodeOutputMaterial")
    m.node_tree.links.new(emit.outputs["Emission"], out.inputs["Surface"])
    return m


def absorber_material(sigma):
    # Volume Absorption: sigma_a = density * (1 - colour); colour black makes it sigma in every
    # channel. No surface shader: the sphere's boundary is invisible, only the medium attenuates.
    m = bpy.data.materials.new("absorber")
    m.use_nodes = True
    nodes = m.node_tree.nodes
    nodes.clear()
    absorb = nodes.new("ShaderNodeVolumeAbsorption")
    absorb.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    absorb.inputs["Density"].default_value = sigma
    out = nodes.new("ShaderNodeOutputMaterial")
    m.node_tree.links.new(absorb.outputs["Volume"], out.inputs["Volume"])
    m.cycles.homogeneous_volume = True
    return m


def add(obj, material):
    obj.data.materials.append(material)
    return obj


def plane(size, location, rotation_deg, rgb, scale=(1.0, 1.0, 1.0)):
    bpy.ops.mesh.primitive_plane_add(size=size, location=location,
                                     rotation=[math.radians(a) for a in rotation_deg])
    obj = bpy.context.active_object
    obj.scale = scale
    return add(obj, emission_material("plane", rgb))


def sphere(radius, location, rgb, subdivisions=4):
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=subdivisions, radius=radius, location=location)
    obj = bpy.context.active_object
    if rgb is not None:
        add(obj, emission_material("sphere", rgb))
    return obj


def inner_radius(obj):
    # The mesh lies between its vertices' sphere (radius R) and the sphere touching its nearest
    # face plane: the smallest distance from the centre to a triangle's plane.
    verts = obj.data.vertices
    return min(abs(p.normal.dot(verts[p.vertices[0]].co)) for p in obj.data.polygons)


def render(scene, path):
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    if not os.path.isfile(path):
        raise RuntimeError("Cycles wrote no " + path)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    out = argv[0]
    mist_start, mist_depth, sigma = (float(a) for a in argv[1:4])

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene

    # Cycles on the CPU, every sample through the pixel centre, nothing adaptive or denoised.
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = SAMPLES
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.pixel_filter_type = "BLACKMAN_HARRIS"
    scene.cycles.filter_width = FILTER_WIDTH
    scene.cycles.seed = 0
    scene.render.resolution_x, scene.render.resolution_y = RESOLUTION
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    settings = scene.render.image_settings
    settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    settings.exr_codec = "NONE"

    layer = scene.view_layers[0]
    layer.use_pass_combined = True
    layer.use_pass_z = True
    layer.use_pass_mist = True

    # The world: a constant sky, and the mist a compositor would fog with (linear from start to
    # start + depth along the ray, the background at 1).
    world = bpy.data.worlds.new("world")
    scene.world = world
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.25, 0.32, 0.45, 1.0)
    world.mist_settings.start = mist_start
    world.mist_settings.depth = mist_depth
    world.mist_settings.falloff = "LINEAR"

    # Planes and spheres: a ground, a wall whose top edge shows the sky, a tilted panel, and two
    # spheres, at distances from 3 to beyond the mist's end.
    plane(80.0, (0.0, 10.0, 0.0), (0.0, 0.0, 0.0), (0.55, 0.45, 0.35))
    plane(1.0, (0.0, 22.0, 2.25), (90.0, 0.0, 0.0), (0.3, 0.5, 0.8), scale=(40.0, 4.5, 1.0))
    plane(3.0, (3.0, 2.0, 1.2), (35.0, -20.0, 25.0), (0.8, 0.75, 0.2))
    sphere(1.4, (-3.0, 7.5, 1.4), (0.85, 0.3, 0.3))
    sphere(2.5, (5.0, 13.0, 2.5), (0.3, 0.8, 0.45))

    # The camera: a general pose (pitched, yawed and rolled), a 30 mm lens on Blender's default
    # 36 mm sensor, fit auto (the width spans the longer, horizontal side).
    cam_data = bpy.data.cameras.new("camera")
    cam_data.lens = 30.0
    cam_data.sensor_width = 36.0
    cam_data.sensor_fit = "AUTO"
    cam_data.clip_start, cam_data.clip_end = CLIP
    cam = bpy.data.objects.new("camera", cam_data)
    scene.collection.objects.link(cam)
    cam.location = Vector((2.0, -9.0, 3.4))
    target = Vector((0.0, 8.0, 2.0))
    direction = target - cam.location
    rotation = direction.to_track_quat("-Z", "Y").to_euler()
    roll = Euler((0.0, 0.0, math.radians(6.0))).to_quaternion()
    cam.rotation_euler = (rotation.to_quaternion() @ roll).to_euler()
    scene.camera = cam

    # The absorber, hidden in the first render.
    absorber = sphere(ABSORBER_RADIUS, ABSORBER_CENTER, None, ABSORBER_SUBDIVISIONS)
    absorber.data.materials.append(absorber_material(sigma))
    r_in = inner_radius(absorber)
    absorber.hide_render = True

    # Blender's own camera, for the comparison's rays (fogcl gets what examples/blender_camera.py
    # prints): the pose without scale, and the half extents of the view frame at unit depth.
    bpy.context.view_layer.update()
    location, rotation, _ = cam.matrix_world.decompose()
    frame = cam_data.view_frame(scene=scene)
    camera = {"location": list(location), "rotation": [list(row) for row in rotation.to_matrix()],
              "tan_half_width": max(abs(c.x) for c in frame) / abs(frame[0].z),
              "tan_half_height": max(abs(c.y) for c in frame) / abs(frame[0].z), "clip": list(CLIP)}

    os.makedirs(out, exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(out, "scene.blend"))
    render(scene, os.path.join(out, "surfaces.exr"))
    absorber.hide_render = False
    render(scene, os.path.join(out, "absorber.exr"))

    # fogcl's sphere: the mesh's mid radius, so a ray's chord through the mesh is within half the
    # faceting of fogcl's (the comparison bounds that per pixel).
    r_mid = 0.5 * (ABSORBER_RADIUS + r_in)
    for name, density in (("absorber.json", sigma), ("absorber-off.json", sigma * 1.01)):
        volume = {"medium": "homogeneous", "center": list(ABSORBER_CENTER), "radius": r_mid, "density": density}
        with open(os.path.join(out, name), "w") as f:
            json.dump({"volumes": [volume]}, f, indent=2)
    with open(os.path.join(out, "scene.json"), "w") as f:
        json.dump({"samples": SAMPLES, "filter_width": FILTER_WIDTH, "resolution": list(RESOLUTION),
                   "mist_start": mist_start, "mist_depth": mist_depth, "sigma": sigma,
                   "absorber_center": list(ABSORBER_CENTER), "absorber_radius_vertices": ABSORBER_RADIUS,
                   "absorber_radius_faces": r_in, "absorber_radius_fogcl": r_mid,
                   "camera": camera}, f, indent=2)


main()
