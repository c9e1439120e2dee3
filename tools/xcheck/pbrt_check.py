"""pbrt_check.py -- the pbrt-v4 rows of the cross-check (xcheck.py --pbrt PATH, or
`make xcheck PBRT=PATH`): the very same pbrt-v4 files rendered by clpt (which reads
pbrt-v4's format, docs/pbrt.md) and by a pbrt-v4 binary built outside the repository.

The scenes are this folder's pbrt/*.pbrt (written by pbrt/make_scenes.py: a smoke ball, a
chromatic medium in glass, a uniformgrid cloud, a homogeneous fog, a fire ball and an
rgbgrid that glows) and
scenes/nanovdb-smoke.pbrt. Each is copied into the output folder with its film set to
size x size and its sampler to pbrt's `independent` (clpt's sampler is its own), and both
renderers render that copy with --spp and --seed 1 and 2; pbrt writes OpenEXR (read by
exr.py), clpt PFM.

The statistics are over the whole image (pbrt's spectral film against clpt's RGB; sky
pixels included):
  means      each channel's mean of the two seeds' images, and their ratio clpt / pbrt,
             with the ratio's standard error from the pixels' seed-to-seed variance; the
             tolerance is issue 41's: 3%, 5% where the medium is chromatic
  blurred    both means averaged over blocks of `block` x `block` pixels, the RMSE
             between the two blurred images, and its noise floor: each renderer's
             blurred-image noise from its two seeds, RMSE(b1, b2) / sqrt(2), combined as
             sqrt(n_clpt^2 + n_pbrt^2) / sqrt(2) for the means of two; 'within noise'
             when the RMSE is at most 1.5 times the floor (the floor itself is an
             estimate from two seeds)
"""
import math
import os
import re
import shutil
import subprocess
import time

import numpy as np

import exr

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
WITHIN_NOISE = 1.5

# name, file, files it reads (copied beside it), chromatic (5% tolerance), what it tests,
# and the known model difference (docs/validation.md)
SPECTRAL = ("pbrt-v4 is spectral (rgb sigma as RGBUnboundedSpectrum, 4 wavelengths a path) where "
            "clpt tracks R, G, B: pbrt's red channel also meets the medium's green-band absorption "
            "(a grey control agrees to 0.1%)")
SCENES = [
    ("pbrt-smoke-ball", "tools/xcheck/pbrt/smoke-ball.pbrt", [], False,
     "a uniformgrid smoke ball over a floor, sun and sky", ""),
    ("pbrt-glass-chromatic", "tools/xcheck/pbrt/glass-chromatic.pbrt", [], True,
     "a chromatic homogeneous medium inside a glass sphere, sun and sky", SPECTRAL),
    ("pbrt-cloud-grid", "tools/xcheck/pbrt/cloud-grid.pbrt", [], False,
     "a dense uniformgrid cumulus (albedo 0.995, g 0.5), sun and sky", ""),
    ("pbrt-fog", "tools/xcheck/pbrt/fog.pbrt", [], False,
     "homogeneous fog around the camera (its medium), a sphere on a floor", ""),
    ("pbrt-fire-ball", "tools/xcheck/pbrt/fire-ball.pbrt", [], True,
     "a uniformgrid temperature grid: blackbody emission, 1200-4500 K, over a floor",
     "clpt takes a blackbody's RGB from a table (Wyman's CIE fit, 4096 steps to the hottest "
     "cell, clamped at 0 out of gamut) where pbrt-v4 samples Planck's law at 4 wavelengths a path"),
    ("pbrt-rgbgrid-glow", "tools/xcheck/pbrt/rgbgrid-glow.pbrt", [], True,
     "an rgbgrid with an \"Le\" grid of one hue (orange) times Lescale, over a floor",
     "pbrt-v4 upsamples the orange Le and the grey sigma to spectra (RGBIlluminantSpectrum, "
     "RGBUnboundedSpectrum) where clpt keeps RGB"),
    ("pbrt-nanovdb-smoke", "scenes/nanovdb-smoke.pbrt", ["scenes/nanovdb-smoke.nvdb"], False,
     "scenes/nanovdb-smoke.pbrt: a NanoVDB grid read by each renderer", ""),
]
NAMES = [s[0] for s in SCENES]


def scene_copy(src, name, size, folder, extra):
    with open(os.path.join(ROOT, src)) as f:
        text = f.read()
    text = re.sub(r'"integer xresolution"\s*\[?\s*\d+\s*\]?', '"integer xresolution" %d' % size, text)
    text = re.sub(r'"integer yresolution"\s*\[?\s*\d+\s*\]?', '"integer yresolution" %d' % size, text)
    text = re.sub(r'"string filename"\s*\[?\s*"[^"]*\.exr"\s*\]?', '"string filename" "%s.exr"' % name, text)
    text = re.sub(r'^Sampler\s+"\w+"', 'Sampler "independent"', text, flags=re.M)
    for e in extra:
        shutil.copyfile(os.path.join(ROOT, e), os.path.join(folder, os.path.basename(e)))
    path = os.path.join(folder, name + ".pbrt")
    with open(path, "w") as f:
        f.write(text)
    return path


def run(cmd, what):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        raise RuntimeError("%s exit %d: %s" % (what, p.returncode, " ".join(p.stdout.strip().splitlines()[-2:])))
    return p.stdout


def blur(img, k):
    h, w, c = img.shape
    h2, w2 = h // k * k, w // k * k
    return img[:h2, :w2].reshape(h2 // k, k, w2 // k, k, c).mean(axis=(1, 3))


def compare(c, q, chromatic, block):
    """c, q: [seed 1, seed 2] images of clpt and pbrt -> a dict of the statistics."""
    cm, qm = (c[0] + c[1]) / 2, (q[0] + q[1]) / 2
    mc, mq = cm.mean(axis=(0, 1)), qm.mean(axis=(0, 1))
    n = cm.shape[0] * cm.shape[1]
    # the variance of one image's pixel is E[(x1 - x2)^2] / 2; a mean of n pixels of two images
    se_c = np.sqrt(((c[0] - c[1]) ** 2).mean(axis=(0, 1)) / 2 / (2 * n))
    se_q = np.sqrt(((q[0] - q[1]) ** 2).mean(axis=(0, 1)) / 2 / (2 * n))
    ratio = mc / mq
    ratio_se = ratio * np.sqrt((se_c / mc) ** 2 + (se_q / mq) ** 2)
    tol = 0.05 if chromatic else 0.03
    bc = [blur(x, block) for x in c]
    bq = [blur(x, block) for x in q]
    noise_c = math.sqrt(float(((bc[0] - bc[1]) ** 2).mean()) / 2)
    noise_q = math.sqrt(float(((bq[0] - bq[1]) ** 2).mean()) / 2)
    floor = math.hypot(noise_c, noise_q) / math.sqrt(2)
    diff = math.sqrt(float(((blur(cm, block) - blur(qm, block)) ** 2).mean()))
    return {"clpt_mean": mc.tolist(), "pbrt_mean": mq.tolist(), "ratio": ratio.tolist(),
            "ratio_se": ratio_se.tolist(), "tolerance": tol,
            "means_ok": bool(np.all(np.abs(ratio - 1) <= tol)),
            "blurred_rmse": diff, "blurred_floor": floor, "noise_clpt": noise_c, "noise_pbrt": noise_q,
            "blurred_ok": diff <= WITHIN_NOISE * floor}


def rows(a, names, folder, read_pfm):
    """Renders and compares the pbrt-v4 scenes named (all when empty; a.clpt, a.pbrt, a.size,
    a.spp, a.pbrt_threads); prints the table and returns {name: statistics or why none}.
    read_pfm: xcheck.py's, for clpt's images."""
    pbrt = os.path.abspath(a.pbrt)
    todo = [s for s in SCENES if not names or s[0] in names]
    if not todo:
        return {}
    block = max(1, a.size // 8)
    print("pbrt-v4 rows: %d scenes, %d x %d, %d spp, seeds 1 and 2; %s" % (len(todo), a.size, a.size, a.spp, pbrt),
          flush=True)
    out, imgs = {}, {}
    for name, src, extra, chromatic, what, note in todo:
        scene = scene_copy(src, name, a.size, folder, extra)
        t0 = time.time()
        try:
            c = []
            for k in (1, 2):
                pfm = os.path.join(folder, "%s-clpt-%d.pfm" % (name, k))
                run([a.clpt, scene, "--spp", str(a.spp), "--seed", str(k), "-o", pfm, "--quiet"], "clpt")
                c.append(read_pfm(pfm))
            t1 = time.time()
            q = []
            for k in (1, 2):
                e = os.path.join(folder, "%s-pbrt-%d.exr" % (name, k))
                run([pbrt, "--quiet", "--nthreads", str(a.pbrt_threads), "--spp", str(a.spp), "--seed", str(k),
                     "--outfile", e, scene], "pbrt")
                q.append(exr.read_exr(e))
        except (RuntimeError, ValueError) as e:
            out[name] = "failed: %s" % e
            print("%-22s %s" % (name, out[name]), flush=True)
            continue
        print("%-22s clpt %.1f s  pbrt %.1f s" % (name, t1 - t0, time.time() - t1), flush=True)
        st = compare(c, q, chromatic, block)
        st["note"] = note
        out[name] = st
        imgs[name] = (c, q)
    print()
    print("### clpt against pbrt-v4, the same .pbrt files (%d x %d, %d spp each, two seeds; blur %d x %d)" % (
        a.size, a.size, a.spp, block, block))
    print()
    print("| scene | clpt mean (R G B) | pbrt-v4 mean | ratio ± s.e. | means (tol.) | blurred RMSE | noise floor "
          "| blurred | known model difference |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, src, extra, chromatic, what, note in todo:
        st = out[name]
        if isinstance(st, str):
            print("| %s | %s | | | | | | | |" % (name, st))
            continue
        f3 = lambda v: " ".join("%.4f" % x for x in v)  # noqa: E731
        rat = " ".join("%.3f±%.3f" % (r, e) for r, e in zip(st["ratio"], st["ratio_se"]))
        print("| %s | %s | %s | %s | %s (%d%%) | %.4f | %.4f | %s | %s |" % (
            name, f3(st["clpt_mean"]), f3(st["pbrt_mean"]), rat, "ok" if st["means_ok"] else "OFF",
            round(st["tolerance"] * 100), st["blurred_rmse"], st["blurred_floor"],
            "within noise" if st["blurred_ok"] else "%.1f x noise" % (st["blurred_rmse"] / st["blurred_floor"]),
            note))
    for name, (c, q) in imgs.items():
        np.save(os.path.join(folder, "%s-clpt.npy" % name), ((c[0] + c[1]) / 2).astype(np.float32))
        np.save(os.path.join(folder, "%s-pbrt.npy" % name), ((q[0] + q[1]) / 2).astype(np.float32))
    return out

