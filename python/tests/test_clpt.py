"""The Python module against the program: the same bits for the same settings, the
errors' words, progress, cancelling and Ctrl-C. Small renders (64x48, 4 spp)."""
import os
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import clpt

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PROGRAM = os.environ.get("CLPT_PROGRAM", os.path.join(REPO, "build", "clpt"))
SCENE = os.path.join(REPO, "scenes", "cornell-box.scene")
SMALL = dict(width=64, height=48, spp=4, threads=2)


def read_pfm(path):
    with open(path, "rb") as f:
        assert f.readline() == b"PF\n"
        w, h = map(int, f.readline().split())
        assert float(f.readline()) < 0  # little-endian
        data = np.frombuffer(f.read(), "<f4").reshape(h, w, 3)
    return data[::-1]  # rows bottom to top


def cli(tmp_path, *flags, name="cli.pfm"):
    out = str(tmp_path / name)
    subprocess.run([PROGRAM, SCENE, "-q", "-o", out, "--width", "64", "--height", "48", "--spp", "4",
                    "--threads", "2", *flags], check=True)
    return read_pfm(out)


def test_devices():
    devs = clpt.devices()
    assert devs[-1]["kind"] == "scalar" and devs[-1]["index"] is None
    assert all(d["kind"] in ("opencl", "scalar") for d in devs)


def test_render_same_bits_as_command_line(tmp_path):
    img = clpt.render(SCENE, device="scalar", seed=1, **SMALL)
    assert img.shape == (48, 64, 3) and img.dtype == np.float32
    assert np.array_equal(img, cli(tmp_path, "--device", "scalar", "--seed", "1"))


def test_render_opencl_cpu_same_bits(tmp_path):
    if not any(d["kind"] == "opencl" and d["type"] == "CPU" for d in clpt.devices()):
        pytest.skip("no OpenCL CPU device (PoCL)")
    img = clpt.render(SCENE, device="cpu", seed=1, **SMALL)
    assert np.array_equal(img, cli(tmp_path, "--device", "cpu", "--seed", "1"))


def test_scene_set_same_bits_as_set_flag(tmp_path):
    scene = clpt.load(SCENE, device="scalar")
    scene.set("camera.fov", 40).set("material.red.albedo", (0.1, 0.2, 0.9))
    img = scene.render(max_depth=3, **SMALL)
    ref = cli(tmp_path, "--device", "scalar", "--max-depth", "3", "--set", "camera.fov=40",
              "--set", "material.red.albedo=0.1,0.2,0.9")
    assert np.array_equal(img, ref)
    assert not np.array_equal(img, clpt.render(SCENE, device="scalar", **SMALL))


def test_noise_threshold_same_bits_as_command_line(tmp_path):
    settings = dict(SMALL, spp=48)
    img = clpt.render(SCENE, device="scalar", noise_threshold=0.05, min_spp=8, **settings)
    ref = cli(tmp_path, "--device", "scalar", "--spp", "48", "--noise-threshold", "0.05", "--min-spp", "8")
    assert np.array_equal(img, ref)


def test_denoise_same_bits_as_command_line(tmp_path, monkeypatch):
    oidn = os.path.join(REPO, "build", "oidn", "lib")
    if not os.path.isdir(oidn):
        pytest.skip("no Open Image Denoise in build/oidn (sh tools/deps.sh oidn)")
    # the library looks beside the program, which here is python: name the folder
    monkeypatch.setenv("CLPT_OIDN_DIR", oidn)
    img = clpt.render(SCENE, device="scalar", denoise=True, **SMALL)
    assert np.array_equal(img, cli(tmp_path, "--device", "scalar", "--denoise"))


def test_aovs():
    out = clpt.load(SCENE, device="scalar").render(aovs=("albedo", "normal", "depth"), **SMALL)
    assert out["rgb"].shape == (48, 64, 3) and out["depth"].shape == (48, 64)
    assert out["albedo"].max() <= 1.0 and out["depth"][24, 32] > 0
    lengths = np.linalg.norm(out["normal"], axis=2)
    assert (abs(lengths - 1.0) < 1e-3).mean() > 0.5 and lengths.max() < 1.001


def test_errors():
    with pytest.raises(clpt.Error) as e:
        clpt.load("/nonexistent/x.scene")
    assert str(e.value) == "cannot open '/nonexistent/x.scene': No such file or directory" and e.value.status == 4
    scene = clpt.load(SCENE, device="scalar")
    with pytest.raises(clpt.Error, match=r"^unknown option 'spp2'$"):
        scene.render(spp2=4)
    with pytest.raises(clpt.Error, match=r"^--spp must be between 1 and 1000000, got 0$"):
        scene.render(spp=0)
    with pytest.raises(clpt.Error, match=r"did you mean 'fov'\?"):
        scene.set("camera.fvo", 40)
    with pytest.raises(clpt.Error, match=r"^no device matches 'nosuch'"):
        clpt.load(SCENE, device="nosuch")


def test_progress_and_cancel():
    seen = []
    clpt.render(SCENE, device="scalar", progress=lambda d, t: seen.append((d, t)), **SMALL)
    assert seen and seen[-1] == (4, 4)
    with pytest.raises(clpt.Cancelled) as e:
        clpt.render(SCENE, device="scalar", width=64, height=48, spp=100000, batch=1,
                    progress=lambda d, t: d >= 2)
    assert e.value.status == 6 and e.value.result.shape == (48, 64, 3)


def test_ctrl_c_stops_the_render():
    """SIGINT during a long render: KeyboardInterrupt, raised within a second or so."""
    code = textwrap.dedent("""
        import sys, clpt
        def tick(done, total):
            if done >= 1 and not getattr(tick, "said", 0):
                tick.said = 1
                print("started", flush=True)
        try:
            clpt.render(%r, device="scalar", width=64, height=48, spp=1000000, batch=1, threads=1,
                        progress=tick)
        except KeyboardInterrupt:
            print("interrupted", flush=True)
            sys.exit(0)
        sys.exit(1)
    """ % SCENE)
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "started"
    p.send_signal(signal.SIGINT)
    out, _ = p.communicate(timeout=20)
    assert p.returncode == 0 and out.strip() == "interrupted"
