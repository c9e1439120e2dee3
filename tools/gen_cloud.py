#!/usr/bin/env python3
"""gen_cloud.py — writes scenes/cloud.scene: a cumulus cloud as a density grid (a
heterogeneous medium, docs/media.md) under a photographed sky, ../shared/envmaps'
sunrise.hdr, which lights it as the only light. The cloud is a few overlapping round
puffs on a flat base whose edges value noise eats away (fBm, three octaves), so its
core is dense and its rim wispy. Procedural and deterministic, so the file is
reproduced exactly by running this again.

    python3 tools/gen_cloud.py > scenes/cloud.scene
"""
import gridgen

NX, NY, NZ = 40, 20, 40
# the grid's box in the world: 4 wide, 2 deep, 1.6 high, floating 1 above the ground
BOX_MIN, BOX_MAX = (-2.0, 1.0, -2.0), (2.0, 2.6, 2.0)
# puffs: centre (relative to the box's bottom centre) and radius, world units
PUFFS = ((0.0, 0.70, 0.0, 0.75), (-0.90, 0.55, 0.20, 0.55), (0.90, 0.50, -0.20, 0.60),
         (0.20, 1.05, 0.10, 0.50), (-0.40, 0.95, -0.50, 0.45), (0.50, 0.80, 0.60, 0.45),
         (-1.40, 0.40, -0.10, 0.35), (1.45, 0.38, 0.25, 0.32))


def smoothstep(a, b, x):
    t = min(1.0, max(0.0, (x - a) / (b - a)))
    return t * t * (3 - 2 * t)


def cloud(x, y, z):
    """(density in 0 .. 1,) at x, z in [-1, 1] across, y in [0, 1] up."""
    wx, wy, wz = 2.0 * x, 1.6 * y, 2.0 * z
    shape = max(1.0 - ((wx - cx) ** 2 + (wy - cy) ** 2 + (wz - cz) ** 2) ** 0.5 / r for cx, cy, cz, r in PUFFS)
    fbm = sum(a * gridgen.value_noise(f * wx + 7.0, f * wy + 3.0, f * wz + 11.0)
              for a, f in ((0.55, 2.5), (0.3, 5.0), (0.15, 10.0)))
    d = min(1.0, max(0.0, 4.0 * (shape + 0.45 * (fbm - 0.5))))
    d *= smoothstep(0.12, 0.32, wy)              # a flat base, as a cumulus' condensation level
    return (d,)


def main():
    (dens,) = gridgen.sample(cloud, NX, NY, NZ, y_from_zero=True)
    print("# A cumulus cloud: a %dx%dx%d density grid (a heterogeneous medium, docs/media.md)" % (NX, NY, NZ))
    print("# floating under a photographed sunrise sky (../shared/envmaps/sunrise.hdr, beside the")
    print("# checkout as for scenes/envmap.scene), its only light: next-event estimation samples")
    print("# the map through the cloud by residual ratio tracking. Nearly no absorption and")
    print("# forward scattering (g 0.6) give the bright rim and the dark, thick core. Written by")
    print("# tools/gen_cloud.py; edit that and run it again rather than this file.")
    print("image { width 480 height 270 spp 256 depth 64 }")
    print("camera { from 0 0.3 5.5  at 0 1.8 0  up 0 1 0  fov 50 }")
    print('background { map "../../shared/envmaps/sunrise.hdr" intensity 1 rotate 150 }')
    print("# densities 0 .. 1; albedo 0.99, extinction 16 per unit at density 1")
    print("medium cloud {")
    print("    type grid  albedo 0.99 0.99 0.99  density 16  g 0.6")
    print("    size %d %d %d  min %g %g %g  max %g %g %g" % ((NX, NY, NZ) + BOX_MIN + BOX_MAX))
    print("    data [")
    print(gridgen.block([round(v, 2) for v in dens], NX).replace(" 0.", " .").replace("        0.", "        ."))
    print("    ]")
    print("}")
    print("# the boundary: a box that is no surface, just around the grid's box")
    print("box { min %g %g %g  max %g %g %g  material none  interior cloud }" % (
        tuple(v - 0.01 for v in BOX_MIN) + tuple(v + 0.01 for v in BOX_MAX)))


if __name__ == "__main__":
    main()
