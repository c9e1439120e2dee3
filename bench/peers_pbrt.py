#!/usr/bin/env python3
"""The peer benchmark against pbrt-v4 (bench/peers.py --pbrt PATH, `make bench-peers
PBRT=PATH`): clpt and a pbrt-v4 binary built outside the repository render the very same
pbrt-v4 scene files (clpt reads pbrt-v4's format: docs/pbrt.md), and each is timed to
equal error against its own converged render.

The scenes (written into --out/pbrt/ at each run; nothing of pbrt-v4 is in the repository):
  pbrt-cornell   McGuire's CornellBox-Original as ../shared/peers' cornell scene (its
                 camera, the MTL's diffuse colours, the light emitting Ke downwards only,
                 512 x 512, 64 spp, 8 bounces); the OBJ is split into one PLY per material
                 by ../shared/peers/cornell_split.py (what Mitsuba reads: duplicate faces
                 left out, the light wound to face down), as pbrt-v4 reads no OBJ
  pbrt-dragon    ../shared/peers' dragon scene (../shared/models' dragon_vrip.ply, the
                 floor and the small area light of ../shared/peers), 512 x 512, 16 spp
  pbrt-killeroo  pbrt-v4-scenes' killeroos/killeroo-simple.pbrt (two coateddiffuse
                 killeroos, loopsubdiv, under a spherical area light), 700 x 700 as the
                 file has it, 16 spp, when --pbrt-scenes names a checkout of
                 mmp/pbrt-v4-scenes (or a folder with killeroos/killeroo-simple.pbrt and
                 killeroos/geometry/killeroo.pbrt); its copy in --out differs from the file
                 only in the lines below and the Include made absolute
Each file sets what both renderers need alike: `PixelFilter "box"` (clpt's pixel filter;
pbrt-v4's default is a Gaussian, and clpt ignores PixelFilter with a warning),
`Integrator "path"` with `maxdepth` 8 (clpt's depth: the same bounce count), `Film "rgb"`
with `savefp16` false (pbrt-v4 writes half floats to EXR by default) and
`Sampler "zsobol"`, pbrt-v4's default and its best general-purpose sampler; its
blue-noise and pmj02bn tables may be zero-filled in a build made without them (as
/work/pbrt-v4-build's are), and zsobol uses neither (clpt reads the sampler's pixelsamples
only; its own Sobol sampler renders). The Cornell box and the dragon put `Scale -1 1 1`
before `LookAt`, so that their images are the right-handed renderers' ones.

Both renderers are timed as whole processes (wall time: start-up, scene load, BVH build,
render, image write), pbrt-v4 with --nthreads N (--pbrt-threads, default 2: the cores this
machine has) and clpt with its default device. They take turns within each round; times are
medians over the rounds, squared errors means over them. Each renderer's error is against
its OWN converged render (--ref-spp, two halves with seeds 777 and 778 whose difference
measures the reference's own error, taken off as in peers.py), because pbrt-v4 is spectral
and clpt RGB: their converged images differ by a bias, reported per scene as the two
references' mean ratio per channel (clpt / pbrt-v4, over the kept pixels), and that bias
belongs to the correctness comparison (tools/xcheck), not to the speed one. Silhouette
pixels are left out as peers.py does, where either reference has an edge.

usage: called by peers.py (run(a, scenes) with its parsed options; a.pbrt_spp: each scene's spp); needs numpy and
tools/xcheck/exr.py (pbrt-v4 writes OpenEXR).
"""
import os
import re
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, '..', 'tools', 'xcheck'))
from exr import read_exr  # noqa: E402
from peers_own import Renderer, compare, read_pfm, timed  # noqa: E402

DEPTH = 8
HEADER = ('# bench/peers_pbrt.py: %s, written for clpt and pbrt-v4 alike (generated)\n'
          'PixelFilter "box"\nIntegrator "path" "integer maxdepth" %d\n'
          'Sampler "zsobol" "integer pixelsamples" %d\n')


def film(size, name):
    return ('Film "rgb" "integer xresolution" %d "integer yresolution" %d "string filename" "%s.exr" '
            '"bool savefp16" false\n' % (size, size, name))


def write_cornell(a, folder):
    split = os.path.join(folder, 'cornell-split')
    if not os.path.exists(os.path.join(split, 'materials.json')):
        os.makedirs(split, exist_ok=True)
        obj = os.path.join(a.peers, '..', 'models', 'cornell-box', 'CornellBox-Original.obj')
        subprocess.run([sys.executable, os.path.join(a.peers, 'cornell_split.py'), obj, split], check=True,
                       stdout=subprocess.DEVNULL)
    import json
    with open(os.path.join(split, 'materials.json')) as f:
        mats = json.load(f)
    text = HEADER % ('McGuire\'s CornellBox-Original as ../shared/peers\' cornell scene', DEPTH,
                     a.pbrt_spp['pbrt-cornell'])
    text += film(512, 'cornell') + 'Scale -1 1 1\nLookAt 0 1 3.9  0 1 0  0 1 0\nCamera "perspective" "float fov" 39.3\n'
    text += 'WorldBegin\n'
    for name, m in mats.items():
        text += 'AttributeBegin\n  Material "diffuse" "rgb reflectance" [ %r %r %r ]\n' % tuple(m['Kd'])
        if any(m['Ke']):
            text += '  AreaLightSource "diffuse" "rgb L" [ %r %r %r ]\n' % tuple(m['Ke'])
        text += '  Shape "plymesh" "string filename" "cornell-split/%s.ply"\nAttributeEnd\n' % name
    return text


def write_dragon(a, folder):
    text = HEADER % ('../shared/peers\' dragon scene', DEPTH, a.pbrt_spp['pbrt-dragon'])
    text += film(512, 'dragon') + ('Scale -1 1 1\nLookAt 0.05 0.2 0.45  -0.005 0.12 0  0 1 0\n'
                                   'Camera "perspective" "float fov" 40\nWorldBegin\n'
                                   'Material "diffuse" "rgb reflectance" [ 0.7 0.7 0.7 ]\n')
    dragon = os.path.abspath(os.path.join(a.peers, '..', 'models', 'dragon', 'dragon_vrip.ply'))
    text += 'Shape "plymesh" "string filename" "%s"\n' % dragon
    text += 'Shape "plymesh" "string filename" "%s"\n' % os.path.join(a.peers, 'dragon-floor.ply')
    text += ('AttributeBegin\n  AreaLightSource "diffuse" "rgb L" [ 10 10 10 ]\n'
             '  Shape "plymesh" "string filename" "%s"\nAttributeEnd\n' % os.path.join(a.peers, 'dragon-light.ply'))
    return text


def write_killeroo(a, folder):
    src = os.path.join(a.pbrt_scenes, 'killeroos', 'killeroo-simple.pbrt')
    with open(src) as f:
        text = f.read()
    # the file's own lines that the benchmark sets: its sampler (halton, 256 spp), its
    # film's name and precision; the Includes made absolute (the copy lives in --out)
    text, n = re.subn(r'Sampler\s+"halton"\s+"integer pixelsamples"\s*\[\s*\d+\s*\]', '', text)
    text, m = re.subn(r'"string filename"\s*\[\s*"killeroo-simple.exr"\s*\]',
                      '"string filename" "killeroo.exr" "bool savefp16" false', text)
    geo = os.path.abspath(os.path.join(os.path.dirname(src), 'geometry', 'killeroo.pbrt'))
    text, k = re.subn(r'Include\s+"geometry/killeroo.pbrt"', 'Include "%s"' % geo, text)
    if (n, m, k) != (1, 1, 2):
        raise SystemExit('%s: not the killeroo-simple.pbrt expected (its Sampler, Film filename and two '
                         'Includes were to be replaced; found %d, %d, %d)' % (src, n, m, k))
    return HEADER % ('pbrt-v4-scenes\' killeroos/killeroo-simple.pbrt', DEPTH, a.pbrt_spp['pbrt-killeroo']) + text


WRITERS = {'pbrt-cornell': write_cornell, 'pbrt-dragon': write_dragon, 'pbrt-killeroo': write_killeroo}


def write_scenes(a, scenes):
    folder = os.path.join(os.path.abspath(a.out), 'pbrt')
    os.makedirs(folder, exist_ok=True)
    paths = {}
    for s in scenes:
        paths[s] = os.path.join(folder, s[len('pbrt-'):] + '.pbrt')
        text = WRITERS[s](a, folder)
        with open(paths[s], 'w') as f:
            f.write(text)
    return paths


def renderers(a):
    folder = os.path.join(os.path.abspath(a.out), 'pbrt')
    clpt = os.path.abspath(a.clpt)
    pbrt = os.path.abspath(a.pbrt)

    def clpt_render(path, spp, seed, out):
        cmd = [clpt, path, '--spp', str(spp), '--seed', str(seed), '-q', '-o', out] + a.clpt_args.split()
        wall, _ = timed(cmd + (['--device', a.device] if a.device else []), folder)
        return wall, read_pfm(out)

    def pbrt_render(path, spp, seed, out):
        exr = os.path.splitext(out)[0] + '.exr'
        wall, _ = timed([pbrt, '--quiet', '--nthreads', str(a.pbrt_threads), '--spp', str(spp), '--seed', str(seed),
                         '--outfile', exr, path], folder)
        return wall, read_exr(exr).astype(np.float64)

    return [Renderer('clpt', 'clpt (%s%s)' % (a.device or 'default device', ', ' + a.clpt_args if a.clpt_args else ''),
                     clpt_render),
            Renderer('pbrt', 'pbrt-v4 (CPU, zsobol, path, %d threads)' % a.pbrt_threads, pbrt_render)]


def run(a, scenes):
    """Renders scenes (of peers.py's PBRT_SCENES) with clpt and pbrt-v4 in a.runs interleaved rounds; prints the table."""
    paths = write_scenes(a, scenes)
    compare(a, scenes, paths, a.pbrt_spp, renderers(a), os.path.join(os.path.abspath(a.out), 'pbrt'),
            'wall time (whole process)')


def check(a, scenes):
    """Why the pbrt-v4 scenes cannot run, or None (before anything renders)."""
    if 'pbrt-killeroo' in scenes and not a.pbrt_scenes:
        return 'pbrt-killeroo: --pbrt-scenes DIR (a checkout of mmp/pbrt-v4-scenes) is needed'
    if not (os.path.isfile(a.pbrt) and os.access(a.pbrt, os.X_OK)):
        return '--pbrt %s: not an executable file' % a.pbrt
    if a.pbrt_scenes and not os.path.exists(os.path.join(a.pbrt_scenes, 'killeroos', 'killeroo-simple.pbrt')):
        return '--pbrt-scenes %s: no killeroos/killeroo-simple.pbrt there' % a.pbrt_scenes
    return None


if __name__ == '__main__':
    raise SystemExit('run through bench/peers.py --pbrt PATH (see its --help)')
