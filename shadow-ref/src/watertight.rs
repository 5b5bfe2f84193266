//! The watertight ray-triangle test of Woop, Benthin and Wald, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1), 2013: the ray is sheared so that it runs along +z from the origin;
//! the 2D edge functions of the sheared triangle are evaluated exactly as in the paper, with the
//! f64 fallback when one is zero. A ray through an edge or vertex shared by two triangles hits
//! at least one of them: no leak through closed meshes.

use glam::{DVec3, Mat3A, Vec3A};

/// Per-ray constants of the test (section 3 of the paper). The permutation (`kx, ky, kz`) and
/// the shear are folded into one matrix, so each vertex is transformed with one SIMD
/// matrix-vector product; every vertex's sheared coordinates still depend only on the vertex and
/// the ray, which is what makes the test watertight.
#[derive(Debug, Clone, Copy)]
pub struct ShearedRay {
    origin: Vec3A,
    /// Maps `v - origin` to `(v[kx] - sx v[kz], v[ky] - sy v[kz], sz v[kz])`.
    shear: Mat3A,
}

impl ShearedRay {
    /// Prepares a ray; `dir` need not be normalised but must be finite and non-zero.
    pub fn new(origin: Vec3A, dir: Vec3A) -> Self {
        let a = dir.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let (sx, sy, sz) = (dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
        // Column c holds the coefficients of input component c in the three outputs.
        let mut cols = [Vec3A::ZERO; 3];
        cols[kx].x = 1.0;
        cols[ky].y = 1.0;
        cols[kz] = Vec3A::new(-sx, -sy, sz);
        Self {
            origin,
            shear: Mat3A::from_cols(cols[0], cols[1], cols[2]),
        }
    }

    /// Ray parameter `t` (in units of the direction given to [`ShearedRay::new`]) of the hit with
    /// triangle `(v0, v1, v2)` when `t_min < t < t_max`, else `None`. Both faces count.
    #[inline]
    pub fn intersect(
        &self,
        v0: Vec3A,
        v1: Vec3A,
        v2: Vec3A,
        t_min: f32,
        t_max: f32,
    ) -> Option<f32> {
        let a = self.shear * (v0 - self.origin);
        let b = self.shear * (v1 - self.origin);
        let c = self.shear * (v2 - self.origin);
        let (ax, ay, bx, by, cx, cy) = (a.x, a.y, b.x, b.y, c.x, c.y);
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // Section 3.3: recompute the edge functions in double precision.
            let (cx, cy, bx, by, ax, ay) = (
                cx as f64, cy as f64, bx as f64, by as f64, ax as f64, ay as f64,
            );
            u = (cx * by - cy * bx) as f32;
            v = (ax * cy - ay * cx) as f32;
            w = (bx * ay - by * ax) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let t_scaled = u * a.z + v * b.z + w * c.z;
        // Compare t_scaled / det against the range without dividing (sign-aware).
        let (t_scaled, det) = if det < 0.0 {
            (-t_scaled, -det)
        } else {
            (t_scaled, det)
        };
        if t_scaled <= t_min * det || t_scaled >= t_max * det {
            return None;
        }
        Some(t_scaled / det)
    }
}

/// Reference implementation in f64 (used by tests as the brute-force oracle's check).
pub fn intersect_f64(o: DVec3, d: DVec3, v0: DVec3, v1: DVec3, v2: DVec3) -> Option<f64> {
    let (e1, e2) = (v1 - v0, v2 - v0);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let s = o - v0;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = d.dot(q) / det;
    let t = e2.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn tri() -> [Vec3A; 3] {
        [
            Vec3A::new(0.0, 0.0, 0.0),
            Vec3A::new(1.0, 0.0, 0.0),
            Vec3A::new(0.0, 1.0, 0.0),
        ]
    }

    #[test]
    fn hits_inside_misses_outside_both_faces() {
        let [a, b, c] = tri();
        let down = ShearedRay::new(Vec3A::new(0.25, 0.25, 1.0), Vec3A::new(0.0, 0.0, -1.0));
        assert!((down.intersect(a, b, c, 0.0, 10.0).unwrap() - 1.0).abs() < 1e-6);
        let up = ShearedRay::new(Vec3A::new(0.25, 0.25, -1.0), Vec3A::new(0.0, 0.0, 1.0));
        assert!(up.intersect(a, b, c, 0.0, 10.0).is_some());
        let out = ShearedRay::new(Vec3A::new(0.75, 0.75, 1.0), Vec3A::new(0.0, 0.0, -1.0));
        assert!(out.intersect(a, b, c, 0.0, 10.0).is_none());
        // Range limits.
        assert!(down.intersect(a, b, c, 0.0, 0.5).is_none());
        assert!(down.intersect(a, b, c, 1.5, 10.0).is_none());
    }

    #[test]
    fn shared_edges_and_vertices_never_leak() {
        // Two triangles sharing the diagonal of the unit square; rays through points exactly on
        // the diagonal and at the shared vertices, from many directions, hit at least one.
        let p = [
            Vec3A::new(0.0, 0.0, 0.0),
            Vec3A::new(1.0, 0.0, 0.0),
            Vec3A::new(1.0, 1.0, 0.0),
            Vec3A::new(0.0, 1.0, 0.0),
        ];
        let t1 = [p[0], p[1], p[2]];
        let t2 = [p[0], p[2], p[3]];
        let mut rays = 0;
        for k in 1..16 {
            let s = k as f32 / 16.0;
            let target = Vec3A::new(s, s, 0.0);
            for (i, dir) in [
                Vec3::new(0.3, -0.2, -1.0),
                Vec3::new(-0.7, 0.1, -0.4),
                Vec3::new(0.01, 0.02, -1.0),
                Vec3::new(1.0, 1.0, -0.001),
            ]
            .iter()
            .enumerate()
            {
                let d = Vec3A::from(dir.normalize());
                let o = target - d * (1.0 + i as f32);
                let r = ShearedRay::new(o, d);
                let h = r
                    .intersect(t1[0], t1[1], t1[2], 0.0, 100.0)
                    .or(r.intersect(t2[0], t2[1], t2[2], 0.0, 100.0));
                assert!(h.is_some(), "leak at {target:?} dir {dir:?}");
                rays += 1;
            }
        }
        assert_eq!(rays, 60);
    }
}
