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

use glam::{DVec3, Vec3};

/// The four linear tests of one (view sample, edge) pair.
#[derive(Debug, Clone, Copy)]
pub(crate) struct EdgeTest {
    p: Vec3,
    a: Vec3,
    /// `orient(p, c, s, a) = ga . (s - p)`.
    ga: Vec3,
    /// `orient(p, c, s, b) = gb . (s - p)`.
    gb: Vec3,
    /// `orient(a, b, c, s) = h1 . (s - a)`.
    h1: Vec3,
    /// `orient(a, b, s, p) = h2 . (s - a)`.
    h2: Vec3,
    /// Sign of `orient(a, b, p, c)`: the line `a b` passes inside the triangle when all three
    /// edge tests share it.
    positive: bool,
}

impl EdgeTest {
    /// The test of edge `a b` seen from `p` with the light centre `c`; `None` when the line of
    /// the edge meets the line `p c` (no sample can be covered robustly).
    pub fn new(p: DVec3, c: DVec3, a: DVec3, b: DVec3) -> Option<Self> {
        let ga = (a - p).cross(c - p);
        let gb = (b - p).cross(c - p);
        let h1 = (b - a).cross(c - a);
        let h2 = (p - a).cross(b - a);
        let k0 = (b - a).cross(p - a).dot(c - a);
        if k0 == 0.0 || !k0.is_finite() {
            return None;
        }
        Some(Self {
            p: p.as_vec3(),
            a: a.as_vec3(),
            ga: ga.as_vec3(),
            gb: gb.as_vec3(),
            h1: h1.as_vec3(),
            h2: h2.as_vec3(),
            positive: k0 > 0.0,
        })
    }

    /// True when the edge crosses the triangle `(p, c, s)`.
    #[inline]
    pub fn covers(&self, s: Vec3) -> bool {
        let sp = s - self.p;
        let sa = s - self.a;
        let (va, vb) = (self.ga.dot(sp), self.gb.dot(sp));
        if !((va > 0.0 && vb < 0.0) || (va < 0.0 && vb > 0.0)) {
            return false;
        }
        let (w1, w2) = (self.h1.dot(sa), self.h2.dot(sa));
        if self.positive {
            w1 > 0.0 && w2 > 0.0
        } else {
            w1 < 0.0 && w2 < 0.0
        }
    }

    /// Sets in `mask` (cleared first) the bits of the samples in `samples` the edge covers,
    /// restricted to `allowed`.
    pub fn mask(&self, samples: &[Vec3], allowed: &[u64], mask: &mut [u64]) -> bool {
        let mut any = 0u64;
        for (w, word) in mask.iter_mut().enumerate() {
            let mut bits = 0u64;
            let mut todo = allowed[w];
            while todo != 0 {
                let k = todo.trailing_zeros();
                todo &= todo - 1;
                if self.covers(samples[w * 64 + k as usize]) {
                    bits |= 1 << k;
                }
            }
            *word = bits;
            any |= bits;
        }
        any != 0
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
                let got = t.covers(s.as_vec3());
                covered += want as u32;
                agree += (want == got) as u32;
            }
        }
        assert!(covered > 200 && covered < 4096 - 200, "{covered}");
        assert_eq!(agree, n * n);
    }
}
