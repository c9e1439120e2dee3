#!/usr/bin/env python3
"""make_gltf.py — writes the small hand-made glTF files of the tests.

    python3 tests/data/gltf/make_gltf.py     (from the project root)

Good files go to tests/data/gltf/ (tests/test_gltf.c checks what they load into), bad
ones to tests/data/bad/ with a NAME.expect beside each (tests/test_bad_input.c checks
the exact message); all of them seed fuzz/fuzz_gltf.c. The committed files are this
script's output.
"""
import base64
import json
import os
import struct
import zlib

GOOD = "tests/data/gltf"
BAD = "tests/data/bad"


def data_uri(raw):
    return "data:application/octet-stream;base64," + base64.b64encode(raw).decode()


def f32(*v):
    return struct.pack("<%df" % len(v), *v)


def doc(buffers, views, accessors, meshes, nodes, extra=None):
    d = {
        "asset": {"version": "2.0", "generator": "clpt tests/data/gltf/make_gltf.py"},
        "buffers": buffers,
        "bufferViews": views,
        "accessors": accessors,
        "meshes": meshes,
        "nodes": nodes,
        "scenes": [{"nodes": [i for i, n in enumerate(nodes) if not n.get("_child")]}],
        "scene": 0,
    }
    for n in nodes:
        n.pop("_child", None)
    d.update(extra or {})
    return d


def write_json(path, d):
    with open(path, "w") as f:
        json.dump(d, f, indent=1)
        f.write("\n")


def glb(d, bin_chunk):
    js = json.dumps(d).encode()
    js += b" " * (-len(js) % 4)
    bin_chunk += b"\0" * (-len(bin_chunk) % 4)
    body = struct.pack("<II", len(js), 0x4E4F534A) + js
    if bin_chunk:
        body += struct.pack("<II", len(bin_chunk), 0x004E4942) + bin_chunk
    return struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body


def write_bad(name, content, status, message):
    path = os.path.join(BAD, name)
    mode = "wb" if isinstance(content, bytes) else "w"
    with open(path, mode) as f:
        f.write(content)
    with open(path + ".expect", "w") as f:
        f.write("# status: %s\n# message: %s\n" % (status, message % {"p": path}))


# A unit quad in z = 0 (corners 0..3 counter-clockwise from +z), as one triangle list.
QUAD = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]


def simple_triangle():
    """One triangle, positions only, in a data: buffer."""
    raw = f32(0, 0, 0, 1, 0, 0, 0, 1, 0)
    return doc([{"byteLength": len(raw), "uri": data_uri(raw)}],
               [{"buffer": 0, "byteLength": len(raw)}],
               [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
               [{"primitives": [{"attributes": {"POSITION": 0}}]}],
               [{"mesh": 0}]), raw


def strided():
    """POSITION and NORMAL interleaved (byteStride 28 with 4 bytes of padding),
    TEXCOORD_0 as normalized unsigned bytes (stride 4, 2 of padding), indices as
    unsigned bytes."""
    inter = b""
    for p in QUAD:
        inter += f32(*p) + f32(0, 0, 1) + b"\xee\xee\xee\xee"
    uv = b""
    for p in QUAD:
        uv += bytes([int(p[0] * 255), int(p[1] * 255), 0xaa, 0xaa])
    idx = bytes([0, 1, 2, 0, 2, 3])
    raw = inter + uv + idx
    return doc([{"byteLength": len(raw), "uri": data_uri(raw)}],
               [{"buffer": 0, "byteLength": len(inter), "byteStride": 28},
                {"buffer": 0, "byteOffset": len(inter), "byteLength": len(uv), "byteStride": 4},
                {"buffer": 0, "byteOffset": len(inter) + len(uv), "byteLength": len(idx)}],
               [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
                {"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 4, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5121, "normalized": True, "count": 4, "type": "VEC2"},
                {"bufferView": 2, "componentType": 5121, "count": 6, "type": "SCALAR"}],
               [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3}]}],
               [{"mesh": 0}])


def sparse():
    """Positions as normalized shorts, then a sparse part that moves vertex 2 to
    (16384, 16384, 8192) / 32767: an unsigned short index list and values of the
    accessor's own component type."""
    base = b""
    for p in QUAD:
        base += struct.pack("<3h", *[int(c * 32767) for c in p]) + b"\0\0"
    ind = struct.pack("<H", 2) + b"\0\0"
    val = struct.pack("<3h", 16384, 16384, 8192) + b"\0\0"
    raw = base + ind + val
    idx = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    raw += idx
    return doc([{"byteLength": len(raw), "uri": data_uri(raw)}],
               [{"buffer": 0, "byteLength": len(base), "byteStride": 8},
                {"buffer": 0, "byteOffset": len(base), "byteLength": 4},
                {"buffer": 0, "byteOffset": len(base) + 4, "byteLength": 6},
                {"buffer": 0, "byteOffset": len(base) + len(ind) + len(val), "byteLength": len(idx)}],
               [{"bufferView": 0, "componentType": 5122, "normalized": True, "count": 4, "type": "VEC3",
                 "sparse": {"count": 1, "indices": {"bufferView": 1, "componentType": 5123},
                            "values": {"bufferView": 2}}},
                {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}],
               [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
               [{"mesh": 0}])


def strips():
    """A triangle strip of 5 vertices (3 triangles) and a fan of 5 (3 triangles), not
    indexed, every triangle facing +z."""
    strip = f32(0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0)
    fan = f32(0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1, -1, 1, 1)
    raw = strip + fan
    return doc([{"byteLength": len(raw), "uri": data_uri(raw)}],
               [{"buffer": 0, "byteLength": len(strip)},
                {"buffer": 0, "byteOffset": len(strip), "byteLength": len(fan)}],
               [{"bufferView": 0, "componentType": 5126, "count": 5, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5126, "count": 5, "type": "VEC3"}],
               [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 5},
                                {"attributes": {"POSITION": 1}, "mode": 6}]}],
               [{"mesh": 0}])


def nodes():
    """A triangle under a parent translated by (10, 0, 0) and rotated 90 degrees about
    +y, the child scaled by 2 through a matrix; two cameras (a perspective one on the
    first node, an orthographic one named "top"); a point, a spot and a directional
    light; a material with every supported extension."""
    d, raw = simple_triangle()
    s = 0.5 ** 0.5
    d["nodes"] = [
        {"translation": [10, 0, 0], "rotation": [0, s, 0, s], "children": [1, 2]},
        {"matrix": [2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1], "mesh": 0},
        {"camera": 0, "name": "front", "translation": [0, 0, 5]},
        {"camera": 1, "translation": [0, 10, 0], "rotation": [-s, 0, 0, s]},
        {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [1, 2, 3]},
        {"extensions": {"KHR_lights_punctual": {"light": 1}}, "rotation": [-s, 0, 0, s]},
        {"extensions": {"KHR_lights_punctual": {"light": 2}}},
    ]
    d["scenes"] = [{"nodes": [0, 3, 4, 5, 6]}]
    d["cameras"] = [
        {"type": "perspective", "perspective": {"yfov": 0.5, "aspectRatio": 2.0, "znear": 0.1}},
        {"type": "orthographic", "name": "top", "orthographic": {"xmag": 3, "ymag": 3, "znear": 0.1, "zfar": 100}},
    ]
    d["extensionsUsed"] = ["KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_ior",
                           "KHR_materials_transmission", "KHR_materials_clearcoat", "EXT_unknown_thing"]
    d["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"type": "point", "intensity": 683, "color": [1, 0.5, 0.25]},
        {"type": "directional", "intensity": 1366},
        {"type": "spot", "intensity": 68.3, "spot": {"innerConeAngle": 0.25, "outerConeAngle": 0.5}},
    ]}}
    d["materials"] = [{
        "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 0.125, 1], "metallicFactor": 0.5,
                                 "roughnessFactor": 0.75},
        "emissiveFactor": [1, 0.5, 0],
        "doubleSided": True,
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4},
                       "KHR_materials_ior": {"ior": 1.33},
                       "KHR_materials_transmission": {"transmissionFactor": 0.5},
                       "KHR_materials_clearcoat": {"clearcoatFactor": 0.7, "clearcoatRoughnessFactor": 0.2}},
    }]
    d["meshes"][0]["primitives"][0]["material"] = 0
    return d, raw


def quat_axis(axis, degrees):
    import math
    x, y, z = axis
    n = math.sqrt(x * x + y * y + z * z)
    h = math.radians(degrees) / 2
    s = math.sin(h) / n
    return [x * s, y * s, z * s, math.cos(h)]


def trs(t=(0, 0, 0), q=(0, 0, 0, 1), s=(1, 1, 1)):
    """T . R . S as a row-major 4x4 (glTF 2.0, 3.5.3), the quaternion normalised."""
    import math
    n = math.sqrt(sum(c * c for c in q))
    x, y, z, w = (c / n for c in q)
    r = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    return [[r[i][0] * s[0], r[i][1] * s[1], r[i][2] * s[2], t[i]] for i in range(3)] + [[0, 0, 0, 1]]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def column_major(m):
    return [m[r][c] for c in range(4) for r in range(4)]


# The instanced cube's placements (issue 42): moved, rotated, stretched, and a child of
# a mirroring parent. EXT_mesh_gpu_instancing's entries, under a node moved by (0, 0, -1):
# TRANSLATION floats, ROTATION normalized shorts, SCALE floats.
CUBE_NODES = [
    {"translation": [0, 0.5, 0]},
    {"translation": [2, 0.5, 0], "rotation": quat_axis((0, 1, 0), 30)},
    {"translation": [-2, 0.7, 0.5], "rotation": quat_axis((1, 1, 0), 25), "scale": [1, 1.4, 0.6]},
]
MIRROR_PARENT = {"translation": [0, 0, -2], "scale": [-1, 1, 1]}
MIRROR_CHILD = {"translation": [1, 0.5, 0]}
GPU_NODE = {"translation": [0, 0, 2]}
GPU_T = [(-1.5, 0.3, 0), (0, 0.3, 0.3), (1.5, 0.5, 0), (0.5, 1.4, -0.5)]
GPU_R = [quat_axis((0, 1, 0), 0), quat_axis((0, 1, 0), 45), quat_axis((1, 0, 1), 60), quat_axis((0, 0, 1), -20)]
GPU_S = [(0.3, 0.3, 0.3), (0.5, 0.25, 0.4), (0.3, 0.5, 0.3), (0.2, 0.2, 0.6)]


def short_norm(q):
    return [max(-32767, min(32767, round(c * 32767))) for c in q]


def instancing(mode):
    """A cube placed several times over a floor, seen by a camera and lit by a point
    light. mode "reuse": one mesh in four nodes; "copies": a mesh per node (the same
    accessors); "gpu": one node with EXT_mesh_gpu_instancing; "gpu-copies": its entries
    written out as nodes with matrices."""
    cube_p = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
    # outward-wound faces of the cube over corners index = 4x + 2y + z
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    cube_i = []
    for a, b, c, d in faces:
        cube_i += [a, b, c, a, c, d]
    floor_p = [(-6, 0, -6), (-6, 0, 6), (6, 0, 6), (6, 0, -6)]
    raw = f32(*[c for p in cube_p for c in p]) + struct.pack("<36H", *cube_i) + f32(*[c for p in floor_p for c in p])
    raw += struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": 96}, {"buffer": 0, "byteOffset": 96, "byteLength": 72},
             {"buffer": 0, "byteOffset": 168, "byteLength": 48}, {"buffer": 0, "byteOffset": 216, "byteLength": 12}]
    accessors = [{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
                  "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]},
                 {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"},
                 {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC3",
                  "min": [-6, 0, -6], "max": [6, 0, 6]},
                 {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}]
    cube = {"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]}
    floor = {"primitives": [{"attributes": {"POSITION": 2}, "indices": 3, "material": 1}]}
    meshes = [cube, floor]
    import math
    pitch = math.degrees(math.atan2(2.4, 9))
    nodes = [{"camera": 0, "translation": [0, 3, 9], "rotation": quat_axis((1, 0, 0), -pitch)},
             {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0, 5, 3]},
             {"mesh": 1}]
    roots = [0, 1, 2]

    def cube_mesh():
        if mode in ("reuse", "gpu"):
            return 0
        meshes.append(json.loads(json.dumps(cube)))
        return len(meshes) - 1

    if mode in ("reuse", "copies"):
        for n in CUBE_NODES:
            nodes.append(dict(n, mesh=cube_mesh()))
            roots.append(len(nodes) - 1)
        nodes.append(dict(MIRROR_PARENT, children=[len(nodes) + 1]))
        roots.append(len(nodes) - 1)
        nodes.append(dict(MIRROR_CHILD, mesh=cube_mesh()))
    elif mode == "gpu":
        count = len(GPU_T)
        base = len(raw)
        raw += f32(*[c for v in GPU_T for c in v])
        raw += struct.pack("<%dh" % (4 * count), *[c for q in GPU_R for c in short_norm(q)])
        raw += f32(*[c for v in GPU_S for c in v])
        views += [{"buffer": 0, "byteOffset": base, "byteLength": 12 * count},
                  {"buffer": 0, "byteOffset": base + 12 * count, "byteLength": 8 * count},
                  {"buffer": 0, "byteOffset": base + 20 * count, "byteLength": 12 * count}]
        accessors += [{"bufferView": 4, "componentType": 5126, "count": count, "type": "VEC3"},
                      {"bufferView": 5, "componentType": 5122, "normalized": True, "count": count, "type": "VEC4"},
                      {"bufferView": 6, "componentType": 5126, "count": count, "type": "VEC3"}]
        nodes.append(dict(GPU_NODE, mesh=0, extensions={"EXT_mesh_gpu_instancing": {
            "attributes": {"TRANSLATION": 4, "ROTATION": 5, "SCALE": 6}}}))
        roots.append(len(nodes) - 1)
    else:
        node = trs(GPU_NODE["translation"])
        for t_, q, s in zip(GPU_T, GPU_R, GPU_S):
            qs = [c / 32767 for c in short_norm(q)]
            nodes.append({"mesh": cube_mesh(), "matrix": column_major(matmul(node, trs(t_, qs, s)))})
            roots.append(len(nodes) - 1)
    d = doc([{"byteLength": len(raw), "uri": data_uri(raw)}], views, accessors, meshes, nodes, {
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "aspectRatio": 4 / 3, "znear": 0.1}}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.25, 0.2, 1], "metallicFactor": 0,
                                                "roughnessFactor": 1}},
                      {"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0,
                                                "roughnessFactor": 1}}],
        "extensionsUsed": ["KHR_lights_punctual"] + (["EXT_mesh_gpu_instancing"] if mode == "gpu" else []),
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 683 * 40}]}},
    })
    d["scenes"] = [{"nodes": roots}]
    return d


def png(width, height, rgb):
    """A minimal 8-bit RGB PNG of the given rows of (r, g, b) pixels."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    raw = b"".join(b"\0" + bytes(c for px in row for c in px) for row in rgb)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


TEXELS = [[(255, 128, 0), (0, 64, 255)], [(10, 20, 30), (200, 100, 50)]]


def textured():
    """Two triangles sharing one 2 x 2 PNG (a data: URI): the first's material tints it
    by baseColorFactor (0.5, 1, 0.25), the second's uses it as base colour, and in
    linear encoding as metallic-roughness texture and normal map (scale 0.5), the
    third's through KHR_texture_transform (a quarter turn, scale and offset)."""
    d, raw = simple_triangle()
    prim = d["meshes"][0]["primitives"][0]
    d["meshes"][0]["primitives"] = [dict(prim, material=0), dict(prim, material=1)]
    d["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(png(2, 2, TEXELS)).decode()}]
    d["textures"] = [{"source": 0}]
    d["materials"] = [
        {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "baseColorFactor": [0.5, 1, 0.25, 1]}},
        {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 0}},
         "normalTexture": {"index": 0, "scale": 0.5}},
        {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
            "offset": [0.5, 0.25], "scale": [2, 3], "rotation": 1.5707963267948966}}}}},
    ]
    d["meshes"][0]["primitives"].append(dict(prim, material=2))
    d["extensionsUsed"] = ["KHR_texture_transform"]
    return d


def extras():
    """Three unit quads in z = 0 facing +z (x from 0, 1.5 and 3), each with NORMAL and
    TEXCOORD_0 (u = x, glTF v = 1 - y), seen from +z by an orthographic camera:
    quad 0 has TANGENT (0, 1, 0, 1), where its uvs give +x, under a normal map whose
    one texel is (255, 128, 255); quad 1 has TEXCOORD_1 (0.75, 0.25) at every corner and
    a base-colour texture read at texCoord 1 through a sampler (magFilter NEAREST, wrapS
    MIRRORED_REPEAT, wrapT CLAMP_TO_EDGE); quad 2 has COLOR_0 (255, 128, 64, 191) as
    normalized unsigned bytes under baseColorFactor 0.8 and alphaMode MASK."""
    bufs = []

    def view(raw):
        bufs.append(raw)
        return len(bufs) - 1

    def acc(raw, ctype, count, typ, normalized=False):
        a = {"bufferView": view(raw), "componentType": ctype, "count": count, "type": typ}
        if normalized:
            a["normalized"] = True
        accessors.append(a)
        return len(accessors) - 1

    accessors = []
    pos = acc(b"".join(f32(*p) for p in QUAD), 5126, 4, "VEC3")
    nrm = acc(f32(*(0, 0, 1) * 4), 5126, 4, "VEC3")
    uv0 = acc(b"".join(f32(p[0], 1 - p[1]) for p in QUAD), 5126, 4, "VEC2")
    idx = acc(struct.pack("<6H", 0, 1, 2, 0, 2, 3), 5123, 6, "SCALAR")
    tan = acc(f32(*(0, 1, 0, 1) * 4), 5126, 4, "VEC4")
    uv1 = acc(f32(*(0.75, 0.25) * 4), 5126, 4, "VEC2")
    col = acc(bytes([255, 128, 64, 191] * 4), 5121, 4, "VEC4", normalized=True)
    base = {"POSITION": pos, "NORMAL": nrm, "TEXCOORD_0": uv0}
    meshes = [{"primitives": [{"attributes": dict(base, TANGENT=tan), "indices": idx, "material": 0}]},
              {"primitives": [{"attributes": dict(base, TEXCOORD_1=uv1), "indices": idx, "material": 1}]},
              {"primitives": [{"attributes": dict(base, COLOR_0=col), "indices": idx, "material": 2}]}]
    nodes = [{"mesh": i, "translation": [1.5 * i, 0, 0]} for i in range(3)]
    nodes.append({"camera": 0, "translation": [2, 0.5, 5]})
    views, raw = [], b""
    for b in bufs:
        views.append({"buffer": 0, "byteOffset": len(raw), "byteLength": len(b)})
        raw += b + b"\0" * (-len(b) % 4)
    d = doc([{"byteLength": len(raw), "uri": data_uri(raw)}], views, accessors, meshes, nodes)
    d["cameras"] = [{"type": "orthographic", "orthographic": {"xmag": 2.4, "ymag": 0.6, "znear": 0.1, "zfar": 10}}]
    d["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(png(1, 1, [[(255, 128, 255)]])).decode()},
                   {"uri": "data:image/png;base64," + base64.b64encode(png(2, 2, TEXELS)).decode()}]
    d["samplers"] = [{"magFilter": 9728, "minFilter": 9987, "wrapS": 33648, "wrapT": 33071}]
    d["textures"] = [{"source": 0}, {"source": 1, "sampler": 0}]
    d["materials"] = [
        {"normalTexture": {"index": 0}},
        {"pbrMetallicRoughness": {"baseColorTexture": {"index": 1, "texCoord": 1}}},
        {"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1]}, "alphaMode": "MASK"},
    ]
    return d


def extras_glb():
    """extras() as a .glb: its buffer and both PNGs in the BIN chunk (the images as
    buffer views); a seed of fuzz/fuzz_glb.c."""
    d = extras()
    raw = base64.b64decode(d["buffers"][0]["uri"].split(",", 1)[1])
    for im in d["images"]:
        raw += b"\0" * (-len(raw) % 4)
        png_bytes = base64.b64decode(im.pop("uri").split(",", 1)[1])
        d["bufferViews"].append({"buffer": 0, "byteOffset": len(raw), "byteLength": len(png_bytes)})
        im.update({"bufferView": len(d["bufferViews"]) - 1, "mimeType": "image/png"})
        raw += png_bytes
    d["buffers"] = [{"byteLength": len(raw)}]
    return glb(d, raw)


def main():
    os.makedirs(GOOD, exist_ok=True)
    write_json(os.path.join(GOOD, "strided.gltf"), strided())
    write_json(os.path.join(GOOD, "sparse.gltf"), sparse())
    write_json(os.path.join(GOOD, "strips.gltf"), strips())
    write_json(os.path.join(GOOD, "textured.gltf"), textured())
    write_json(os.path.join(GOOD, "extras.gltf"), extras())
    with open(os.path.join(GOOD, "extras.glb"), "wb") as f:
        f.write(extras_glb())
    nd, _ = nodes()
    write_json(os.path.join(GOOD, "nodes.gltf"), nd)
    for mode in ("reuse", "copies", "gpu", "gpu-copies"):
        write_json(os.path.join(GOOD, "instancing-%s.gltf" % mode), instancing(mode))

    # the same triangle as a .glb (buffer 0 the BIN chunk) and as a .gltf with an
    # external .bin file
    d, raw = simple_triangle()
    d["buffers"] = [{"byteLength": len(raw)}]
    with open(os.path.join(GOOD, "triangle.glb"), "wb") as f:
        f.write(glb(d, raw))
    d["buffers"] = [{"byteLength": len(raw), "uri": "triangle.bin"}]
    write_json(os.path.join(GOOD, "external.gltf"), d)
    with open(os.path.join(GOOD, "triangle.bin"), "wb") as f:
        f.write(raw)

    # bad files, each with its exact message
    d, raw = simple_triangle()
    d["extensionsRequired"] = ["KHR_draco_mesh_compression"]
    d["extensionsUsed"] = ["KHR_draco_mesh_compression"]
    write_bad("gltf-required-extension.gltf", json.dumps(d), "input",
              "%(p)s: extensionsRequired[0]: the file requires the extension 'KHR_draco_mesh_compression', "
              "which clpt does not support")
    d, raw = simple_triangle()
    d["accessors"][0]["count"] = 4
    write_bad("gltf-accessor-range.gltf", json.dumps(d), "input",
              "%(p)s: meshes[0].primitives[0].attributes.POSITION: accessor 0 reads bytes 0..48 of "
              "bufferView 0, which has 36")
    d, raw = simple_triangle()
    d["buffers"][0]["uri"] = "gltf-missing.bin"
    write_bad("gltf-missing-buffer.gltf", json.dumps(d), "io",
              "%(p)s: buffers[0].uri: cannot open 'tests/data/bad/gltf-missing.bin'")
    d, raw = simple_triangle()
    d["meshes"][0]["primitives"][0]["indices"] = 1
    d["accessors"].append({"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"})
    d["bufferViews"].append({"buffer": 1, "byteLength": 6})
    d["buffers"].append({"byteLength": 6, "uri": data_uri(struct.pack("<3H", 0, 1, 3))})
    write_bad("gltf-index-range.gltf", json.dumps(d), "input",
              "%(p)s: meshes[0].primitives[0].indices: index 2 is 3, past the 3 vertices")
    d, raw = simple_triangle()
    d["bufferViews"][0]["byteStride"] = 8
    write_bad("gltf-short-stride.gltf", json.dumps(d), "input",
              "%(p)s: meshes[0].primitives[0].attributes.POSITION: accessor 0: byteStride 8 of bufferView 0 is "
              "less than an element's 12 bytes")
    d, raw = simple_triangle()
    d["nodes"] = [{"mesh": 0, "children": [1]}, {"children": [0]}]
    d["scenes"] = [{"nodes": [0]}]
    write_bad("gltf-node-cycle.gltf", json.dumps(d), "input",
              "%(p)s: nodes[0]: reached twice in the node tree (a node has one parent, no cycles)")
    d, raw = simple_triangle()
    d["buffers"] = [{"byteLength": len(raw)}]
    whole = glb(d, raw)
    write_bad("gltf-truncated-chunk.glb", whole[:-8], "input",
              "%(p)s: the GLB header says the file has " + str(len(whole)) + " bytes, but it has " +
              str(len(whole) - 8))
    cut = bytearray(whole[:-8])
    struct.pack_into("<I", cut, 8, len(cut))
    write_bad("gltf-truncated-bin.glb", bytes(cut), "input",
              "%(p)s: GLB chunk 1 at byte " + str(len(cut) - len(raw) - 8 + 8) + " declares 36 bytes, more "
              "than the 28 left in the file")
    write_bad("gltf-wrong-magic.glb", b"gLTF" + whole[4:], "input",
              "%(p)s: not a binary glTF file (it does not start with the magic 'glTF')")
    d = extras()
    d["accessors"][6]["type"] = "VEC2"
    write_bad("gltf-color-type.gltf", json.dumps(d), "input",
              "%(p)s: meshes[2].primitives[0].attributes.COLOR_0: accessor 6: type must be VEC3 or VEC4 here")
    d = extras()
    del d["accessors"][6]["normalized"]
    write_bad("gltf-color-component.gltf", json.dumps(d), "input",
              "%(p)s: meshes[2].primitives[0].attributes.COLOR_0: accessor 6: componentType must be 5126 (float), "
              "or 5121 or 5123 (unsigned byte or short) with normalized true")
    d = extras()
    d["accessors"][4]["type"] = "VEC3"
    write_bad("gltf-tangent-type.gltf", json.dumps(d), "input",
              "%(p)s: meshes[0].primitives[0].attributes.TANGENT: accessor 4: type must be VEC4 here")
    d = extras()
    d["samplers"][0]["wrapT"] = 10496
    write_bad("gltf-sampler-wrap.gltf", json.dumps(d), "input",
              "%(p)s: samplers[0].wrapT: expected 10497 (REPEAT), 33071 (CLAMP_TO_EDGE) or 33648 (MIRRORED_REPEAT)")
    gpu_node = "nodes[3].extensions.EXT_mesh_gpu_instancing"
    d = instancing("gpu")
    d["accessors"][6]["count"] = 3
    write_bad("gltf-gpu-instancing-count.gltf", json.dumps(d), "input",
              "%(p)s: " + gpu_node + ".attributes.SCALE: accessor 6 has 3 elements, another attribute has 4 (all "
              "must have the same count)")
    d = instancing("gpu")
    d["accessors"][4]["type"] = "VEC4"
    write_bad("gltf-gpu-instancing-type.gltf", json.dumps(d), "input",
              "%(p)s: " + gpu_node + ".attributes.TRANSLATION: accessor 4: type must be VEC3 here")
    d = instancing("gpu")
    del d["accessors"][5]["normalized"]
    write_bad("gltf-gpu-instancing-component.gltf", json.dumps(d), "input",
              "%(p)s: " + gpu_node + ".attributes.ROTATION: accessor 5: componentType must be 5126 (float), or "
              "5120 or 5122 (byte or short) with normalized true")
    d = instancing("gpu")
    d["nodes"][3]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"] = 9
    write_bad("gltf-gpu-instancing-index.gltf", json.dumps(d), "input",
              "%(p)s: " + gpu_node + ".attributes.SCALE: accessors[9] does not exist (the file has 7)")
    d = instancing("gpu")
    d["nodes"][3]["extensions"]["EXT_mesh_gpu_instancing"] = {"attributes": {}}
    write_bad("gltf-gpu-instancing-empty.gltf", json.dumps(d), "input",
              "%(p)s: " + gpu_node + ": attributes: none of TRANSLATION, ROTATION, SCALE")
    write_bad("gltf-not-json.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [", "input",
              "%(p)s: not valid glTF JSON")

if __name__ == "__main__":
    main()
