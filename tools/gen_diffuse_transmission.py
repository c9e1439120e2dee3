#!/usr/bin/env python3
"""gen_diffuse_transmission.py — writes scenes/diffuse-transmission.gltf, an example of
KHR_materials_diffuse_transmission (docs/gltf.md): three thin sheets stand between the
camera and a warm point light behind them, over a grey floor under a dim sun. The left
sheet is opaque white (no transmission), the middle one passes half its diffuse layer
to the back, white, and the right one all of it, tinted leaf-green by
diffuseTransmissionColorFactor. A wax cube in front is a solid (KHR_materials_volume)
whose diffuse transmission enters a scattering interior (KHR_materials_volume_scatter,
read as a subsurface walk: docs/subsurface.md). Blender 3.4's exporter does not write the extension,
hence this script. Deterministic: running it again writes the same bytes.

    python3 tools/gen_diffuse_transmission.py > scenes/diffuse-transmission.gltf
    clpt scenes/diffuse-transmission.gltf -o sheets.png
"""
import base64
import json
import struct


def f32(values):
    return struct.pack("<%df" % len(values), *values)


def quad(cx, cy, cz, hx, hy, normal_z):
    """A rectangle in a plane of constant z (normal +-z) or, with hy None, a floor in
    y = cy of half size hx; 4 corners and 2 triangles."""
    if hy is None:
        pos = [cx - hx, cy, cz - hx, cx + hx, cy, cz - hx, cx + hx, cy, cz + hx, cx - hx, cy, cz + hx]
        nrm = [0, 1, 0] * 4
        idx = [0, 2, 1, 0, 3, 2]
    else:
        pos = [cx - hx, cy - hy, cz, cx + hx, cy - hy, cz, cx + hx, cy + hy, cz, cx - hx, cy + hy, cz]
        nrm = [0, 0, normal_z] * 4
        idx = [0, 1, 2, 0, 2, 3]
    return pos, nrm, idx


def cube(cx, cy, cz, h):
    """A closed box of half size h, each face its own 4 corners and outward normal."""
    pos, nrm, idx = [], [], []
    for axis in range(3):
        for sign in (1, -1):
            u, v = (axis + 1) % 3, (axis + 2) % 3
            base = len(pos) // 3
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0, 0, 0]
                p[axis], p[u], p[v] = sign * h, a * h, b * h * sign
                pos += [cx + p[0], cy + p[1], cz + p[2]]
                n = [0, 0, 0]
                n[axis] = sign
                nrm += n
            idx += [base, base + 1, base + 2, base, base + 2, base + 3]
    return pos, nrm, idx


def main():
    shapes = [quad(0, 0, 0, 6, None, 0)] + [quad(x, 1.0, 0, 0.55, 0.9, 1) for x in (-1.3, 0.0, 1.3)]
    shapes.append(cube(0.6, 0.35, 1.1, 0.35))
    blob, views, accessors, meshes = b"", [], [], []
    for i, (pos, nrm, idx) in enumerate(shapes):
        prim = {}
        for name, data, kind in (("POSITION", pos, "VEC3"), ("NORMAL", nrm, "VEC3")):
            raw = f32(data)
            views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(raw)})
            acc = {"bufferView": len(views) - 1, "componentType": 5126, "count": len(data) // 3, "type": kind}
            if name == "POSITION":
                acc["min"] = [min(data[k::3]) for k in range(3)]
                acc["max"] = [max(data[k::3]) for k in range(3)]
            accessors.append(acc)
            prim[name] = len(accessors) - 1
            blob += raw
        raw = struct.pack("<%dH" % len(idx), *idx)
        raw += b"\0" * (-len(raw) % 4)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": 2 * len(idx)})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5123, "count": len(idx), "type": "SCALAR"})
        blob += raw
        meshes.append({"primitives": [{"attributes": prim, "indices": len(accessors) - 1, "material": i}]})
    sheet = {"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0,
                                      "roughnessFactor": 0.6}, "doubleSided": True}
    materials = [
        {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0,
                                                   "roughnessFactor": 0.8}},
        dict(sheet, name="opaque"),
        dict(sheet, name="half", extensions={"KHR_materials_diffuse_transmission": {
            "diffuseTransmissionFactor": 0.5}}),
        dict(sheet, name="leaf", extensions={"KHR_materials_diffuse_transmission": {
            "diffuseTransmissionFactor": 1.0, "diffuseTransmissionColorFactor": [0.35, 0.8, 0.2]}}),
        {"name": "wax", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.8, 0.6, 1], "metallicFactor": 0,
                                                 "roughnessFactor": 0.4},
         "extensions": {"KHR_materials_volume": {"thicknessFactor": 0.7, "attenuationDistance": 0.05,
                                                 "attenuationColor": [0.5, 0.5, 0.5]},
                        "KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 1.0},
                        "KHR_materials_volume_scatter": {"multiscatterColor": [0.9, 0.6, 0.3],
                                                         "scatterAnisotropy": 0.2}}},
    ]
    nodes = [{"mesh": i} for i in range(len(meshes))]
    nodes.append({"name": "lamp", "translation": [0, 1.1, -1.2], "extensions": {"KHR_lights_punctual": {"light": 0}}})
    nodes.append({"name": "sun", "rotation": [-0.5, 0.0, 0.0, 0.8660254], "extensions": {
        "KHR_lights_punctual": {"light": 1}}})
    nodes.append({"name": "camera", "camera": 0, "translation": [0, 1.3, 4.2], "rotation": [-0.0436194, 0, 0, 0.9990482]})
    d = {
        "asset": {"version": "2.0", "generator": "clpt tools/gen_diffuse_transmission.py"},
        "extensionsUsed": ["KHR_materials_diffuse_transmission", "KHR_materials_volume",
                           "KHR_materials_volume_scatter", "KHR_lights_punctual"],
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "aspectRatio": 1.5, "znear": 0.1}}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1.0, 0.75, 0.45], "intensity": 300.0},
            {"type": "directional", "color": [0.6, 0.7, 1.0], "intensity": 2.5}]}},
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    }
    print(json.dumps(d, indent=1))


if __name__ == "__main__":
    main()
