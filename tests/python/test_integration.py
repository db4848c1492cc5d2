"""fogcl.FogPass / fogcl.VolumePass on PyOpenCL's objects (docs/python.md, "On your PyOpenCL
context"): the same passes as fogcl.apply, bit for bit, on the caller's context, queue and buffers."""

import gc
import os
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

import fogcl

cl = pytest.importorskip("pyopencl", reason="python3-pyopencl is not installed (scripts/setup.sh installs it)")

ROOT = Path(__file__).resolve().parents[2]


def pocl_cpu():
    for platform in cl.get_platforms():
        if "Portable Computing Language" in platform.name:
            for device in platform.get_devices(device_type=cl.device_type.CPU):
                return device
    return None


DEVICE = pocl_cpu()
pytestmark = pytest.mark.skipif(DEVICE is None, reason="no PoCL CPU device (scripts/setup.sh installs pocl-opencl-icd)")


@pytest.fixture(scope="module")
def ctx():
    return cl.Context([DEVICE])


@pytest.fixture(scope="module")
def queue(ctx):
    return cl.CommandQueue(ctx)


def frame(rng, width, height, dtype=np.float32, sky=0.1):
    """Random color and raw depth (conventional Z; a fraction `sky` of pixels at 1, the sky)."""
    color = rng.uniform(0.0, 4.0, size=(height, width, 4)).astype(dtype)
    depth = rng.uniform(0.0, 1.0, size=(height, width)).astype(np.float32) ** 0.25
    depth[rng.random((height, width)) < sky] = 1.0
    return color, depth


def to_device(ctx, array):
    flags = cl.mem_flags.READ_WRITE | cl.mem_flags.COPY_HOST_PTR
    return cl.Buffer(ctx, flags, hostbuf=np.ascontiguousarray(array))


def from_device(queue, buffer, like, wait_for=None):
    out = np.empty_like(like)
    cl.enqueue_copy(queue, out, buffer, wait_for=wait_for)
    return out


def report_bits(name, got, want):
    """Prints the worst difference (also when there is none) and returns how many values differ."""
    g = got.astype(np.float64)
    w = want.astype(np.float64)
    worst = float(np.nanmax(np.abs(g - w))) if g.size else 0.0
    differ = int(np.count_nonzero(got.view(np.uint8) != want.view(np.uint8)))
    print(f"{name}: worst |difference| {worst:.3g}, {differ} bytes differ of {got.nbytes}")
    return differ


DEFERRED_CASES = [
    dict(mode="exp2", density=0.05),
    dict(mode="exp", density=0.2, distance=True),
    dict(mode="linear", start=0.5, end=20.0, fog_color=(0.3, 0.5, 0.9)),
    dict(mode="exp2", density=0.08, fog_skybox=True),
    dict(mode="exp", density=0.1, reversed_z=True),
    dict(mode="height", density=0.05, height_falloff=0.3, base_height=-1.0, sun_color=(1.0, 0.9, 0.7),
         light_dir=(0.3, 0.5, 1.0), eye=(0, 1.5, 0), forward=(0, 0, 1), up=(0, 1, 0)),
    dict(mode="off"),
]


@pytest.mark.parametrize("case", range(len(DEFERRED_CASES)))
@pytest.mark.parametrize("dtype", [np.float32, np.float16])
def test_fog_pass_equals_apply_bit_for_bit(ctx, queue, case, dtype):
    options = dict(near=0.3, far=100.0, fov=60.0, **DEFERRED_CASES[case])
    rng = np.random.default_rng(1000 + case)
    width, height = int(rng.integers(17, 90)), int(rng.integers(9, 60))
    color, depth = frame(rng, width, height, dtype)
    if options.get("reversed_z"):
        depth = 1.0 - depth
    fmt = "rgba32f" if dtype == np.float32 else "rgba16f"
    want = fogcl.apply(color, depth, **options)

    fog = fogcl.FogPass(ctx, queue=queue)
    fog.prepare(width, height, fmt, **options)
    c, d, o = to_device(ctx, color), to_device(ctx, depth), to_device(ctx, np.zeros_like(color))
    event = fog.enqueue(c, d, o, width=width, height=height, format=fmt, **options)
    assert isinstance(event, cl.Event)
    got = from_device(queue, o, color, wait_for=[event])
    assert report_bits(f"FogPass {options} {fmt} {width}x{height}", got, want) == 0
    if options["mode"] != "off":
        assert np.any(got != color), "the fog changed no pixel: the test would not see a wrong pass"
    # In place (out left out): the same bytes in the color buffer itself.
    event = fog.enqueue(c, d, width=width, height=height, format=fmt, **options)
    got = from_device(queue, c, color, wait_for=[event])
    assert report_bits("  in place", got, want) == 0


def volumes_document(rng, count):
    """Dense spheres in front of the camera, which looks down +Z from the origin (VOLUME_OPTIONS),
    with library.md's settings for volumes a few units across (the defaults suit tens of units)."""
    volumes = []
    for _ in range(count):
        radius = float(rng.uniform(1.0, 3.0))
        volumes.append({
            "center": [float(rng.uniform(-2, 2)), float(rng.uniform(-1, 1)), float(rng.uniform(2, 6))],
            "radius": radius,
            "density": float(rng.uniform(2.0, 6.0)),
            "fade_edge": 0.25 * radius,
            "proximity_fade": 1.0,
            "tiling": [0.25, 0.25, 0.25],
            "detail_tiling": [0.25, 0.25, 0.25],
            "fog_color": [float(x) for x in rng.uniform(0.2, 1.0, 3)] + [1.0],
        })
    return {"volumes": volumes}


VOLUME_OPTIONS = dict(near=0.3, far=100.0, fov=60.0, eye=(0, 0, 0), forward=(0, 0, 1), up=(0, 1, 0), steps=12)


@pytest.mark.parametrize("seed", range(3))
def test_volume_pass_equals_apply_bit_for_bit(ctx, queue, seed):
    rng = np.random.default_rng(2000 + seed)
    width, height = int(rng.integers(20, 80)), int(rng.integers(12, 50))
    color, depth = frame(rng, width, height)
    options = dict(VOLUME_OPTIONS, volumes=volumes_document(rng, 1 + seed), mode="off")
    if seed == 2:
        options.update(integrator="physical", volume_resolution="full")
    want = fogcl.apply(color, depth, **options)

    volumes = fogcl.VolumePass(ctx, device=DEVICE, queue=queue)
    volumes.prepare(width, height, **options)
    c, d, o = to_device(ctx, color), to_device(ctx, depth), to_device(ctx, np.zeros_like(color))
    event = volumes.enqueue(c, d, o, width=width, height=height, **options)
    got = from_device(queue, o, color, wait_for=[event])
    assert report_bits(f"VolumePass seed {seed} {width}x{height}", got, want) == 0
    assert np.any(got != color), "the volumes changed no pixel: the test would not see a wrong pass"


def test_volume_pass_with_a_shadow_map(ctx, queue, tmp_path):
    """shadow_map= (a file, as fogcl.apply reads it) goes to the device with the frame: the same
    bits as fogcl.apply, and not those of the frame without it."""
    rng = np.random.default_rng(2500)
    width, height = 48, 32
    color, depth = frame(rng, width, height)
    fogcl.write_exr_depth(str(tmp_path / "shadow.exr"), rng.uniform(0.0, 0.35, (24, 20)).astype(np.float32))
    # An orthographic light above the volumes looking down: x / 10, (z - 6) / 8, depth (5 - y) / 15.
    light = [0.1, 0, 0, 0, 0, 0, 0.125, -0.75, 0, -1 / 15, 0, 1 / 3, 0, 0, 0, 1]
    document = volumes_document(rng, 2)
    lit = dict(VOLUME_OPTIONS, volumes=document, mode="off")
    options = dict(lit, shadow_map=tmp_path / "shadow.exr", light_view_proj=light)
    want = fogcl.apply(color, depth, **options)

    volumes = fogcl.VolumePass(ctx, queue=queue)
    volumes.prepare(width, height, **options)
    c, d, o = to_device(ctx, color), to_device(ctx, depth), to_device(ctx, np.zeros_like(color))
    event = volumes.enqueue(c, d, o, width=width, height=height, **options)
    got = from_device(queue, o, color, wait_for=[event])
    assert report_bits("VolumePass with a shadow map", got, want) == 0
    unshadowed = fogcl.apply(color, depth, **lit)
    print(f"  the shadow changes the frame by up to {np.abs(want - unshadowed).max():.3g}")
    assert np.any(got != unshadowed)

    # The next frames reuse the map on the device while its file is unchanged, and read it again
    # once it is rewritten (another size, so its size and time both change).
    event = volumes.enqueue(c, d, o, width=width, height=height, **options)
    assert report_bits("VolumePass, the same map again", from_device(queue, o, color, wait_for=[event]), want) == 0
    fogcl.write_exr_depth(str(tmp_path / "shadow.exr"), np.ones((30, 26), np.float32))  # nothing in shadow
    rewritten = fogcl.apply(color, depth, **options)
    assert np.any(rewritten != want), "the new map would not show"
    event = volumes.enqueue(c, d, o, width=width, height=height, **options)
    assert report_bits("VolumePass, the map rewritten", from_device(queue, o, color, wait_for=[event]), rewritten) == 0


CHAINED_CASES = {
    "volumes": lambda rng: dict(VOLUME_OPTIONS, volumes=volumes_document(rng, 2), mode="exp2", density=0.05),
    # The height fog marched with the volumes (the deferred pass then runs none of it).
    "height-volumetric": lambda rng: dict(VOLUME_OPTIONS, volumes=volumes_document(rng, 1), mode="height",
                                          density=0.08, height_falloff=0.2, height_volumetric=True,
                                          light_dir=(0.2, 1.0, 0.4)),
}


@pytest.mark.parametrize("case", sorted(CHAINED_CASES))
def test_chained_passes_equal_apply_with_both(ctx, case):
    """The volumes, then the deferred fog on their result, chained by events on an out-of-order
    queue: fogcl.apply runs the same two passes in the same order (docs/DESIGN.md §5)."""
    props = cl.command_queue_properties.OUT_OF_ORDER_EXEC_MODE_ENABLE
    queue = cl.CommandQueue(ctx, properties=props)
    rng = np.random.default_rng(3000)
    width, height = 64, 40
    color, depth = frame(rng, width, height)
    options = CHAINED_CASES[case](rng)
    want = fogcl.apply(color, depth, **options)

    volumes = fogcl.VolumePass(ctx, queue=queue)
    fog = fogcl.FogPass(ctx, queue=queue)
    volumes.prepare(width, height, **options)
    fog.prepare(width, height, **options)
    c, d = to_device(ctx, color), to_device(ctx, depth)
    mid, out = to_device(ctx, np.zeros_like(color)), to_device(ctx, np.zeros_like(color))
    marched = volumes.enqueue(c, d, mid, width=width, height=height, **options)
    fogged = fog.enqueue(mid, d, out, width=width, height=height, wait_for=[marched], **options)
    got = from_device(queue, out, color, wait_for=[fogged])
    assert report_bits(f"VolumePass -> FogPass (wait_for), {case}", got, want) == 0
    assert np.any(got != color)
    assert fogged.command_execution_status == cl.command_execution_status.COMPLETE


def test_enqueue_waits_for_its_events(ctx, queue):
    """A user event holds the pass back until it is set: the output stays untouched till then."""
    width, height = 32, 16
    rng = np.random.default_rng(4000)
    color, depth = frame(rng, width, height)
    options = dict(near=0.3, far=100.0, fov=60.0, mode="exp", density=0.3)
    fog = fogcl.FogPass(ctx, queue=queue)
    fog.prepare(width, height, **options)
    c, d = to_device(ctx, color), to_device(ctx, depth)
    zeros = np.zeros_like(color)
    o = to_device(ctx, zeros)
    gate = cl.UserEvent(ctx)
    event = fog.enqueue(c, d, o, width=width, height=height, wait_for=[gate], **options)
    queue.flush()
    statuses = [event.command_execution_status for _ in range(3)]
    print("event status before the gate opens:", statuses)
    assert all(s != cl.command_execution_status.COMPLETE for s in statuses)
    gate.set_status(cl.command_execution_status.COMPLETE)
    event.wait()
    got = from_device(queue, o, color)
    assert report_bits("after the gate", got, fogcl.apply(color, depth, **options)) == 0


def test_one_pass_shared_by_threads(ctx):
    """Threads enqueue on one pass, each on its own queue with its own settings: the pass takes one
    call at a time (its kernels carry arguments from setArg to the enqueue), so every frame is the
    one fogcl.apply makes of its options."""
    width, height = 40, 24
    rng = np.random.default_rng(6000)
    color, depth = frame(rng, width, height)
    densities = [0.02, 0.05, 0.1, 0.3]
    fog = fogcl.FogPass(ctx)
    for density in densities:
        fog.prepare(width, height, near=0.3, far=100.0, fov=60.0, mode="exp", density=density)
    wants = [fogcl.apply(color, depth, near=0.3, far=100.0, fov=60.0, mode="exp", density=x) for x in densities]
    differ = [0] * len(densities)
    FRAMES = 60

    def run(i):
        # The frames are enqueued back to back, each into its own buffer, and read at the end: the
        # threads' enqueues interleave as closely as they can.
        queue = cl.CommandQueue(ctx)
        c, d = to_device(ctx, color), to_device(ctx, depth)
        outs = [cl.Buffer(ctx, cl.mem_flags.READ_WRITE, color.nbytes) for _ in range(FRAMES)]
        events = [fog.enqueue(c, d, o, width=width, height=height, queue=queue, near=0.3, far=100.0, fov=60.0,
                              mode="exp", density=densities[i]) for o in outs]
        for o, event in zip(outs, events):
            got = from_device(queue, o, color, wait_for=[event])
            differ[i] += int(np.count_nonzero(got.view(np.uint32) != wants[i].view(np.uint32)))

    threads = [threading.Thread(target=run, args=(i,)) for i in range(len(densities))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    print(f"values differing from fogcl.apply per thread ({FRAMES} frames each):", differ)
    assert differ == [0] * len(densities)


def test_many_frames_leak_nothing():
    """300 frames through both passes: whatever a frame takes it gives back. PoCL keeps references
    of its own (to the last commands' events, and each live event holds its queue), so the counts
    are compared between frames: the OpenCL reference counts of the context, the queue (which a
    leaked event would raise) and the buffers are the same after frame 300 as after frame 100,
    and Python's objects grow by less than one a frame. A marker's event, which PoCL keeps no
    reference to, holds exactly the one its Python object owns; released passes give the context
    back."""
    gc.collect()  # what earlier tests left is not this test's to count
    ctx = cl.Context([DEVICE])  # its own context: no other test's objects come and go on it
    queue = cl.CommandQueue(ctx)
    width, height = 24, 16
    rng = np.random.default_rng(5000)
    color, depth = frame(rng, width, height)
    options = dict(VOLUME_OPTIONS, volumes=volumes_document(rng, 1), mode="exp2", density=0.05)
    c, d = to_device(ctx, color), to_device(ctx, depth)
    mid, out = to_device(ctx, np.zeros_like(color)), to_device(ctx, np.zeros_like(color))
    queue.finish()
    before_passes = ctx.reference_count

    volumes, fog = fogcl.VolumePass(ctx, queue=queue), fogcl.FogPass(ctx, queue=queue)
    volumes.prepare(width, height, **options)
    fog.prepare(width, height, **options)
    counts = []
    for i in range(300):
        marched = volumes.enqueue(c, d, mid, width=width, height=height, **options)
        fogged = fog.enqueue(mid, d, out, width=width, height=height, wait_for=[marched], **options)
        fogged.wait()
        del marched, fogged
        if i in (99, 299):
            queue.finish()
            gc.collect()
            counts.append((len(gc.get_objects()), ctx.reference_count, queue.reference_count, c.reference_count,
                           d.reference_count, mid.reference_count, out.reference_count))
    print("after frame 100 and 300 (objects, context, queue, color, depth, mid, out):", counts)
    assert counts[0][1:] == counts[1][1:]
    assert counts[1][0] - counts[0][0] < 200, "Python objects grew by one a frame or more"

    # Fog off in place: the pass enqueues a marker after the event it is given.
    gate = cl.UserEvent(ctx)
    marker = fog.enqueue(c, d, width=width, height=height, wait_for=[gate], **dict(options, mode="off"))
    gate.set_status(cl.command_execution_status.COMPLETE)
    queue.finish()
    print("reference count of the marker's event:", marker.reference_count)
    assert marker.reference_count == 1
    second = cl.Event.from_int_ptr(marker.int_ptr)  # a second owner (retains)
    assert second.reference_count == 2
    del marker
    gc.collect()
    assert second.reference_count == 1, "the Python object owned exactly one reference and gave it back"

    volumes.release()
    fog.release()
    del second, gate
    queue.finish()
    gc.collect()
    print(f"context reference count: {before_passes} before the passes, {ctx.reference_count} after release()")
    assert ctx.reference_count == before_passes


def test_with_block_releases_and_a_released_pass_says_so(ctx, queue):
    before = ctx.reference_count
    with fogcl.FogPass(ctx, queue=queue) as fog:
        assert ctx.reference_count > before
        assert fog.context == ctx
    assert fog.released
    assert ctx.reference_count == before
    with pytest.raises(ValueError, match="released"):
        fog.prepare(8, 8, near=0.3, far=100.0, fov=60.0, mode="off")
    with pytest.raises(ValueError, match="released"):
        fog.enqueue(None, None, width=8, height=8)


def test_file_camera_as_fogcl_apply_takes_it(ctx, queue, tmp_path):
    """camera= (fogcl.read_exr(...).camera) is taken as fogcl.apply takes it: a file without
    worldToNDC gives no fov (the same message), and with fov= the same bits."""
    rng = np.random.default_rng(7000)
    width, height = 30, 20
    color, depth = frame(rng, width, height)
    fogcl.write_exr(str(tmp_path / "color.exr"), color)
    fogcl.write_exr_depth(str(tmp_path / "depth.exr"), depth)
    read = fogcl.read_exr(str(tmp_path / "color.exr"), depth=str(tmp_path / "depth.exr"))
    options = dict(camera=read.camera, near=0.3, far=100.0, mode="exp", density=0.2)
    fog = fogcl.FogPass(ctx, queue=queue)
    with pytest.raises(ValueError) as ours:
        fog.prepare(width, height, **options)
    with pytest.raises(ValueError) as theirs:
        fogcl.apply(read.color, read.depth, **options)
    print(f"FogPass: {ours.value}\nfogcl.apply: {theirs.value}")
    assert str(ours.value) == str(theirs.value).replace("fogcl.apply", "fogcl.FogPass.prepare", 1)

    options["fov"] = 50.0
    fog.prepare(width, height, **options)
    c, d, o = to_device(ctx, read.color), to_device(ctx, read.depth), to_device(ctx, np.zeros_like(read.color))
    event = fog.enqueue(c, d, o, width=width, height=height, **options)
    got = from_device(queue, o, read.color, wait_for=[event])
    assert report_bits("camera= and fov=", got, fogcl.apply(read.color, read.depth, **options)) == 0


def bad_call(ctx, q, **change):
    """FogPass.enqueue of an 8x4 float frame with one argument changed."""
    width, height = 8, 4
    args = dict(color=cl.Buffer(ctx, cl.mem_flags.READ_WRITE, width * height * 16),
                depth=cl.Buffer(ctx, cl.mem_flags.READ_WRITE, width * height * 4),
                out=None, width=width, height=height, queue=q, wait_for=None)
    args.update(change)
    fog = fogcl.FogPass(ctx, queue=q)
    options = dict(near=0.3, far=100.0, fov=60.0, mode="exp", density=0.1)
    fog.prepare(width, height, **options)
    return fog.enqueue(args.pop("color"), args.pop("depth"), args.pop("out"), **args, **options)


def test_misuse_is_a_value_error_naming_the_value(ctx, queue):
    other = cl.Context([DEVICE])
    other_queue = cl.CommandQueue(other)
    cases = [
        (dict(color=cl.Buffer(ctx, cl.mem_flags.READ_WRITE, 8 * 4 * 8)), r"color: .*256 bytes.*512"),
        (dict(depth=cl.Buffer(ctx, cl.mem_flags.READ_WRITE, 8 * 4 * 4 + 4)), r"depth: .*132 bytes.*128"),
        (dict(out=cl.Buffer(ctx, cl.mem_flags.READ_WRITE, 16)), r"out: .*16 bytes"),
        (dict(queue=other_queue), r"queue: .*another OpenCL context"),
        (dict(color=cl.Buffer(other, cl.mem_flags.READ_WRITE, 8 * 4 * 16)), r"color: .*another OpenCL context"),
        (dict(wait_for=[cl.UserEvent(other)]), r"wait_for\[0\]: .*another OpenCL context"),
        (dict(width=0), r"enqueue: width and height must be at least 1 \(got 0x4\)"),
    ]
    for change, message in cases:
        with pytest.raises(ValueError, match=message) as caught:
            bad_call(ctx, queue, **change)
        print(f"{sorted(change)}: {caught.value}")
    with pytest.raises(TypeError, match="color must be a pyopencl.Buffer"):
        bad_call(ctx, queue, color=np.zeros((4, 8, 4), np.float32))
    with pytest.raises(TypeError, match=r"wait_for\[0\] must be a pyopencl.Event"):
        bad_call(ctx, queue, wait_for=[None])


def test_pass_setup_errors(ctx, queue):
    other_queue = cl.CommandQueue(cl.Context([DEVICE]))
    with pytest.raises(ValueError, match="queue: the queue belongs to another OpenCL context"):
        fogcl.FogPass(ctx, queue=other_queue)
    with pytest.raises(TypeError, match="context must be a pyopencl.Context"):
        fogcl.VolumePass(queue)
    fog = fogcl.FogPass(ctx)  # one device: it is the pass's
    c, d = cl.Buffer(ctx, cl.mem_flags.READ_WRITE, 64), cl.Buffer(ctx, cl.mem_flags.READ_WRITE, 16)
    with pytest.raises(ValueError, match="no queue: give queue="):
        fog.enqueue(c, d, width=2, height=2, near=0.3, far=100.0, fov=60.0, mode="exp", density=0.1)
    with pytest.raises(ValueError, match="not prepared"):
        fog.enqueue(c, d, width=2, height=2, queue=queue, near=0.3, far=100.0, fov=60.0, mode="exp", density=0.1)
    with pytest.raises(ValueError, match="format must be 'rgba32f'"):
        fog.prepare(2, 2, "float64", near=0.3, far=100.0, fov=60.0, mode="off")
    with pytest.raises(ValueError, match="--nearr|nearr"):
        fog.prepare(2, 2, nearr=0.3)
    camera = dict(near=0.3, far=100.0, mode="exp", density=0.1)
    with pytest.raises(ValueError, match=r"^fogcl.FogPass.prepare: no --fov or --focal-length given \(nor --ortho-size\)"):
        fog.prepare(2, 2, **camera)
    with pytest.raises(ValueError, match=r"prepare: give either --fov .* or --ortho-size .*, not both"):
        fog.prepare(2, 2, fov=60.0, ortho_size=3.0, **camera)
    for key, value in [("device", "cpu"), ("max_error", 1e-3), ("host_transfer", "staged"), ("max_memory", "1G")]:
        with pytest.raises(ValueError, match=f"enqueue: {key}= is fogcl.apply's"):
            fog.enqueue(c, d, width=2, height=2, queue=queue, fov=60.0, **camera, **{key: value})
    with pytest.raises(TypeError, match="camera must be a fogcl.Camera"):
        fog.prepare(2, 2, camera="wide", fov=60.0, **camera)
    volumes = fogcl.VolumePass(ctx, queue=queue)
    with pytest.raises(ValueError, match="no volumes: give volumes="):
        volumes.prepare(2, 2, near=0.3, far=100.0, fov=60.0, mode="off")


def test_example_runs():
    """examples/python/pyopencl_pass.py: a renderer's frame on the device, fogged there."""
    env = dict(os.environ)
    result = subprocess.run([sys.executable, str(ROOT / "examples/python/pyopencl_pass.py")], env=env,
                            capture_output=True, text=True, timeout=300)
    print(result.stdout, result.stderr)
    assert result.returncode == 0
    assert "0 values differ" in result.stdout
