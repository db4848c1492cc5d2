"""Print the `fogcl apply` flags for a Blender scene's camera.

Run inside Blender, headless:

    blender -b scene.blend --python examples/blender_camera.py
    blender -b scene.blend --python examples/blender_camera.py -- --camera CameraName --frame 42

The first line printed is the flags, ready to paste after `fogcl apply`:

    --camera-to-world m00,...,m33 --axes blender --focal-length F --sensor-width W --sensor-fit auto
    --near CLIP_START --far CLIP_END

(all on one line; an orthographic camera gets --ortho-size instead of the lens). --frame N reads the
camera at frame N (default: the scene's current frame); an animated camera needs a run per frame,
as Blender's EXRs carry no camera attributes. The lines after it,
starting with '#', give the render size and notes. Exit status 1 with one line on stderr for a
camera fogcl cannot take (lens shift, non-square pixels, a panoramic camera, a missing camera).

What the flags mean (docs: the renderer's camera):
- --camera-to-world is the camera object's matrix_world without its scale (Cycles ignores a
  camera's scale too), row by row: Blender's matrices take column vectors, so the translation is
  the last column and the last row is 0 0 0 1. --axes blender says the world is right-handed with
  +z up and the camera looks along its local -z with +y up.
- --focal-length, --sensor-width, --sensor-height and --sensor-fit are the camera's Lens and
  Sensor settings; fogcl turns them into the vertical field of view for the frame's aspect by
  Blender's rules (auto: the sensor width spans the larger image dimension).
- --near and --far are the camera's clip start and end.
"""

import math
import struct
import sys

import bpy


def fail(message):
    sys.stderr.write("blender_camera.py: error: " + message + "\n")
    sys.exit(1)


def script_args():
    argv = sys.argv
    return argv[argv.index("--") + 1:] if "--" in argv else []


def number(x):
    # The shortest decimal that reads back as the same float32 (Blender stores float32): 0.05, not
    # 0.0500000007; nine digits always do.
    f32 = struct.unpack("f", struct.pack("f", x))[0]
    for digits in range(6, 10):
        text = "%.*g" % (digits, f32)
        if struct.unpack("f", struct.pack("f", float(text)))[0] == f32:
            return text
    return "%.9g" % f32


def main():
    args = script_args()
    scene = bpy.context.scene
    camera = scene.camera
    while args:
        if len(args) >= 2 and args[0] == "--camera":
            camera = bpy.data.objects.get(args[1])
            if camera is None:
                fail("no object named '%s' in the scene" % args[1])
        elif len(args) >= 2 and args[0] == "--frame":
            try:
                scene.frame_set(int(args[1]))
            except ValueError:
                fail("--frame must be an integer (got '%s')" % args[1])
        else:
            fail("unknown arguments '%s' (expected: -- [--camera NAME] [--frame N])" % " ".join(args))
        args = args[2:]
    if camera is None:
        fail("the scene has no camera (scene.camera is None; name one with -- --camera NAME)")
    if camera.type != "CAMERA":
        fail("'%s' is a %s object, not a camera" % (camera.name, camera.type))
    data = camera.data
    if data.type == "PANO":
        fail("'%s' is a panoramic camera; fogcl takes perspective and orthographic cameras" % camera.name)
    if data.shift_x != 0.0 or data.shift_y != 0.0:
        fail("'%s' has lens shift (%g, %g); fogcl takes a centred frustum" % (camera.name, data.shift_x, data.shift_y))

    render = scene.render
    if render.pixel_aspect_x != render.pixel_aspect_y:
        fail("the render has non-square pixels (pixel aspect %g:%g); fogcl assumes square pixels"
             % (render.pixel_aspect_x, render.pixel_aspect_y))
    scale = render.resolution_percentage / 100.0
    width = int(render.resolution_x * scale)
    height = int(render.resolution_y * scale)

    # The pose without the object's scale, as Cycles renders it.
    location, rotation, _ = camera.matrix_world.decompose()
    m = rotation.to_matrix().to_4x4()
    m.translation = location
    rows = ",".join(number(m[r][c]) for r in range(4) for c in range(4))
    flags = ["--camera-to-world", rows, "--axes", "blender"]

    fit = {"AUTO": "auto", "HORIZONTAL": "horizontal", "VERTICAL": "vertical"}[data.sensor_fit]
    if data.type == "ORTHO":
        # ortho_scale spans the fitted image dimension (auto: the larger one); fogcl's
        # --ortho-size is half the vertical extent.
        vertical = fit == "vertical" or (fit == "auto" and width < height)
        half_height = data.ortho_scale / 2.0 if vertical else data.ortho_scale / 2.0 * height / width
        flags += ["--ortho-size", number(half_height)]
    else:
        flags += ["--focal-length", number(data.lens), "--sensor-width", number(data.sensor_width)]
        if fit == "vertical":
            flags += ["--sensor-height", number(data.sensor_height)]
        flags += ["--sensor-fit", fit]
    flags += ["--near", number(data.clip_start), "--far", number(data.clip_end)]

    print(" ".join(flags))
    print("# camera '%s', render size %dx%d (fogcl takes the aspect from the EXR's display window)"
          % (camera.name, width, height))
    if data.type == "PERSP":
        # Blender's own vertical fov for the same settings, as a check: the frame's corners.
        corners = data.view_frame(scene=scene)
        tan_half = max(abs(c.y) for c in corners) / abs(corners[0].z)
        print("# vertical fov %s degrees (Blender's view frame)" % number(math.degrees(2.0 * math.atan(tan_half))))
    print("# Cycles' and Eevee's Z pass holds eye depth (along the view axis): give --depth-kind eye")


main()
