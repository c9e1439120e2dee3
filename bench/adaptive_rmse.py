#!/usr/bin/env python3
"""Adaptive sampling (--noise-threshold) against uniform sampling at equal time.

usage: bench/adaptive_rmse.py [--clpt build/clpt] [--scene scenes/cornell-box.scene]
                              [--size 128] [--ref-spp 2048] [--thresholds 0.05,0.02,0.01]
                              [--max-spp 1024] [--device cpu] [--out DIR] [--repeats 2]

Renders a converged reference (uniform, --ref-spp samples, seed 777 so that no test
image shares its samples), then for each threshold an adaptive render (seed 1, at most
--max-spp samples a pixel), timed by the wall clock of the whole process, and a uniform
render given that same time as --time-limit (whole batches; its samples are what fits).
Each pair runs --repeats times, the two taking turns, and the table gives the medians:
seconds, mean samples per pixel, RMSE against the reference and the ratio uniform MSE /
adaptive MSE (above 1: adaptive sampling wins). The reference's own noise adds to both
MSEs alike. Standard library only.
"""
import argparse
import math
import os
import re
import statistics
import subprocess
import sys
import time

import peers  # bench/peers.py: the one PFM reader of the bench scripts


def read_pfm(path):
    """The image's floats (peers.read_pfm, which also gives the size)."""
    return peers.read_pfm(path)[2]


def rmse(a, b):
    return math.sqrt(sum((x - y) * (x - y) for x, y in zip(a, b)) / len(a))


def run(args, extra, out):
    cmd = [args.clpt, args.scene, '--width', str(args.size), '--height', str(args.size), '--device',
           args.device, '-o', out] + extra
    t0 = time.monotonic()
    p = subprocess.run(cmd, capture_output=True, text=True)
    secs = time.monotonic() - t0
    if p.returncode not in (0,):
        raise SystemExit('%s failed (%d): %s' % (' '.join(cmd), p.returncode, p.stderr))
    return secs, p.stderr


def mean_spp(stderr):
    # the summary line: "adaptive 16..1024 spp (mean 87.5)", or "128x128, 150 spp"
    for line in stderr.splitlines():
        m = re.search(r'adaptive \d+\.\.\d+ spp \(mean ([0-9.]+)\)', line)
        if m:
            return float(m.group(1))
        m = re.search(r'\d+x\d+, (\d+) spp', line)
        if m:
            return float(m.group(1))
    return float('nan')


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--clpt', default='build/clpt')
    ap.add_argument('--scene', default='scenes/cornell-box.scene')
    ap.add_argument('--size', type=int, default=128)
    ap.add_argument('--ref-spp', type=int, default=2048)
    ap.add_argument('--thresholds', default='0.05,0.02,0.01')
    ap.add_argument('--max-spp', type=int, default=1024)
    ap.add_argument('--device', default='cpu')
    ap.add_argument('--out', default='/tmp/clpt-bench-adaptive')
    ap.add_argument('--repeats', type=int, default=2)
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    ref_path = os.path.join(args.out, 'ref.pfm')
    if not os.path.exists(ref_path):
        secs, _ = run(args, ['--spp', str(args.ref_spp), '--seed', '777', '-q'], ref_path)
        print('reference: %d spp in %.1f s' % (args.ref_spp, secs))
    ref = read_pfm(ref_path)
    print('%-10s %8s %9s %10s %8s %9s %10s %9s' % ('threshold', 'seconds', 'adapt spp', 'adapt RMSE',
                                                   'unif spp', 'unif RMSE', 'MSE ratio', 'time/unif'))
    for t in args.thresholds.split(','):
        rows = []
        for rep in range(args.repeats):
            a_out = os.path.join(args.out, 'adaptive-%s.pfm' % t)
            u_out = os.path.join(args.out, 'uniform-%s.pfm' % t)
            secs, err = run(args, ['--spp', str(args.max_spp), '--noise-threshold', t], a_out)
            a_spp = mean_spp(err)
            usecs, uerr = run(args, ['--spp', str(args.max_spp), '--time-limit', '%.3f' % secs], u_out)
            u_spp = mean_spp(uerr)
            ea, eu = rmse(read_pfm(a_out), ref), rmse(read_pfm(u_out), ref)
            rows.append((secs, a_spp, ea, u_spp, eu, usecs))
        med = [statistics.median(r[i] for r in rows) for i in range(6)]
        print('%-10s %8.2f %9.1f %10.5f %8.1f %9.5f %10.2f %9.2f' % (t, med[0], med[1], med[2], med[3], med[4],
                                                                   (med[4] / med[2]) ** 2, med[5] / med[0]))
        sys.stdout.flush()


if __name__ == '__main__':
    main()
