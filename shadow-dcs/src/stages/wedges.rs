//! Penumbra wedges (DCS section 4.2): for each silhouette edge, the region of space from which
//! the edge, seen toward the light, covers part of it, and the edge's weight `k_e(p)` there.
//!
//! The wedge of edge `e` is the set of points `x + t (x - y)`, `x` on the edge, `y` on the
//! light, `t > 0`: the points `z` whose segment to some light point crosses the edge. It is the
//! union over `x` on the edge of the anti-cones `K_x = {x + t (x - y)}` of the light, and lies in
//! the intersection of half-spaces bounded by (`wedge_planes`, prepared once per light):
//! * the planes through the edge's line that support the light (the classic wedge planes of
//!   AAM03): the light on one side, every `K_x` on the other;
//! * for a planar light, the planes through an end point `v` and a side of the light's polygon
//!   (the faces of the anti-cone `K_v`) that have the other end point on the anti-cone's side:
//!   every `K_x` for `x` on the edge then lies on that side too, since `x` does;
//! * for a sphere light, the two planes through the edge's line tangent to the sphere, and
//!   planes through each end point tangent to the sphere with the other end in front.
//!
//! A view sample outside any of these planes sees no part of the light through the edge. The
//! view samples inside each wedge are found by the box hierarchy of `bins` (the spatial
//! structure that plays the part of the GPU's rasterization of wedges); each gets the exact
//! weight `k_e(p)` (`SceneEdge::sweep_weight`, or its single-precision form with an error bound,
//! in the acceleration's `centred_wedges`), and only view samples with a non-zero weight are
//! kept. The
//! shadow-volume quad splits the wedge: `k_e > 0` is the outer part (samples beyond the projected
//! edge gain depth complexity), `k_e < 0` the inner part.

use glam::DVec3;

use crate::stages::edges::SceneEdge;
use crate::stages::light_shape::LightShape;

/// One (pixel, silhouette edge) pair: the edge and its weight `k_e(p)`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pair {
    /// Index into the silhouette list (of scene edge indices), which keeps the edges a frame
    /// touches together.
    pub edge: u32,
    /// `k_e(p)`: positive for the outer part of the wedge, negative for the inner part.
    pub k: i32,
}

/// A half-space `n . x + d >= 0` (`n` unit).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Plane {
    n: DVec3,
    d: f64,
}

impl Plane {
    /// Whether `x` lies in the half-space.
    pub(crate) fn contains(&self, x: DVec3) -> bool {
        self.n.dot(x) + self.d >= 0.0
    }

    /// The unit normal `n`.
    pub(crate) fn normal(&self) -> DVec3 {
        self.n
    }

    /// The offset `d`.
    pub(crate) fn offset(&self) -> f64 {
        self.d
    }
}

/// Side planes per end point taken from a light polygon with many sides (any subset of valid
/// planes bounds the wedge; four keep the box tests of [`crate::accel::bins`] within their budget).
const END_PLANES: usize = 4;

/// Half-spaces that hold the wedge of edge `e` for `light` (see the module documentation):
/// the supporting planes through the edge's line, and the anti-cone faces at each end point
/// (planar lights: through a side of the light's polygon; sphere lights: tangent to the sphere).
/// Other shapes get one tilted side plane per end point. Each is moved outward
/// by `1e-6` of the edge's scale, so that rounding never rejects a view sample the wedge holds.
pub(crate) fn wedge_planes(e: &SceneEdge, light: &LightShape) -> Vec<Plane> {
    let c = light.center.as_dvec3();
    let hull: Vec<DVec3> = light.hull.iter().map(|p| p.as_dvec3()).collect();
    let mut planes = Vec::with_capacity(2 + 2 * END_PLANES);
    let ab = e.b - e.a;
    let scale = ab.length() + hull.iter().map(|l| (*l - e.a).length()).fold(0.0, f64::max);
    let eps = 1e-9 * scale;
    let plane = |n: DVec3, at: DVec3| -> Option<Plane> {
        let len = n.length();
        (len > 0.0 && len.is_finite()).then(|| {
            let n = n / len;
            Plane {
                n,
                d: -n.dot(at) + 1e-6 * scale,
            }
        })
    };
    // The sides of `points` relative to the plane through `at` with normal `n`.
    let sides = |n: DVec3, at: DVec3, points: &[DVec3]| -> (f64, f64) {
        let len = n.length();
        points
            .iter()
            .map(|q| n.dot(*q - at) / len)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            })
    };
    if let Some((sc, sr)) = light.sphere() {
        // The two planes through the edge's line tangent to the sphere, the sphere behind.
        let d = ab.normalize();
        let q = (sc - e.a) - d * d.dot(sc - e.a);
        let ql = q.length();
        if ql > sr * (1.0 + 1e-9) {
            let (qh, perp) = (q / ql, d.cross(q / ql));
            let (cos, sin) = (sr / ql, (1.0 - (sr / ql).powi(2)).sqrt());
            for side in [-1.0, 1.0] {
                planes.extend(plane(-qh * cos + perp * sin * side, e.a));
            }
        }
    }
    for l in tangent_candidates(ab, e.a, c, &hull)
        .iter()
        .filter(|_| light.sphere().is_none())
    {
        let n = ab.cross(*l - e.a);
        if !(n.length() > eps * scale) {
            continue;
        }
        let (lo, hi) = sides(n, e.a, &hull);
        if hi <= eps {
            planes.extend(plane(n, e.a));
        } else if lo >= -eps {
            planes.extend(plane(-n, e.a));
        }
    }
    // Both tangent planes are found once per supporting vertex; keep distinct ones.
    planes.dedup_by(|x, y| (x.n - y.n).length_squared() < 1e-18);
    match &light.plane {
        Some(lp) => {
            let poly: Vec<DVec3> = lp.polygon.iter().map(|p| p.as_dvec3()).collect();
            let m = poly.len();
            let stride = m.div_ceil(END_PLANES).max(1);
            for (v, w) in [(e.a, e.b), (e.b, e.a)] {
                for i in (0..m).step_by(stride) {
                    let (l0, l1) = (poly[i], poly[(i + 1) % m]);
                    let n = (l0 - v).cross(l1 - v);
                    if !(n.length() > eps * scale) {
                        continue;
                    }
                    // The light on the negative side; `v` in the light's plane has none.
                    let (lo, hi) = sides(n, v, &poly);
                    let n = match (lo >= -eps, hi <= eps) {
                        (true, false) => -n,
                        (false, true) => n,
                        _ => continue,
                    };
                    if n.dot(w - v) >= 0.0 {
                        planes.extend(plane(n, v));
                    }
                }
            }
        }
        None if light.sphere().is_some() => {
            // Planes through each end point tangent to the sphere, the sphere behind and the
            // other end in front: the faces of the end point's anti-cone that hold the edge.
            let (sc, sr) = light.sphere().expect("a sphere light");
            for (v, w) in [(e.a, e.b), (e.b, e.a)] {
                let to_c = sc - v;
                let dist = to_c.length();
                if !(dist > sr * (1.0 + 1e-9)) {
                    continue;
                }
                let u = to_c / dist;
                let along = (w - v) - u * u.dot(w - v);
                if !(along.length() > 0.0) {
                    continue;
                }
                let e0 = along.normalize();
                let e1 = u.cross(e0);
                let (sin, cos) = (sr / dist, (1.0 - (sr / dist).powi(2)).sqrt());
                for t in [e0, (e0 + e1).normalize(), (e0 - e1).normalize()] {
                    let n = -u * sin + t * cos;
                    if n.dot(w - v) >= 0.0 {
                        planes.extend(plane(n, v));
                    }
                }
            }
        }
        None => {
            for (v, w) in [(e.a, e.b), (e.b, e.a)] {
                let d = w - v;
                let u = c - v;
                let uu = u.length_squared();
                if !(uu > 0.0) {
                    continue;
                }
                let perp = d - u * (d.dot(u) / uu);
                let mut lambda = 0.0f64;
                let mut ok = true;
                for l in &hull {
                    let den = u.dot(*l - v);
                    if !(den > 0.0) {
                        ok = false;
                        break;
                    }
                    lambda = lambda.max(perp.dot(*l - v) / den);
                }
                let n = perp - u * lambda;
                if ok && n.dot(d) >= 0.0 {
                    planes.extend(plane(n, v));
                }
            }
        }
    }
    planes
}

/// Hull points through which the planes containing the edge's line (`a` + t `ab`) may touch
/// the hull without cutting it: every point for a small hull; for a large one (a polygon light
/// of many sides) only the two of extreme angle around the line, seen from the light's centre
/// `c`. The tangent planes pass through those, so the quadratic test of every point against
/// every other (100k sides: two minutes, issue 51) becomes linear. Points on the line itself
/// have no angle and stay candidates.
fn tangent_candidates(ab: DVec3, a: DVec3, c: DVec3, hull: &[DVec3]) -> Vec<DVec3> {
    const SMALL: usize = 64;
    let d = ab.normalize_or_zero();
    let to_c = (c - a) - d * d.dot(c - a);
    if hull.len() <= SMALL || !(to_c.length() > 0.0) || d == DVec3::ZERO {
        return hull.to_vec();
    }
    let e1 = to_c.normalize();
    let e2 = d.cross(e1);
    let mut out = Vec::new();
    let (mut lo, mut hi) = (
        (f64::INFINITY, DVec3::ZERO),
        (f64::NEG_INFINITY, DVec3::ZERO),
    );
    for &l in hull {
        let q = l - a;
        let (x, y) = (q.dot(e1), q.dot(e2));
        if x == 0.0 && y == 0.0 {
            out.push(l);
            continue;
        }
        let angle = y.atan2(x);
        if angle < lo.0 {
            lo = (angle, l);
        }
        if angle > hi.0 {
            hi = (angle, l);
        }
    }
    if lo.0.is_finite() {
        out.extend([lo.1, hi.1]);
    }
    out
}

/// For a manifold edge whose faces weigh the same, `k_e(p)` is non-zero only where both faces
/// lie on one side of the plane through `p` and the edge (the edge is a silhouette of `p`):
/// with `P_i(p) = orient(w_i, a, b, p)` that is `P_1(p) P_2(p) > 0`. Two plane evaluations then
/// replace the full weight where the edge is not a silhouette of the pixel. Both planes carry
/// a small slack so that the prefilter never rejects a tie the exact weight would keep.
pub(crate) fn fold_planes(e: &SceneEdge) -> Option<(Plane, Plane)> {
    if e.always || e.faces.len() != 2 {
        return None;
    }
    let plane = |w: DVec3| -> Option<Plane> {
        let n = (e.a - w).cross(e.b - w);
        let len = n.length();
        (len > 0.0 && len.is_finite()).then(|| {
            let n = n / len;
            Plane { n, d: -n.dot(w) }
        })
    };
    let (p1, p2) = (plane(e.faces[0].third)?, plane(e.faces[1].third)?);
    Some((p1, p2))
}

/// Slack of the fold prefilter (distance), relative to the scene's extent.
pub(crate) const FOLD_SLACK: f64 = 1e-6;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stages::coverage::EdgeTest;
    use glam::Vec3;
    use shadow_core::light::{
        AreaLight, DiskLight, PolygonLight, Radiance, RectLight, SphereLight,
    };
    use shadow_core::sampling::{hash_words, unit_float};

    /// Issue 51: the tangent planes through an edge's line were found by testing every hull
    /// point against every other (a 100k-sided light: 115 s of wedge set-up, now 0.03 s). The
    /// linear search keeps every point whose plane through the line has the whole hull on one
    /// side.
    #[test]
    fn tangent_candidates_keep_every_supporting_point() {
        let n = 500;
        // A star-shaped light outline in the plane y = 3.
        let hull: Vec<DVec3> = (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                let r = if k % 2 == 0 { 1.0 } else { 0.9 };
                DVec3::new(r * a.cos(), 3.0, -r * a.sin())
            })
            .collect();
        let c = DVec3::new(0.0, 3.0, 0.0);
        let mut supported = 0;
        for t in 0..200u32 {
            let r = |k: u32| unit_float(hash_words(&[t as u64, k as u64])) as f64 * 4.0 - 2.0;
            let a = DVec3::new(r(0), r(1).abs() * 0.7, r(2));
            let ab = DVec3::new(r(3), r(4) * 0.2, r(5));
            let candidates = tangent_candidates(ab, a, c, &hull);
            assert!(candidates.len() < 8);
            for l in &hull {
                let nrm = ab.cross(*l - a);
                let side: Vec<f64> = hull.iter().map(|q| nrm.dot(*q - a)).collect();
                let tol = 1e-9 * nrm.length();
                let one_side = side.iter().all(|&v| v <= tol) || side.iter().all(|&v| v >= -tol);
                if one_side && nrm.length() > 1e-12 {
                    supported += 1;
                    let found = candidates.iter().any(|q| {
                        let m = ab.cross(*q - a).normalize();
                        let u = nrm.normalize();
                        (m - u).length() < 1e-9 || (m + u).length() < 1e-9
                    });
                    assert!(found, "case {t}: the plane through {l} is missed");
                }
            }
        }
        assert!(supported > 200, "{supported}");
    }

    /// A view sample from which the edge covers any point of the light lies inside every
    /// bounding plane of the wedge (rectangle, disk, polygon and sphere lights; view samples
    /// all around, some far from the origin): the planes never drop a pair that matters.
    #[test]
    fn wedge_planes_hold_every_view_sample_that_sees_the_edge_over_the_light() {
        let white = || Radiance::constant(Vec3::ONE).unwrap();
        let (mut inside_covering, mut outside) = (0, 0);
        for k in 0..1500u64 {
            let r = |i: u64| unit_float(hash_words(&[k, i])) * 2.0 - 1.0;
            let o = Vec3::splat([0.0, 1e3][k as usize % 2]);
            let c = o + Vec3::new(r(0), 3.0 + r(1) * 0.3, r(2));
            let light: Box<dyn AreaLight> = match k % 4 {
                0 => Box::new(
                    RectLight::facing(
                        c,
                        Vec3::new(r(3) * 0.3, -1.0, r(4) * 0.3),
                        1.0 + r(5),
                        0.8,
                        white(),
                    )
                    .unwrap(),
                ),
                1 => Box::new(DiskLight::new(c, Vec3::NEG_Y, 0.7 + 0.3 * r(5), white()).unwrap()),
                2 => Box::new(
                    PolygonLight::new(
                        (0..5)
                            .map(|j| {
                                let a = -(j as f32) * std::f32::consts::TAU / 5.0;
                                c + Vec3::new(a.cos(), 0.0, a.sin()) * (0.6 + 0.2 * r(6 + j))
                            })
                            .collect(),
                        white(),
                    )
                    .unwrap(),
                ),
                _ => Box::new(SphereLight::new(c, 0.4 + 0.2 * r(5), white()).unwrap()),
            };
            let shape = LightShape::new(light.as_ref(), "test").unwrap();
            let mid = o + Vec3::new(r(7), 1.6 + r(8) * 0.8, r(9));
            let dir = Vec3::new(r(10), r(11) * 0.5, r(12)) * 0.4;
            let (a, b) = ((mid - dir).as_dvec3(), (mid + dir).as_dvec3());
            let third = (mid + Vec3::new(r(13), r(14), r(15)) * 0.3).as_dvec3();
            let e = SceneEdge::boundary(a, b, third);
            let planes = wedge_planes(&e, &shape);
            let cd = shape.center.as_dvec3();
            for j in 0..40u64 {
                let p = o.as_dvec3()
                    + glam::DVec3::new(
                        r(20 + 3 * j) as f64 * 4.0,
                        r(21 + 3 * j) as f64 * 0.5,
                        r(22 + 3 * j) as f64 * 4.0,
                    );
                let inside = planes.iter().all(|q| q.n.dot(p) + q.d >= 0.0);
                let Some(t) = EdgeTest::new(p, cd, a, b) else {
                    continue;
                };
                // Points of the light on a grid of its unit square.
                let n = 24;
                let covers = (0..n * n).any(|g| {
                    let u = glam::Vec2::new(
                        ((g % n) as f32 + 0.5) / n as f32,
                        ((g / n) as f32 + 0.5) / n as f32,
                    );
                    let s = light.sample(u).position.as_dvec3();
                    t.covers_offset((s - p).as_vec3())
                });
                if covers {
                    assert!(
                        inside,
                        "case {k} view sample {j}: a covering edge outside a plane"
                    );
                    inside_covering += 1;
                } else if !inside {
                    outside += 1;
                }
            }
        }
        assert!(inside_covering > 500, "{inside_covering}");
        // The planes do reject view samples.
        assert!(outside > 5000, "{outside}");
    }
}
