#!/usr/bin/env python3
"""gen_glow.py — writes scenes/glow.scene: emission from media (docs/media.md,
"Emission") at dusk. A glowing fog ball (a homogeneous medium that emits, absorbs and
scatters) and a flame (a grid medium: a tapering column of density whose emission scale,
pbrt-v4's "Lescale" grid, is hottest low in its core) over a floor, under a dim sky and
a low, weak sun. Procedural and deterministic, so the file is reproduced exactly by
running this again.

    python3 tools/gen_glow.py > scenes/glow.scene
"""
import math

import gridgen

NX, NY, NZ = 12, 24, 12


def flame(x, y, z):
    """(density, emission scale) at x, z in [-1, 1] across, y in [0, 1] up."""
    sway = 0.12 * math.sin(6.0 * y) * y
    radius = 0.55 * (1.0 - y) ** 0.6 + 0.05
    r2 = ((x - sway) ** 2 + z * z) / (radius * radius)
    d = math.exp(-2.5 * r2) * (1.0 - y) ** 0.5 * min(1.0, 8.0 * y + 0.3)
    heat = math.exp(-3.0 * r2) * (1.0 - y) ** 1.5
    return d, heat


def main():
    dens, heat = gridgen.sample(flame, NX, NY, NZ, y_from_zero=True)

    def block(values):
        return gridgen.block(values, NX)

    print("""# Glow: emission from media (docs/media.md, "Emission"). A fog ball that glows
# (a homogeneous medium emitting Le, absorbing and scattering) and a flame (a %dx%dx%d
# grid: density, and an emission scale per cell, hottest low in its core) over a floor
# at dusk. Media emission is found by paths only (no light samples toward it), so
# the floor is lit by the glow through its bounces. Written by tools/gen_glow.py; edit
# that and run it again rather than this file.
image { width 480 height 320 spp 256 depth 12 }
camera { from 0 1.0 4.6  at 0 0.7 0  up 0 1 0  fov 38 }
background { horizon 0.05 0.05 0.08  zenith 0.01 0.01 0.03 }
light { type directional  direction 0.6 -0.35 -0.5  intensity 0.25 0.2 0.3 }
material floor { type diffuse albedo 0.55 0.5 0.45 }
plane { point 0 0 0  normal 0 1 0  material floor }

# the glowing fog ball: extinction 1.5 per unit, two fifths of it absorbing, emitting a pale
# cyan Le (a stretch ds emits sigma_a Le ds)
medium ball { type homogeneous  albedo 0.6 0.6 0.6  density 1.5  g 0.2  emission 0.4 0.9 1.0  emission_scale 2.5 }
sphere { center -0.9 0.6 0  radius 0.6  material none  interior ball }

# the flame: density 0 .. 1 times extinction 12 (albedo 0.3), emission an orange Le
# times the cell's scale
medium flame {
    type grid  sigma_a 8.4 8.4 8.4  sigma_s 3.6 3.6 3.6  g 0.1
    size %d %d %d  min -1 0 -1  max 1 1 1  scale 0.6 1.6 0.6  translate 0.9 0 0
    emission 8 2.4 0.45
    data [
%s
    ]
    emission_data [
%s
    ]
}
# the boundary: a box that is no surface, around the grid's box
box { min 0.29 0.001 -0.61  max 1.51 1.61 0.61  material none  interior flame }""" % (
        NX, NY, NZ, NX, NY, NZ, block(dens), block(heat)))


main()
