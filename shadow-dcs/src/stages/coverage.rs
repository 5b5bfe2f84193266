//! The light samples an edge covers from a view sample (DCS section 4.2, Algorithm 1 lines 4-7;
//! Fig. 2): the samples `s` for which the path from the light centre `c` to `s` crosses the
//! edge's projection from `p`, i.e. the samples inside the angular sector of the projected end
//! points and beyond the projected segment.
//!
//! The test is done in 3D, which needs no projection plane and so serves planar and sphere
//! lights alike, and is exact where projection would have to clip: the segment `a b` crosses
//! the triangle `(p, c, s)` (swept by the segment from `p` as its end moves from `c` to `s`).
//! With `p`, `c`, `a`, `b` fixed, each of the four orientation tests of a segment-triangle test
//! is a linear function of `s`, set up once per (pixel, edge); each sample then costs four dot
//! products.

#[cfg(test)]
use glam::DVec3;
use glam::Vec3;

/// A pixel's light samples relative to its view sample `p`, structure of arrays, padded to
/// whole 64-sample words so the per-edge loop has no tail and vectorises.
#[derive(Debug, Clone, Default)]
pub(crate) struct RelativeSamples {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
}

impl RelativeSamples {
    /// Sets the samples `positions - p`.
    pub fn set(&mut self, p: Vec3, positions: &[Vec3]) {
        let padded = positions.len().div_ceil(64) * 64;
        for v in [&mut self.x, &mut self.y, &mut self.z] {
            v.clear();
            v.resize(padded, 0.0);
        }
        for (k, s) in positions.iter().enumerate() {
            let d = *s - p;
            self.x[k] = d.x;
            self.y[k] = d.y;
            self.z[k] = d.z;
        }
    }
}

/// A planar light's convex polygon relative to a view sample `p`, with the largest L1 norm of
/// its vertices (which bounds the Euclidean distances from above: a looser, cheaper slack for
/// [`EdgeTest::may_cover`]).
#[derive(Debug, Clone, Default)]
pub(crate) struct RelativePolygon {
    points: Vec<Vec3>,
    reach: f32,
}

impl RelativePolygon {
    /// Sets the polygon `vertices - x`.
    pub fn set(&mut self, vertices: &[Vec3], x: Vec3) {
        self.points.clear();
        self.points.extend(vertices.iter().map(|v| *v - x));
        self.reach = self
            .points
            .iter()
            .map(|v| v.abs().element_sum())
            .fold(0.0f32, f32::max);
    }
}

/// The four linear tests of one (view sample, edge) pair.
///
/// The samples an edge covers lie in one cone of the double cone between the planes
/// `(p, c, a)` and `(p, c, b)`: where the edge crosses the triangle `(p, c, s)` at
/// `x = a + t (b - a)`, `orient(p, c, s, a)` has the sign of `orient(p, c, x, a) =
/// t det(a - p, c - p, b - p)` and `orient(p, c, s, b)` the opposite one (the sample lies on the
/// ray from `c` through the projection of `x`). With `det(a - p, c - p, b - p) =
/// -orient(a, b, p, c)`, `ga` and `gb` are oriented so that the covered cone is `ga . d > 0`,
/// `gb . d < 0`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct EdgeTest {
    /// `+-orient(p, c, s, a) = ga . (s - p)`.
    ga: Vec3,
    /// `+-orient(p, c, s, b) = gb . (s - p)` (the same sign as `ga`).
    gb: Vec3,
    /// `+-orient(a, b, c, s) = h1 . (s - p) + k1`, the sign chosen so that the line `a b`
    /// passes inside the triangle when this and the next are positive.
    h1: Vec3,
    k1: f32,
    /// `+-orient(a, b, s, p) = h2 . (s - p)` (no constant: it vanishes at `s = p`).
    h2: Vec3,
}

impl EdgeTest {
    /// The test of edge `a b` seen from `p` with the light centre `c`; `None` when the line of
    /// the edge meets the line `p c` (no sample can be covered robustly). The technique builds
    /// the same test from light-centred data ([`crate::accel::centred::CentredEdge`]); this direct form
    /// is what tests check it against.
    #[cfg(test)]
    pub fn new(p: DVec3, c: DVec3, a: DVec3, b: DVec3) -> Option<Self> {
        let ga = (a - p).cross(c - p);
        let gb = (b - p).cross(c - p);
        let h1 = (b - a).cross(c - a);
        let h2 = (p - a).cross(b - a);
        let k0 = (b - a).cross(p - a).dot(c - a);
        if k0 == 0.0 || !k0.is_finite() {
            return None;
        }
        // orient(a, b, c, s) = h1 . (s - a) = h1 . (s - p) + h1 . (p - a).
        let k1 = h1.dot(p - a);
        Some(Self::from_parts(
            ga.as_vec3(),
            gb.as_vec3(),
            h2.as_vec3(),
            h1.as_vec3(),
            k1 as f32,
            k0 > 0.0,
        ))
    }

    /// The test from its parts: `ga`, `gb`, `h2 = (p - a) x (b - a)`, `h1 = (b - a) x (c - a)`,
    /// `k1 = h1 . (p - a)`, and the sign of `k0 = orient(a, b, p, c)`.
    #[inline]
    pub(crate) fn from_parts(
        ga: Vec3,
        gb: Vec3,
        h2: Vec3,
        h1: Vec3,
        k1: f32,
        positive: bool,
    ) -> Self {
        let sign = if positive { 1.0 } else { -1.0 };
        Self {
            ga: ga * -sign,
            gb: gb * -sign,
            h1: h1 * sign,
            k1: k1 * sign,
            h2: h2 * sign,
        }
    }

    /// `+-orient(p, c, s, a)` and `+-orient(p, c, s, b)` as linear functions of `s - p`: their
    /// zero sets are the planes through `p`, `c` and an end point, which bound the angular
    /// sector (used by [`crate::accel::angular`]); covered samples have the first positive and the
    /// second negative.
    pub fn sector_normals(&self) -> (Vec3, Vec3) {
        (self.ga, self.gb)
    }

    /// Whether the edge may cover any point of a convex planar light holding the centre `c`,
    /// given the light's convex polygon relative to `p` (counter-clockwise or clockwise):
    /// `false` proves that no light sample is covered, so the pair need not be kept.
    ///
    /// The covered region is `cone & w1 > 0 & w2 > 0`, with `w2 < 0` at `c`. If a light
    /// point `q` is covered, the segment from `c` to `q` stays in the light, in the open
    /// sector (a cone with apex `c`) and in `w1 > 0` (`w1(c) = 0`), and crosses `w2 = 0`: so
    /// the chord `w2 = 0` of the light polygon meets the sector and `w1 > 0`. The chord is
    /// found on the polygon's boundary and the three linear functions clipped along it, with
    /// a relative slack of `1e-5` so that only clear misses are rejected (ties are kept).
    pub fn may_cover(&self, light: &RelativePolygon) -> bool {
        let (polygon, reach) = (&light.points[..], light.reach);
        let n = polygon.len();
        if n == 0 {
            return true;
        }
        let tol = |g: Vec3| 1e-5 * g.abs().element_sum() * reach;
        let t2 = tol(self.h2);
        let mut ends = [Vec3::ZERO; 2];
        let mut found = 0;
        let mut any_beyond = false;
        let mut prev = polygon[n - 1];
        let mut fp = self.h2.dot(prev);
        for &x in polygon {
            let fx = self.h2.dot(x);
            any_beyond |= fx > -t2;
            if (fp > 0.0) != (fx > 0.0) {
                if found == 2 {
                    return true;
                }
                ends[found] = prev + (x - prev) * (fp / (fp - fx));
                found += 1;
            }
            prev = x;
            fp = fx;
        }
        if !any_beyond {
            return false;
        }
        if found != 2 || !ends[0].is_finite() || !ends[1].is_finite() {
            return true;
        }
        // Along the chord e0 + t (e1 - e0), t in [0, 1].
        let [e0, e1] = ends;
        let span = |g: Vec3, k: f32| (g.dot(e0) + k, g.dot(e1) + k);
        let (w0, w1) = span(self.h1, self.k1);
        let (a0, a1) = span(self.ga, 0.0);
        let (b0, b1) = span(self.gb, 0.0);
        if !(w0 + w1 + a0 + a1 + b0 + b1).is_finite() {
            return true;
        }
        let (tw, ta, tb) = (tol(self.h1), tol(self.ga), tol(self.gb));
        let whole = clip_unit((0.0, 1.0), w0 + tw, w1 + tw);
        let r = clip_unit(whole, a0 + ta, a1 + ta);
        let r = clip_unit(r, tb - b0, tb - b1);
        r.0 <= r.1
    }

    /// True when the edge crosses the triangle `(p, c, p + d)`, `d` a sample relative to `p`.
    #[inline(always)]
    fn covers_relative(&self, x: f32, y: f32, z: f32) -> bool {
        let va = self.ga.x * x + self.ga.y * y + self.ga.z * z;
        let vb = self.gb.x * x + self.gb.y * y + self.gb.z * z;
        let w1 = self.h1.x * x + self.h1.y * y + self.h1.z * z + self.k1;
        let w2 = self.h2.x * x + self.h2.y * y + self.h2.z * z;
        (va > 0.0) & (vb < 0.0) & (w1 > 0.0) & (w2 > 0.0)
    }

    /// True when the edge crosses the triangle `(p, c, s)`.
    #[cfg(test)]
    pub fn covers(&self, p: Vec3, s: Vec3) -> bool {
        let d = s - p;
        self.covers_relative(d.x, d.y, d.z)
    }

    /// True when the edge crosses the triangle `(p, c, p + d)`.
    #[cfg(test)]
    pub fn covers_offset(&self, d: Vec3) -> bool {
        self.covers_relative(d.x, d.y, d.z)
    }

    /// Adds to `mask` the samples of `subset` the edge covers.
    pub fn add_covered(&self, samples: &RelativeSamples, subset: &[u64], mask: &mut [u64]) {
        for (w, (word, sub)) in mask.iter_mut().zip(subset).enumerate() {
            let mut todo = *sub;
            while todo != 0 {
                let k = todo.trailing_zeros() as usize;
                todo &= todo - 1;
                let i = w * 64 + k;
                if self.covers_relative(samples.x[i], samples.y[i], samples.z[i]) {
                    *word |= 1 << k;
                }
            }
        }
    }

    /// Sets in `mask` the bits of the samples the edge covers, restricted to `allowed`;
    /// returns whether any is set.
    pub fn mask(&self, samples: &RelativeSamples, allowed: &[u64], mask: &mut [u64]) -> bool {
        let mut any = 0u64;
        for (w, word) in mask.iter_mut().enumerate() {
            let base = w * 64;
            let (xs, ys, zs) = (
                &samples.x[base..base + 64],
                &samples.y[base..base + 64],
                &samples.z[base..base + 64],
            );
            let mut hits = [false; 64];
            for j in 0..64 {
                hits[j] = self.covers_relative(xs[j], ys[j], zs[j]);
            }
            let mut bits = 0u64;
            for (j, h) in hits.iter().enumerate() {
                bits |= (*h as u64) << j;
            }
            *word = bits & allowed[w];
            any |= *word;
        }
        any != 0
    }
}

/// The part of the interval `r` (within `[0, 1]`) where the linear function with values `g0`
/// at 0 and `g1` at 1 is non-negative.
#[inline]
fn clip_unit(r: (f32, f32), g0: f32, g1: f32) -> (f32, f32) {
    match (g0 >= 0.0, g1 >= 0.0) {
        (true, true) => r,
        (false, false) => (1.0, 0.0),
        (in0, _) => {
            let t = g0 / (g0 - g1);
            if in0 {
                (r.0, r.1.min(t))
            } else {
                (r.0.max(t), r.1)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: does segment a b cross triangle p c s (Möller-Trumbore on the segment)?
    fn brute(p: DVec3, c: DVec3, s: DVec3, a: DVec3, b: DVec3) -> bool {
        let d = b - a;
        let (e1, e2) = (c - p, s - p);
        let pv = d.cross(e2);
        let det = e1.dot(pv);
        if det.abs() < 1e-300 {
            return false;
        }
        let tv = a - p;
        let u = tv.dot(pv) / det;
        let qv = tv.cross(e1);
        let v = d.dot(qv) / det;
        let t = e2.dot(qv) / det;
        u > 0.0 && v > 0.0 && u + v < 1.0 && t > 0.0 && t < 1.0
    }

    #[test]
    fn covered_samples_match_brute_force_point_in_region() {
        // One edge above a receiver, a 1 x 1 light at height 4; a 64 x 64 grid of samples.
        let p = DVec3::new(0.1, 0.0, -0.2);
        let c = DVec3::new(0.0, 4.0, 0.0);
        let (a, b) = (DVec3::new(-0.3, 1.5, 0.05), DVec3::new(0.4, 1.7, -0.1));
        let t = EdgeTest::new(p, c, a, b).unwrap();
        let mut agree = 0;
        let mut covered = 0;
        let n = 64;
        for i in 0..n {
            for j in 0..n {
                let s = DVec3::new(
                    -0.5 + (i as f64 + 0.5) / n as f64,
                    4.0,
                    -0.5 + (j as f64 + 0.5) / n as f64,
                );
                let want = brute(p, c, s, a, b);
                let got = t.covers(p.as_vec3(), s.as_vec3());
                covered += want as u32;
                agree += (want == got) as u32;
            }
        }
        assert!(covered > 200 && covered < 4096 - 200, "{covered}");
        assert_eq!(agree, n * n);
    }
}

#[cfg(test)]
mod light_overlap_tests {
    use super::*;
    use shadow_core::sampling::{hash_words, unit_float};

    /// `may_cover` never rejects an edge that covers a light point (a dense grid over a
    /// rectangle light, edges from random view samples, some far from the origin), and it
    /// rejects most edges that cover none.
    #[test]
    fn light_overlap_test_is_conservative_and_useful() {
        let (mut covering, mut rejected_empty, mut empty) = (0, 0, 0);
        for k in 0..4000u64 {
            let r = |i: u64| unit_float(hash_words(&[k, i])) as f64 * 2.0 - 1.0;
            let offset = DVec3::splat([0.0, 1e4][k as usize % 2]);
            let c = offset + DVec3::new(0.0, 3.0, 0.0);
            let (hu, hv) = (0.3 + 0.2 * r(0).abs(), 0.2 + 0.3 * r(1).abs());
            let corners = [(-hu, -hv), (hu, -hv), (hu, hv), (-hu, hv)]
                .map(|(x, z)| c + DVec3::new(x, 0.0, z));
            let p = offset + DVec3::new(r(2) * 2.0, 0.0, r(3) * 2.0);
            let mid = offset + DVec3::new(r(4), 1.0 + r(5).abs(), r(6));
            let dir = DVec3::new(r(7), r(8) * 0.2, r(9)) * 0.2 * r(10).abs();
            let (a, b) = (mid - dir, mid + dir);
            let Some(t) = EdgeTest::new(p, c, a, b) else {
                continue;
            };
            let mut polygon = RelativePolygon::default();
            polygon.set(&corners.map(|v| (v - p).as_vec3()), Vec3::ZERO);
            let n = 48;
            let covers = (0..n * n).any(|j| {
                let s = c + DVec3::new(
                    hu * (2.0 * ((j % n) as f64 + 0.5) / n as f64 - 1.0),
                    0.0,
                    hv * (2.0 * ((j / n) as f64 + 0.5) / n as f64 - 1.0),
                );
                t.covers_offset((s - p).as_vec3())
            });
            let kept = t.may_cover(&polygon);
            if covers {
                covering += 1;
                assert!(kept, "case {k}: a covering edge was rejected");
            } else {
                empty += 1;
                rejected_empty += usize::from(!kept);
            }
        }
        assert!(covering > 100, "{covering}");
        // Grid points miss thin slivers, so a kept "empty" edge may still cover the light.
        assert!(
            rejected_empty * 10 > empty * 8,
            "{rejected_empty} of {empty}"
        );
    }
}
