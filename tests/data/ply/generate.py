#!/usr/bin/env python3
"""Writes the PLY test files of tests/test_ply.c (run from this folder).

One small mesh, a square pyramid: a quad base (a polygon of 4 corners, split into 2
triangles) and 4 side triangles, 6 triangles in all, with per-vertex normals and
texture coordinates. The same mesh is written in every format, with extra elements
and properties placed where a reader must skip them.
"""
import struct

V = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0.5, 0.5, 1)]
N = [(0, 0, -1), (0, 0, -1), (0, 0, -1), (0, 0, -1), (0, 0, 2)]   # not unit: the reader normalises
UV = [(0, 0), (1, 0), (1, 1), (0, 1), (0.5, 0.5)]
F = [(0, 3, 2, 1), (0, 1, 4), (1, 2, 4), (2, 3, 4), (3, 0, 4)]

def basic():
    lines = ["ply", "format ascii 1.0", "comment the pyramid, positions only",
             "obj_info written by generate.py", "element vertex 5", "property float x",
             "property float y", "property float z", "element face 5",
             "property list uchar int vertex_indices", "end_header"]
    lines += ["%g %g %g" % v for v in V]
    lines += [" ".join(str(x) for x in (len(f),) + f) for f in F]
    open("ascii-basic.ply", "w").write("\n".join(lines) + "\n")

HEADER_EXTRAS = """ply
format {fmt} 1.0
comment the pyramid with normals, uvs and things to skip
element vertex 5
property float confidence
property double x
property float y
property short z
property list uchar int neighbours
property float nx
property float ny
property float nz
property uchar red
property float s
property float t
element edge 2
property int vertex1
property int vertex2
element face 5
property uchar flags
property list uchar uint vertex_index
property list uchar float texcoord
end_header
"""

def extras_ascii():
    out = HEADER_EXTRAS.format(fmt="ascii").replace("\n", "\r\n")
    for i, v in enumerate(V):
        out += "0.5 %g %g %d 2 %d %d %g %g %g 255 %g %g\r\n" % (
            v[0], v[1], v[2], i, (i + 1) % 5, N[i][0], N[i][1], N[i][2], UV[i][0], UV[i][1])
    out += "0 1\r\n1 2\r\n"
    for f in F:
        out += "7 %d %s 2 0.25 0.75\r\n" % (len(f), " ".join(str(x) for x in f))
    open("ascii-extras.ply", "wb").write(out.encode())

def extras_binary(name, fmt, e):
    out = HEADER_EXTRAS.format(fmt=fmt).encode()
    for i, v in enumerate(V):
        out += struct.pack(e + "fdfhBiifffBff", 0.5, v[0], v[1], v[2], 2, i, (i + 1) % 5,
                           N[i][0], N[i][1], N[i][2], 255, UV[i][0], UV[i][1])
    out += struct.pack(e + "iiii", 0, 1, 1, 2)
    for f in F:
        out += struct.pack(e + "BB" + "I" * len(f) + "Bff", 7, len(f), *f, 2, 0.25, 0.75)
    open(name, "wb").write(out)

def face_first():
    lines = ["ply", "format ascii 1.0", "element face 5", "property list uchar int vertex_indices",
             "element vertex 5", "property float x", "property float y", "property float z",
             "end_header"]
    lines += [" ".join(str(x) for x in (len(f),) + f) for f in F]
    lines += ["%g %g %g" % v for v in V]
    open("face-first.ply", "w").write("\n".join(lines) + "\n")

basic()
extras_ascii()
extras_binary("binary-le.ply", "binary_little_endian", "<")
extras_binary("binary-be.ply", "binary_big_endian", ">")
face_first()
