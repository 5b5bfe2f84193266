//! The covered-sample test of DCS section 4.2 (Algorithm 1, lines 4-7) in the plane of a planar
//! light, set up per (pixel, edge) in single precision from per-edge vectors prepared once.
//!
//! Around the light centre `c` (`x' = x - c`), with the light's in-plane axes `u` and `v`, a
//! light sample is `s' = s_u u + s_v v`. The four orientation tests of [`EdgeTest`] (the edge
//! `a b` crosses the triangle `(p, c, s)`) are then linear forms in `(s_u, s_v)`:
//! * the sector sides `orient(p, c, s, a) ~ (p' x a') . s' = s_u p' . (a' x u) + s_v p' . (a' x v)`,
//!   and the same with `b`;
//! * the shadow-volume side `orient(a, b, c, s) ~ (a' x b') . s'`, the same for every pixel;
//! * the edge side `orient(a, b, s, p) ~ (p' x e - a' x b') . s' + (a' x b') . p'` with
//!   `e = b - a`.
//!
//! So a pair costs seven dot products with `p'` (the cross products of the edge with `u` and
//! `v` are prepared per edge), and a sample four two-term forms. The covered cone's orientation
//! is the sign of `orient(a, b, p, c) = -(a' x b') . p'`; where single precision cannot tell
//! that sign (the edge's line passes within rounding of the line `p c`), it is taken from the
//! double-precision [`CentredEdge`]. Two edges that share an end point evaluate the same sector
//! form for it (same prepared vector, same `p'`), so the sectors of a silhouette chain tile the
//! light without gap or overlap whatever the rounding. Agreement with the 3D form of
//! [`EdgeTest`] up to rounding at ties is tested below.

use glam::{DVec3, Vec2, Vec3, Vec4};

use crate::stages::edges::SceneEdge;

/// Relative error bound of the orientation `(a' x b') . p'` in single precision, against
/// `|a' x b'| . |p'|` (componentwise absolute values): the rounding of the prepared vector and
/// of three products and two sums is below `1e-6` of it.
const ORIENT_BOUND: f32 = 1e-5;

/// One silhouette edge prepared for the light-plane test, so that the test's forms come out of
/// two small matrix-vector products with `p'` (no lane shuffles):
/// `cx = s (p' . [-a'xu, b'xu, 0, exu] + [0, 0, w1.u, -w1.u])`, the same with `v` for `cy`, and
/// `k2 = s (a'xb') . p'`, with `s` the cone's orientation.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PlanarEdge {
    /// The x, y and z rows of the `cx` matrix, then of the `cy` matrix.
    rows: [[f32; 4]; 6],
    /// The constant parts of `cx` and `cy`.
    kx: [f32; 4],
    ky: [f32; 4],
    /// `a' x b'` and its length.
    m: [f32; 4],
}

impl PlanarEdge {
    /// Edge `e` around the light centre `c` with in-plane axes `u`, `v`.
    pub fn new(e: &SceneEdge, c: DVec3, u: DVec3, v: DVec3) -> Self {
        let (a, b) = (e.a - c, e.b - c);
        let d = b - a;
        let m = a.cross(b);
        let (w1u, w1v) = (m.dot(u) as f32, m.dot(v) as f32);
        let cols =
            |w: DVec3| [-a.cross(w), b.cross(w), DVec3::ZERO, d.cross(w)].map(|x| x.as_vec3());
        let (cu, cv) = (cols(u), cols(v));
        let row = |c: &[Vec3; 4], k: usize| -> [f32; 4] { std::array::from_fn(|j| c[j][k]) };
        Self {
            rows: [
                row(&cu, 0),
                row(&cu, 1),
                row(&cu, 2),
                row(&cv, 0),
                row(&cv, 1),
                row(&cv, 2),
            ],
            kx: [0.0, 0.0, w1u, -w1u],
            ky: [0.0, 0.0, w1v, -w1v],
            m: [m.x as f32, m.y as f32, m.z as f32, m.length() as f32],
        }
    }

    /// The test from the centred view sample `p` (`p_norm` at least its length), `None` on the
    /// tie of [`EdgeTest::new`](crate::stages::coverage::EdgeTest) (the edge's line meets the line
    /// `p c`). `exact` gives the orientation (`Some(orient(a, b, p, c) > 0)`, `None` on the
    /// tie) when single precision cannot tell it.
    #[inline(always)]
    pub fn test(
        &self,
        p: Vec3,
        p_norm: f32,
        exact: impl FnOnce() -> Option<bool>,
    ) -> Option<PlanarTest> {
        let mp = self.m[0] * p.x + self.m[1] * p.y + self.m[2] * p.z;
        // The cone's orientation: `orient(a, b, p, c) = -mp` positive gives sign +1.
        let positive = if mp.abs() > ORIENT_BOUND * self.m[3] * p_norm {
            mp < 0.0
        } else {
            exact()?
        };
        let s = Vec4::splat(if positive { 1.0 } else { -1.0 });
        let (px, py, pz) = (Vec4::splat(p.x), Vec4::splat(p.y), Vec4::splat(p.z));
        let r = |i: usize| Vec4::from(self.rows[i]);
        let cx = (px * r(0) + py * r(1) + pz * r(2) + Vec4::from(self.kx)) * s;
        let cy = (px * r(3) + py * r(4) + pz * r(5) + Vec4::from(self.ky)) * s;
        Some(PlanarTest {
            cx: cx.to_array(),
            cy: cy.to_array(),
            k2: if positive { mp } else { -mp },
            k: 0,
        })
    }
}

/// The covered-sample test of one (pixel, edge) pair in the light plane: sample `s` (in-plane
/// coordinates around the centre) is covered when `a . s > 0`, `b . s < 0`, `w1 . s > 0` and
/// `h2 . s + k2 > 0`, stored as the four forms `cx s_x + cy s_y + c0`, all positive where
/// covered.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PlanarTest {
    /// `(a.x, -b.x, w1.x, h2.x)` (arrays rather than vectors: without their 16-byte alignment a
    /// test takes 40 bytes, not 48, and a pixel's list of them is read once after being written
    /// once).
    cx: [f32; 4],
    /// `(a.y, -b.y, w1.y, h2.y)`.
    cy: [f32; 4],
    /// The constant of the last form.
    k2: f32,
    /// The pair's weight `k_e(p)` (it fills the padding after `k2`, so a pixel's pairs need no
    /// second list).
    pub k: i32,
}

impl PlanarTest {
    /// A placeholder that covers nothing.
    pub const NONE: Self = Self {
        cx: [0.0; 4],
        cy: [0.0; 4],
        k2: 0.0,
        k: 0,
    };

    /// The sector's sides: the covered cone is `a . s > 0`, `b . s < 0`.
    #[cfg(test)]
    pub fn sector(&self) -> (glam::Vec2, glam::Vec2) {
        (
            glam::Vec2::new(self.cx[0], self.cy[0]),
            glam::Vec2::new(-self.cx[1], -self.cy[1]),
        )
    }

    /// The forms' coefficients of `s_x` and of `s_y`: `(a, -b, w1, h2)` component by
    /// component.
    #[inline]
    pub fn coefficients(&self) -> (Vec4, Vec4) {
        (Vec4::from_array(self.cx), Vec4::from_array(self.cy))
    }

    /// The samples of `subset` (one word: `xs`, `ys` hold its 64 samples) the edge covers.
    #[inline(always)]
    pub fn covered_of(&self, xs: &[f32; 64], ys: &[f32; 64], subset: u64) -> u64 {
        let c0 = Vec4::new(0.0, 0.0, 0.0, self.k2);
        let (cx, cy) = self.coefficients();
        let (mut todo, mut out) = (subset, 0u64);
        while todo != 0 {
            let k = todo.trailing_zeros() as usize & 63;
            todo &= todo - 1;
            let v = cx * xs[k] + cy * ys[k] + c0;
            // Without a branch: a candidate is covered about as often as not.
            out |= u64::from(v.cmpgt(Vec4::ZERO).bitmask() == 0xf) << k;
        }
        out
    }

    /// Whether the sample at in-plane coordinates `(x, y)` is covered.
    #[inline(always)]
    pub fn covers(&self, x: f32, y: f32) -> bool {
        let (cx, cy) = self.coefficients();
        (cx * x + cy * y + Vec4::new(0.0, 0.0, 0.0, self.k2))
            .cmpgt(Vec4::ZERO)
            .all()
    }

    /// The samples of the word `subset` (word `w` of `samples`) the edge covers.
    #[inline]
    pub fn covered_in(&self, samples: &PlanarSamples, w: usize, subset: u64) -> u64 {
        let (mut todo, mut out) = (subset, 0u64);
        while todo != 0 {
            let k = todo.trailing_zeros() as usize;
            todo &= todo - 1;
            let i = w * 64 + k;
            if self.covers(samples.x[i], samples.y[i]) {
                out |= 1 << k;
            }
        }
        out
    }

    /// The samples of word `w` of `samples` the edge covers (every sample tested, four at a
    /// time).
    pub fn covered_word(&self, samples: &PlanarSamples, w: usize) -> u64 {
        let base = w * 64;
        let (xs, _) = samples.x[base..base + 64].as_chunks::<4>();
        let (ys, _) = samples.y[base..base + 64].as_chunks::<4>();
        let f = |c: [f32; 4]| -> [Vec4; 4] { c.map(Vec4::splat) };
        let (cx, cy, c0) = (f(self.cx), f(self.cy), self.k2);
        let mut bits = 0u64;
        for (q, (x, y)) in xs.iter().zip(ys).enumerate() {
            let (x, y) = (Vec4::from(*x), Vec4::from(*y));
            let va = cx[0] * x + cy[0] * y;
            let vb = cx[1] * x + cy[1] * y;
            let w1 = cx[2] * x + cy[2] * y;
            let w2 = cx[3] * x + cy[3] * y + Vec4::splat(c0);
            let all = va.cmpgt(Vec4::ZERO)
                & vb.cmpgt(Vec4::ZERO)
                & w1.cmpgt(Vec4::ZERO)
                & w2.cmpgt(Vec4::ZERO);
            bits |= u64::from(all.bitmask()) << (4 * q);
        }
        bits
    }
}

/// A pixel's light samples in the light plane around the centre, structure of arrays, padded to
/// whole 64-sample words.
#[derive(Debug, Clone, Default)]
pub(crate) struct PlanarSamples {
    pub x: Vec<f32>,
    pub y: Vec<f32>,
}

impl PlanarSamples {
    /// The first `64 W` samples' in-plane `x`, a word at a time.
    #[inline]
    pub fn words_x<const W: usize>(&self) -> &[[f32; 64]; W] {
        Self::words(&self.x)
    }

    /// The first `64 W` samples' in-plane `y`, a word at a time.
    #[inline]
    pub fn words_y<const W: usize>(&self) -> &[[f32; 64]; W] {
        Self::words(&self.y)
    }

    #[inline(always)]
    fn words<const W: usize>(v: &[f32]) -> &[[f32; 64]; W] {
        let (words, _) = v.as_chunks::<64>();
        words[..W]
            .try_into()
            .expect("samples are padded to whole words")
    }

    /// Sets the samples `positions` (world space) around `c` on axes `u`, `v`.
    pub fn set(&mut self, positions: &[Vec3], c: Vec3, u: Vec3, v: Vec3) {
        self.clear_to(positions.len());
        for (k, s) in positions.iter().enumerate() {
            let d = *s - c;
            self.x[k] = d.dot(u);
            self.y[k] = d.dot(v);
        }
    }

    /// Sets the samples of a rectangle light straight from its unit samples, without world
    /// positions: the light's point of `u` is `c + a half_u + b half_v` with `a = 2 u.x - 1`,
    /// `b = 2 u.y - 1`, so its coordinates on the light plane's axes are the affine map
    /// `x = a map.x + b map.y`, `y = a map.z + b map.w`, where `map` holds the half sides' own
    /// coordinates ([`RectMap`]). The same points as [`PlanarSamples::set`] on the light's
    /// positions, up to the rounding that those positions add.
    pub fn set_rect(&mut self, units: &[Vec2], map: &RectMap) {
        self.clear_to(units.len());
        let [hux, hvx, huy, hvy] = map.0;
        for ((x, y), u) in self.x.iter_mut().zip(self.y.iter_mut()).zip(units) {
            let (a, b) = (2.0 * u.x - 1.0, 2.0 * u.y - 1.0);
            *x = a * hux + b * hvx;
            *y = a * huy + b * hvy;
        }
    }

    /// `n` samples' room, padded with zeros to whole words.
    fn clear_to(&mut self, n: usize) {
        let padded = n.div_ceil(64) * 64;
        for w in [&mut self.x, &mut self.y] {
            w.clear();
            w.resize(padded, 0.0);
        }
    }
}

/// A rectangle light's half sides in its light plane's coordinates: `[half_u . u, half_v . u,
/// half_u . v, half_v . v]` for the plane's axes `u`, `v` (taken in double precision).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RectMap(pub [f32; 4]);

impl RectMap {
    /// The map of a rectangle with half sides `half_u`, `half_v` on the plane axes `u`, `v`.
    pub fn new(half_u: Vec3, half_v: Vec3, u: Vec3, v: Vec3) -> Self {
        let (hu, hv, u, v) = (
            half_u.as_dvec3(),
            half_v.as_dvec3(),
            u.as_dvec3(),
            v.as_dvec3(),
        );
        Self([hu.dot(u), hv.dot(u), hu.dot(v), hv.dot(v)].map(|x| x as f32))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::centred::CentredEdge;
    use crate::stages::coverage::EdgeTest;
    use shadow_core::sampling::{hash_words, unit_float};

    fn edge(a: DVec3, b: DVec3) -> SceneEdge {
        SceneEdge::boundary(a, b, (a + b) * 0.5 + DVec3::new(0.0, 0.0, 0.1))
    }

    /// A rectangle light's light-plane coordinates straight from its unit samples
    /// ([`PlanarSamples::set_rect`]) equal those of its world positions
    /// ([`PlanarSamples::set`]) up to the positions' rounding: tilted, far from the origin too,
    /// with sides orthogonal only within the light's tolerance, the normal either way round.
    #[test]
    fn rectangle_coordinates_from_unit_samples_equal_those_of_positions() {
        use crate::stages::light_shape::LightShape;
        use shadow_core::light::{AreaLight, RectLight};
        use shadow_core::prelude::Radiance;
        for case in 0..6u64 {
            let r = |i: u64| unit_float(hash_words(&[case, i])) * 2.0 - 1.0;
            let offset = [0.0, 50.0, 1e3][case as usize % 3];
            let center = Vec3::new(r(0), 3.0 + r(1), r(2)) + Vec3::splat(offset);
            let half_u = Vec3::new(0.5 + 0.3 * r(3), 0.2 * r(4), 0.2 * r(5));
            let mut half_v = half_u.cross(Vec3::new(r(6), 1.0, r(7))).normalize() * 0.4;
            half_v += half_u.normalize() * (0.4 * 5e-5);
            if case % 2 == 1 {
                half_v = -half_v;
            }
            let radiance = Radiance::constant(Vec3::ONE).unwrap();
            let light = RectLight::new(center, half_u, half_v, radiance).unwrap();
            let shape = LightShape::new(&light, "test").unwrap();
            let pl = shape.plane.as_ref().unwrap();
            let units: Vec<Vec2> = (0..100u64)
                .map(|k| {
                    let h = hash_words(&[case, 100 + k]);
                    Vec2::new(unit_float(h), unit_float(h << 24))
                })
                .collect();
            let mut positions = Vec::new();
            light.positions_into(&units, &mut positions);
            let (mut a, mut b) = (PlanarSamples::default(), PlanarSamples::default());
            a.set(&positions, shape.center, pl.u, pl.v);
            b.set_rect(&units, &RectMap::new(half_u, half_v, pl.u, pl.v));
            assert_eq!((a.x.len(), b.x.len()), (128, 128));
            let tol = 4.0 * f32::EPSILON * (center.length() + 1.0);
            for k in 0..units.len() {
                let (dx, dy) = ((a.x[k] - b.x[k]).abs(), (a.y[k] - b.y[k]).abs());
                assert!(
                    dx <= tol && dy <= tol,
                    "case {case} sample {k}: {dx} {dy} > {tol}"
                );
            }
            // The padding is zero either way.
            assert!(b.x[units.len()..].iter().all(|x| *x == 0.0));
        }
    }

    /// The light-plane test covers the samples the 3D test covers, up to rounding at ties, far
    /// from the origin too; and it gives the same sector sides to two edges sharing an end.
    #[test]
    fn light_plane_test_equals_the_3d_test() {
        let (mut compared, mut differ, mut covered) = (0u64, 0u64, 0u64);
        for k in 0..4000u64 {
            let r = |i: u64| unit_float(hash_words(&[k, i])) as f64 * 2.0 - 1.0;
            let offset = DVec3::splat([0.0, 1e3, 1e5][k as usize % 3]);
            // A light tilted by case, its centre, axes and a half size.
            let n = DVec3::new(r(20) * 0.3, -1.0, r(21) * 0.3).normalize();
            let u = n.any_orthonormal_vector();
            let v = n.cross(u);
            let c = offset + DVec3::new(r(0), 3.0 + r(1), r(2));
            let p = offset + DVec3::new(r(3) * 2.0, 0.1 * r(4), r(5) * 2.0);
            let mid = offset + DVec3::new(r(6), 1.5 + r(7), r(8));
            let dir = DVec3::new(r(9), r(10) * 0.3, r(11)) * 0.3;
            let (a, b) = (mid - dir, mid + dir);
            let e = edge(a, b);
            let centred = CentredEdge::new(&e, c);
            let planar = PlanarEdge::new(&e, c, u, v);
            let pc = p - c;
            let (Some(t3), Some(t2)) = (
                EdgeTest::new(p, c, a, b),
                planar.test(pc.as_vec3(), pc.length() as f32, || centred.orientation(pc)),
            ) else {
                continue;
            };
            for j in 0..64 {
                let (x, y) = (r(30 + 2 * j) * 0.8, r(31 + 2 * j) * 0.8);
                let s = c + u * x + v * y;
                let want = t3.covers_offset((s - p).as_vec3());
                let got = t2.covers(x as f32, y as f32);
                compared += 1;
                covered += u64::from(want);
                differ += u64::from(want != got);
            }
            // A neighbouring edge from b: its sector side at b is the same form.
            let e2 = edge(b, b + DVec3::new(r(12), 0.1 * r(13), r(14)) * 0.3);
            let ce2 = CentredEdge::new(&e2, c);
            let t22 = PlanarEdge::new(&e2, c, u, v)
                .test(pc.as_vec3(), pc.length() as f32, || ce2.orientation(pc));
            if let Some(t22) = t22 {
                let (a2, _) = t22.sector();
                let (_, b1) = t2.sector();
                assert!(
                    a2 == b1 || a2 == -b1,
                    "case {k}: shared end point, different sector sides"
                );
            }
            // Every sample of a word at once gives the same answer as one by one.
            let mut samples = PlanarSamples::default();
            let pos: Vec<Vec3> = (0..64)
                .map(|j| (c + u * r(30 + 2 * j) * 0.8 + v * r(31 + 2 * j) * 0.8).as_vec3())
                .collect();
            samples.set(&pos, c.as_vec3(), u.as_vec3(), v.as_vec3());
            assert_eq!(
                t2.covered_word(&samples, 0),
                t2.covered_in(&samples, 0, u64::MAX),
                "case {k}"
            );
        }
        assert!(covered > 2000, "{covered}");
        assert!(differ * 100_000 <= compared, "{differ} of {compared}");
        eprintln!("{differ} of {compared}");
    }
}
