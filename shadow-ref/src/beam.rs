//! Beam culling for the occlusion segments of one receiver: every segment from a view sample's
//! (offset) origin to a planar light lies inside the pyramid with the origin as apex and the
//! light's bounding rectangle as base. Triangles the pyramid cannot touch cannot block any of
//! those segments, so one traversal of the BVH2 with the pyramid answers a fully lit receiver
//! for all its samples at once, and gives a short candidate list to the others. The per-segment
//! test on the candidates is the same watertight test as the single-ray path, so the answer is
//! identical (a conservative cull, never an approximation).

use glam::{Vec3, Vec3A, Vec4};

use crate::watertight::Triangles4;

/// A pyramid (apex and a base quad), tested conservatively against boxes and triangles.
#[derive(Debug, Clone, Copy)]
pub struct Beam {
    /// Unit normals pointing out of the pyramid, and offsets: outside when `n . x > d + eps`.
    planes: [(Vec3A, f32); 5],
    lo: Vec3A,
    hi: Vec3A,
    eps: f32,
    /// The same planes splatted for four-wide tests: `[nx, ny, nz, |nx|, |ny|, |nz|, d + eps]`.
    wide: [[Vec4; 7]; 5],
}

impl Beam {
    /// The plane-test slack for the pyramid from `apex` to `base`: the rounding of its planes'
    /// normals and offsets, relative to the largest coordinate involved and to the pyramid's
    /// length. It follows the beam, not the scene (a 200 km floor elsewhere must not widen it
    /// past the receivers' ray offsets, issue 51 item 5), and stays below the offset that puts
    /// the apex above its own surface ([`shadow_core::offset::RayOffset`]), so the receiver's
    /// coplanar neighbours are culled. A larger slack would only cost speed: the cull stays
    /// conservative and the candidates get the exact test.
    pub fn rounding_slack(apex: Vec3, base: &[Vec3; 4]) -> f32 {
        let coord = base
            .iter()
            .fold(apex.abs(), |m, q| m.max(q.abs()))
            .max_element();
        let length = base.iter().map(|q| q.distance(apex)).fold(0.0f32, f32::max);
        8.0 * f32::EPSILON * (coord + length)
    }

    /// The pyramid from `apex` to the convex quad `base` (corners in order). `eps` is the
    /// distance slack of every plane test (use a small multiple of the scene's float precision).
    /// `None` when the pyramid is degenerate (apex on the base plane).
    pub fn new(apex: Vec3, base: [Vec3; 4], eps: f32) -> Option<Self> {
        let a = Vec3A::from(apex);
        let q = base.map(Vec3A::from);
        let centroid = (q[0] + q[1] + q[2] + q[3]) * 0.25;
        let mut planes = [(Vec3A::ZERO, 0.0); 5];
        for i in 0..4 {
            let n = (q[i] - a).cross(q[(i + 1) % 4] - a);
            let n = n.try_normalize()?;
            let n = if n.dot(centroid - a) > 0.0 { -n } else { n };
            planes[i] = (n, n.dot(a));
        }
        let n = (q[1] - q[0]).cross(q[3] - q[0]).try_normalize()?;
        let n = if n.dot(a - q[0]) > 0.0 { -n } else { n };
        if n.dot(a - q[0]).abs() <= eps {
            return None;
        }
        planes[4] = (n, n.dot(q[0]));
        let lo = q.iter().fold(a, |m, p| m.min(*p));
        let hi = q.iter().fold(a, |m, p| m.max(*p));
        let wide = planes.map(|(n, d)| {
            let m = n.abs();
            [n.x, n.y, n.z, m.x, m.y, m.z, d + eps].map(Vec4::splat)
        });
        Some(Self {
            planes,
            lo,
            hi,
            eps,
            wide,
        })
    }

    /// [`Beam::box_outside`] for four boxes at once, given as `[min x, min y, min z, max x,
    /// max y, max z]` with one box per lane: bit `i` is set when box `i` is outside. Empty boxes
    /// (min `+inf`, max `-inf`) are outside.
    #[inline]
    pub fn boxes_outside4(&self, b: &[Vec4; 6]) -> u32 {
        let mut out = 0;
        for axis in 0..3 {
            out |= b[axis]
                .cmpgt(Vec4::splat(self.hi[axis] + self.eps))
                .bitmask()
                | b[axis + 3]
                    .cmplt(Vec4::splat(self.lo[axis] - self.eps))
                    .bitmask();
        }
        if out == 0xf {
            return out;
        }
        let half = Vec4::splat(0.5);
        let c = [0, 1, 2].map(|k| half * (b[k] + b[k + 3]));
        let e = [0, 1, 2].map(|k| half * (b[k + 3] - b[k]));
        for p in &self.wide {
            let s =
                p[0] * c[0] + p[1] * c[1] + p[2] * c[2] - (p[3] * e[0] + p[4] * e[1] + p[5] * e[2]);
            out |= s.cmpgt(p[6]).bitmask();
        }
        out
    }

    /// [`Beam::triangle_outside`] for the four lanes of `t`, and the test of each triangle's
    /// bounding box against the pyramid's (a leaf's box may reach the beam while some of its
    /// triangles cannot, like the receiver's own floor below the apex): bit `i` is set when
    /// triangle `i` is outside.
    #[inline]
    pub fn triangles_outside4(&self, t: &Triangles4) -> u32 {
        let mut out = 0;
        for axis in 0..3 {
            let (a, b, c) = (t.v[0][axis], t.v[1][axis], t.v[2][axis]);
            out |= a
                .min(b)
                .min(c)
                .cmpgt(Vec4::splat(self.hi[axis] + self.eps))
                .bitmask()
                | a.max(b)
                    .max(c)
                    .cmplt(Vec4::splat(self.lo[axis] - self.eps))
                    .bitmask();
        }
        for p in &self.wide {
            let side = |k: usize| {
                let v = &t.v[k];
                (p[0] * v[0] + p[1] * v[1] + p[2] * v[2]).cmpgt(p[6])
            };
            out |= (side(0) & side(1) & side(2)).bitmask();
        }
        out
    }

    /// True when the box `[min, max]` lies entirely outside the pyramid.
    #[inline]
    pub fn box_outside(&self, min: Vec3A, max: Vec3A) -> bool {
        if min.cmpgt(self.hi + Vec3A::splat(self.eps)).any()
            || max.cmplt(self.lo - Vec3A::splat(self.eps)).any()
        {
            return true;
        }
        let c = 0.5 * (min + max);
        let e = 0.5 * (max - min);
        self.planes
            .iter()
            .any(|(n, d)| n.dot(c) - n.abs().dot(e) > d + self.eps)
    }

    /// True when the triangle lies entirely outside one face of the pyramid or its bounding
    /// box outside the pyramid's.
    #[inline]
    pub fn triangle_outside(&self, v: &[Vec3A; 3]) -> bool {
        let (lo, hi) = (v[0].min(v[1]).min(v[2]), v[0].max(v[1]).max(v[2]));
        lo.cmpgt(self.hi + Vec3A::splat(self.eps)).any()
            || hi.cmplt(self.lo - Vec3A::splat(self.eps)).any()
            || self
                .planes
                .iter()
                .any(|(n, d)| v.iter().all(|p| n.dot(*p) > d + self.eps))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pyramid_contains_its_segments_and_rejects_outside_boxes() {
        let base = [
            Vec3::new(-1.0, 2.0, -1.0),
            Vec3::new(1.0, 2.0, -1.0),
            Vec3::new(1.0, 2.0, 1.0),
            Vec3::new(-1.0, 2.0, 1.0),
        ];
        let beam = Beam::new(Vec3::ZERO, base, 1e-6).unwrap();
        // A tiny box around a point on a segment from the apex to the base is never outside.
        for k in 0..=10 {
            let t = k as f32 / 10.0;
            for corner in base {
                let p = Vec3A::from(corner * t);
                assert!(!beam.box_outside(p - Vec3A::splat(1e-4), p + Vec3A::splat(1e-4)));
            }
        }
        assert!(beam.box_outside(Vec3A::new(3.0, 0.5, 0.0), Vec3A::new(4.0, 1.0, 1.0)));
        assert!(beam.box_outside(Vec3A::new(-0.5, 2.5, -0.5), Vec3A::new(0.5, 3.0, 0.5)));
        assert!(beam.box_outside(Vec3A::new(-0.5, -1.0, -0.5), Vec3A::new(0.5, -0.5, 0.5)));
        assert!(!beam.box_outside(Vec3A::new(-0.1, 0.9, -0.1), Vec3A::new(0.1, 1.1, 0.1)));
        let inside = [
            Vec3A::new(0.0, 1.0, 0.0),
            Vec3A::new(0.2, 1.0, 0.0),
            Vec3A::new(0.0, 1.0, 0.2),
        ];
        assert!(!beam.triangle_outside(&inside));
        let outside = [
            Vec3A::new(2.0, 1.0, 0.0),
            Vec3A::new(2.2, 1.0, 0.0),
            Vec3A::new(2.0, 1.0, 0.2),
        ];
        assert!(beam.triangle_outside(&outside));
        assert!(Beam::new(Vec3::new(0.0, 2.0, 0.0), base, 1e-6).is_none());
    }

    #[test]
    fn four_wide_tests_equal_the_scalar_tests() {
        let base = [
            Vec3::new(-1.0, 2.0, -0.5),
            Vec3::new(1.0, 2.0, -0.5),
            Vec3::new(1.0, 2.2, 0.5),
            Vec3::new(-1.0, 2.2, 0.5),
        ];
        let beam = Beam::new(Vec3::new(0.1, 0.0, 0.2), base, 1e-6).unwrap();
        let mut st = 11u64;
        let mut r = || {
            st = st
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((st >> 40) as f32) / (1u64 << 24) as f32 * 4.0 - 2.0
        };
        let (mut inside, mut outside) = (0, 0);
        for _ in 0..2000 {
            let boxes: Vec<(Vec3A, Vec3A)> = (0..4)
                .map(|_| {
                    let c = Vec3A::new(r(), r() + 1.0, r());
                    let e = Vec3A::new(r().abs(), r().abs(), r().abs()) * 0.2;
                    (c - e, c + e)
                })
                .collect();
            let mut b = [Vec4::ZERO; 6];
            for (lane, (lo, hi)) in boxes.iter().enumerate() {
                for axis in 0..3 {
                    b[axis][lane] = lo[axis];
                    b[axis + 3][lane] = hi[axis];
                }
            }
            let wide = beam.boxes_outside4(&b);
            let tris: Vec<[Vec3A; 3]> = boxes
                .iter()
                .map(|(lo, hi)| [*lo, *hi, (*lo + *hi) * 0.5 + Vec3A::X * 0.1])
                .collect();
            let wide_t = beam.triangles_outside4(&Triangles4::pack(&tris));
            for lane in 0..4 {
                let scalar = beam.box_outside(boxes[lane].0, boxes[lane].1);
                assert_eq!(wide & (1 << lane) != 0, scalar);
                assert_eq!(
                    wide_t & (1 << lane) != 0,
                    beam.triangle_outside(&tris[lane])
                );
                if scalar {
                    outside += 1;
                } else {
                    inside += 1;
                }
            }
        }
        assert!(inside > 500 && outside > 500, "{inside} {outside}");
        // Empty boxes (min +inf, max -inf) are outside.
        let inf = Vec4::splat(f32::INFINITY);
        assert_eq!(beam.boxes_outside4(&[inf, inf, inf, -inf, -inf, -inf]), 0xf);
    }
}
