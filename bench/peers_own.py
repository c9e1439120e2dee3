"""Time to equal error with each renderer measured against its OWN converged render: the
comparison bench/peers_pbrt.py (clpt and pbrt-v4 on the same pbrt-v4 files) and
bench/peers_gltf.py (clpt and Cycles on the same glTF files) share.

Two renderers that model a scene differently (pbrt-v4 is spectral, Cycles' Principled BSDF
is Disney's rather than glTF's) converge to different images; measured against one
reference, that bias would count as noise for one of them. So each renders its own
reference (--ref-spp, two halves with seeds 777 and 778, whose difference measures the
reference's own error, taken off as in peers.py), and the bias between the two references
is printed per channel, for the correctness comparison (tools/xcheck), not the speed one.
Silhouette pixels are left out as peers.py does, where either reference has an edge.

A renderer here is a name, a label and a render(path, spp, seed, out) that returns (the
seconds it is timed by, the image as an H x W x 3 float64 array).
"""
import math
import os
import statistics
import subprocess
import time

import numpy as np


class Renderer:
    def __init__(self, name, label, render):
        self.name, self.label, self.render = name, label, render


def read_pfm(path):
    with open(path, 'rb') as f:
        if f.readline().strip() != b'PF':
            raise SystemExit('%s: not a colour PFM' % path)
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        a = np.frombuffer(f.read(), dtype='<f4' if scale < 0 else '>f4')
    return a.reshape(h, w, 3)[::-1].astype(np.float64)


def timed(cmd, cwd=None, env=None):
    """Runs a command; returns (its wall seconds, its output). A failure ends the benchmark with its output."""
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        raise SystemExit('failed (exit %d): %s\n%s' % (p.returncode, ' '.join(cmd), p.stdout[-4000:]))
    return wall, p.stdout


def clpt_total_s(text):
    """The render seconds of clpt's --stats: its "total" line's third field."""
    for line in text.splitlines():
        if line.startswith('total '):
            return float(line.split()[2])
    raise SystemExit('clpt --stats printed no "total" line:\n' + text)


def edges(ref):
    """True where the reference's 3x3 neighbourhood spans more than 0.05 in mean RGB (peers.py's rule)."""
    lum = ref.mean(-1)
    h, w = lum.shape
    pad = np.pad(lum, 1, mode='edge')
    nb = np.stack([pad[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] for dy in (-1, 0, 1) for dx in (-1, 0, 1)])
    return nb.max(0) - nb.min(0) > 0.05


def reference(a, r, scene, path, folder):
    """r's converged render of scene, as its two halves (kept in folder and reused)."""
    spp = a.ref_spp[scene]
    halves = []
    for seed, half in ((777, 'a'), (778, 'b')):
        out = os.path.join(folder, 'ref-%s-%s-%d-%s.pfm' % (scene, r.name, spp, half))
        npy = out + '.npy'
        if not os.path.exists(npy):
            print('making half %s of the %s reference with %s, %d spp (once; kept as %s)...' % (
                half, scene, r.name, spp // 2, npy), flush=True)
            _, img = r.render(path, spp // 2, seed, out)
            np.save(npy, img)
        halves.append(np.load(npy))
    return halves


def compare(a, scenes, paths, spp, rs, folder, time_label):
    """Renders each scene (paths: scene -> file, spp: scene -> samples) with the renderers rs
    (clpt first) in a.runs interleaved rounds; prints the table, time_label naming what the
    renderers' seconds are, and the bias between each peer's reference and clpt's."""
    refs, keep = {}, {}
    for s in scenes:
        for r in rs:
            refs[s, r.name] = reference(a, r, s, paths[s], folder)
        keep[s] = ~np.logical_or.reduce([edges((ha + hb) / 2) for (ha, hb) in (refs[s, r.name] for r in rs)])
    own = {}   # (scene, renderer) -> (reference, its own MSE over the kept pixels)
    for s in scenes:
        for r in rs:
            ha, hb = refs[s, r.name]
            own[s, r.name] = ((ha + hb) / 2, float(((ha - hb)[keep[s]] ** 2).mean()) / 4)
        print('%s: %d spp; references %d spp in two halves, their own RMSE %s; %.1f%% of the pixels kept' % (
            s, spp[s], a.ref_spp[s], ', '.join('%s %.5f' % (r.name, math.sqrt(own[s, r.name][1])) for r in rs),
            100.0 * keep[s].mean()), flush=True)

    results = {}
    for rnd in range(1, a.runs + 1):
        for s in scenes:
            for r in rs:
                out = os.path.join(folder, '%s-%s-%d.pfm' % (s, r.name, rnd))
                secs, img = r.render(paths[s], spp[s], rnd, out)
                ref, ref_mse = own[s, r.name]
                mse = float(((img - ref)[keep[s]] ** 2).mean()) - ref_mse
                results.setdefault((s, r.name), []).append((secs, mse))
                print('round %d %-14s %-6s %7.2f s  RMSE %.5f' % (rnd, s, r.name, secs, math.sqrt(max(mse, 0.0))),
                      flush=True)

    print()
    print('| scene | renderer | %s | RMSE against its own reference (masked, less the '
          "reference's own) | time x MSE | clpt time to equal error (per round) |" % time_label)
    print('|---|---|---|---|---|---|')
    for s in scenes:
        rows = {}
        for r in rs:
            got = results[s, r.name]
            secs = statistics.median(t for t, _ in got)
            mse = max(sum(m for _, m in got) / len(got), 0.0)
            rows[r.name] = (r.label, secs, math.sqrt(mse), secs * mse, [t * max(m, 0.0) for t, m in got])
        clpt_rounds = rows['clpt'][4]
        for name, (label, secs, e, tm, rounds) in rows.items():
            if name == 'clpt':
                ratio = '1 (itself)'
            else:
                ratio = '%.2f' % (rows['clpt'][3] / tm if tm > 0 else float('nan'))
                ratio += ' (%s)' % ' '.join('%.2f' % (c / p) if p > 0 else 'nan' for c, p in zip(clpt_rounds, rounds))
            print('| %s | %s | %.2f s | %.5f | %.2e | %s |' % (s, label, secs, e, tm, ratio))
    print()
    for s in scenes:
        for r in rs[1:]:
            print(bias_line(s, r.name, own[s, 'clpt'][0], own[s, r.name][0], keep[s]))


def bias_line(scene, peer, clpt_ref, peer_ref, keep):
    """The two references' mean ratio per channel: over the kept pixels and over the whole image
    (the kept pixels leave out edges, the light's among them, so the two differ where the
    renderers' models differ most in the light's or the walls' saturated colours)."""
    def ratio(c, p):
        return ' '.join('%.4f' % x for x in c.mean(0) / p.mean(0))
    return '%s: bias clpt / %s (R G B), mean over the kept pixels %s, over the whole image %s' % (
        scene, peer, ratio(clpt_ref[keep], peer_ref[keep]), ratio(clpt_ref.reshape(-1, 3), peer_ref.reshape(-1, 3)))
