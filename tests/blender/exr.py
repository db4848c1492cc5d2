"""The uncompressed scanline OpenEXR files the Blender test writes, read with the standard library.

Cycles writes its multilayer EXR uncompressed there (exr_codec NONE) and fogcl writes with
--compression none, so no codec is needed: a header of attributes, a table of line offsets, then
one chunk per scanline holding each channel's row (channels in the header's order, which is
alphabetical). HALF and FLOAT channels are read; anything else is refused by name.
"""

import struct

MAGIC = b"\x76\x2f\x31\x01"
PIXEL_TYPES = {1: ("e", 2), 2: ("f", 4)}  # HALF, FLOAT (UINT = 0 is not used here)


class ExrError(Exception):
    pass


def _cstring(data, pos):
    end = data.index(b"\0", pos)
    return data[pos:end].decode("latin-1"), end + 1


def read(path):
    """Returns (width, height, {channel: [floats, row-major, top row first]})."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != MAGIC:
        raise ExrError("%s: not an OpenEXR file" % path)
    flags = struct.unpack_from("<I", data, 4)[0] >> 8
    if flags & (0x2 | 0x8 | 0x10):  # tiled, deep, multi-part
        raise ExrError("%s: only single-part scanline files are read here (version flags 0x%x)" % (path, flags))
    pos = 8
    header = {}
    while data[pos] != 0:
        name, pos = _cstring(data, pos)
        kind, pos = _cstring(data, pos)
        size = struct.unpack_from("<i", data, pos)[0]
        pos += 4
        header[name] = (kind, data[pos:pos + size])
        pos += size
    pos += 1
    if header["compression"][1] != b"\0":
        raise ExrError("%s: compressed (code %d); the test writes uncompressed files"
                       % (path, header["compression"][1][0]))
    x0, y0, x1, y1 = struct.unpack("<4i", header["dataWindow"][1])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    channels = []
    chlist = header["channels"][1]
    cpos = 0
    while chlist[cpos] != 0:
        name, cpos = _cstring(chlist, cpos)
        pixel_type, _, xs, ys = struct.unpack_from("<iB3xii", chlist, cpos)
        cpos += 16
        if pixel_type not in PIXEL_TYPES or xs != 1 or ys != 1:
            raise ExrError("%s: channel %s has pixel type %d, sampling %dx%d" % (path, name, pixel_type, xs, ys))
        channels.append((name, PIXEL_TYPES[pixel_type]))
    offsets = struct.unpack_from("<%dQ" % height, data, pos)
    planes = {name: [] for name, _ in channels}
    for offset in offsets:
        y, size = struct.unpack_from("<ii", data, offset)
        p = offset + 8
        for name, (code, nbytes) in channels:
            planes[name].extend(struct.unpack_from("<%d%s" % (width, code), data, p))
            p += width * nbytes
        if p != offset + 8 + size:
            raise ExrError("%s: scanline %d holds %d bytes, expected %d" % (path, y, size, p - offset - 8))
    return width, height, planes
