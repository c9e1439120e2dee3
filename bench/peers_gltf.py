#!/usr/bin/env python3
"""The peer benchmark against Cycles on glTF files (bench/peers.py --scenes gltf-..., part
of `make bench-peers` when Blender is installed): clpt reads the .glb itself and Blender
imports it with its own glTF importer, then renders it with Cycles; each is timed to equal
error against its own converged render (bench/peers_own.py), since Cycles 3.4's Principled
BSDF is Disney's and not glTF's (retro-reflective diffuse, specular added on top: 5-25%
brighter on rough dielectrics, ../shared/peers/README.md), so the two converge to
different images; that bias is printed per scene.

The scenes are the three Blender-exported files of ../shared/models/gltf, each through its
own camera, 320 x 180 (their 16:9), 8 bounces (clpt --max-depth 8, Cycles max_bounces 7),
no background:
  gltf-cornell   cornell-box.glb: McGuire's box with principled walls (roughness 1) and
                 a double-sided emissive lamp, 64 spp
  gltf-spheres   material-spheres.glb: ten red dielectric and copper spheres of roughness
                 0 to 1 under a sun and a point light, 16 spp
  gltf-suzanne   textured-suzanne.glb: a checker-textured Suzanne under a sun, 16 spp
Cycles renders through tools/xcheck/cycles_render.py (lights made points as glTF's are,
path tracing, PMJ, no denoising or clamping, box filter), with --threads threads; its
seconds are the render operator's (scene sync, BVH build, render), clpt's its --stats
total (the render; its load and BVH build are milliseconds on these files), so Blender's
start-up and import are left out as clpt's start-up is.

usage: called by peers.py (run(a, scenes) with its parsed options); needs numpy and
Debian's blender.
"""
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from peers_own import Renderer, clpt_total_s, compare, read_pfm, timed  # noqa: E402

WIDTH, HEIGHT, DEPTH = 320, 180, 8
# name: (file under ../shared/models/gltf, spp)
FILES = {'gltf-cornell': ('cornell-box.glb', 64), 'gltf-spheres': ('material-spheres.glb', 16),
         'gltf-suzanne': ('textured-suzanne.glb', 16)}


def blender_env():
    """Blender takes its Python from the first python3 on PATH: a pyenv or venv one lacks
    the numpy that Debian's python3-numpy gives Blender's."""
    env = dict(os.environ)
    env['PATH'] = os.pathsep.join(p for p in env.get('PATH', '').split(os.pathsep)
                                  if '.pyenv' not in p and p != os.path.dirname(sys.executable))
    return env


def renderers(a):
    clpt = os.path.abspath(a.clpt)
    script = os.path.join(HERE, '..', 'tools', 'xcheck', 'cycles_render.py')

    def clpt_render(path, spp, seed, out):
        cmd = [clpt, path, '--width', str(WIDTH), '--height', str(HEIGHT), '--max-depth', str(DEPTH),
               '--spp', str(spp), '--seed', str(seed), '--stats', '-q', '-o', out] + a.clpt_args.split()
        _, text = timed(cmd + (['--device', a.device] if a.device else []))
        return clpt_total_s(text), read_pfm(out)

    def cycles_render(path, spp, seed, out):
        base = os.path.splitext(out)[0]
        job = {'gltf': path, 'out': base, 'width': WIDTH, 'height': HEIGHT, 'spp': spp, 'seed': seed,
               'bounces': DEPTH - 1, 'background': {'kind': 'black'}, 'override': None, 'threads': a.threads}
        with open(base + '-job.json', 'w') as f:
            json.dump([job], f)
        timed(['blender', '-b', '--factory-startup', '--python-exit-code', '1', '-P', script, '--',
               base + '-job.json'], env=blender_env())
        with open(base + '.json') as f:
            secs = json.load(f)['render_s']
        return secs, np.load(base + '.npy').astype(np.float64)

    return [Renderer('clpt', 'clpt (%s%s)' % (a.device or 'default device', ', ' + a.clpt_args if a.clpt_args else ''),
                     clpt_render),
            Renderer('cycles', 'Cycles (Blender, CPU, PMJ, %d threads)' % a.threads, cycles_render)]


def check(a):
    """Why the glTF scenes cannot run, or None."""
    import shutil
    if shutil.which('blender') is None:
        return ('the glTF scenes need Cycles: `sh tools/deps.sh peers` (Debian\'s blender and python3-numpy)')
    for name, _ in FILES.values():
        if not os.path.exists(os.path.join(a.peers, '..', 'models', 'gltf', name)):
            return '%s: not there' % os.path.join(a.peers, '..', 'models', 'gltf', name)
    return None


def run(a, scenes):
    """Renders scenes (of FILES) with clpt and Cycles in a.runs interleaved rounds; prints the table."""
    folder = os.path.join(os.path.abspath(a.out), 'gltf')
    os.makedirs(folder, exist_ok=True)
    paths = dict((s, os.path.abspath(os.path.join(a.peers, '..', 'models', 'gltf', FILES[s][0]))) for s in scenes)
    spp = dict((s, FILES[s][1]) for s in scenes)
    compare(a, scenes, paths, spp, renderers(a), folder,
            "render time (clpt's --stats total, Cycles' render operator)")


if __name__ == '__main__':
    raise SystemExit('run through bench/peers.py --scenes gltf-cornell,gltf-spheres,gltf-suzanne (see its --help)')
