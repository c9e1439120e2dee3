#!/usr/bin/env python3
"""Error per sample of clpt's samplers: RMSE at equal spp against a converged reference.

usage: bench/sampler_rmse.py [--clpt build/clpt] [--refs DIR] [--ref-spp N] [--spp 4,16,64]
                             [--seeds 1,2,3] [--device cpu] [--out DIR] [--reuse] [SCENE...]

SCENE is NAME=PATH (default: the McGuire Cornell box and the dragon of ../shared/peers,
and scenes/one-weekend.scene), rendered at 256x256 (the one-weekend scene at its own
400x225). For each scene the reference is REFS/NAME.pfm, rendered first when missing with
--ref-spp samples by the independent sampler with seed 777 (a seed no test image uses).
Then every spp of --spp is rendered with --sampler sobol and --sampler independent, once
per seed of --seeds, and the table gives the mean RMSE over the seeds, overall and with
silhouette pixels left out ("masked": pixels whose 3x3 neighbourhood in the reference
spans more than 0.05 in mean RGB, as ../shared/peers/compare.py), and the MSE ratio
independent / sobol (how many times more samples the independent sampler needs for the
same error). The reference's own noise adds to both MSEs: as its samples are
independent, its share is MSE_ref = MSE_independent(N) * N / (N + R) for N spp against a
reference of R spp, and the last column is the ratio with that share taken out of both
(--ref-spp-for NAME=R when a reference holds another count than --ref-spp, as one cut
short by --time-limit). Standard library only (no numpy).
"""
import argparse
import array
import math
import os
import subprocess
import sys


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


def silhouette_mask(w, h, ref):
    lum = [(ref[3 * i] + ref[3 * i + 1] + ref[3 * i + 2]) / 3.0 for i in range(w * h)]
    keep = bytearray(w * h)
    for y in range(h):
        for x in range(w):
            lo = hi = lum[y * w + x]
            for dy in (-1, 0, 1):
                yy = min(max(y + dy, 0), h - 1)
                for dx in (-1, 0, 1):
                    v = lum[yy * w + min(max(x + dx, 0), w - 1)]
                    lo = min(lo, v)
                    hi = max(hi, v)
            keep[y * w + x] = hi - lo <= 0.05
    return keep


def rmse(img, ref, keep):
    s = sm = 0.0
    n = nm = 0
    for i in range(len(ref) // 3):
        e = 0.0
        for c in range(3):
            d = img[3 * i + c] - ref[3 * i + c]
            e += d * d
        s += e
        n += 3
        if keep[i]:
            sm += e
            nm += 3
    return math.sqrt(s / n), math.sqrt(sm / max(nm, 1))


def render(clpt, scene, size, spp, seed, sampler, device, out, reuse=False):
    if reuse and os.path.exists(out):
        return
    cmd = [clpt, scene, '--spp', str(spp), '--seed', str(seed), '--sampler', sampler, '-q', '-o', out]
    if device:
        cmd += ['--device', device]
    if size:
        cmd += ['--width', str(size[0]), '--height', str(size[1])]
    subprocess.run(cmd, check=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--clpt', default='build/clpt')
    ap.add_argument('--refs', default='build/sampler-refs')
    ap.add_argument('--ref-spp', type=int, default=4096)
    ap.add_argument('--ref-spp-for', action='append', default=[], metavar='NAME=R')
    ap.add_argument('--spp', default='4,16,64')
    ap.add_argument('--seeds', default='1,2')
    ap.add_argument('--device', default='')
    ap.add_argument('--out', default='build/sampler-rmse')
    ap.add_argument('--reuse', action='store_true', help='keep images already in --out (same settings)')
    ap.add_argument('scenes', nargs='*')
    a = ap.parse_args()
    scenes = a.scenes or ['cornell=../shared/peers/cornell-mcguire.scene', 'weekend=scenes/one-weekend.scene',
                          'dragon=../shared/peers/dragon.scene']
    os.makedirs(a.refs, exist_ok=True)
    os.makedirs(a.out, exist_ok=True)
    ref_spp = dict((k, int(v)) for k, v in (x.split('=', 1) for x in a.ref_spp_for))
    print('| scene | spp | RMSE independent | RMSE sobol | masked independent | masked sobol | MSE ratio (masked) '
          '| MSE ratio, reference noise out |')
    print('|---|---|---|---|---|---|---|---|')
    for item in scenes:
        name, path = item.split('=', 1)
        size = None if name == 'weekend' else (256, 256)
        ref_path = os.path.join(a.refs, name + '.pfm')
        if not os.path.exists(ref_path):
            render(a.clpt, path, size, a.ref_spp, 777, 'independent', a.device, ref_path)
        w, h, ref = read_pfm(ref_path)
        keep = silhouette_mask(w, h, ref)
        for spp in [int(s) for s in a.spp.split(',')]:
            res = {}
            for sampler in ('independent', 'sobol'):
                tot = [0.0, 0.0]
                seeds = [int(s) for s in a.seeds.split(',')]
                for seed in seeds:
                    out = os.path.join(a.out, '%s-%s-%d-%d.pfm' % (name, sampler, spp, seed))
                    render(a.clpt, path, size, spp, seed, sampler, a.device, out, a.reuse)
                    r = rmse(read_pfm(out)[2], ref, keep)
                    tot[0] += r[0] / len(seeds)
                    tot[1] += r[1] / len(seeds)
                res[sampler] = tot
            i, s = res['independent'], res['sobol']
            r = ref_spp.get(name, a.ref_spp)
            noise = i[1] ** 2 * spp / (spp + r)
            print('| %s | %d | %.5f | %.5f | %.5f | %.5f | %.2f | %.2f |' % (
                name, spp, i[0], s[0], i[1], s[1], (i[1] / s[1]) ** 2, (i[1] ** 2 - noise) / (s[1] ** 2 - noise)))
            sys.stdout.flush()


if __name__ == '__main__':
    main()
