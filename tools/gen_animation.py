#!/usr/bin/env python3
"""gen_animation.py — writes scenes/animation.gltf: a two-second glTF animation for
`clpt --frames` (docs/animation.md). A red cube (its mesh used once: copied into the
world each frame) slides across a grey floor while it turns half a turn (LINEAR
rotation keys: slerp) and swells and settles (a CUBICSPLINE scale); two blue cubes share
one mesh (instances) and one of them hops up a step at a time (STEP); the camera's node
drifts and turns towards the middle (LINEAR translation and rotation). A sun
(KHR_lights_punctual) lights it under the glTF sky. Deterministic: running this again
writes the same bytes.

    python3 tools/gen_animation.py > scenes/animation.gltf
    clpt scenes/animation.gltf --frames 0:48 -o anim.png      # anim_0000.png ... anim_0048.png
"""
import base64
import json
import math
import struct


def f32(values):
    return struct.pack("<%df" % len(values), *values)


def quat_y(degrees):
    h = math.radians(degrees) / 2
    return [0.0, math.sin(h), 0.0, math.cos(h)]


def quat_look(yaw, pitch):
    """The rotation that turns -z by yaw about y, after pitch about x (degrees)."""
    cy, sy = math.cos(math.radians(yaw) / 2), math.sin(math.radians(yaw) / 2)
    cp, sp = math.cos(math.radians(pitch) / 2), math.sin(math.radians(pitch) / 2)
    # q = qy * qx
    return [cy * sp, sy * cp, -sy * sp, cy * cp]


def cube():
    """24 corners (4 per face, each face its own normal) and 12 triangles."""
    pos, nrm, idx = [], [], []
    faces = [((1, 0, 0), (0, 1, 0), (0, 0, 1)), ((-1, 0, 0), (0, 0, 1), (0, 1, 0)),
             ((0, 1, 0), (0, 0, 1), (1, 0, 0)), ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
             ((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 0, -1), (0, 1, 0), (1, 0, 0))]
    for n, u, v in faces:
        base = len(pos) // 3
        for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            pos += [0.5 * (n[i] + a * u[i] + b * v[i]) for i in range(3)]
            nrm += list(n)
        idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    return pos, nrm, idx


def main():
    blob = bytearray()
    views, accessors = [], []

    def add(data, count, type_, ctype=5126, minmax=None, target=None):
        while len(blob) % 4:
            blob.append(0)
        view = {"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)}
        if target:
            view["target"] = target
        views.append(view)
        blob.extend(data)
        acc = {"bufferView": len(views) - 1, "componentType": ctype, "count": count, "type": type_}
        if minmax:
            acc["min"], acc["max"] = minmax
        accessors.append(acc)
        return len(accessors) - 1

    pos, nrm, idx = cube()
    cube_pos = add(f32(pos), 24, "VEC3", minmax=([-0.5] * 3, [0.5] * 3), target=34962)
    cube_nrm = add(f32(nrm), 24, "VEC3", target=34962)
    cube_idx = add(struct.pack("<36H", *idx), 36, "SCALAR", ctype=5123, target=34963)
    floor_pos = add(f32([-6, 0, -6, 6, 0, -6, 6, 0, 6, -6, 0, 6]), 4, "VEC3",
                    minmax=([-6, 0, -6], [6, 0, 6]), target=34962)
    floor_nrm = add(f32([0, 1, 0] * 4), 4, "VEC3", target=34962)
    floor_idx = add(struct.pack("<6H", 0, 2, 1, 0, 3, 2), 6, "SCALAR", ctype=5123, target=34963)

    times = [0.0, 0.5, 1.0, 1.5, 2.0]
    t_in = add(f32(times), len(times), "SCALAR", minmax=([0.0], [2.0]))
    slide = add(f32(sum(([-2.5 + 1.6 * t, 0.5, 0.6 - 0.6 * t] for t in times), [])), 5, "VEC3")
    turn = add(f32(sum((quat_y(90.0 * t) for t in times), [])), 5, "VEC4")
    # CUBICSPLINE: in-tangent, value, out-tangent per key; swells to 1.5 and back
    swell = []
    for t in times:
        s = 1.0 + 0.5 * math.sin(math.pi * t / 2.0)
        d = 0.25 * math.pi * math.cos(math.pi * t / 2.0)
        swell += [d, d, d, s, s, s, d, d, d]
    swell_acc = add(f32(swell), 3 * len(times), "VEC3")
    hop = add(f32(sum(([2.3, 0.5 + 0.4 * (i % 2), -1.5] for i in range(len(times))), [])), 5, "VEC3")
    cam_t = add(f32(sum(([0.4 * t - 0.4, 3.0, 7.5 - 0.5 * t] for t in times), [])), 5, "VEC3")
    cam_r = add(f32(sum((quat_look(6.0 * t - 6.0, -18.0) for t in times), [])), 5, "VEC4")

    doc = {
        "asset": {"version": "2.0", "generator": "clpt tools/gen_animation.py"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3, 4]}],
        "nodes": [
            {"name": "floor", "mesh": 0},
            {"name": "red cube", "mesh": 1, "translation": [-2.5, 0.5, 0.6]},
            {"name": "blue cube", "mesh": 2, "translation": [2.3, 0.5, 1.5]},
            {"name": "hopping blue cube", "mesh": 2, "translation": [2.3, 0.5, -1.5]},
            {"name": "camera", "camera": 0, "translation": [-0.4, 3.0, 7.5], "rotation": quat_look(-6.0, -18.0)},
        ],
        "meshes": [
            {"name": "floor", "primitives": [{"attributes": {"POSITION": floor_pos, "NORMAL": floor_nrm},
                                              "indices": floor_idx, "material": 0}]},
            {"name": "red cube", "primitives": [{"attributes": {"POSITION": cube_pos, "NORMAL": cube_nrm},
                                                 "indices": cube_idx, "material": 1}]},
            {"name": "blue cube", "primitives": [{"attributes": {"POSITION": cube_pos, "NORMAL": cube_nrm},
                                                  "indices": cube_idx, "material": 2}]},
        ],
        "materials": [
            {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1],
                                                       "metallicFactor": 0.0, "roughnessFactor": 0.9}},
            {"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.08, 1],
                                                     "metallicFactor": 0.0, "roughnessFactor": 0.4}},
            {"name": "blue", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.2, 0.8, 1],
                                                      "metallicFactor": 0.0, "roughnessFactor": 0.3}},
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "aspectRatio": 1.5, "znear": 0.1}}],
        "animations": [{
            "name": "move",
            "channels": [
                {"sampler": 0, "target": {"node": 1, "path": "translation"}},
                {"sampler": 1, "target": {"node": 1, "path": "rotation"}},
                {"sampler": 2, "target": {"node": 1, "path": "scale"}},
                {"sampler": 3, "target": {"node": 3, "path": "translation"}},
                {"sampler": 4, "target": {"node": 4, "path": "translation"}},
                {"sampler": 5, "target": {"node": 4, "path": "rotation"}},
            ],
            "samplers": [
                {"input": t_in, "output": slide, "interpolation": "LINEAR"},
                {"input": t_in, "output": turn, "interpolation": "LINEAR"},
                {"input": t_in, "output": swell_acc, "interpolation": "CUBICSPLINE"},
                {"input": t_in, "output": hop, "interpolation": "STEP"},
                {"input": t_in, "output": cam_t, "interpolation": "LINEAR"},
                {"input": t_in, "output": cam_r, "interpolation": "LINEAR"},
            ],
        }],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
    }
    print(json.dumps(doc, indent=1))


main()
