#!/usr/bin/env python3
"""Adaptive sampling (--noise-threshold) against uniform sampling at equal CPU time.

usage: bench/adaptive_rmse.py [--clpt build/clpt] [--scene scenes/cornell-box.scene]
                              [--size 128] [--height H] [--ref-spp 2048]
                              [--thresholds 0.05,0.02,0.01] [--max-spp 1024]
                              [--min-spp N] [--adaptive-args ARGS] [--device cpu]
                              [--out DIR] [--repeats 3]

Renders a converged reference, then for each threshold, --repeats times, an adaptive
render (seed 1, 2, ... for repeat 1, 2, ...: the repeats are independent images, at
most --max-spp samples a pixel) and right after it a uniform render (the same seed)
whose spp is chosen to take the same CPU time (the adaptive run's user + system
seconds over the uniform renders' CPU seconds per spp measured so far). Each process is
timed by its CPU seconds (os.wait4), which a machine shared with other jobs disturbs
far less than the wall clock; the wall seconds are printed too (the adaptive rounds
leave cores idle between them, which CPU seconds do not count).

The reference is the mean of two uniform renders with seeds 777 and 778 (so that no test
image shares its samples): a quarter of their mean squared difference is the
reference's own squared error, which would add to every MSE alike and pull the ratios
toward 1, so it is taken off each MSE. The table gives medians over the repeats: CPU
and wall seconds, mean samples per pixel, RMSE against the reference, the ratio uniform
MSE / adaptive MSE at (about) equal CPU time, and the efficiency ratio (uniform MSE x
CPU seconds) / (adaptive MSE x CPU seconds), which corrects a small time mismatch (MSE
falls as 1/time for unbiased sampling). Above 1: adaptive sampling wins.
Needs numpy.
"""
import argparse
import math
import os
import statistics
import subprocess
import sys
import time

import numpy as np

import peers  # bench/peers.py: the one PFM reader of the bench scripts


def read_pfm(path):
    return np.frombuffer(peers.read_pfm(path)[2], dtype=np.float32).astype(np.float64)


def run(args, extra, out):
    """Runs clpt; returns (CPU seconds, wall seconds, stderr)."""
    cmd = [args.clpt, args.scene, '--width', str(args.size), '--height', str(args.height), '--device', args.device,
           '-o', out, '--stats'] + extra
    t0 = time.monotonic()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    err = p.stderr.read()
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.monotonic() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit('%s failed: %s' % (' '.join(cmd), err))
    return ru.ru_utime + ru.ru_stime, wall, err


def mean_spp(stderr):
    import re
    for line in stderr.splitlines():
        m = re.search(r'adaptive \d+\.\.\d+ spp \(mean ([0-9.]+)\)', line)
        if m:
            return float(m.group(1))
        m = re.search(r'\d+x\d+, (\d+) spp', line)
        if m:
            return float(m.group(1))
    return float('nan')


def load():
    return os.getloadavg()[0]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--clpt', default='build/clpt')
    ap.add_argument('--scene', default='scenes/cornell-box.scene')
    ap.add_argument('--size', type=int, default=128)
    ap.add_argument('--height', type=int, default=0, help='default: --size')
    ap.add_argument('--ref-spp', type=int, default=2048)
    ap.add_argument('--thresholds', default='0.05,0.02,0.01')
    ap.add_argument('--max-spp', type=int, default=1024)
    ap.add_argument('--min-spp', type=int, default=0, help='0: clpt\'s default')
    ap.add_argument('--adaptive-args', default='', help='more arguments for the adaptive renders')
    ap.add_argument('--device', default='cpu')
    ap.add_argument('--out', default='/tmp/clpt-bench-adaptive')
    ap.add_argument('--repeats', type=int, default=3)
    args = ap.parse_args()
    args.height = args.height or args.size
    os.makedirs(args.out, exist_ok=True)
    refs = []
    unif_rate = []   # CPU seconds per spp of the uniform renders
    for seed in (777, 778):
        path = os.path.join(args.out, 'ref-%d.pfm' % seed)
        if not os.path.exists(path):
            cpu, wall, _ = run(args, ['--spp', str(args.ref_spp), '--seed', str(seed), '-q'], path)
            print('reference seed %d: %d spp in %.1f CPU s (%.1f s wall)' % (seed, args.ref_spp, cpu, wall))
            unif_rate.append(cpu / args.ref_spp)
        refs.append(read_pfm(path))
    ref = (refs[0] + refs[1]) / 2.0
    ref_mse = float(((refs[0] - refs[1]) ** 2).mean()) / 4.0
    print('scene %s at %dx%d; reference noise (MSE) %.3g' % (args.scene, args.size, args.height, ref_mse))
    if not unif_rate:
        cpu, _, _ = run(args, ['--spp', '64', '--seed', '1', '-q'], os.path.join(args.out, 'rate.pfm'))
        unif_rate.append(cpu / 64)

    def mse(path):
        return max(float(((read_pfm(path) - ref) ** 2).mean()) - ref_mse, 1e-30)

    print('%-9s %6s %8s %7s %9s %10s %8s %7s %9s %10s %9s %10s' %
          ('threshold', 'load', 'adapt s', 'wall s', 'adapt spp', 'adapt RMSE', 'unif s', 'wall s', 'unif spp',
           'unif RMSE', 'MSE ratio', 'efficiency'))
    extra = ['--min-spp', str(args.min_spp)] if args.min_spp else []
    extra += args.adaptive_args.split()
    for t in args.thresholds.split(','):
        rows = []
        for rep in range(args.repeats):
            l0 = load()
            a_out = os.path.join(args.out, 'adaptive-%s.pfm' % t)
            u_out = os.path.join(args.out, 'uniform-%s.pfm' % t)
            seed = str(rep + 1)
            a_cpu, a_wall, err = run(args, ['--spp', str(args.max_spp), '--noise-threshold', t, '--seed', seed] + extra,
                                     a_out)
            a_spp = mean_spp(err)
            u_n = max(1, int(round(a_cpu / statistics.median(unif_rate))))
            u_cpu, u_wall, _ = run(args, ['--spp', str(u_n), '--seed', seed], u_out)
            unif_rate.append(u_cpu / u_n)
            ea, eu = mse(a_out), mse(u_out)
            rows.append((l0, a_cpu, a_wall, a_spp, ea, u_cpu, u_wall, u_n, eu, eu / ea, (eu * u_cpu) / (ea * a_cpu)))
        med = [statistics.median(r[i] for r in rows) for i in range(len(rows[0]))]
        print('%-9s %6.1f %8.2f %7.2f %9.1f %10.5f %8.2f %7.2f %9.0f %10.5f %9.2f %10.2f' %
              (t, med[0], med[1], med[2], med[3], math.sqrt(med[4]), med[5], med[6], med[7], math.sqrt(med[8]), med[9],
               med[10]))
        sys.stdout.flush()


if __name__ == '__main__':
    main()
