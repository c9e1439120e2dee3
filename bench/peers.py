#!/usr/bin/env python3
"""Peer benchmark: clpt against Mitsuba 3 and Blender Cycles at equal quality.

usage: bench/peers.py [--clpt build/clpt] [--clpt-args ARGS] [--peers DIR] [--out DIR]
                      [--runs N] [--ref-spp cornell=1024,dragon=512,...] [--device DEV]
                      [--threads N] [--scenes cornell,dragon,envmat,fog,smoke,gltf-cornell,...]
                      [--renderers mitsuba,cycles]
                      [--pbrt PATH [--pbrt-scenes DIR] [--pbrt-threads N]]

Renders the two scenes of ../shared/peers (its README says how they were matched across
renderers; the scene files and peer scripts are used from there as they are, so every
renderer sees the same scene):
  cornell  McGuire's CornellBox-Original, 512x512, 64 spp, 8 bounces, light facing down
  dragon   the Stanford dragon (871k triangles) on a floor under a small area light,
           512x512, 16 spp
and three that bench/peers_scenes.py writes into --out for clpt and Mitsuba from the same
triangles (tools/xcheck's geometry and media), 256x256 (a quarter of the pixels, so that
their references take minutes on two cores), 16 spp, 8 bounces:
  envmat   rough gold, rough glass and Lambertian spheres on a floor under courtyard.hdr
  fog      a sphere of homogeneous fog and a Lambertian sphere under a square area light
  smoke    the same with a 16^3 density grid in the sphere (a heterogeneous medium)
with clpt and, when installed, Mitsuba 3 (`pip install mitsuba`; its fast variant
llvm_ad_rgb needs Debian's libllvm19, else scalar_rgb is used) and Cycles (Debian
`blender` and `python3-numpy`; of these five the Cornell box only, as in ../shared/peers); `sh
tools/deps.sh peers` installs all three. The renderers take turns within
each of --runs rounds (interleaved, so a change in the machine's load hits all of them
alike); times are medians over the rounds, squared errors the mean over them (seed = round).

RMSE is against a converged reference made by clpt (--ref-spp samples, kept in --out and
reused), with silhouette pixels left out as ../shared/peers/compare.py does (pixels whose
3x3 neighbourhood in the reference spans more than 0.05 in mean RGB), so that renderers
with different pixel filters compare on noise and bias. The reference is the mean of two
halves rendered with seeds 777 and 778: a quarter of their squared difference is the
reference's own squared error, which would otherwise add to every renderer's (the less
noisy renderer's the most, in proportion), so it is taken off each MSE; at 16 to 32
times a scene's spp it is 3-6% of clpt's (bench/RESULTS.md: 2026-12-02, the McGuire box
at 1024 spp 5.9%, the dragon at 512 spp 2.8%). clpt renders the McGuire box and the
dragon with 16 continuations a camera sample (`--split auto` chooses 16 there), so a
reference of 64 times their spp took about two hours for the box alone on two cores.
"mean / ref" is the kept pixels' mean over the reference's: a renderer that models the scene differently shows it there (and its
bias adds to its RMSE). time x MSE is the
error-per-time figure (lower is better; for unbiased Monte Carlo, MSE falls as 1/time),
and "clpt time to equal error" is clpt's time x MSE over the peer's: the share of the
peer's time that clpt needs to reach the peer's error (below 1: clpt is faster).

Each peer runs with its best settings for these scenes: Mitsuba with its multijitter
sampler, Cycles with PMJ; clpt with its defaults, as a user gets it (issue 45: a setting
that wins becomes clpt's default), plus --clpt-args when given. `--clpt-args "--split
2"` (two continuations from each camera sample's first hit, sharing its camera ray) gave
the Cornell box and the dragon a fifth to a quarter less time x MSE with silhouettes left
out as here, but costs the McGuire box 9% over whole images (bench/RESULTS.md), so it is
not clpt's default. Part of its gain is the Sobol points' faster convergence at twice the
continuations, which the peers would also see at twice their samples.

With --pbrt PATH (`make bench-peers PBRT=PATH`), a pbrt-v4 binary built outside the
repository (nothing of pbrt-v4 is in it: no code, binary or build script), the scenes
pbrt-cornell and pbrt-dragon (and pbrt-killeroo, pbrt-v4-scenes' killeroo-simple.pbrt,
with --pbrt-scenes DIR, a checkout of mmp/pbrt-v4-scenes; `make bench-peers
PBRT_SCENES=DIR`) are added: bench/peers_pbrt.py writes them as pbrt-v4 files into
--out/pbrt/, and clpt (which reads pbrt-v4's format, docs/pbrt.md) and pbrt-v4 render the
very same files, pbrt-v4 with its zsobol sampler, both with a box pixel filter and 8
bounces, in turns, timed as whole processes (wall time), each against ITS OWN converged
render (pbrt-v4 is spectral, clpt RGB; the bias between the two references is printed per
channel, for the correctness comparison, not the speed one); its docstring says how. They
print a table of their own after the one above; `--scenes pbrt-cornell,pbrt-dragon` runs
them alone. Their reference samples are 64 times each scene's by default, which
for pbrt-v4 on two cores means hours: `--ref-spp pbrt-cornell=256,...` for a quick run.

When Blender is installed (and cycles is among --renderers), the default scenes also
include gltf-cornell, gltf-spheres and gltf-suzanne: the three Blender-exported files of
../shared/models/gltf, read by clpt and imported by Blender's own glTF importer for
Cycles, each renderer timed by its render alone and measured against its own converged
render, since Cycles' Principled BSDF is Disney's rather than glTF's
(bench/peers_gltf.py says how; they print a table of their own).

Standard library only for the peers' scenes (the pbrt-v4 scenes need numpy); numpy is used for the error when it is importable
(faster), and the generated scenes need it (tools/xcheck's writers).
"""
import argparse
import array
import glob
import hashlib
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import time

try:
    import numpy as np
except ImportError:
    np = None

SCENES = {
    # name: (clpt scene file in the peers folder, or None: written by peers_scenes.py into
    # --out; spp; whether Cycles has the scene)
    'cornell': ('cornell-mcguire.scene', 64, True),
    'dragon': ('dragon.scene', 16, False),
    'envmat': (None, 16, False),
    'fog': (None, 16, False),
    'smoke': (None, 16, False),
}
# the reference's samples: 16 times the scene's on the McGuire box (half an hour on two
# cores at split 16), 32 times on the others (their references' own error is measured
# and taken off all the same)
REF_SPP = {'cornell': 1024, 'dragon': 512, 'envmat': 512, 'fog': 512, 'smoke': 512}
# --pbrt's scenes (bench/peers_pbrt.py): name -> (spp, reference spp)
PBRT_SCENES = {'pbrt-cornell': (64, 4096), 'pbrt-dragon': (16, 1024), 'pbrt-killeroo': (16, 1024)}
# the glTF scenes against Cycles (bench/peers_gltf.py): name -> reference spp (each
# renderer's own; Cycles renders them at about a million samples a second on two cores)
GLTF_REF_SPP = {'gltf-cornell': 2048, 'gltf-spheres': 1024, 'gltf-suzanne': 1024}
LLVM19 = '/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1'


def read_pfm(path):
    with open(path, 'rb') as f:
        kind = f.readline().strip()
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        a = array.array('f')
        a.frombytes(f.read())
    if (scale < 0) != (sys.byteorder == 'little'):
        a.byteswap()
    if kind != b'PF' or len(a) != w * h * 3:
        raise SystemExit('%s: not a colour PFM of %dx%d' % (path, w, h))
    return w, h, a


def silhouette_keep(w, h, ref):
    """1 for the pixels that count: not on an edge of the reference."""
    if np is not None:
        lum = np.frombuffer(ref, dtype=np.float32).astype(np.float64).reshape(h, w, 3).mean(-1)
        pad = np.pad(lum, 1, mode='edge')
        nb = np.stack([pad[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] for dy in (-1, 0, 1) for dx in (-1, 0, 1)])
        return ((nb.max(0) - nb.min(0)) <= 0.05).reshape(-1)
    lum = [(ref[3 * i] + ref[3 * i + 1] + ref[3 * i + 2]) / 3.0 for i in range(w * h)]
    keep = bytearray(w * h)
    for y in range(h):
        for x in range(w):
            lo = hi = lum[y * w + x]
            for dy in (-1, 0, 1):
                yy = min(max(y + dy, 0), h - 1)
                for dx in (-1, 0, 1):
                    v = lum[yy * w + min(max(x + dx, 0), w - 1)]
                    lo, hi = min(lo, v), max(hi, v)
            keep[y * w + x] = hi - lo <= 0.05
    return keep


def masked_mse(img, ref, keep):
    """Mean squared difference over the kept pixels' channels."""
    if np is not None:
        d = (np.frombuffer(img, dtype=np.float32).astype(np.float64) -
             np.frombuffer(ref, dtype=np.float32).astype(np.float64)).reshape(-1, 3)
        return float((d[np.asarray(keep, dtype=bool)] ** 2).mean())
    s, n = 0.0, 0
    for i in range(len(ref) // 3):
        if keep[i]:
            for c in range(3):
                d = img[3 * i + c] - ref[3 * i + c]
                s += d * d
            n += 3
    return s / max(n, 1)


def run(cmd, cwd=None, env=None):
    """Runs a command; returns (wall seconds, stdout). A failure ends the benchmark with its output."""
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise SystemExit('failed (exit %d): %s\n%s%s' % (p.returncode, ' '.join(cmd), p.stdout, p.stderr))
    return wall, p.stdout


class Clpt:
    name = 'clpt'

    def __init__(self, a):
        self.a = a
        self.label = 'clpt (%s%s)' % (a.device or 'default device', ', ' + a.clpt_args if a.clpt_args else '')

    def cmd(self, scene, spp, seed, out):
        c = [self.a.clpt, scene_file(self.a, scene), '--spp', str(spp), '--seed', str(seed),
             '--stats', '-q', '-o', out] + self.a.clpt_args.split()
        return c + (['--device', self.a.device] if self.a.device else [])

    def render(self, scene, spp, seed, out):
        wall, text = run(self.cmd(scene, spp, seed, out))
        render_s = None
        for line in text.splitlines():
            if line.startswith('total '):
                render_s = float(line.split()[2])
        if render_s is None:
            raise SystemExit('clpt --stats printed no "total" line:\n' + text)
        return {'render_s': render_s, 'wall_s': wall, 'setup_s': wall - render_s}


class Mitsuba:
    name = 'mitsuba'
    install = ('not installed: `sh tools/deps.sh peers` (pip installs mitsuba; Debian\'s libllvm19 '
               'gives it its fast variant llvm_ad_rgb)')

    def __init__(self, a):
        self.a = a
        self.env = dict(os.environ)
        if os.path.exists(self.env.get('DRJIT_LIBLLVM_PATH', '')) or os.path.exists(LLVM19):
            self.env.setdefault('DRJIT_LIBLLVM_PATH', LLVM19)
            self.variant = 'llvm_ad_rgb'
        else:
            self.variant = 'scalar_rgb'
        self.label = 'Mitsuba 3 %s, multijitter' % self.variant
        self.warm = set()

    @staticmethod
    def available():
        return subprocess.run([sys.executable, '-c', 'import mitsuba'], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL).returncode == 0

    def cmd(self, scene, spp, seed, out):
        if SCENES[scene][0] is None:
            return [sys.executable, os.path.join(os.path.dirname(os.path.abspath(__file__)), 'peers_scenes.py'),
                    'mitsuba', scene, str(spp), out, str(seed), self.variant, 'multijitter',
                    os.path.abspath(self.a.out)]
        return [sys.executable, os.path.join(self.a.peers, 'mitsuba_render.py'), scene, str(spp), out, str(seed),
                self.variant, 'multijitter']

    def render(self, scene, spp, seed, out):
        # mitsuba_render.py reads the Cornell box as split/ in its working folder.
        work = os.path.abspath(self.a.out)
        if scene == 'cornell' and not os.path.exists(os.path.join(work, 'split', 'materials.json')):
            os.makedirs(os.path.join(work, 'split'), exist_ok=True)
            obj = os.path.join(self.a.peers, '..', 'models', 'cornell-box', 'CornellBox-Original.obj')
            run([sys.executable, os.path.join(self.a.peers, 'cornell_split.py'), obj, os.path.join(work, 'split')])
        if self.variant.startswith('llvm') and scene not in self.warm:
            # Dr.Jit compiles its kernels on first use and caches them: not part of a render.
            run(self.cmd(scene, spp, seed, os.path.abspath(out)), cwd=work, env=self.env)
            self.warm.add(scene)
        wall, text = run(self.cmd(scene, spp, seed, os.path.abspath(out)), cwd=work, env=self.env)
        # Mitsuba logs lines of its own (a slow ASCII PLY) and ends them with a colour
        # escape that shares the script's JSON line: read from the JSON's start.
        r = json.loads(text[text.rindex('{"renderer"'):].splitlines()[0])
        return {'render_s': r['render_s'], 'wall_s': wall, 'setup_s': wall - r['render_s']}


class Cycles:
    name = 'cycles'
    install = 'not installed: `sh tools/deps.sh peers` (Debian\'s blender and python3-numpy; Debian 12: Blender 3.4)'

    def __init__(self, a):
        self.a = a
        self.label = 'Cycles (Blender, CPU, PMJ)'

    @staticmethod
    def available():
        return shutil.which('blender') is not None

    def render(self, scene, spp, seed, out):
        prefix = os.path.splitext(os.path.abspath(out))[0]
        # Blender takes its Python from the first python3 on PATH: a pyenv or venv one
        # lacks the numpy that Debian's python3-numpy gives Blender's.
        env = dict(os.environ)
        env['PATH'] = os.pathsep.join(p for p in env.get('PATH', '').split(os.pathsep)
                                      if '.pyenv' not in p and p != os.path.dirname(sys.executable))
        wall, _ = run(['blender', '-b', '--factory-startup', '--python-exit-code', '1', '--python',
                       os.path.join(self.a.peers, 'cycles_cornell.py'), '--', '--spp', str(spp), '--seed', str(seed),
                       '--threads', str(self.a.threads), '--one-sided-light', '--out', prefix], env=env)
        with open(prefix + '.json') as f:
            render_s = json.load(f)['timing_s']['render_op']
        return {'render_s': render_s, 'wall_s': wall, 'setup_s': wall - render_s}


def scene_file(a, scene):
    """The clpt scene file: the peers folder's, or the one peers_scenes.py wrote into --out."""
    if SCENES[scene][0] is None:
        return os.path.join(a.out, scene + '.scene')
    return os.path.join(a.peers, SCENES[scene][0])


def masked_mean(img, keep):
    if np is not None:
        return float(np.frombuffer(img, dtype=np.float32).astype(np.float64).reshape(-1, 3)[
            np.asarray(keep, dtype=bool)].mean())
    s = sum(img[3 * i] + img[3 * i + 1] + img[3 * i + 2] for i in range(len(img) // 3) if keep[i])
    return s / max(3 * sum(1 for k in keep if k), 1)


def ref_tag(a, scene):
    """The name a reference is kept under: a generated scene's carries a hash of its files,
    so that a changed scene is not compared with the reference of the scene before."""
    if SCENES[scene][0] is None:
        h = hashlib.sha256()
        for path in [scene_file(a, scene)] + sorted(glob.glob(os.path.join(a.out, scene + '-*.ply'))):
            with open(path, 'rb') as f:
                h.update(f.read())
        return '%s-%s' % (scene, h.hexdigest()[:8])
    return scene


def reference(a, scene):
    """The scene's reference: (width, height, the mean of its two halves, the squared error
    of that mean as a quarter of the halves' mean squared difference, per kept pixel)."""
    spp = a.ref_spp[scene]
    halves = []
    for seed, name in ((777, 'a'), (778, 'b')):
        path = os.path.join(a.out, 'ref-%s-%d-%s.pfm' % (ref_tag(a, scene), spp, name))
        if not os.path.exists(path):
            print('making half %s of the %s reference with clpt, %d spp (once; kept as %s)...' % (
                name, scene, spp // 2, path), flush=True)
            Clpt(a).render(scene, spp // 2, seed, path)
        halves.append(read_pfm(path))
    (w, h, ha), (_, _, hb) = halves
    ref = array.array('f', ((x + y) * 0.5 for x, y in zip(ha, hb)))
    keep = silhouette_keep(w, h, ref)
    return w, h, ref, keep, masked_mse(ha, hb, keep) / 4.0, masked_mean(ref, keep)


def fmt_s(x):
    return '%.2f s' % x


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--clpt', default='build/clpt')
    ap.add_argument('--clpt-args', default='', help="clpt's options for the scenes (default: none, clpt's defaults)")
    ap.add_argument('--peers', default='../shared/peers', help='the folder of the peer scenes and scripts')
    ap.add_argument('--out', default='build/peers')
    ap.add_argument('--runs', type=int, default=3, help='rounds (at least 1)')
    ap.add_argument('--ref-spp', default='', help='SCENE=SPP,... the reference samples where not %s' % (
        ','.join('%s=%d' % kv for kv in list(REF_SPP.items()) + list(GLTF_REF_SPP.items()))))
    ap.add_argument('--device', default='', help="clpt's --device (default: clpt's default)")
    ap.add_argument('--threads', type=int, default=2, help="Cycles' render threads")
    ap.add_argument('--scenes', default=','.join(SCENES))
    ap.add_argument('--renderers', default='mitsuba,cycles', help='the peers to run when installed')
    ap.add_argument('--pbrt', default='', help='a pbrt-v4 binary: adds the scenes %s, written as pbrt-v4 files that '
                    'clpt and it read (bench/peers_pbrt.py)' % ','.join(PBRT_SCENES))
    ap.add_argument('--pbrt-scenes', default='', help='a checkout of mmp/pbrt-v4-scenes: adds pbrt-killeroo '
                    '(killeroos/killeroo-simple.pbrt) to the pbrt-v4 scenes')
    ap.add_argument('--pbrt-threads', type=int, default=2, help="pbrt-v4's --nthreads")
    a = ap.parse_args()
    a.peers = os.path.abspath(a.peers)   # the peer scripts run in --out
    given = dict((k, int(v)) for k, v in (x.split('=', 1) for x in a.ref_spp.split(',') if x))
    a.ref_spp = dict(REF_SPP)
    a.ref_spp.update((k, v[1]) for k, v in PBRT_SCENES.items())
    a.ref_spp.update(GLTF_REF_SPP)
    a.ref_spp.update(given)
    if a.scenes == ap.get_default('scenes') and 'cycles' in a.renderers.split(',') and Cycles.available():
        a.scenes += ',' + ','.join(GLTF_REF_SPP)
    if a.scenes == ap.get_default('scenes') and a.pbrt:
        # --pbrt adds its scenes to the default list (pbrt-killeroo only with --pbrt-scenes)
        a.scenes += ',pbrt-cornell,pbrt-dragon' + (',pbrt-killeroo' if a.pbrt_scenes else '')
    if a.runs < 1:
        raise SystemExit('--runs %d: at least one round' % a.runs)
    for s, n in a.ref_spp.items():
        if n < 2 or n % 2:
            raise SystemExit('--ref-spp %s=%d: an even number of samples, at least 2 (two halves)' % (s, n))
    scenes = [s for s in a.scenes.split(',') if s]
    for s in scenes:
        if s in PBRT_SCENES and not a.pbrt:
            raise SystemExit('scene %s: --pbrt PATH (a pbrt-v4 binary) is needed' % s)
        if s not in SCENES and s not in PBRT_SCENES and s not in GLTF_REF_SPP:
            raise SystemExit('unknown scene %s (known: %s)' % (s, ', '.join(
                list(SCENES) + list(GLTF_REF_SPP) + list(PBRT_SCENES))))
    pbrt_scenes = [s for s in scenes if s in PBRT_SCENES]
    gltf_scenes = [s for s in scenes if s in GLTF_REF_SPP]
    scenes = [s for s in scenes if s in SCENES]
    if gltf_scenes:
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        try:
            import peers_gltf
        except ImportError as e:
            raise SystemExit('the glTF scenes: %s (apt-get install python3-numpy)' % e)
        why = peers_gltf.check(a)
        if why:
            raise SystemExit(why)
    if pbrt_scenes:
        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
        try:
            import peers_pbrt
        except ImportError as e:
            raise SystemExit('the pbrt-v4 scenes: %s (apt-get install python3-numpy)' % e)
        a.pbrt_spp = dict((k, v[0]) for k, v in PBRT_SCENES.items())
        why = peers_pbrt.check(a, pbrt_scenes)
        if why:
            raise SystemExit(why)
    if not os.path.exists(os.path.join(a.peers, 'README.md')):
        raise SystemExit('%s: the peer scenes are not there (--peers DIR)' % a.peers)
    os.makedirs(a.out, exist_ok=True)
    for s in scenes:
        if SCENES[s][0] is None:
            # tools/xcheck's writers need numpy (which Mitsuba needs anyway)
            sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
            try:
                import peers_scenes
            except ImportError as e:
                raise SystemExit('scene %s: %s (apt-get install python3-numpy, or --scenes cornell,dragon)' % (s, e))
            if s == 'envmat' and not os.path.exists(peers_scenes.ENVMAP):
                raise SystemExit('%s: the envmat scene\'s map is not there' % peers_scenes.ENVMAP)
            peers_scenes.write_clpt(s, a.out)

    if not scenes:
        if gltf_scenes:
            peers_gltf.run(a, gltf_scenes)
            print()
        if pbrt_scenes:
            peers_pbrt.run(a, pbrt_scenes)
        return
    renderers = [Clpt(a)]
    for cls in (Mitsuba, Cycles):
        if cls.name not in a.renderers.split(','):
            continue
        if cls.available():
            renderers.append(cls(a))
        else:
            print('%s: skipped, %s' % (cls.name, cls.install))
    refs = {s: reference(a, s) for s in scenes}
    for s in scenes:
        print('%s reference: %d spp in two halves, its own RMSE %.5f (its square is taken off each MSE below)' % (
            s, a.ref_spp[s], math.sqrt(refs[s][4])), flush=True)

    results = {}   # (scene, renderer name) -> list of (times dict, MSE less the reference's)
    for rnd in range(1, a.runs + 1):
        for s in scenes:
            _, _, ref, keep, ref_mse, _ = refs[s]
            spp = SCENES[s][1]
            for r in renderers:
                if r.name == 'cycles' and not SCENES[s][2]:
                    continue
                out = os.path.join(a.out, '%s-%s-%d.pfm' % (s, r.name, rnd))
                t = r.render(s, spp, rnd, out)
                img = read_pfm(out)[2]
                mse = masked_mse(img, ref, keep) - ref_mse
                t['mean'] = masked_mean(img, keep) / refs[s][5]
                results.setdefault((s, r.name), []).append((t, mse))
                print('round %d %-8s %-8s render %6.2f s  wall %6.2f s  RMSE %.5f' % (
                    rnd, s, r.name, t['render_s'], t['wall_s'], math.sqrt(max(mse, 0.0))), flush=True)

    print()
    print("| scene | renderer | render time | start-up + load + build | Msamples/s | RMSE (masked, less the reference's own) "
          '| mean / ref | time x MSE | clpt time to equal error |')
    print('|---|---|---|---|---|---|---|---|---|')
    for s in scenes:
        spp = SCENES[s][1]
        w, h = refs[s][0], refs[s][1]
        rows = {}
        for r in renderers:
            got = results.get((s, r.name))
            if not got:
                continue
            render_s = statistics.median(t['render_s'] for t, _ in got)
            setup_s = statistics.median(t['setup_s'] for t, _ in got)
            mse = max(sum(x for _, x in got) / len(got), 0.0)
            mean = sum(t['mean'] for t, _ in got) / len(got)
            rows[r.name] = (r.label, render_s, setup_s, math.sqrt(mse), mean, render_s * mse)
        clpt_tm = rows['clpt'][5]
        for name, (label, render_s, setup_s, e, mean, tm) in rows.items():
            ratio = '1 (itself)' if name == 'clpt' else '%.2f' % (clpt_tm / tm)
            print('| %s | %s | %s | %s | %.2f | %.5f | %.4f | %.2e | %s |' % (
                s, label, fmt_s(render_s), fmt_s(setup_s), w * h * spp / render_s / 1e6, e, mean, tm, ratio))
        if 'cycles' not in rows and any(r.name == 'cycles' for r in renderers):
            print('| %s | Cycles | not rendered: ../shared/peers has the Cornell box only for Cycles '
                  '| | | | | | |' % s)
    if gltf_scenes:
        print()
        peers_gltf.run(a, gltf_scenes)
    if pbrt_scenes:
        print()
        peers_pbrt.run(a, pbrt_scenes)


if __name__ == '__main__':
    main()
