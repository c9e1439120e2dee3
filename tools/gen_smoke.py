#!/usr/bin/env python3
"""gen_smoke.py — writes scenes/smoke.scene: a plume of smoke as a 32^3 density grid
(docs/media.md, heterogeneous media) over a floor, lit by a sun-like directional light
and a dim sky. The density is a wavy column of Gaussian puffs, broken up by value noise
and thinning with height: procedural and deterministic (no random module), so the file
is reproduced exactly by running this again.

    python3 tools/gen_smoke.py > scenes/smoke.scene
"""
import math

from gridgen import value_noise

N = 32


def density(x, y, z):
    """x, z in [-1, 1] across, y in [0, 1] up."""
    cx = 0.25 * math.sin(5.0 * y) * y
    cz = 0.15 * math.sin(3.0 * y + 1.0) * y
    radius = 0.18 + 0.45 * y
    r2 = ((x - cx) ** 2 + (z - cz) ** 2) / (radius * radius)
    column = math.exp(-2.5 * r2) * (1.0 - 0.6 * y)
    n = 0.65 * value_noise(4 * x + 10, 6 * y, 4 * z + 10) + 0.35 * value_noise(9 * x + 3, 12 * y, 9 * z + 3)
    d = column * max(0.0, 2.2 * n - 0.75)
    d *= min(1.0, y * 12.0)          # fades in just above the floor
    return d if d > 0.01 else 0.0


def main():
    vals = []
    for k in range(N):
        for j in range(N):
            for i in range(N):
                vals.append(density((i + 0.5) / N * 2 - 1, (j + 0.5) / N, (k + 0.5) / N * 2 - 1))
    peak = max(vals)
    print("# Smoke: a plume in a 32^3 density grid (a heterogeneous medium, docs/media.md)")
    print("# over a grey floor, lit by a low sun and a dim blue sky. Written by")
    print("# tools/gen_smoke.py; edit that and run it again rather than this file.")
    print("image { width 480 height 360 spp 64 depth 16 }")
    print("camera { from 0 1.1 4.2  at 0 0.85 0  up 0 1 0  fov 40 }")
    print("background { horizon 0.25 0.3 0.4  zenith 0.08 0.12 0.3 }")
    print("light { type directional  direction -0.7 -0.45 -0.3  intensity 3 2.7 2.3 }")
    print("material floor { type diffuse albedo 0.5 0.48 0.45 }")
    print("plane { point 0 0 0  normal 0 1 0  material floor }")
    print("# the grid's densities are 0 .. 1; albedo 0.9, extinction 14 per unit at density 1")
    print("medium smoke {")
    print("    type grid  albedo 0.9 0.9 0.9  density 14  g 0.3")
    print("    size %d %d %d  min -1 0 -1  max 1 1 1  scale 1 2 1" % (N, N, N))
    print("    data [")
    line = []
    for v in vals:
        line.append("0" if v == 0.0 else ("%.2f" % (v / peak)).lstrip("0"))
        if len(line) == N:
            print("       ", " ".join(line))
            line = []
    print("    ]")
    print("}")
    print("# the boundary: a box that is no surface, around the grid's box (y 0 .. 2)")
    print("box { min -1.01 0.001 -1.01  max 1.01 2.01 1.01  material none  interior smoke }")


main()
