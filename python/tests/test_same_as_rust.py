"""Every preset through Python gives the Rust call's V, bit for bit.

The Rust call is ``xtask render`` (the command-line front end of the same crates), which
writes V as ``visibility.npy`` (``visibility-K.npy`` per light with several). A preset that
refuses a scene must refuse it through both.
"""

import subprocess

import numpy as np
import pytest

import soft_shadows as ss

SCENES = ["bunny", "interior"]  # one light; three lights of three kinds (panel, disk, sphere)
WIDTH, HEIGHT, SEED = 32, 24, 1
FALLBACK = "ref-64"  # shadows the lights a technique refuses, through both front ends
NAMES = [t["name"] for t in ss.techniques()]


def rust_render(xtask, scene, technique, out):
    """V per light from ``xtask render``, or the error text when it refused."""
    args = [
        str(xtask), "render", "--scene", scene, "--technique", technique,
        "--width", str(WIDTH), "--height", str(HEIGHT), "--seed", str(SEED),
        "--fallback", FALLBACK, "--out", str(out),
    ]
    run = subprocess.run(args, capture_output=True, text=True)
    if run.returncode != 0:
        return None, run.stderr
    files = sorted(out.glob("visibility*.npy"))
    if [f.name for f in files] == ["visibility.npy"]:
        return [np.load(files[0])], None
    by_light = sorted(files, key=lambda f: int(f.stem.split("-")[1]))
    return [np.load(f) for f in by_light], None


@pytest.mark.parametrize("scene", SCENES)
@pytest.mark.parametrize("technique", NAMES)
def test_every_preset_gives_the_rust_calls_visibility(xtask, require_gpu, tmp_path, scene, technique):
    setup = ss.builtin(scene)
    receivers = ss.Receivers.from_camera(
        setup.scene, setup.camera_or_default(), WIDTH, HEIGHT
    )
    expected, refusal = rust_render(xtask, scene, technique, tmp_path)
    try:
        frame = ss.estimate(
            technique, setup.scene, setup.lights, receivers, seed=SEED, fallback=FALLBACK
        )
    except ss.UnsupportedError as e:
        if require_gpu:
            assert e.reason != "no_adapter", f"{technique}: {e}"
        assert refusal is not None, f"Python refused ({e}) where Rust rendered"
        return
    assert refusal is None, f"Rust refused ({refusal.strip()}) where Python rendered"
    got = [light.visibility for light in frame.lights]
    assert len(got) == len(expected) == len(setup.lights)
    for k, (g, e) in enumerate(zip(got, expected)):
        assert g.shape == e.shape and g.dtype == e.dtype == np.float32, (k, g.shape, e.shape)
        # Bit for bit: the same float32 words, NaN never present.
        assert np.array_equal(g.view(np.uint32), e.view(np.uint32)), (
            f"light {k}: {np.count_nonzero(g != e)} receivers differ, "
            f"largest by {np.abs(g - e).max()}"
        )
