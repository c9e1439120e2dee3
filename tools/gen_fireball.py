#!/usr/bin/env python3
"""gen_fireball.py — writes scenes/fireball.scene: blackbody emission from a temperature
grid (docs/media.md, "Blackbody emission"). A small ball of fire (a grid medium: a
density, and a temperature per cell, hottest low in its core and cooling as it rises)
over a floor at night. Each cell glows with pbrt-v4's BlackbodySpectrum of its
temperature, baked to RGB at load, so the colour runs from deep red at the rim to
yellow-white in the core. Procedural and deterministic, so the file is reproduced
exactly by running this again.

    python3 tools/gen_fireball.py > scenes/fireball.scene
"""
import math

import gridgen

NX, NY, NZ = 12, 16, 12


def fire(x, y, z):
    """(density, heat in [0, 1]) at x, y, z in [-1, 1]: a ball squashed upward, its heat
    highest a little below the centre."""
    sway = 0.08 * math.sin(5.0 * y)
    r2 = (x - sway) ** 2 + (1.3 * (y + 0.15)) ** 2 * (0.8 if y > 0 else 1.2) + z * z
    d = max(0.0, 1.0 - r2) ** 1.5 * (0.85 + 0.15 * math.sin(6 * x + 2 * y) * math.cos(5 * z))
    heat = max(0.0, 1.0 - 1.3 * r2) ** 1.2
    return d, heat


def main():
    dens, heat = gridgen.sample(fire, NX, NY, NZ)

    def block(values):
        return gridgen.block(values, NX)

    print("""# Fireball: blackbody emission from a temperature grid (docs/media.md, "Blackbody
# emission"). A %dx%dx%d grid medium holds a density and a heat per cell; the heat becomes
# kelvin by T = (heat - temperature_offset) * temperature_scale, 960 K (a dull red) to
# 4160 K (yellow-white), and each cell emits pbrt-v4's BlackbodySpectrum(T) (peak 1) as
# RGB times emission_scale. A film records that spectrum's integrals against the colour
# matching functions, with no photometric normalisation (as pbrt-v4's): about 100 times
# an RGB 1 1 1 at 6500 K, hence the small emission_scale. Media emission is found by paths only, so the floor is lit by the
# fire through its bounces. Written by tools/gen_fireball.py; edit that and run it again
# rather than this file.
image { width 320 height 320 spp 256 depth 8 }
camera { from 0 0.9 4.2  at 0 0.7 0  up 0 1 0  fov 36 }
background { horizon 0.02 0.02 0.03  zenith 0.005 0.005 0.01 }
material floor { type diffuse albedo 0.5 0.5 0.5 }
plane { point 0 0 0  normal 0 1 0  material floor }

medium fire {
    type grid  sigma_a 6 6 6  sigma_s 1.5 1.5 1.5  g 0.2
    size %d %d %d  min -1 -1 -1  max 1 1 1  scale 0.7 0.7 0.7  translate 0 0.75 0
    temperature_offset -0.3  temperature_scale 3200  emission_scale 0.03
    data [
%s
    ]
    temperature_data [
%s
    ]
}
# the boundary: a box that is no surface, around the grid's box
box { min -0.71 0.04 -0.71  max 0.71 1.46 0.71  material none  interior fire }""" % (
        NX, NY, NZ, NX, NY, NZ, block(dens), block(heat)))


main()
