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


def hdr_rle():
    """8 wide (stb_image reads narrower images flat): per scanline the marker 2 2, the
    width, then each component as one literal packet."""
    w = 8
    head = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (H, w)
    body = b""
    for y in range(H):
        body += bytes((2, 2, 0, w))
        for k in range(4):
            body += bytes((w,)) + bytes(((x * 30 + y * 50 + k * 20) % 128 if k < 3 else 128) for x in range(w))
    return head + body


def psd(rle):
    """RGB, 8 bits, no mode data, resources or layers; RLE: one literal packet per row."""
    head = struct.pack(">4sH6xHIIHH", b"8BPS", 1, 3, H, W, 8, 3) + struct.pack(">III", 0, 0, 0)
    planes = [bytes(p[c] for p in PIX) for c in range(3)]
    if not rle:
        return head + struct.pack(">H", 0) + b"".join(planes)
    rows = [bytes((W - 1,)) + plane[y * W:(y + 1) * W] for plane in planes for y in range(H)]
    return head + struct.pack(">H", 1) + b"".join(struct.pack(">H", len(r)) for r in rows) + b"".join(rows)


def png():
    raw = b"".join(b"\0" + b"".join(bytes(p) for p in PIX[y * W:(y + 1) * W]) for y in range(H))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


for name, data in [("tiny.bmp", bmp()), ("tiny.tga", tga(False)), ("tiny-rle.tga", tga(True)),
                   ("tiny.ppm", ppm()), ("tiny.pgm", pgm()), ("tiny.hdr", hdr()), ("tiny.png", png()),
                   ("tiny-rle.hdr", hdr_rle()), ("tiny.psd", psd(False)), ("tiny-rle.psd", psd(True))]:
    with open(name, "wb") as f:
        f.write(data)

# The truncated images of ../bad/ (test_bad_input.c reads each with its .expect file):
# each of the above cut short, and an HDR header that claims 8192x8192 in 51 bytes.
BAD = [("truncated.tga", tga(False), 40, "an uncompressed TGA cut inside its pixels"),
       ("truncated-rle.tga", tga(True), 40, "a run-length TGA cut inside its packets"),
       ("truncated.bmp", bmp(), 60, "a 24-bit BMP cut inside its first row"),
       ("truncated.psd", psd(False), 50, "a raw PSD cut inside its red channel"),
       ("truncated-rle.psd", psd(True), 70, "a run-length PSD cut inside its packets"),
       ("truncated.hdr", hdr(), 60, "a flat HDR cut inside its pixels"),
       ("truncated-rle.hdr", hdr_rle(), 80, "a run-length HDR cut inside its first scanline"),
       ("huge-claim.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8192 +X 8192\n", None,
        "51 bytes of HDR header claiming 8192x8192 (stb_image allocated 1.5 GB for it)")]
for name, data, cut, why in BAD:
    with open("../bad/" + name, "wb") as f:
        f.write(data if cut is None else data[:cut])
