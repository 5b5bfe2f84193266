"""Bad arrays and bad arguments give clear exceptions naming what is wrong, never a crash."""

import numpy as np
import pytest

import soft_shadows as ss

FLOOR_V = np.array([[-1, 0, -1], [1, 0, -1], [1, 0, 1], [-1, 0, 1]], np.float32)
FLOOR_F = np.array([[0, 2, 1], [0, 3, 2]], np.int32)


@pytest.fixture(scope="module")
def floor():
    return ss.Scene.from_arrays(FLOOR_V, FLOOR_F)


@pytest.fixture(scope="module")
def light():
    return ss.Light.rectangle_facing((0, 1, 0), (0, -1, 0), 0.5, 0.5)


def points(n=4):
    p = np.zeros((n, 3), np.float32)
    p[:, 0] = np.linspace(-0.5, 0.5, n)
    return p, np.tile(np.float32([0, 1, 0]), (n, 1))


@pytest.mark.parametrize(
    "vertices, indices, match",
    [
        (FLOOR_V[:, :2], FLOOR_F, r"vertices: shape \[4, 2\] is not \(\.\.\., 3\)"),
        (FLOOR_V.astype(np.int64), FLOOR_F, "vertices: dtype int64 is not float32 or float64"),
        (FLOOR_V.astype(np.complex64), FLOOR_F, "vertices: dtype complex64"),
        (FLOOR_V, FLOOR_F[:, :2], r"indices: shape \[2, 2\] is not \(M, 3\)"),
        (FLOOR_V, FLOOR_F.astype(np.float32), "indices: dtype float32 is not an integer type"),
        (FLOOR_V, np.array([[0, -1, 2]]), "triangle 0 has index -1"),
        (FLOOR_V, np.array([[0, 1, 9]]), "9"),
        (np.where(np.arange(12).reshape(4, 3) == 4, np.nan, FLOOR_V), FLOOR_F, "(?i)finite|nan"),
        ("not an array", FLOOR_F, "vertices"),
    ],
)
def test_bad_scene_arrays_are_named(vertices, indices, match):
    with pytest.raises(ss.InvalidInputError, match=match):
        ss.Scene.from_arrays(vertices, indices)


def test_bad_opacity_and_degenerate_triangles():
    with pytest.raises(ss.InvalidInputError, match=r"opacity: shape \[3\]"):
        ss.Scene.from_arrays(FLOOR_V, FLOOR_F, opacity=np.ones(3, np.float32))
    flat = np.array([[0, 1, 1]])
    with pytest.raises(ss.InvalidInputError):
        ss.Scene.from_arrays(FLOOR_V, flat)
    kept = ss.Scene.from_arrays(FLOOR_V, np.vstack([FLOOR_F, flat]), drop_degenerate=True)
    assert kept.triangle_count == 2 and kept.dropped_degenerate == 1


def test_bad_receivers_are_named(floor):
    p, n = points()
    cases = [
        ((p[:, :2], n), r"points: shape \[4, 2\]"),
        ((p, n[:3]), "(?i)length|3"),
        ((p.astype(np.int32), n), "points: dtype int32"),
        ((np.where(np.arange(12).reshape(4, 3) == 7, np.nan, p), n), "receiver 2: its position is not finite"),
        ((p, np.zeros_like(n)), "receiver 0"),
        ((p[:0], n[:0]), "(?i)no valid receiver"),
        ((p[None], n[None]), r"points: shape \[1, 4, 3\] is not \(n, 3\)"),
    ]
    for (pp, nn), match in cases:
        with pytest.raises(ss.InvalidInputError, match=match):
            ss.Receivers.from_points(floor, pp, nn)
    with pytest.raises(ss.InvalidInputError, match="tolerance"):
        ss.Receivers.from_points(floor, p, n, tolerance=-1.0)


def test_bad_gbuffers_are_named(floor):
    pos = np.zeros((4, 5, 3), np.float32)
    nor = np.tile(np.float32([0, 1, 0]), (4, 5, 1))
    with pytest.raises(ss.InvalidInputError, match="normals: shape"):
        ss.Receivers.from_gbuffer(floor, pos, nor[:3])
    with pytest.raises(ss.InvalidInputError, match="valid: dtype"):
        ss.Receivers.from_gbuffer(floor, pos, nor, valid=np.ones((4, 5), np.uint8))
    with pytest.raises(ss.InvalidInputError, match=r"valid: shape \[5, 4\]"):
        ss.Receivers.from_gbuffer(floor, pos, nor, valid=np.ones((5, 4), bool))
    with pytest.raises(ss.InvalidInputError, match="positions: shape"):
        ss.Receivers.from_gbuffer(floor, pos[0], nor[0])


def test_bad_lights_and_cameras_are_named():
    with pytest.raises(ss.InvalidInputError, match="radius"):
        ss.Light.disk((0, 1, 0), (0, -1, 0), 0.0)
    with pytest.raises(ss.InvalidInputError, match="degenerate: zero-length direction"):
        ss.Light.rectangle_facing((0, 1, 0), (0, 0, 0), 1.0, 1.0)
    with pytest.raises(ss.InvalidInputError, match="center: .* is not a sequence of three numbers"):
        ss.Light.sphere((0, 1), 0.5)
    with pytest.raises(ss.InvalidInputError, match="(?i)radiance"):
        ss.Light.sphere((0, 1, 0), 0.5, radiance=-1.0)
    with pytest.raises(ss.InvalidInputError, match=r"texture: shape \[4, 4\]"):
        ss.Light.rectangle_facing((0, 1, 0), (0, -1, 0), 1, 1, texture=np.ones((4, 4), np.float32))
    with pytest.raises(ss.InvalidInputError, match="(?i)texture"):
        ss.Light.rectangle_facing((0, 1, 0), (0, -1, 0), 1, 1, texture=-np.ones((2, 2, 3)))
    with pytest.raises(ss.InvalidInputError, match="camera"):
        ss.Camera.look_at((0, 1, 0), (0, 1, 0))


def test_bad_estimate_arguments_are_named(floor, light):
    p, n = points()
    r = ss.Receivers.from_points(floor, p, n)
    with pytest.raises(ss.InvalidInputError, match="unknown technique `nope`; valid names: ref"):
        ss.estimate("nope", floor, light, r)
    with pytest.raises(ss.InvalidInputError, match="fixed sample count; use its family: `dcs`"):
        ss.estimate("dcs-64", floor, light, r, samples=32)
    with pytest.raises(ss.InvalidInputError, match=r"lights\[1\]: not a Light"):
        ss.estimate("ref-64", floor, [light, "lamp"], r)
    with pytest.raises(ss.InvalidInputError, match="(?i)empty"):
        ss.estimate("ref-64", floor, [], r)
    with pytest.raises(OverflowError, match="samples"):
        ss.estimate("ref-64", floor, light, r, samples=-3)
    with pytest.raises(ss.InvalidInputError, match="declares no light samples"):
        ss.sample_points("pcss", light, r)


def test_a_refusal_carries_its_typed_reason(floor, light):
    p, n = points()
    r = ss.Receivers.from_points(floor, p, n)
    with pytest.raises(ss.UnsupportedError) as e:
        ss.estimate("ssm-adaptive", floor, [light, light], r)
    assert e.value.reason == "view" and e.value.technique == "ssm-adaptive"
    assert e.value.light_index == 0 and "camera" in e.value.detail
    assert isinstance(e.value, ss.ShadowError)
    textured = ss.Light.rectangle_facing((0, 1, 0), (0, -1, 0), 1, 1, texture=np.ones((2, 2, 3)))
    with pytest.raises(ss.UnsupportedError) as e:
        ss.estimate("pcss", floor, textured, ss.Receivers.from_camera(
            floor, ss.Camera.look_at((0, 2, 2), (0, 0, 0)), 8, 6))
    assert e.value.reason == "textured_light"


def test_too_many_receivers_is_a_limit_error(floor):
    with pytest.raises(ss.ShadowError):
        ss.Receivers.from_camera(floor, ss.Camera.look_at((0, 2, 2), (0, 0, 0)), 0, 10)
    with pytest.raises(ss.LimitError, match="above the largest supported view"):
        ss.Receivers.from_camera(floor, ss.Camera.look_at((0, 2, 2), (0, 0, 0)), 100_000, 100_000)


def test_a_missing_file_names_it(tmp_path):
    with pytest.raises(ss.InvalidInputError, match="nowhere.obj"):
        ss.load(tmp_path / "nowhere.obj")
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nf 1 2 3\n")
    with pytest.raises(ss.ShadowError, match="bad.obj"):
        ss.load(bad)
