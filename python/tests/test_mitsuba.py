"""V at random points of a scene built from arrays, against Mitsuba 3's ray tests.

Mitsuba (``scalar_rgb``, Embree-free CPU ray tracing) traces the very rays of our reference's
per-sample visibility: from each receiver to each of its light samples (``sample_points``).
Stated tolerance: at least 99.9% of the per-sample answers agree, V differs by at most 1/64 at
any receiver and by at most 0.001 on average (measured: all 19,200 answers agree). A
disagreement could only come from a ray that grazes an edge or leaves a receiver's own surface,
where the two ray tracers' offsets differ.
"""

import numpy as np
import pytest

import soft_shadows as ss

mi = pytest.importorskip("mitsuba")
mi.set_variant("scalar_rgb")

SAMPLES = 64


def box(lo, hi):
    """A closed box's vertices and outward-facing triangles."""
    lo, hi = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    v = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    f = np.array([
        [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
        [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3],
    ])
    return v, f


def scene_arrays():
    """A floor, a box and a tilted plank under a ceiling panel, as one vertex/index array."""
    floor_v = np.array([[-3, 0, -3], [3, 0, -3], [3, 0, 3], [-3, 0, 3]], np.float64)
    floor_f = np.array([[0, 2, 1], [0, 3, 2]])
    box_v, box_f = box((-0.6, 0.4, -0.4), (0.1, 0.9, 0.3))
    plank_v = np.array([[0.3, 0.6, -0.8], [1.2, 1.0, -0.8], [1.2, 1.0, 0.6], [0.3, 0.6, 0.6]])
    plank_f = np.array([[0, 1, 2], [0, 2, 3]])
    parts = [(floor_v, floor_f), (box_v, box_f), (plank_v, plank_f)]
    vertices, indices, base = [], [], 0
    for v, f in parts:
        vertices.append(v)
        indices.append(f + base)
        base += len(v)
    return np.concatenate(vertices), np.concatenate(indices)


def mitsuba_scene(vertices, indices):
    mesh = mi.Mesh("occluders", len(vertices), len(indices))
    params = mi.traverse(mesh)
    params["vertex_positions"] = vertices.astype(np.float32).ravel()
    params["faces"] = indices.astype(np.uint32).ravel()
    params.update()
    return mi.load_dict({"type": "scene", "occluders": mesh})


def mitsuba_visibility(scene, points, normals, light_points, light_normal):
    """Per-sample visibility by Mitsuba's ray tests, with DCS eq. 1's rules: a sample below the
    receiver's tangent plane, or a receiver behind the one-sided light, sees nothing."""
    n_recv, n_samples = light_points.shape[:2]
    out = np.zeros((n_recv, n_samples), bool)
    for i in range(n_recv):
        p, n = points[i].astype(np.float64), normals[i].astype(np.float64)
        origin = p + 1e-4 * n
        for k in range(n_samples):
            y = light_points[i, k].astype(np.float64)
            if np.dot(n, y - p) <= 0 or np.dot(light_normal, p - y) <= 0:
                continue
            d = y - origin
            dist = np.linalg.norm(d)
            ray = mi.Ray3f(mi.Point3f(*origin), mi.Vector3f(*(d / dist)))
            ray.maxt = dist * (1 - 1e-4)
            out[i, k] = not scene.ray_test(ray)
    return out


def test_reference_agrees_with_mitsuba_at_random_points():
    vertices, indices = scene_arrays()
    scene = ss.Scene.from_arrays(vertices, indices)
    light = ss.Light.rectangle_facing((0.2, 2.2, 0.1), (0, -1, 0), 1.0, 0.8)
    rng = np.random.default_rng(7)
    n = 300
    points = np.column_stack([rng.uniform(-2, 2, n), np.zeros(n), rng.uniform(-2, 2, n)])
    normals = np.tile([0.0, 1.0, 0.0], (n, 1))
    receivers = ss.Receivers.from_points(scene, points, normals)
    assert receivers.unmatched == 0
    frame = ss.estimate("ref", scene, light, receivers, samples=SAMPLES, per_sample=True)
    ours = frame.lights[0].per_sample
    assert ours.shape == (n, SAMPLES)
    snapped = receivers.arrays()
    light_points = ss.sample_points("ref", light, receivers, samples=SAMPLES)
    theirs = mitsuba_visibility(
        mitsuba_scene(vertices, indices),
        snapped["position"],
        snapped["geometric_normal"],
        light_points,
        np.array([0.0, -1.0, 0.0]),
    )
    agreement = np.mean(ours == theirs)
    v_ours, v_theirs = frame.visibility, theirs.mean(axis=1)
    # V is the share of visible samples: the per-sample answers are V's own.
    assert np.array_equal(v_ours, ours.mean(axis=1, dtype=np.float32))
    # The scene is not trivial: shadowed, penumbra and lit receivers all occur.
    assert (v_theirs == 0).any() and (v_theirs == 1).any()
    assert ((v_theirs > 0) & (v_theirs < 1)).sum() > 20
    assert agreement >= 0.999, agreement
    assert np.abs(v_ours - v_theirs).max() <= 1 / SAMPLES
    assert np.abs(v_ours - v_theirs).mean() <= 0.001
