"""The package's API: layouts, dtypes, several lights, per-sample output, progress, the GIL."""

import threading
import time

import numpy as np
import pytest

import soft_shadows as ss


@pytest.fixture(scope="module")
def bunny():
    return ss.builtin("bunny")


@pytest.fixture(scope="module")
def view(bunny):
    return ss.Receivers.from_camera(bunny.scene, bunny.camera_or_default(), 40, 30)


def test_techniques_list_every_preset_with_its_capabilities():
    all_ = ss.techniques()
    names = [t["name"] for t in all_]
    assert len(names) == len(set(names)) >= 20
    for family in ["ref", "dcs", "pcss", "ssm", "afsm", "auto"]:
        assert any(t["family"] == family for t in all_), family
    for t in all_:
        assert t["processor"] in ("cpu", "gpu")
        assert set(t["lights"]) <= {"rectangle", "disk", "polygon", "sphere", "point", "mesh"}
        assert t["samples"] is None or t["samples"] > 0


def test_float64_and_fortran_order_give_the_same_bits_as_float32(bunny, view):
    g = view.arrays()
    valid = g["valid"]
    p32, n32 = g["position"][valid], g["geometric_normal"][valid]
    a = ss.Receivers.from_points(bunny.scene, p32, n32)
    b = ss.Receivers.from_points(
        bunny.scene, np.asfortranarray(p32.astype(np.float64)), np.asfortranarray(n32.astype(np.float64))
    )
    c = ss.Receivers.from_points(bunny.scene, p32[::-1][::-1], n32.tolist())
    va = ss.estimate("dcs-64", bunny.scene, bunny.lights, a).visibility
    for other in (b, c):
        vb = ss.estimate("dcs-64", bunny.scene, bunny.lights, other).visibility
        assert np.array_equal(va.view(np.uint32), vb.view(np.uint32))


def test_a_gbuffer_of_the_cameras_own_view_gives_its_visibility(bunny, view):
    g = view.arrays()
    cam = bunny.camera_or_default()
    again = ss.Receivers.from_gbuffer(
        bunny.scene, g["position"], g["geometric_normal"], valid=g["valid"], camera=cam
    )
    assert again.shape == [30, 40] and again.has_camera and again.unmatched == 0
    v0 = ss.estimate("ref-64", bunny.scene, bunny.lights, view).visibility
    v1 = ss.estimate("ref-64", bunny.scene, bunny.lights, again).visibility
    # Snapping moves a foreign point onto its triangle: the rasterizer's own points stay put
    # up to float rounding, so V matches the camera path's at all but a few receivers.
    assert np.mean(v0 == v1) > 0.99 and np.abs(v0 - v1).max() < 0.1


def test_per_sample_visibility_and_direct_light(bunny, view):
    f = ss.estimate("ref-64", bunny.scene, bunny.lights, view, per_sample=True, direct=True)
    light = f.lights[0]
    assert light.per_sample.shape == (30, 40, 64) and light.per_sample.dtype == bool
    valid = f.valid
    assert np.array_equal(light.visibility[valid], light.per_sample[valid].mean(-1, dtype=np.float32))
    assert light.direct.shape == (30, 40, 3) and np.all(light.direct >= 0)
    assert np.array_equal(f.direct, light.direct)
    assert light.visibility[~valid].max() == 0
    plain = ss.estimate("ref-64", bunny.scene, bunny.lights, view)
    assert plain.lights[0].per_sample is None and plain.direct is None
    assert plain.stats["counters"]["occlusion-rays"] > 0


def test_several_lights_give_v_per_light_and_direct_light_summed():
    setup = ss.builtin("interior")
    r = ss.Receivers.from_camera(setup.scene, setup.camera_or_default(), 24, 18)
    kinds = [l.kind for l in setup.lights]
    assert kinds == ["rectangle", "disk", "sphere"]
    calls = []
    f = ss.estimate(
        "ref-64", setup.scene, setup.lights, r, direct=True,
        progress=lambda done, total: calls.append((done, total)),
    )
    assert calls == [(0, 3), (1, 3), (2, 3), (3, 3)]
    assert [l.index for l in f.lights] == [0, 1, 2]
    total = sum(l.direct for l in f.lights)
    assert np.allclose(f.direct, total, rtol=1e-5, atol=1e-6)
    with pytest.raises(ss.InvalidInputError, match="3 lights"):
        f.visibility


def test_a_fallback_shadows_the_lights_a_technique_refuses():
    setup = ss.builtin("interior")
    r = ss.Receivers.from_camera(setup.scene, setup.camera_or_default(), 24, 18)
    f = ss.estimate("dcs-64", setup.scene, setup.lights, r, fallback="ref-64")
    techniques = [l.technique for l in f.lights]
    refused = [l.fallback_reason for l in f.lights if l.technique == "ref-64"]
    assert "dcs-64" in techniques and all(refused)


def test_an_exception_in_the_progress_callback_stops_the_estimate():
    setup = ss.builtin("interior")
    r = ss.Receivers.from_camera(setup.scene, setup.camera_or_default(), 16, 12)

    def stop(done, total):
        if done == 1:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        ss.estimate("ref-64", setup.scene, setup.lights, r, progress=stop)


def test_a_textured_light_gives_rgb_visibility():
    setup = ss.builtin("textured-light")
    r = ss.Receivers.from_camera(setup.scene, setup.camera_or_default(), 20, 15)
    assert setup.lights[0].textured
    v = ss.estimate("ref-64", setup.scene, setup.lights, r).visibility
    assert v.shape == (15, 20, 3) and v.dtype == np.float32
    texture = np.zeros((2, 2, 3), np.float32)
    texture[..., 0] = 1.0
    own = ss.Light.rectangle_facing((0, 2, 0), (0, -1, 0), 1, 1, texture=texture)
    v = ss.estimate("ref-64", setup.scene, own, r).visibility
    assert v[..., 1:].max() == 0 and v[..., 0].max() > 0


def test_the_gil_is_released_while_a_technique_runs(bunny):
    r = ss.Receivers.from_camera(bunny.scene, bunny.camera_or_default(), 160, 120)
    ticks = []
    done = threading.Event()

    def work():
        ss.estimate("ref", bunny.scene, bunny.lights, r, samples=256)
        done.set()

    t = threading.Thread(target=work)
    t.start()
    while not done.is_set():
        ticks.append(time.perf_counter())
        time.sleep(0.001)
    t.join()
    # Python code kept running in this thread while the estimate ran in the other.
    assert len(ticks) > 20


def test_scenes_from_meshes_files_and_builtins(tmp_path):
    assert "bunny" in ss.builtin_scenes() and "cornell-box" in ss.builtin_scenes()
    quad = np.array([[-1, 0, -1], [1, 0, -1], [1, 0, 1], [-1, 0, 1]], np.float32)
    tris = np.array([[0, 2, 1], [0, 3, 2]])
    s = ss.Scene.from_meshes([(quad, tris), (quad + [0, 0.5, 0], tris, 0.5, (0.2, 0.3, 0.4))])
    assert s.triangle_count == 4 and s.has_semi_opaque
    obj = tmp_path / "tri.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 3 2\n")
    setup = ss.load(obj)
    assert setup.scene.triangle_count == 1 and setup.lights == [] and setup.name == "tri"
