#!/usr/bin/env python3
"""xcheck.py -- the cross-check: renders single-feature scenes (tools/xcheck/scenes.py) with
clpt and, when installed, with Mitsuba 3 and with Blender's Cycles, and prints per scene
and peer the two means, their ratio, the RMSE between the images and its noise floor,
with the known model difference of that peer (docs/validation.md).

usage: python3 tools/xcheck/xcheck.py [--clpt build/clpt] [--out build/xcheck] [--size 64]
           [--spp 256] [--only NAME,...] [--peers mitsuba,cycles] [--envmap FILE]
           [--mitsuba-variant scalar_rgb] [--pbrt PATH [--pbrt-threads 2]]

Each scene is a glTF file written here (a UV sphere of radius 1 at the origin, 64 x 32
segments with normals, uvs and tangents; a floor for the light scenes, or the floor alone;
the camera; the lights): clpt renders it through `mesh { file ... }` in a scene of its own format (camera,
background, image settings), Cycles through Blender's glTF importer (cycles_render.py,
one Blender process for all scenes), Mitsuba from the same triangles as PLY files with its
own BSDF. Paths are 16 bounces long after the camera ray (Mitsuba max_depth 17, Cycles
max_bounces 15), box pixel filter, Russian roulette as each renderer does it.

Each renderer renders each scene twice (seeds 1 and 2). The statistics are over the
pixels of the objects, leaving out silhouettes (pixels whose slightly enlarged corners'
rays do not all hit the same object, computed analytically): the mean of each renderer's
two images, their ratio clpt / peer, the RMSE between the two means, and its noise floor
sqrt(n_clpt^2 + n_peer^2) / sqrt(2), each n the noise of one image estimated as
RMSE(seed 1, seed 2) / sqrt(2). An RMSE near its floor means the images agree to the
noise; a ratio off 1 by more than noise is a difference of model (the notes) or a bug.

A peer that is not installed is skipped with the line that installs it. A scene whose
feature clpt does not read yet (it warns that the scene's glTF extension is ignored) is
reported 'unsupported' for clpt and the run goes on. Standard library and numpy (which
Mitsuba needs anyway).

With --pbrt PATH (`make xcheck PBRT=PATH`), a pbrt-v4 binary built outside the repository,
the media scenes written in pbrt-v4's format (pbrt/*.pbrt and scenes/nanovdb-smoke.pbrt)
are rendered by clpt and by pbrt-v4 from the very same files and compared per channel and
as blurred images against each renderer's noise (pbrt_check.py says how); without it those
rows are skipped with a line that says so.
"""
import argparse
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import time
import zlib

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import pbrt_check  # noqa: E402
import scenes as xscenes  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
DEPTH = 16                      # clpt depth: bounces after the camera ray
LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"
CAMERAS = {                     # (from, at, vertical fov in degrees)
    "sphere": ((0.0, 0.0, 4.0), (0.0, 0.0, 0.0), 30.0),
    "floor": ((0.0, 2.0, 6.0), (0.0, -0.5, 0.0), 35.0),
}
FLOOR_HALF = 4.0


# ---------------------------------------------------------------- geometry and images
def uv_sphere(nlon=64, nlat=32):
    """Positions, normals, glTF uvs (v down from the +y pole), tangents (w = 1), indices.
    u = 0 faces +z and grows toward +x."""
    th = np.linspace(0.0, math.pi, nlat + 1)
    ph = np.linspace(0.0, 2.0 * math.pi, nlon + 1)
    T, P = np.meshgrid(th, ph, indexing="ij")
    n = np.stack([np.sin(T) * np.sin(P), np.cos(T), np.sin(T) * np.cos(P)], -1).reshape(-1, 3)
    uv = np.stack([P / (2 * math.pi), T / math.pi], -1).reshape(-1, 2)
    # tangent along +u; bitangent = cross(n, t) points to the +y pole (toward -v in glTF's
    # uvs, the image's up), as glTF's normal textures expect
    tan = np.stack([np.cos(P), np.zeros_like(P), -np.sin(P)], -1).reshape(-1, 3)
    tan4 = np.concatenate([tan, np.ones((len(tan), 1))], 1)
    idx = []
    W = nlon + 1
    for i in range(nlat):
        for j in range(nlon):
            a, b, c, d = i * W + j, i * W + j + 1, (i + 1) * W + j, (i + 1) * W + j + 1
            if i > 0:
                idx.append((a, c, b))
            if i < nlat - 1:
                idx.append((b, c, d))
    return (n.astype(np.float32), n.astype(np.float32), uv.astype(np.float32), tan4.astype(np.float32),
            np.array(idx, dtype=np.uint32))


def floor_quad():
    h = FLOOR_HALF
    p = np.array([[-h, -1, -h], [h, -1, -h], [h, -1, h], [-h, -1, h]], np.float32)
    n = np.tile(np.array([0, 1, 0], np.float32), (4, 1))
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    tan = np.tile(np.array([1, 0, 0, 1], np.float32), (4, 1))
    return p, n, uv, tan, np.array([(0, 2, 1), (0, 3, 2)], np.uint32)


def write_png(path, rgb8):
    h, w, _ = rgb8.shape
    raw = b"".join(b"\x00" + rgb8[y].tobytes() for y in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def texture_image(kind, size):
    """8-bit RGB, row 0 the top (glTF v = 0). 'checker': 8 x 8 cells whose red grows with
    the column and green with the row (so a flip shows), blue alternating; 'bumps': a
    tangent-space normal map of the height sin(8 pi u) sin(8 pi v)."""
    y, x = np.mgrid[0:size, 0:size]
    u, v = (x + 0.5) / size, (y + 0.5) / size
    if kind == "checker":
        cx, cy = (u * 8).astype(int), (v * 8).astype(int)
        img = np.stack([30 + 28 * cx, 30 + 28 * cy, np.where((cx + cy) % 2 == 1, 210, 40)], -1)
        return img.astype(np.uint8)
    k, a = 8 * math.pi, 0.04
    du = a * k * np.cos(k * u) * np.sin(k * v)
    dv = a * k * np.sin(k * u) * np.cos(k * v)
    # green is +bitangent, toward the image's top, where v decreases: d/d(-v)
    nrm = np.stack([-du, dv, np.ones_like(du)], -1)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    return np.clip((nrm * 0.5 + 0.5) * 255 + 0.5, 0, 255).astype(np.uint8)


def quat_from_matrix(m):
    t = m[0, 0] + m[1, 1] + m[2, 2]
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        return [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
    i = int(np.argmax([m[0, 0], m[1, 1], m[2, 2]]))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k]) * 2
    q = [0.0, 0.0, 0.0, (m[k, j] - m[j, k]) / s]
    q[i] = 0.25 * s
    q[j] = (m[j, i] + m[i, j]) / s
    q[k] = (m[k, i] + m[i, k]) / s
    return q


def look_rotation(direction, up=(0.0, 1.0, 0.0)):
    """The rotation that turns -z to direction (and +y as near to up as it can)."""
    f = np.array(direction, float)
    f /= np.linalg.norm(f)
    if abs(f @ np.array(up)) > 0.999:
        up = (0.0, 0.0, -1.0)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    return quat_from_matrix(np.stack([r, u, -f], 1))


# ---------------------------------------------------------------- writing a scene
class Gltf:
    def __init__(self):
        self.bin = bytearray()
        self.j = {"asset": {"version": "2.0", "generator": "clpt tools/xcheck"}, "buffers": [], "bufferViews": [],
                  "accessors": [], "meshes": [], "nodes": [], "materials": [], "scenes": [{"nodes": []}],
                  "scene": 0}

    def accessor(self, arr, kind, target):
        while len(self.bin) % 4:
            self.bin.append(0)
        off = len(self.bin)
        self.bin += arr.tobytes()
        self.j["bufferViews"].append({"buffer": 0, "byteOffset": off, "byteLength": arr.nbytes, "target": target})
        a = {"bufferView": len(self.j["bufferViews"]) - 1, "componentType": 5125 if arr.dtype == np.uint32 else 5126,
             "count": int(arr.size if kind == "SCALAR" else arr.shape[0]), "type": kind}
        if kind == "VEC3" and arr.dtype == np.float32:
            a["min"], a["max"] = arr.min(0).tolist(), arr.max(0).tolist()
        self.j["accessors"].append(a)
        return len(self.j["accessors"]) - 1

    def mesh(self, geo, material):
        p, n, uv, tan, idx = geo
        attrs = {"POSITION": self.accessor(p, "VEC3", 34962), "NORMAL": self.accessor(n, "VEC3", 34962),
                 "TEXCOORD_0": self.accessor(uv, "VEC2", 34962), "TANGENT": self.accessor(tan, "VEC4", 34962)}
        self.j["meshes"].append({"primitives": [{"attributes": attrs, "indices": self.accessor(idx.reshape(-1),
                                                                                               "SCALAR", 34963),
                                                 "material": material}]})
        self.node({"mesh": len(self.j["meshes"]) - 1})

    def node(self, nd):
        self.j["nodes"].append(nd)
        self.j["scenes"][0]["nodes"].append(len(self.j["nodes"]) - 1)

    def save(self, path):
        base = os.path.splitext(os.path.basename(path))[0]
        with open(os.path.join(os.path.dirname(path), base + ".bin"), "wb") as f:
            f.write(self.bin)
        self.j["buffers"] = [{"uri": base + ".bin", "byteLength": len(self.bin)}]
        with open(path, "w") as f:
            json.dump(self.j, f, indent=1)


def texture_files(s, folder):
    out = {}
    for key, (kind, size) in s["textures"].items():
        path = os.path.join(folder, "%s-%s.png" % (s["name"], key))
        write_png(path, texture_image(kind, size))
        out[key] = path
    return out


def write_gltf(s, folder, tex):
    g = Gltf()
    mat = json.loads(json.dumps(s["material"]))
    if tex:
        g.j["samplers"] = [{"magFilter": 9728, "minFilter": 9728, "wrapS": 10497, "wrapT": 10497}]
        g.j["images"], g.j["textures"] = [], []
        for key, path in tex.items():
            g.j["images"].append({"uri": os.path.basename(path)})
            g.j["textures"].append({"sampler": 0, "source": len(g.j["images"]) - 1})
            ti = {"index": len(g.j["textures"]) - 1}
            for slot in ("emissiveTexture", "normalTexture"):
                if mat.get(slot) == key:
                    mat[slot] = ti
            if mat["pbrMetallicRoughness"].get("baseColorTexture") == key:
                mat["pbrMetallicRoughness"]["baseColorTexture"] = ti
    g.j["materials"].append(mat)
    if s["ext"]:
        g.j["extensionsUsed"] = list(s["ext"])
    if s["sphere"]:
        g.mesh(uv_sphere(), 0)
    if s["floor"]:
        g.mesh(floor_quad(), 0)
    cam_from, cam_at, fov = CAMERAS["floor" if s["floor"] else "sphere"]
    g.j["cameras"] = [{"type": "perspective", "perspective": {"yfov": math.radians(fov), "aspectRatio": 1.0,
                                                              "znear": 0.01, "zfar": 100.0}}]
    g.node({"camera": 0, "translation": list(cam_from),
            "rotation": look_rotation(np.subtract(cam_at, cam_from))})
    L = s["light"]
    if L:
        light = {k: v for k, v in L.items() if k not in ("at", "dir")}
        g.j["extensions"] = {"KHR_lights_punctual": {"lights": [light]}}
        nd = {"extensions": {"KHR_lights_punctual": {"light": 0}}}
        if "at" in L:
            nd["translation"] = list(L["at"])
        if L["type"] == "spot":
            nd["rotation"] = look_rotation((0.0, -1.0, 0.0))
        if L["type"] == "directional":
            nd["rotation"] = look_rotation(L["dir"])
        g.node(nd)
    path = os.path.join(folder, s["name"] + ".gltf")
    g.save(path)
    return path


def write_ply(path, geo):
    """Mitsuba's bitmap lookup puts v = 0 at the image's top row, as glTF does: the uvs go
    in as they are (the texture-emission scene shows a flip at once)."""
    p, n, uv, _, idx = geo
    v = np.concatenate([p, n, uv], 1).astype("<f4")
    head = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\n" % len(p) +
            "".join("property float %s\n" % c for c in ("x", "y", "z", "nx", "ny", "nz", "u", "v")) +
            "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % len(idx))
    faces = np.zeros(len(idx), dtype=[("n", "u1"), ("i", "<i4", 3)])
    faces["n"], faces["i"] = 3, idx
    with open(path, "wb") as f:
        f.write(head.encode() + v.tobytes() + faces.tobytes())


# ---------------------------------------------------------------- statistics
def camera_frame(s):
    """The scene's camera: eye, forward, right and up unit vectors, tan(fov / 2)."""
    cam_from, cam_at, fov = CAMERAS["floor" if s["floor"] else "sphere"]
    f = np.subtract(cam_at, cam_from)
    f = f / np.linalg.norm(f)
    r = np.cross(f, (0.0, 1.0, 0.0))
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    half = math.tan(math.radians(fov) / 2)
    return np.array(cam_from, float), f, r, u, half


def object_ids(s, size, xs, ys):
    """For film points (xs, ys) in pixels (grids), which object the ray hits: 0 none, 1 the
    sphere, 2 the floor."""
    o, f, r, u, half = camera_frame(s)
    sx = (2 * xs / size - 1) * half
    sy = (1 - 2 * ys / size) * half
    d = f[None, None] + sx[..., None] * r[None, None] + sy[..., None] * u[None, None]
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    b = d @ o
    disc = b * b - (o @ o - 1.0)
    t_s = np.where(disc > 0, -b - np.sqrt(np.maximum(disc, 0)), np.inf)
    t_s = np.where((t_s > 0) & s["sphere"], t_s, np.inf)
    ids = np.where(np.isfinite(t_s), 1, 0)
    if s["floor"]:
        with np.errstate(divide="ignore", invalid="ignore"):
            t_f = (-1.0 - o[1]) / d[..., 1]
        hx, hz = o[0] + t_f * d[..., 0], o[2] + t_f * d[..., 2]
        on = (t_f > 0) & (abs(hx) <= FLOOR_HALF) & (abs(hz) <= FLOOR_HALF) & (t_f < t_s)
        ids = np.where(on, 2, ids)
    return ids


def object_mask(s, size, grow=0.25):
    """Pixels inside an object: the four corners of the pixel, enlarged by `grow`, all see
    the same object (not the background)."""
    px = np.arange(size, dtype=float)
    lo, hi = px - grow, px + 1 + grow
    ids = []
    for cy in (lo, hi):
        for cx in (lo, hi):
            X, Y = np.meshgrid(cx, cy)
            ids.append(object_ids(s, size, X, Y))
    first = ids[0]
    same = np.all([i == first for i in ids], axis=0)
    return same & (first > 0)


def rmse(a, b, keep):
    d = (a - b)[keep]
    return float(np.sqrt(np.mean(d * d)))


# ---------------------------------------------------------------- renderers
def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    return data.reshape(h, w, 3 if kind == b"PF" else 1)[::-1].astype(np.float64)


class Unsupported(Exception):
    pass


def render_clpt(a, s, gltf, seed, base):
    cam_from, cam_at, fov = CAMERAS["floor" if s["floor"] else "sphere"]
    bg = {"white": "background { color 1 1 1 }\n", "black": "",
          "env": 'background { map "%s" }\n' % a.envmap}[s["background"]]
    mat = "material m { %s }\n" % s["clpt"] if s["clpt"] else ""
    # a medium scene (docs/media.md): the medium `fog`, and the mesh's own keys
    med = "medium fog { %s }\n" % s["clpt_medium"] if s.get("clpt_medium") else ""
    mesh_keys = " " + s["clpt_mesh"] if s.get("clpt_mesh") else (" material m" if s["clpt"] else "")
    text = ("image { width %d height %d spp %d depth %d seed %d }\n" % (a.size, a.size, a.spp, DEPTH, seed) +
            "camera { from %g %g %g at %g %g %g up 0 1 0 fov %g }\n" % (cam_from + cam_at + (fov,)) + bg + mat +
            med + 'mesh { file "%s"%s }\n' % (os.path.basename(gltf), mesh_keys))
    scene = base + ".scene"
    with open(scene, "w") as f:
        f.write(text)
    p = subprocess.run([a.clpt, scene, "-o", base + ".pfm", "--quiet"], stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, text=True)
    for e in s["needs"]:
        if "'%s'" % e in p.stdout and ("ignored" in p.stdout or "does not support" in p.stdout):
            raise Unsupported("clpt ignores %s" % e)
    if p.returncode != 0:
        raise RuntimeError("clpt exit %d: %s" % (p.returncode, p.stdout.strip().splitlines()[-1:]))
    return read_pfm(base + ".pfm")


class Mitsuba:
    name = "mitsuba"
    install = "`pip install mitsuba` (scalar_rgb needs nothing else)"

    @staticmethod
    def available():
        try:
            import mitsuba  # noqa: F401
            return True
        except ImportError:
            return False

    def __init__(self, a):
        if a.mitsuba_variant.startswith("llvm") and os.path.exists(LLVM19):
            os.environ.setdefault("DRJIT_LIBLLVM_PATH", LLVM19)
        import mitsuba as mi
        mi.set_variant(a.mitsuba_variant)
        self.mi, self.a = mi, a
        self.label = "Mitsuba %s %s" % (mi.__version__, a.mitsuba_variant)

    def bitmap(self, path, raw):
        return {"type": "bitmap", "filename": path, "filter_type": "nearest", "raw": raw}

    def scene(self, s, folder, tex):
        mi, a = self.mi, self.a
        cam_from, cam_at, fov = CAMERAS["floor" if s["floor"] else "sphere"]
        t = {k: self.bitmap(p, k == "normal") for k, p in tex.items()}
        bsdf = s["mitsuba"](mi, t)
        sph = os.path.join(folder, s["name"] + "-sphere.ply")
        if s["sphere"]:
            write_ply(sph, uv_sphere())
        d = {"type": "scene",
             "integrator": {"type": "volpath" if s.get("mitsuba_interior") else "path", "max_depth": DEPTH + 1},
             "sensor": {"type": "perspective", "fov": fov, "fov_axis": "y",
                        "to_world": mi.ScalarTransform4f().look_at(origin=list(cam_from), target=list(cam_at),
                                                                   up=[0, 1, 0]),
                        "film": {"type": "hdrfilm", "width": a.size, "height": a.size,
                                 "rfilter": {"type": "box"}, "pixel_format": "rgb"},
                        "sampler": {"type": "independent", "sample_count": a.spp}}}
        if s["sphere"]:
            d["sphere"] = {"type": "ply", "filename": sph, "bsdf": bsdf, "face_normals": False}
        em = s["mitsuba_emitter"]
        if em is not None:
            d["sphere"]["emitter"] = {"type": "area", "radiance": t[em] if isinstance(em, str) else
                                      {"type": "rgb", "value": list(em)}}
        if s.get("mitsuba_interior"):
            interior = s["mitsuba_interior"]   # a dict, or a function of mi (a grid needs mi.VolumeGrid)
            d["sphere"]["interior"] = interior(mi) if callable(interior) else interior
        if s["floor"]:
            fl = os.path.join(folder, s["name"] + "-floor.ply")
            write_ply(fl, floor_quad())
            d["floor"] = {"type": "ply", "filename": fl, "bsdf": s["mitsuba"](mi, t)}
        if s["background"] == "white":
            d["bg"] = {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}}
        elif s["background"] == "env":
            d["bg"] = {"type": "envmap", "filename": a.envmap}
        L = s["light"]
        if L:
            w = [c * L["intensity"] / 683.0 for c in L["color"]]
            if L["type"] == "point":
                d["light"] = {"type": "point", "position": list(L["at"]), "intensity": {"type": "rgb", "value": w}}
            elif L["type"] == "spot":
                d["light"] = {"type": "spot", "intensity": {"type": "rgb", "value": w},
                              "cutoff_angle": math.degrees(L["spot"]["outerConeAngle"]),
                              "beam_width": math.degrees(L["spot"]["innerConeAngle"]),
                              "to_world": mi.ScalarTransform4f().look_at(
                                  origin=list(L["at"]), target=list(np.add(L["at"], (0, -1, 0))), up=[0, 0, 1])}
            else:
                d["light"] = {"type": "directional", "direction": list(L["dir"]),
                              "irradiance": {"type": "rgb", "value": w}}
        return mi.load_dict(d)

    def render(self, s, folder, tex, seeds, base):
        if s["mitsuba"] is None:
            raise Unsupported("no equivalent")
        sc = self.scene(s, folder, tex)
        return [np.array(self.mi.render(sc, spp=self.a.spp, seed=k), dtype=np.float64)[:, :, :3] for k in seeds]


class Cycles:
    name = "cycles"
    install = "`apt-get install blender python3-numpy` (Debian 12: Blender 3.4)"

    @staticmethod
    def available():
        return shutil.which("blender") is not None

    def __init__(self, a):
        self.a = a
        self.label = "Cycles (Blender's glTF importer)"

    def render_all(self, todo, folder):
        """todo: [(scene, gltf, seeds)] -> {(name, seed): image}, one Blender process."""
        jobs = []
        for s, gltf, seeds in todo:
            for k in seeds:
                jobs.append({"gltf": gltf, "out": os.path.join(folder, "%s-cycles-%d" % (s["name"], k)),
                             "width": self.a.size, "height": self.a.size, "spp": self.a.spp, "seed": k,
                             "bounces": DEPTH - 1, "override": s["cycles"],
                             "background": {"kind": s["background"], "map": self.a.envmap, "rotz": 90.0}})
        if not jobs:
            return {}
        jf = os.path.join(folder, "cycles-jobs.json")
        with open(jf, "w") as f:
            json.dump(jobs, f, indent=1)
        # Blender takes the first python3 on PATH for its numpy: not a pyenv or venv one
        env = dict(os.environ)
        env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep)
                                      if ".pyenv" not in p and p != os.path.dirname(sys.executable))
        log = os.path.join(folder, "cycles.log")
        with open(log, "w") as f:
            p = subprocess.run(["blender", "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                                os.path.join(HERE, "cycles_render.py"), "--", jf], stdout=f,
                               stderr=subprocess.STDOUT, env=env)
        out = {}
        for j in jobs:
            if os.path.exists(j["out"] + ".npy"):
                name = os.path.basename(j["out"]).rsplit("-cycles-", 1)[0]
                out[(name, j["seed"])] = np.load(j["out"] + ".npy").astype(np.float64)
        if p.returncode != 0:
            print("cycles: Blender exited %d (log: %s); %d of %d images made" % (p.returncode, log, len(out),
                                                                                len(jobs)), flush=True)
        return out


# ---------------------------------------------------------------- the run
def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--clpt", default="build/clpt")
    ap.add_argument("--out", default="build/xcheck")
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--only", default="", help="the scenes to render (comma-separated names)")
    ap.add_argument("--peers", default="mitsuba,cycles", help="the peers to try (comma-separated)")
    ap.add_argument("--envmap", default=None, help="the env scenes' map (default ../shared/envmaps/courtyard.hdr)")
    ap.add_argument("--mitsuba-variant", default="scalar_rgb")
    ap.add_argument("--pbrt", default="", help="a pbrt-v4 binary: also render the pbrt-v4 media scenes with it")
    ap.add_argument("--pbrt-threads", type=int, default=2, help="pbrt-v4's --nthreads")
    ap.add_argument("--list", action="store_true", help="list the scenes and exit")
    a = ap.parse_args()
    all_scenes = xscenes.scene_list()
    if a.list:
        for s in all_scenes:
            print("%-20s %s" % (s["name"], s["what"]))
        for s in pbrt_check.SCENES:
            print("%-20s %s (pbrt-v4 file; with --pbrt)" % (s[0], s[4]))
        return 0
    names = [n for n in a.only.split(",") if n]
    unknown = set(names) - {s["name"] for s in all_scenes} - set(pbrt_check.NAMES)
    if unknown:
        raise SystemExit("unknown scenes: %s (--list names them)" % ", ".join(sorted(unknown)))
    pbrt_names = [n for n in names if n in pbrt_check.NAMES]
    todo = [s for s in all_scenes if not names or s["name"] in names]
    if names and not todo and pbrt_names and not a.pbrt:
        raise SystemExit("%s: pbrt-v4 scenes, rendered only with --pbrt PATH" % ", ".join(pbrt_names))
    a.clpt = os.path.abspath(a.clpt)
    if not os.path.exists(a.clpt):
        raise SystemExit("%s: build clpt first (make)" % a.clpt)
    a.envmap = os.path.abspath(a.envmap or os.path.join(HERE, "..", "..", "..", "shared", "envmaps",
                                                         "courtyard.hdr"))
    if any(s["background"] == "env" for s in todo) and not os.path.exists(a.envmap):
        print("env scenes skipped: %s is not there (--envmap FILE)" % a.envmap)
        todo = [s for s in todo if s["background"] != "env"]
    folder = os.path.abspath(a.out)
    os.makedirs(folder, exist_ok=True)
    if a.pbrt and not (os.path.isfile(a.pbrt) and os.access(a.pbrt, os.X_OK)):
        raise SystemExit("%s: not an executable pbrt-v4 binary (--pbrt / PBRT=)" % a.pbrt)
    pbrt_results = {}
    if not a.pbrt:
        print("pbrt-v4: skipped, no binary given: `make xcheck PBRT=/path/to/pbrt` (a pbrt-v4 build; "
              "nothing of it is in this repository)", flush=True)
    elif not names or pbrt_names:
        pbrt_results = pbrt_check.rows(a, pbrt_names, folder, read_pfm)
        print(flush=True)
    if names and not todo:
        with open(os.path.join(folder, "results.json"), "w") as f:
            json.dump({"pbrt/%s" % k: v for k, v in pbrt_results.items()}, f, indent=1)
        return 0

    peers = []
    for cls in (Mitsuba, Cycles):
        if cls.name not in a.peers.split(","):
            continue
        if cls.available():
            peers.append(cls(a))
        else:
            print("%s: skipped, not installed: %s" % (cls.name, cls.install), flush=True)
    print("%d scenes, %d x %d, %d spp, seeds 1 and 2; clpt %s; peers: %s" % (
        len(todo), a.size, a.size, a.spp, a.clpt, ", ".join(p.label for p in peers) or "none"), flush=True)

    seeds = (1, 2)
    imgs = {}          # (renderer, scene) -> [img, img] or a string (why none)
    files = {}
    for s in todo:
        tex = texture_files(s, folder)
        gltf = write_gltf(s, folder, tex)
        files[s["name"]] = (gltf, tex)
        t0 = time.time()
        try:
            imgs[("clpt", s["name"])] = [render_clpt(a, s, gltf, k, os.path.join(folder, "%s-clpt-%d" % (
                s["name"], k))) for k in seeds]
        except Unsupported as e:
            imgs[("clpt", s["name"])] = "unsupported (%s)" % e
        except RuntimeError as e:
            imgs[("clpt", s["name"])] = "failed: %s" % e
        t1 = time.time()
        line = "%-20s clpt %.1f s" % (s["name"], t1 - t0)
        if isinstance(imgs[("clpt", s["name"])], str):
            print(line + "  " + imgs[("clpt", s["name"])] + ": no peer renders it", flush=True)
            continue
        for p in peers:
            if p.name != "mitsuba":
                continue
            try:
                imgs[(p.name, s["name"])] = p.render(s, folder, tex, seeds, None)
            except Unsupported as e:
                imgs[(p.name, s["name"])] = str(e)
            except Exception as e:  # a peer's failure is reported in its row, not fatal
                imgs[(p.name, s["name"])] = "failed: %s" % str(e).splitlines()[0][:80]
            line += "  mitsuba %.1f s" % (time.time() - t1)
        print(line, flush=True)
    for p in peers:
        if p.name == "cycles":
            t0 = time.time()
            got = p.render_all([(s, files[s["name"]][0], seeds) for s in todo
                                if not isinstance(imgs[("clpt", s["name"])], str) and not s.get("no_cycles")],
                               folder)
            print("cycles: %d images in %.1f s" % (len(got), time.time() - t0), flush=True)
            for s in todo:
                if isinstance(imgs[("clpt", s["name"])], str):
                    imgs[("cycles", s["name"])] = "not rendered"
                elif s.get("no_cycles"):
                    imgs[("cycles", s["name"])] = "no equivalent"
                elif all((s["name"], k) in got for k in seeds):
                    imgs[("cycles", s["name"])] = [got[(s["name"], k)] for k in seeds]
                else:
                    imgs[("cycles", s["name"])] = "failed (see cycles.log)"

    results = {}
    for p in peers:
        print()
        print("### clpt against %s (%d x %d, %d spp each, two seeds)" % (p.label, a.size, a.size, a.spp))
        print()
        print("| scene | clpt mean | %s mean | ratio | RMSE | noise floor | known model difference |" % p.name)
        print("|---|---|---|---|---|---|---|")
        for s in todo:
            c, q = imgs[("clpt", s["name"])], imgs.get((p.name, s["name"]), "not rendered")
            note = s["notes"].get(p.name, "")
            if isinstance(c, str) or isinstance(q, str):
                why = "clpt: " + c if isinstance(c, str) else "%s: %s" % (p.name, q)
                print("| %s | %s | | | | | %s |" % (s["name"], why, note))
                results[(p.name, s["name"])] = why
                continue
            keep = np.repeat(object_mask(s, a.size)[:, :, None], 3, axis=2)
            cm, qm = (c[0] + c[1]) / 2, (q[0] + q[1]) / 2
            nc, nq = rmse(c[0], c[1], keep) / math.sqrt(2), rmse(q[0], q[1], keep) / math.sqrt(2)
            mc, mq = float(cm[keep].mean()), float(qm[keep].mean())
            row = (mc, mq, mc / mq if mq > 0 else float("nan"), rmse(cm, qm, keep),
                   math.hypot(nc, nq) / math.sqrt(2))
            results[(p.name, s["name"])] = row
            print("| %s | %.4f | %.4f | %.3f | %.4f | %.4f | %s |" % ((s["name"],) + row + (note,)))
    if not peers:
        print("no peer installed: clpt rendered the scenes alone (%s)" % folder)
        for s in todo:
            c = imgs[("clpt", s["name"])]
            print("%-20s %s" % (s["name"], c if isinstance(c, str) else "image mean %.4f" % float(
                ((c[0] + c[1]) / 2).mean())))
    results.update({("pbrt", k): v for k, v in pbrt_results.items()})
    with open(os.path.join(folder, "results.json"), "w") as f:
        json.dump({"%s/%s" % k: v for k, v in results.items()}, f, indent=1)
    for (r, name), v in imgs.items():
        if not isinstance(v, str):
            np.save(os.path.join(folder, "%s-%s.npy" % (name, r)), ((v[0] + v[1]) / 2).astype(np.float32))
    return 0


if __name__ == "__main__":
    sys.exit(main())
