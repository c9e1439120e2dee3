#!/usr/bin/env python3
"""Writes the small images that seed fuzz_texture (tests/data/images/): one 4x3 picture
in each uncompressed or simple format stb_image reads, so the fuzzer starts from every
decoder's real structure. Run from this folder; the output is committed."""
import struct
import zlib

W, H = 4, 3
PIX = [((x * 60) % 256, (y * 90) % 256, ((x + y) * 40) % 256) for y in range(H) for x in range(W)]


def bmp():
    row = (W * 3 + 3) & ~3
    data = b""
    for y in reversed(range(H)):
        line = b"".join(bytes((b, g, r)) for (r, g, b) in PIX[y * W:(y + 1) * W])
        data += line + b"\0" * (row - len(line))
    head = struct.pack("<2sIHHI", b"BM", 54 + len(data), 0, 0, 54)
    info = struct.pack("<IiiHHIIiiII", 40, W, H, 1, 24, 0, len(data), 2835, 2835, 0, 0)
    return head + info + data


def tga(rle):
    head = struct.pack("<BBBHHBHHHHBB", 0, 0, 10 if rle else 2, 0, 0, 0, 0, 0, W, H, 24, 0x20)
    body = b""
    for (r, g, b) in PIX:
        body += (b"\x00" if rle else b"") + bytes((b, g, r))   # RLE: one raw packet per pixel
    return head + body


def ppm():
    return b"P6\n%d %d\n255\n" % (W, H) + b"".join(bytes(p) for p in PIX)


def pgm():
    return b"P5\n%d %d\n255\n" % (W, H) + bytes(p[0] for p in PIX)


def hdr():
    head = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (H, W)
    return head + b"".join(bytes((r, g, b, 128)) for (r, g, b) in PIX)   # flat RGBE, no RLE


def png():
    raw = b"".join(b"\0" + b"".join(bytes(p) for p in PIX[y * W:(y + 1) * W]) for y in range(H))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


for name, data in [("tiny.bmp", bmp()), ("tiny.tga", tga(False)), ("tiny-rle.tga", tga(True)),
                   ("tiny.ppm", ppm()), ("tiny.pgm", pgm()), ("tiny.hdr", hdr()), ("tiny.png", png())]:
    with open(name, "wb") as f:
        f.write(data)
