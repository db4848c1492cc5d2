"""numpy frames without copies: the kernels read and write the arrays' memory where alignment lets
them (PassStats through stats=), strided rows and in-place fogging give the contiguous result's
bits, and the GIL is released while a frame is fogged."""

import threading

import numpy as np
import pytest

import fogcl
from frames import bits, random_frame, worst

OPTIONS = {"near": 0.3, "far": 1000, "fov": 60, "mode": "exp2", "density": 0.025, "fog_color": (0.62, 0.68, 0.76)}


def aligned_copy(a):
    b = fogcl.empty(a.shape, a.dtype)
    b[...] = a
    return b


@pytest.mark.parametrize("dtype", [np.float32, np.float16], ids=["float32", "float16"])
def test_page_aligned_arrays_are_fogged_in_place_of_copies(dtype):
    color, depth = random_frame(np.random.default_rng(10), 64, 96, dtype)
    expected = fogcl.apply(color, depth, **OPTIONS)
    c, d = aligned_copy(color), aligned_copy(depth)
    for a in (c, d):
        assert a.ctypes.data % 4096 == 0 and a.flags.c_contiguous
    out = fogcl.empty(color.shape, dtype)
    stats = {}
    got = fogcl.apply(c, d, out=out, stats=stats, **OPTIONS)
    print("aligned:", stats)
    assert got is out
    assert np.array_equal(bits(got), bits(expected))
    if stats.get("host_transfer") == "direct":  # a CPU device uses host memory where it is
        assert stats["zero_copy_frames"] == 1 and stats["copied_frames"] == 0
    # numpy's own memory is not at the device's alignment in general: then it is copied once.
    stats = {}
    fogcl.apply(color, depth, stats=stats, **OPTIONS)
    print("numpy.empty's memory:", stats)
    assert stats.get("kernel_dispatches", 1) == 1


@pytest.mark.parametrize("dtype", [np.float32, np.float16], ids=["float32", "float16"])
def test_strided_rows_and_in_place_give_the_contiguous_bits(dtype):
    rng = np.random.default_rng(11)
    for trial in range(6):
        h, w, pad = int(rng.integers(1, 50)), int(rng.integers(1, 50)), int(rng.integers(1, 9))
        color, depth = random_frame(rng, h, w, dtype)
        expected = fogcl.apply(color, depth, **OPTIONS)
        # Rows strided inside larger arrays, as slicing makes them.
        big_c = np.full((h, w + pad, 4), np.nan, dtype)
        big_c[:, pad:] = color
        big_d = np.full((h, w + pad), np.nan, np.float32)
        big_d[:, :w] = depth
        big_o = np.full((h, w + pad, 4), -7, dtype)
        c, d, o = big_c[:, pad:], big_d[:, :w], big_o[:, :w]
        assert not c.flags.c_contiguous or h == 1
        got = fogcl.apply(c, d, out=o, **OPTIONS)
        assert got is o
        assert np.array_equal(bits(np.ascontiguousarray(o)), bits(expected))
        assert np.all(big_o[:, w:] == -7)  # nothing outside the view written
        # In place: out is color itself.
        inplace = color.copy()
        fogcl.apply(inplace, depth, out=inplace, **OPTIONS)
        print(f"{h}x{w} pad {pad}: worst |strided - contiguous| = {worst(o, expected)}, "
              f"in place {worst(inplace, expected)}")
        assert np.array_equal(bits(inplace), bits(expected))


def test_the_gil_is_released_while_a_frame_is_fogged():
    """Another Python thread runs while fogcl.apply fogs: it sees a frame in flight. With the GIL
    held through the call it never could (no Python runs then)."""
    color, depth = random_frame(np.random.default_rng(12), 512, 512)
    fogcl.apply(color, depth, **OPTIONS)  # the device opened and the program built
    seen = []
    stop = threading.Event()

    def watch():
        while not stop.is_set():
            seen.append(fogcl._frames_in_flight())

    def fog(n):
        for _ in range(n):
            fogcl.apply(color, depth, **OPTIONS)

    watcher = threading.Thread(target=watch)
    workers = [threading.Thread(target=fog, args=(20,)) for _ in range(2)]
    watcher.start()
    for t in workers:
        t.start()
    for t in workers:
        t.join()
    stop.set()
    watcher.join()
    print(f"observations {len(seen)}, with a frame in flight {sum(1 for s in seen if s > 0)}, most at once {max(seen)}")
    assert max(seen) >= 1
    assert fogcl._frames_in_flight() == 0


def test_threads_give_the_bits_of_one_thread():
    rng = np.random.default_rng(13)
    frames = [random_frame(rng, 40, 60) for _ in range(8)]
    expected = [fogcl.apply(c, d, **OPTIONS) for c, d in frames]
    results = [None] * len(frames)

    def fog(i):
        results[i] = fogcl.apply(*frames[i], **OPTIONS)

    threads = [threading.Thread(target=fog, args=(i,)) for i in range(len(frames))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    print("worst |threaded - serial| =", max(worst(a, b) for a, b in zip(results, expected)))
    for a, b in zip(results, expected):
        assert np.array_equal(bits(a), bits(b))


def test_threads_that_open_the_device_at_once():
    """A fresh process whose first calls come from several threads at once: each opens the device
    (one at a time) and gets the serial bits."""
    import subprocess
    import sys
    script = """
import threading, numpy as np, fogcl
rng = np.random.default_rng(14)
frames = [(rng.uniform(0, 4, (16, 24, 4)).astype(np.float32), rng.uniform(0, 1, (16, 24)).astype(np.float32))
          for _ in range(4)]
options = dict(near=0.3, far=1000, fov=60, mode="exp2", density=0.025)
out = [None] * 4
def fog(i):
    out[i] = fogcl.apply(*frames[i], **options)
threads = [threading.Thread(target=fog, args=(i,)) for i in range(4)]
[t.start() for t in threads]
[t.join() for t in threads]
serial = [fogcl.apply(*f, **options) for f in frames]
print(max(float(np.abs(a - b).max()) for a, b in zip(out, serial)))
assert all(np.array_equal(a.view(np.uint32), b.view(np.uint32)) for a, b in zip(out, serial))
"""
    r = subprocess.run([sys.executable, "-X", "faulthandler", "-c", script], capture_output=True, text=True)
    print("worst |first threads - serial| =", r.stdout.strip(), r.stderr[-2000:])
    assert r.returncode == 0
