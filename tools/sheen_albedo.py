#!/usr/bin/env python3
"""Writes kernels/bsdf/sheen_albedo.h: the directional albedo E(mu, r) of the sheen lobe of
KHR_materials_sheen (kernels/bsdf/principled.h), for the albedo scaling of the layers below it.

The lobe is the extension's "Charlie" one (Estevez & Kulla 2017, "Production Friendly
Microfacet Sheen BRDF"): D = (2 + 1/a) sin(h)^(1/a) / (2 pi) and the visibility
1 / ((1 + Lambda(mu_o) + Lambda(mu_i)) 4 mu_o mu_i) with the paper's fit of Lambda,
a = r^2 for the perceptual sheen roughness r. E(mu, r) = integral of f mu_i over the
hemisphere, by the midpoint rule on a (cos theta, phi) grid. The columns are spaced in
sqrt(mu), as E is steepest at grazing views. Run: python3 tools/sheen_albedo.py > kernels/bsdf/sheen_albedo.h
"""
import numpy as np

MU_N, R_N = 32, 16          # table size: cos(theta_o) from 0 to 1, r from R_MIN to 1
R_MIN = 0.25                # kernels/bsdf/principled.h SHEEN_ROUGHNESS_MIN
GRAZING = (1e-3, 3e-3, 1e-2)  # E at mu = 0: the largest at these cosines (the quadrature
                              # loses the limit; a table value too low would gain energy)


def lambda_fit(x, a):
    t = (1.0 - a) ** 2
    lerp = lambda lo, hi: lo + (hi - lo) * t
    l_of = lambda y: (lerp(21.5473, 25.3245) / (1.0 + lerp(3.82987, 3.32435) * np.power(y, lerp(0.19823, 0.16801)))
                      + lerp(-1.97760, -1.27393) * y + lerp(-4.32054, -4.85967))
    x = np.abs(x)
    return np.where(x < 0.5, np.exp(l_of(x)), np.exp(2.0 * l_of(0.5) - l_of(1.0 - x)))


def albedo(mu, r, n=400):
    a = r * r
    ct = (np.arange(n) + 0.5) / n
    ph = (np.arange(2 * n) + 0.5) / (2 * n) * 2.0 * np.pi
    c, p = np.meshgrid(ct, ph, indexing="ij")
    s = np.sqrt(1.0 - c * c)
    wi = np.stack([s * np.cos(p), s * np.sin(p), c], -1)
    wo = np.array([np.sqrt(1.0 - mu * mu), 0.0, mu])
    h = wi + wo
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    sin2h = np.maximum(1.0 - h[..., 2] ** 2, 0.0)
    d = (2.0 + 1.0 / a) * np.power(sin2h, 0.5 / a) / (2.0 * np.pi)
    v = 1.0 / ((1.0 + lambda_fit(mu, a) + lambda_fit(c, a)) * 4.0 * mu * c)
    return float((d * v * c).sum() / n * (np.pi / n))


def main():
    print("/* sheen_albedo.h — written by tools/sheen_albedo.py; do not edit. The directional")
    print(" * albedo E(mu, r) of the Charlie sheen lobe (kernels/bsdf/principled.h), row j for the")
    print(" * perceptual roughness r = %.2f + %.2f j / %d, column i for mu = (i / %d)^2. */" % (R_MIN, 1 - R_MIN, R_N - 1, MU_N - 1))
    print("#ifndef CLPT_SHEEN_ALBEDO_H\n#define CLPT_SHEEN_ALBEDO_H\n")
    print("#define SHEEN_TABLE_MU %d\n#define SHEEN_TABLE_R %d\n#define SHEEN_ROUGHNESS_MIN %.2ff\n" % (MU_N, R_N, R_MIN))
    print("static CONSTANT float sheen_albedo_table[SHEEN_TABLE_R * SHEEN_TABLE_MU] = {")
    for j in range(R_N):
        r = R_MIN + (1.0 - R_MIN) * j / (R_N - 1)
        row = [max(albedo(m, r) for m in GRAZING)] + [albedo((i / (MU_N - 1)) ** 2, r) for i in range(1, MU_N)]
        for k in range(0, MU_N, 8):
            print("    " + " ".join("%.5ff," % v for v in row[k:k + 8]))
    print("};\n\n#endif /* CLPT_SHEEN_ALBEDO_H */")


if __name__ == "__main__":
    main()
