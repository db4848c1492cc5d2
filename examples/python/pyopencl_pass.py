#!/usr/bin/env python3
"""A PyOpenCL renderer's frame fogged where it lies (docs/python.md, "On your PyOpenCL context").

The "renderer" is a PyOpenCL kernel that draws a ground plane and a sky into device buffers. fogcl's
fog volumes and deferred fog then run on the same context and queue, chained by events, with no
copy to the host in between. At the end the frame is read back once and compared with fogcl.apply
on the same pixels, which runs the same passes.
"""

import numpy as np
import pyopencl as cl

import fogcl

WIDTH, HEIGHT = 320, 180
NEAR, FAR = 0.3, 200.0

# What both passes take, in fogcl.apply's words: the camera, the deferred fog, the volumes.
OPTIONS = dict(
    near=NEAR, far=FAR, fov=60.0,
    mode="exp2", density=0.02, fog_color=(0.62, 0.68, 0.76),
    eye=(0, 1.5, 0), forward=(0, 0, 1), up=(0, 1, 0),
    volumes={"volumes": [{"center": [2.0, 1.0, 9.0], "radius": 3.0, "density": 0.6,
                          "fog_color": [0.9, 0.8, 0.7]}]},
)

RENDER = """
// A ground plane 1.5 below the eye, looking down +Z with a 60 degree vertical field of view:
// color by distance, raw depth (conventional Z) of the plane, the sky beyond the horizon.
__kernel void render(__global float4* color, __global float* depth, int w, int h, float near, float far) {
  int x = get_global_id(0), y = get_global_id(1);
  float t = tan(radians(30.0f));
  float ny = (1.0f - 2.0f * (y + 0.5f) / h) * t;
  if (ny >= -1e-3f) {  // above the horizon: the sky
    color[y * w + x] = (float4)(0.4f, 0.6f, 0.9f, 1.0f);
    depth[y * w + x] = 1.0f;
    return;
  }
  float z = min(1.5f / -ny, far);  // eye depth of the plane
  float check = fmod(floor(z) + floor((2.0f * (x + 0.5f) / w - 1.0f) * t * w / h * z), 2.0f);
  color[y * w + x] = (float4)(0.3f + 0.4f * check, 0.5f, 0.2f, 1.0f);
  // Unity's raw depth for conventional Z: (1/z - 1/near) / (1/far - 1/near)
  depth[y * w + x] = (1.0f / z - 1.0f / near) / (1.0f / far - 1.0f / near);
}
"""


def main():
    platform = next(p for p in cl.get_platforms() if p.get_devices(device_type=cl.device_type.CPU))
    device = platform.get_devices(device_type=cl.device_type.CPU)[0]
    ctx = cl.Context([device])
    queue = cl.CommandQueue(ctx)
    mf = cl.mem_flags
    color = cl.Buffer(ctx, mf.READ_WRITE, WIDTH * HEIGHT * 16)  # RGBA float32, packed rows
    depth = cl.Buffer(ctx, mf.READ_WRITE, WIDTH * HEIGHT * 4)
    fogged = cl.Buffer(ctx, mf.READ_WRITE, WIDTH * HEIGHT * 16)

    render = cl.Program(ctx, RENDER).build().render
    rendered = render(queue, (WIDTH, HEIGHT), None, color, depth, np.int32(WIDTH), np.int32(HEIGHT),
                      np.float32(NEAR), np.float32(FAR))

    # Load time: the passes build their programs for this frame size, format and options.
    with fogcl.VolumePass(ctx, queue=queue) as volumes, fogcl.FogPass(ctx, queue=queue) as fog:
        volumes.prepare(WIDTH, HEIGHT, "rgba32f", **OPTIONS)
        fog.prepare(WIDTH, HEIGHT, "rgba32f", **OPTIONS)
        # Each frame: the volumes in place on the rendered color, then the deferred fog into
        # `fogged`, each after the previous command's event. Nothing waits on the host.
        marched = volumes.enqueue(color, depth, width=WIDTH, height=HEIGHT, wait_for=[rendered], **OPTIONS)
        done = fog.enqueue(color, depth, fogged, width=WIDTH, height=HEIGHT, wait_for=[marched], **OPTIONS)
        out = np.empty((HEIGHT, WIDTH, 4), np.float32)
        cl.enqueue_copy(queue, out, fogged, wait_for=[done])

    # The check: fogcl.apply on the rendered pixels gives the same bits.
    plain = np.empty_like(out)
    z = np.empty((HEIGHT, WIDTH), np.float32)
    rendered_again = render(queue, (WIDTH, HEIGHT), None, color, depth, np.int32(WIDTH), np.int32(HEIGHT),
                            np.float32(NEAR), np.float32(FAR))
    cl.enqueue_copy(queue, plain, color, wait_for=[rendered_again])
    cl.enqueue_copy(queue, z, depth)
    want = fogcl.apply(plain, z, **OPTIONS)
    differ = int(np.count_nonzero(out.view(np.uint32) != want.view(np.uint32)))
    changed = int(np.count_nonzero(np.any(out != plain, axis=2)))
    print(f"{WIDTH}x{HEIGHT} frame fogged on {device.name.strip()}: {changed} pixels changed by the fog, "
          f"{differ} values differ from fogcl.apply")
    return 0 if differ == 0 and changed > 0 else 1


if __name__ == "__main__":
    raise SystemExit(main())
