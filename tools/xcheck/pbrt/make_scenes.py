#!/usr/bin/env python3
"""make_scenes.py -- writes the pbrt-v4 media scenes of the cross-check (this folder's .pbrt
files; tools/xcheck/xcheck.py --pbrt renders each with clpt and with pbrt-v4). Run it again
after changing a scene here; the files are committed so that either renderer can be run on
them by hand. The density grids are written inline (pbrt-v4's `uniformgrid` medium), with
an outer layer of empty voxels: pbrt's grid fades to 0 over the outer half voxel where
clpt's keeps the outermost value (docs/media.md), so with empty borders the two densities
are the same function.

No medium's boundary lies in the floor's plane (y = -1): the boxes start at y = -0.98.
A boundary coplanar with the floor leaves which side a floor point is on to rounding,
and pbrt-v4 shadowed the floor under the box where clpt did not (measured: the first
version of these scenes, 4-7% apart in red).

Every scene is square (the harness sets the size and the samples), pbrt's `independent`
sampler (clpt uses its own), `volpath` with 64 bounces, lit by a sun (`distant`) and a
sky (a constant `infinite` light).
"""
import math
import os

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SKY_SUN = ('LightSource "infinite" "rgb L" [0.25 0.32 0.45]\n'
           'LightSource "distant" "point3 from" [-2 3 2] "point3 to" [0 0 0] "rgb L" [2.6 2.4 2.1]\n')
FLOOR = ('AttributeBegin\n  Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]\n'
         '  Shape "bilinearmesh" "point3 P" [-8 -1 -8  8 -1 -8  -8 -1 8  8 -1 8]\nAttributeEnd\n')
# the 12 triangles of a box, wound so that every geometric normal points out: the inside
# medium is behind the normal, as pbrt-v4's MediumInterface reads it
BOX_INDICES = "0 2 1 0 3 2  4 5 6 4 6 7  0 1 5 0 5 4  3 7 6 3 6 2  0 4 7 0 7 3  1 2 6 1 6 5"


def head(comment, cam_from, cam_at, fov, name, maxdepth=64):
    return ("".join("# %s\n" % c for c in comment.strip().splitlines()) +
            "# Written by tools/xcheck/pbrt/make_scenes.py; rendered by `make xcheck PBRT=...`.\n"
            "LookAt %g %g %g   %g %g %g   0 1 0\n" % (cam_from + cam_at) +
            'Camera "perspective" "float fov" %g\n' % fov +
            'Film "rgb" "integer xresolution" 64 "integer yresolution" 64 "string filename" "%s.exr"\n' % name +
            'Sampler "independent" "integer pixelsamples" 64\n'
            'Integrator "volpath" "integer maxdepth" %d\n' % maxdepth)


def box(p0, p1):
    (x0, y0, z0), (x1, y1, z1) = p0, p1
    pts = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
           (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    return ('  Shape "trianglemesh" "point3 P" [%s]\n    "integer indices" [%s]\n' %
            ("  ".join("%g %g %g" % p for p in pts), BOX_INDICES))


def grid_text(d):
    """A pbrt `float density` array: x fastest, then y, then z (d indexed [z, y, x])."""
    vals = ["0" if v == 0 else "%.3g" % v for v in d.reshape(-1)]
    lines = [" ".join(vals[i:i + 16]) for i in range(0, len(vals), 16)]
    return "\n    ".join(lines)


def centers(n):
    return (np.arange(n) + 0.5) / n


def smoke_ball_density(n=20):
    """A ball of smoke in the unit cube: density 1 at the centre falling smoothly to 0 at
    radius 0.45 (of the cube's side), with a gentle swirl of two sines."""
    c = centers(n)
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    r = np.sqrt((x - 0.5) ** 2 + (y - 0.5) ** 2 + (z - 0.5) ** 2) / 0.45
    d = np.clip(1 - r * r, 0, None) ** 1.5 * (0.75 + 0.25 * np.sin(9 * x + 4 * y) * np.cos(7 * z - 3 * y))
    d[0, :, :] = d[-1, :, :] = d[:, 0, :] = d[:, -1, :] = d[:, :, 0] = d[:, :, -1] = 0
    return np.round(d, 3)


def cloud_density(n=24):
    """A cumulus of seven Gaussian puffs on a flat base, in the unit cube."""
    c = centers(n)
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    puffs = [(0.5, 0.38, 0.5, 0.2), (0.3, 0.33, 0.45, 0.15), (0.7, 0.33, 0.55, 0.15), (0.5, 0.58, 0.5, 0.14),
             (0.4, 0.5, 0.62, 0.12), (0.62, 0.5, 0.38, 0.12), (0.5, 0.3, 0.3, 0.12)]
    d = np.zeros_like(x)
    for px, py, pz, s in puffs:
        d += np.exp(-((x - px) ** 2 + (y - py) ** 2 + (z - pz) ** 2) / (2 * s * s))
    d = np.clip(1.6 * d - 0.5, 0, 1) * np.clip((y - 0.18) / 0.08, 0, 1)   # thresholded, a flat base
    d[0, :, :] = d[-1, :, :] = d[:, 0, :] = d[:, -1, :] = d[:, :, 0] = d[:, :, -1] = 0
    return np.round(d, 3)


def fire_ball(n=16):
    """A fire ball in the unit cube: (density, temperature in kelvin) per cell. The
    density falls from 1 at the centre to 0 at radius 0.45 (of the cube's side); the
    temperature from 4500 K at the centre to 1200 K at the rim, 0 outside (no emission:
    pbrt-v4 and clpt emit only above 100 K), with a gentle flicker of two sines."""
    c = centers(n)
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    r = np.sqrt((x - 0.5) ** 2 + (y - 0.5) ** 2 + (z - 0.5) ** 2) / 0.45
    inside = r < 1
    d = np.where(inside, np.clip(1 - r * r, 0, None) * (0.8 + 0.2 * np.sin(7 * x + 3 * y) * np.cos(5 * z)), 0)
    t = np.where(inside, 1200 + 3300 * (1 - r * r) * (0.9 + 0.1 * np.sin(11 * y)), 0)
    for a in (d, t):
        a[0, :, :] = a[-1, :, :] = a[:, 0, :] = a[:, -1, :] = a[:, :, 0] = a[:, :, -1] = 0
    return np.round(d, 3), np.round(t, 0)


def scenes():
    out = {}
    n = 20
    out["smoke-ball"] = (
        head("""A ball of grey smoke (a uniformgrid, 20^3, a smooth radial density) over a
grey floor, under a sun and a sky: a heterogeneous medium, albedo 0.9, forward scattering.""",
             (0, 0.6, 5), (0, 0, 0), 36, "smoke-ball") + "WorldBegin\n" + SKY_SUN + FLOOR +
        'MakeNamedMedium "smoke" "string type" "uniformgrid"\n'
        '  "integer nx" %d "integer ny" %d "integer nz" %d\n' % (n, n, n) +
        '  "point3 p0" [-1.1 -0.98 -1.1] "point3 p1" [1.1 1.2 1.1]\n'
        '  "rgb sigma_a" [0.4 0.4 0.4] "rgb sigma_s" [3.6 3.6 3.6] "float scale" 1.5 "float g" 0.4\n'
        '  "float density" [\n    %s ]\n' % grid_text(smoke_ball_density(n)) +
        'AttributeBegin\n  MediumInterface "smoke" ""\n  Material "interface"\n' +
        box((-1.1, -0.98, -1.1), (1.1, 1.2, 1.1)) + "AttributeEnd\n")
    out["glass-chromatic"] = (
        head("""A chromatic medium (sigma_a and sigma_s differ per channel: RGB against pbrt's
spectra) inside a glass sphere (eta 1.5) over a grey floor, under a sun and a sky.""",
             (0, 0.6, 5), (0, -0.1, 0), 36, "glass-chromatic") + "WorldBegin\n" + SKY_SUN + FLOOR +
        'MakeNamedMedium "tint" "string type" "homogeneous"\n'
        '  "rgb sigma_a" [0.05 0.25 0.6] "rgb sigma_s" [1.2 0.8 0.4] "float scale" 1 "float g" 0.2\n'
        'AttributeBegin\n  MediumInterface "tint" ""\n  Material "dielectric" "float eta" 1.5\n'
        '  Shape "sphere" "float radius" 1\nAttributeEnd\n')
    n = 24
    out["cloud-grid"] = (
        head("""A cumulus (a uniformgrid, 24^3, seven Gaussian puffs on a flat base) over a
grey floor under a sun and a sky: dense (sigma_s up to 10), albedo 0.995, g 0.5.""",
             (0, 0.4, 5), (0, 0.1, 0), 40, "cloud-grid") + "WorldBegin\n" + SKY_SUN + FLOOR +
        'MakeNamedMedium "cloud" "string type" "uniformgrid"\n'
        '  "integer nx" %d "integer ny" %d "integer nz" %d\n' % (n, n, n) +
        '  "point3 p0" [-1.6 -0.98 -1.6] "point3 p1" [1.6 2.2 1.6]\n'
        '  "rgb sigma_a" [0.05 0.05 0.05] "rgb sigma_s" [10 10 10] "float scale" 1 "float g" 0.5\n'
        '  "float density" [\n    %s ]\n' % grid_text(cloud_density(n)) +
        'AttributeBegin\n  MediumInterface "cloud" ""\n  Material "interface"\n' +
        box((-1.6, -0.98, -1.6), (1.6, 2.2, 1.6)) + "AttributeEnd\n")
    fog = head("""Homogeneous fog around the camera (its medium, from the MediumInterface before
Camera) and a diffuse sphere on a floor, all inside a fog box, under a sun and a sky.""",
               (0, 0.6, 5), (0, -0.2, 0), 40, "fog")
    # the medium is named before the camera, which takes the MediumInterface's outside one
    fog = fog.replace("LookAt", 'MakeNamedMedium "fog" "string type" "homogeneous"\n'
                      '  "rgb sigma_a" [0.02 0.02 0.02] "rgb sigma_s" [0.15 0.15 0.15] "float scale" 1 "float g" 0.3\n'
                      'MediumInterface "fog" "fog"\nLookAt', 1)
    out["fog"] = (
        fog + "WorldBegin\n" + SKY_SUN +
        'AttributeBegin\n  MediumInterface "fog" "fog"\n' +
        '  Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]\n'
        '  Shape "bilinearmesh" "point3 P" [-6 -1 -6  6 -1 -6  -6 -1 6  6 -1 6]\n'
        '  Material "diffuse" "rgb reflectance" [0.7 0.45 0.25]\n'
        '  Shape "sphere" "float radius" 1\nAttributeEnd\n'
        'AttributeBegin\n  MediumInterface "fog" ""\n  Material "interface"\n' +
        box((-6, -1.001, -6), (6, 4, 7)) + "AttributeEnd\n")
    n = 16
    dens, temp = fire_ball(n)
    out["fire-ball"] = (
        head("""A fire ball (a uniformgrid, 16^3, with a "temperature" grid: blackbody emission,
1200 K at its rim to 4500 K in its core) over a grey floor under a dim sky: the medium
absorbs (sigma_a 4) and scatters a little (sigma_s 1); its light reaches the floor only
through paths (no light samples toward media).""",
             (0, 0.6, 5), (0, -0.1, 0), 36, "fire-ball") + "WorldBegin\n" +
        'LightSource "infinite" "rgb L" [0.03 0.04 0.06]\n' + FLOOR +
        'MakeNamedMedium "fire" "string type" "uniformgrid"\n'
        '  "integer nx" %d "integer ny" %d "integer nz" %d\n' % (n, n, n) +
        '  "point3 p0" [-1.1 -0.98 -1.1] "point3 p1" [1.1 1.2 1.1]\n'
        '  "rgb sigma_a" [4 4 4] "rgb sigma_s" [1 1 1] "float scale" 1 "float g" 0\n'
        '  "float density" [\n    %s ]\n' % grid_text(dens) +
        '  "float temperature" [\n    %s ]\n' % grid_text(temp) +
        # an explicit Lescale grid of ones: without one pbrt-v4 looks its emission scale up
        # in a 1 x 1 x 1 grid, which its trilinear lookup fades to 0.5 at each face (a
        # tent, 0.125 at the corners); clpt takes the scale as 1 everywhere
        '  "float Lescale" [\n    %s ]\n' % grid_text(np.ones((n, n, n))) +
        'AttributeBegin\n  MediumInterface "fire" ""\n  Material "interface"\n' +
        box((-1.1, -0.98, -1.1), (1.1, 1.2, 1.1)) + "AttributeEnd\n")
    # the same ball as an rgbgrid: sigma_a and sigma_s colours per voxel (grey, in
    # proportion to the density) and an orange "Le" grid of one hue, whose brightness
    # follows the fire ball's heat; clpt reads it as one colour times a scale per voxel,
    # exact for one hue (docs/media.md, "RGB grids"); pbrt-v4 does not normalise an
    # rgbgrid's Le by its illuminant's luminance, so a unit of it is 106.857 of radiance
    # (as clpt reads it too) and Lescale 0.005 makes the hottest voxel about 1.6 in red
    glow = np.clip((temp - 1200) / 3300, 0, None) * 3
    def rgb_text(a, colour):
        vals = ["0 0 0" if v == 0 else " ".join("%.4g" % (v * c) for c in colour) for v in a.reshape(-1)]
        return "\n    ".join(" ".join(vals[i:i + 8]) for i in range(0, len(vals), 8))
    out["rgbgrid-glow"] = (
        head("""The fire ball as an rgbgrid (16^3): sigma_a 3 and sigma_s 1 per unit of its density,
given per voxel, and an orange "Le" grid (one hue, up to 3 1.35 0.45) times "Lescale" 0.005,
over a grey floor under a dim sky: emission read from pbrt-v4's RGBGridMedium.""",
             (0, 0.6, 5), (0, -0.1, 0), 36, "rgbgrid-glow") + "WorldBegin\n" +
        'LightSource "infinite" "rgb L" [0.03 0.04 0.06]\n' + FLOOR +
        'MakeNamedMedium "glow" "string type" "rgbgrid"\n'
        '  "integer nx" %d "integer ny" %d "integer nz" %d\n' % (n, n, n) +
        '  "point3 p0" [-1.1 -0.98 -1.1] "point3 p1" [1.1 1.2 1.1] "float scale" 1 "float g" 0\n'
        '  "rgb sigma_a" [\n    %s ]\n' % rgb_text(dens, (3, 3, 3)) +
        '  "rgb sigma_s" [\n    %s ]\n' % rgb_text(dens, (1, 1, 1)) +
        '  "rgb Le" [\n    %s ]\n' % rgb_text(glow, (1, 0.45, 0.15)) +
        '  "float Lescale" 0.005\n'
        'AttributeBegin\n  MediumInterface "glow" ""\n  Material "interface"\n' +
        box((-1.1, -0.98, -1.1), (1.1, 1.2, 1.1)) + "AttributeEnd\n")
    return out


def main():
    for name, text in scenes().items():
        with open(os.path.join(HERE, name + ".pbrt"), "w") as f:
            f.write(text)
        print("wrote %s.pbrt (%d bytes)" % (name, len(text)))


if __name__ == "__main__":
    main()
