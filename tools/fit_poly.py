#!/usr/bin/env python3
"""Coefficients of the short polynomials in kernels/util/kmath.h (plain Python, no numpy).

Near-minimax fits by Lawson's iteratively reweighted least squares: a weighted
least-squares fit on Chebyshev-spaced points, the weights multiplied each round by the
error, which drives the fit toward equal ripple (the minimax polynomial).

  k_atan: atan(t) = t + t^3 P(t^2) on |t| <= tan(pi/8), P of degree 3.

Prints the coefficients and the largest error of the function itself (before float
rounding), checked on a finer grid than the fit's.
"""
import math


def solve(a, b):
    """Gaussian elimination with partial pivoting: a x = b for a small dense a."""
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        for r in range(c + 1, n):
            f = m[r][c] / m[c][c]
            for k in range(c, n + 1):
                m[r][k] -= f * m[c][k]
    x = [0.0] * n
    for r in range(n - 1, -1, -1):
        x[r] = (m[r][n] - sum(m[r][k] * x[k] for k in range(r + 1, n))) / m[r][r]
    return x


def lawson(g, weight, hi, terms, points=2000, rounds=300):
    """Coefficients c of sum c_k s^k ~ g(s) on (0, hi], minimising max |weight(s) (fit - g)|."""
    s = [hi * (1.0 - math.cos(math.pi * (i + 0.5) / points)) / 2.0 for i in range(points)]
    w = [1.0] * points
    for _ in range(rounds):
        ata = [[0.0] * terms for _ in range(terms)]
        atb = [0.0] * terms
        for si, wi in zip(s, w):
            ww = wi * weight(si) ** 2
            col = [(si / hi) ** k for k in range(terms)]   # scaled powers: better conditioned
            for i in range(terms):
                atb[i] += ww * col[i] * g(si)
                for j in range(terms):
                    ata[i][j] += ww * col[i] * col[j]
        c = solve(ata, atb)
        err = [abs(sum(c[k] * (si / hi) ** k for k in range(terms)) - g(si)) * weight(si) for si in s]
        total = sum(wi * e for wi, e in zip(w, err))
        w = [wi * e / total for wi, e in zip(w, err)]
    return [c[k] / hi ** k for k in range(terms)]


def main():
    t8 = math.tan(math.pi / 8)
    hi = t8 * t8
    c = lawson(lambda s: (math.atan(math.sqrt(s)) - math.sqrt(s)) / s ** 1.5, lambda s: s ** 1.5, hi, 4)
    worst = 0.0
    for i in range(1, 100001):
        t = t8 * i / 100000
        p = sum(ck * (t * t) ** k for k, ck in enumerate(c))
        worst = max(worst, abs(t + t ** 3 * p - math.atan(t)))
    print('k_atan P(s):', ', '.join('%.9g' % ck for ck in c))
    print('largest error of atan on [0, tan(pi/8)]: %.3g' % worst)


if __name__ == '__main__':
    main()
