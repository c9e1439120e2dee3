#!/usr/bin/env python3
"""mitsuba_compare.py -- renders the same small scenes in clpt and in Mitsuba 3 and
compares the converged images (docs/validation.md has the table and what it means).

    python3 -m venv /tmp/mts && /tmp/mts/bin/pip install mitsuba numpy
    /tmp/mts/bin/python tools/mitsuba_compare.py [--size 64] [--spp 1024] [--mts-spp 512]
        [--clpt build/clpt] [--out /tmp/mitsuba-compare] [--variant scalar_rgb] [--only NAME]

Each scene is one sphere of radius 1 at the origin, seen from (0, 0, 4) with a 30 degree
vertical field of view, under a uniform white background of radiance 1 (clpt:
`background { color 1 1 1 }`, Mitsuba: a `constant` emitter). Both render with a box
pixel filter, path depth 16 (Mitsuba's max_depth counts the camera segment: 17), and
Russian roulette. The comparison leaves out the pixels on the sphere's silhouette (any
pixel whose four corners' rays do not all hit, or all miss, the sphere) and reports over
the sphere's other pixels: both means, the mean difference, the RMSE between the two, and the noise floor
of that RMSE, sqrt(noise_clpt^2 + noise_mitsuba^2), each renderer's noise estimated from
two renders with different seeds (RMSE(a, b) / sqrt(2)). A difference is above noise when
the RMSE clearly exceeds the floor or the mean difference exceeds a few standard errors.

Images (linear PFM, and PNG for looking at them) are written to --out. It needs pip's
mitsuba and numpy; `scalar_rgb` needs nothing else. It is not part of `make test`.
"""
import argparse
import math
import os
import subprocess
import sys
import time

import numpy as np

# name, clpt material block body, Mitsuba BSDF dict (a function of mi, for its types)
GGX = "ggx"


def scenes():
    au_eta, au_k = (0.1678, 0.3504, 1.5085), (3.1378, 2.7141, 1.8788)
    fe_eta, fe_k = (2.9114, 2.9497, 2.5845), (3.0893, 2.9318, 2.7670)

    def rgb(v):
        return {"type": "rgb", "value": list(v)}

    return [
        ("diffuse", "type diffuse albedo 0.8 0.5 0.2",
         {"type": "diffuse", "reflectance": rgb((0.8, 0.5, 0.2))}),
        ("conductor-au-r0.5", "type conductor metal Au roughness 0.5",
         {"type": "roughconductor", "distribution": GGX, "alpha": 0.25,
          "eta": rgb(au_eta), "k": rgb(au_k)}),
        ("conductor-fe-r0.2", "type conductor metal Fe roughness 0.2",
         {"type": "roughconductor", "distribution": GGX, "alpha": 0.04,
          "eta": rgb(fe_eta), "k": rgb(fe_k)}),
        ("conductor-f1-r1", "type conductor specular 1 1 1 roughness 1",
         {"type": "roughconductor", "distribution": GGX, "alpha": 1.0,
          "material": "none"}),
        ("glass-r0.4", "type dielectric ior 1.5 roughness 0.4",
         {"type": "roughdielectric", "distribution": GGX, "alpha": 0.16,
          "int_ior": 1.5, "ext_ior": 1.0}),
        ("principled-plastic-r0.5", "type principled albedo 0.8 0.2 0.1 metallic 0 roughness 0.5",
         {"type": "principled", "base_color": rgb((0.8, 0.2, 0.1)), "metallic": 0.0,
          "roughness": 0.5, "specular": 0.5}),
        # black base colour: the specular lobe alone, to tell it from the diffuse
        ("principled-black-r0.5", "type principled albedo 0 0 0 metallic 0 roughness 0.5",
         {"type": "principled", "base_color": rgb((0.0, 0.0, 0.0)), "metallic": 0.0,
          "roughness": 0.5, "specular": 0.5}),
        # the black principled sphere's specular lobe as a conductor with a dielectric's
        # Fresnel (eta 1.5, k 0): Mitsuba's principled uses that exact Fresnel where clpt's
        # (glTF Appendix B) uses Schlick's with F0 0.04; this row tells the two apart
        ("conductor-eta1.5-r0.5", "type conductor eta 1.5 1.5 1.5 k 0 0 0 roughness 0.5",
         {"type": "roughconductor", "distribution": GGX, "alpha": 0.25,
          "eta": rgb((1.5, 1.5, 1.5)), "k": rgb((0.0, 0.0, 0.0))}),
        ("principled-metal-r0.3", "type principled albedo 0.9 0.6 0.2 metallic 1 roughness 0.3",
         {"type": "principled", "base_color": rgb((0.9, 0.6, 0.2)), "metallic": 1.0,
          "roughness": 0.3, "specular": 0.5}),
    ]


CAM_FROM, FOV = (0.0, 0.0, 4.0), 30.0
DEPTH = 16


def env_scenes():
    """The scenes under an environment map: a plain diffuse sphere, two metals, rough
    glass and principled spheres."""
    by_name = {name: (body, bsdf) for name, body, bsdf in scenes()}
    return [("env-" + n,) + by_name[n] for n in ("diffuse", "conductor-au-r0.5", "conductor-fe-r0.2", "glass-r0.4",
                                                 "principled-plastic-r0.5", "principled-metal-r0.3")]


def clpt_scene(body, size, spp, seed, envmap):
    bg = f'background {{ map "{envmap}" }}\n' if envmap else "background { color 1 1 1 }\n"
    return (f"image {{ width {size} height {size} spp {spp} depth {DEPTH} seed {seed} }}\n"
            f"camera {{ from {CAM_FROM[0]} {CAM_FROM[1]} {CAM_FROM[2]} at 0 0 0 up 0 1 0 fov {FOV} }}\n"
            + bg +
            f"material m {{ {body} }}\n"
            "sphere { center 0 0 0 radius 1 material m }\n")


def read_pfm(path):
    with open(path, "rb") as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
    ch = 3 if kind == b"PF" else 1
    return data.reshape(h, w, ch)[::-1].astype(np.float64)   # PFM rows are bottom-up


def write_pfm(path, img):
    h, w, _ = img.shape
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (w, h))
        f.write(np.ascontiguousarray(img[::-1], dtype="<f4").tobytes())


def write_png(path, img):
    """Linear radiance to an sRGB 8-bit PNG, each pixel 4 x 4 (written with zlib, so no
    image tool is needed)."""
    import struct
    import zlib
    c = np.clip(img, 0.0, 1.0)
    s = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1 / 2.4) - 0.055)
    px = np.repeat(np.repeat((s * 255 + 0.5).astype(np.uint8), 4, axis=0), 4, axis=1)
    h, w, _ = px.shape
    raw = b"".join(b"\x00" + px[y].tobytes() for y in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))


def render_clpt(clpt, body, size, spp, seed, out, envmap):
    scene = out + ".scene"
    with open(scene, "w") as f:
        f.write(clpt_scene(body, size, spp, seed, envmap))
    t = time.time()
    subprocess.run([clpt, scene, "-o", out + ".pfm", "--quiet"], check=True)
    return read_pfm(out + ".pfm"), time.time() - t


def render_mitsuba(mi, bsdf, size, spp, seed, envmap):
    light = ({"type": "envmap", "filename": envmap} if envmap
             else {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}})
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": DEPTH + 1},
        "sensor": {
            "type": "perspective", "fov": FOV, "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=list(CAM_FROM), target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"},
                     "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "sphere": {"type": "sphere", "center": [0, 0, 0], "radius": 1.0, "bsdf": bsdf},
        "light": light,
    })
    t = time.time()
    img = np.array(mi.render(scene, spp=spp, seed=seed), dtype=np.float64)
    return img[:, :, :3], time.time() - t


def interior_mask(size):
    """Pixels whose four corners' rays all hit or all miss the unit sphere (clpt's camera:
    film position (s, t) in [0,1]^2, t = 0 at the top)."""
    half = math.tan(math.radians(FOV) / 2)
    o = np.array(CAM_FROM)
    edges = np.linspace(0.0, 1.0, size + 1)
    xs = (2 * edges - 1) * half
    ys = (1 - 2 * edges) * half
    X, Y = np.meshgrid(xs, ys)
    d = np.stack([X, Y, -np.ones_like(X)], axis=-1)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    b = d @ o
    disc = b * b - (o @ o - 1.0)
    hit = disc > 0
    c = hit[:-1, :-1].astype(int) + hit[1:, :-1] + hit[:-1, 1:] + hit[1:, 1:]
    return (c == 0) | (c == 4), c == 4


def compare(a, b, keep):
    d = (a - b)[keep]
    return float(np.sqrt(np.mean(d * d)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--clpt", default="build/clpt")
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--spp", type=int, default=1024, help="clpt samples per pixel")
    ap.add_argument("--mts-spp", type=int, default=512, help="Mitsuba samples per pixel")
    ap.add_argument("--variant", default="scalar_rgb")
    ap.add_argument("--out", default="/tmp/mitsuba-compare")
    ap.add_argument("--only", default=None, help="render only the scenes of these names (comma-separated)")
    ap.add_argument("--envmap", default=None,
                    help="also render env-* scenes under this equirectangular .hdr (clpt's "
                         "`background { map }`, Mitsuba's `envmap`: the same orientation)")
    args = ap.parse_args()
    import mitsuba as mi
    mi.set_variant(args.variant)
    os.makedirs(args.out, exist_ok=True)
    keep, inside = interior_mask(args.size)
    rows = []
    envmap = os.path.abspath(args.envmap) if args.envmap else None
    todo = [s + (None,) for s in scenes()] + ([s + (envmap,) for s in env_scenes()] if envmap else [])
    for name, body, bsdf, env in todo:
        if args.only and name not in args.only.split(","):
            continue
        base = os.path.join(args.out, name)
        c1, tc = render_clpt(args.clpt, body, args.size, args.spp, 1, base + "-clpt", env)
        c2, _ = render_clpt(args.clpt, body, args.size, args.spp, 2, base + "-clpt2", env)
        m1, tm = render_mitsuba(mi, bsdf, args.size, args.mts_spp, 1, env)
        m2, _ = render_mitsuba(mi, bsdf, args.size, args.mts_spp, 2, env)
        write_pfm(base + "-mitsuba.pfm", m1)
        for tag, img in (("clpt", c1), ("mitsuba", m1)):
            write_png(f"{base}-{tag}.png", img)
        write_png(base + "-diff.png", np.abs(c1 - m1) * 4)
        # over the sphere's pixels: where the background is a map, its own pixels differ by
        # the lookup (clpt: nearest pixel; Mitsuba: bilinear), which is no BSDF's doing
        sphere = np.repeat((keep & inside)[:, :, None], 3, axis=2)
        noise_c = compare(c1, c2, sphere) / math.sqrt(2)
        noise_m = compare(m1, m2, sphere) / math.sqrt(2)
        mean_c, mean_m = float(c1[sphere].mean()), float(m1[sphere].mean())
        n = int(sphere.sum())
        se = math.sqrt(noise_c ** 2 + noise_m ** 2) / math.sqrt(n)
        rows.append((name, mean_c, mean_m, mean_c - mean_m, se, compare(c1, m1, sphere),
                     math.hypot(noise_c, noise_m), tc, tm))
        print("%-26s sphere mean clpt %.4f mitsuba %.4f diff %+.4f (se %.4f) | RMSE %.4f floor %.4f"
              " | %.1f s / %.1f s" % rows[-1], flush=True)
    print()
    print("| scene | clpt mean | Mitsuba mean | difference (std. error) | RMSE | noise floor |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        print("| %s | %.4f | %.4f | %+.4f (%.4f) | %.4f | %.4f |" % r[:7])
    return 0


if __name__ == "__main__":
    sys.exit(main())
