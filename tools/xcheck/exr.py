"""exr.py -- reads the scanline OpenEXR files pbrt-v4 writes (its RGB film: channels B, G, R
in HALF or FLOAT, compression NONE, ZIPS or ZIP), with the standard library and numpy only.

The layout is the OpenEXR file format's ("OpenEXR File Layout", openexr.com): a header of
attributes (name, type, size, value) ending in a 0 byte, a table of chunk offsets, then
chunks of scanlines (one a chunk for NONE and ZIPS, 16 for ZIP), each chunk the scanlines
one after another and within a scanline each channel's pixels in the channels' (sorted)
order. ZIP data are zlib streams of bytes that were split into even and odd halves and
then delta-coded (the format's predictor); undoing those two steps gives the raw chunk.
Anything else (tiles, other compressions, deep data) is an error that names it.
"""
import struct
import zlib

import numpy as np

LINES_PER_CHUNK = {0: 1, 2: 1, 3: 16}          # NONE, ZIPS, ZIP
PIXEL_TYPES = {1: np.dtype("<f2"), 2: np.dtype("<f4")}   # HALF, FLOAT (UINT unused here)


def _header(data):
    pos, attrs = 8, {}
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        tend = data.index(b"\0", end + 1)
        kind = data[end + 1:tend].decode()
        size = struct.unpack_from("<i", data, tend + 1)[0]
        attrs[name] = (kind, data[tend + 5:tend + 5 + size])
        pos = tend + 5 + size
    return attrs, pos + 1


def _channels(raw):
    out, pos = [], 0
    while raw[pos] != 0:
        end = raw.index(b"\0", pos)
        ptype, _, xs, ys = struct.unpack_from("<iB3xii", raw, end + 1)
        out.append((raw[pos:end].decode(), ptype, xs, ys))
        pos = end + 17
    return out


def _unzip(chunk, size):
    t = np.frombuffer(zlib.decompress(chunk), dtype=np.uint8)
    if t.size != size:
        raise ValueError("a ZIP chunk of %d bytes, %d expected" % (t.size, size))
    # undo the predictor, t[i] = t[i-1] + d[i] - 128 (mod 256), the first byte as stored
    d = t.astype(np.int64) - 128
    d[0] = t[0]
    t = (np.cumsum(d) & 0xFF).astype(np.uint8)
    half = (size + 1) // 2
    out = np.empty(size, np.uint8)
    out[0::2], out[1::2] = t[:half], t[half:]
    return out.tobytes()


def read_exr(path):
    """-> float64 array (height, width, 3) in R, G, B order, row 0 the top."""
    with open(path, "rb") as f:
        data = f.read()
    magic, version = struct.unpack_from("<iI", data, 0)
    if magic != 20000630:
        raise ValueError("%s: not an OpenEXR file" % path)
    if version & 0x1E00:
        raise ValueError("%s: tiled, multi-part or deep OpenEXR (flags 0x%x): not read here" % (path, version))
    attrs, pos = _header(data)
    comp = attrs["compression"][1][0]
    if comp not in LINES_PER_CHUNK:
        raise ValueError("%s: OpenEXR compression %d not read here (NONE, ZIPS, ZIP are)" % (path, comp))
    x0, y0, x1, y1 = struct.unpack("<4i", attrs["dataWindow"][1])
    w, h = x1 - x0 + 1, y1 - y0 + 1
    chans = _channels(attrs["channels"][1])
    if any(c[1] not in PIXEL_TYPES or c[2] != 1 or c[3] != 1 for c in chans):
        raise ValueError("%s: a channel that is not HALF or FLOAT at full resolution" % path)
    lines = LINES_PER_CHUNK[comp]
    nchunks = (h + lines - 1) // lines
    offsets = struct.unpack_from("<%dQ" % nchunks, data, pos)
    planes = {c[0]: np.zeros((h, w)) for c in chans}
    for off in offsets:
        y, size = struct.unpack_from("<ii", data, off)
        n = min(lines, y1 + 1 - y)
        raw_size = n * w * sum(PIXEL_TYPES[c[1]].itemsize for c in chans)
        chunk = data[off + 8:off + 8 + size]
        raw = chunk if size == raw_size else _unzip(chunk, raw_size)
        p = 0
        for row in range(n):
            for name, ptype, _, _ in chans:
                dt = PIXEL_TYPES[ptype]
                planes[name][y - y0 + row] = np.frombuffer(raw, dt, w, p)
                p += w * dt.itemsize
    missing = [c for c in "RGB" if c not in planes]
    if missing:
        raise ValueError("%s: no %s channel" % (path, ",".join(missing)))
    return np.stack([planes["R"], planes["G"], planes["B"]], -1)
