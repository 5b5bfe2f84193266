//! The watertight ray-triangle test of Woop, Benthin and Wald, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1), 2013: the ray is sheared so that it runs along +z from the origin;
//! the 2D edge functions of the sheared triangle are evaluated exactly as in the paper, with the
//! f64 fallback when one is zero. A ray through an edge or vertex shared by two triangles hits
//! at least one of them: no leak through closed meshes.

use glam::{DVec3, Mat3A, Vec3A, Vec4};

/// Per-ray constants of the test (section 3 of the paper). The permutation (`kx, ky, kz`) and
/// the shear are folded into one matrix, so each vertex is transformed with one SIMD
/// matrix-vector product; every vertex's sheared coordinates still depend only on the vertex and
/// the ray, which is what makes the test watertight.
#[derive(Debug, Clone, Copy)]
pub struct ShearedRay {
    origin: Vec3A,
    /// Maps `v - origin` to `(v[kx] - sx v[kz], v[ky] - sy v[kz], sz v[kz])`.
    shear: Mat3A,
    /// The permutation `[kx, ky, kz]` and `(sx, sy, sz)`, for the four-wide test.
    axes: [usize; 3],
    s: Vec3A,
}

/// Four triangles in structure-of-arrays form for [`ShearedRay::intersect4`]: `v[k][c]` holds
/// coordinate `c` of vertex `k`, one lane per triangle. Unused lanes repeat a used triangle.
#[derive(Debug, Clone, Copy)]
pub struct Triangles4 {
    /// Vertex, then coordinate, then lane.
    pub v: [[Vec4; 3]; 3],
}

impl Triangles4 {
    /// Packs one to four triangles; fewer than four are padded by repeating the first.
    ///
    /// # Panics
    /// When `tris` is empty or longer than four.
    pub fn pack(tris: &[[Vec3A; 3]]) -> Self {
        assert!((1..=4).contains(&tris.len()), "one to four triangles");
        let mut v = [[Vec4::ZERO; 3]; 3];
        for lane in 0..4 {
            let t = tris.get(lane).unwrap_or(&tris[0]);
            for (k, vertex) in t.iter().enumerate() {
                for c in 0..3 {
                    v[k][c][lane] = vertex[c];
                }
            }
        }
        Self { v }
    }

    /// Writes `tri` into `lane`.
    pub fn set_lane(&mut self, lane: usize, tri: [Vec3A; 3]) {
        for (k, vertex) in tri.iter().enumerate() {
            for c in 0..3 {
                self.v[k][c][lane] = vertex[c];
            }
        }
    }

    /// The triangle in `lane`.
    pub fn lane(&self, lane: usize) -> [Vec3A; 3] {
        self.v
            .map(|c| Vec3A::new(c[0][lane], c[1][lane], c[2][lane]))
    }
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
            axes: [kx, ky, kz],
            s: Vec3A::new(sx, sy, sz),
        }
    }

    /// [`ShearedRay::intersect`] on four triangles at once with `t_min = 0`: bit `i` of the
    /// result is set when lane `i` is hit with `0 < t < t_max`. Every lane computes exactly
    /// the scalar test's operations (the same sheared coordinates and edge functions, in the
    /// same order), so the answers are identical to four scalar calls; a lane with an edge
    /// function at zero takes the scalar test and its double-precision fallback.
    #[inline]
    pub fn intersect4(&self, tris: &Triangles4, t_max: f32) -> u32 {
        let [kx, ky, kz] = self.axes;
        let o = [
            Vec4::splat(self.origin.x),
            Vec4::splat(self.origin.y),
            Vec4::splat(self.origin.z),
        ];
        let (sx, sy, sz) = (
            Vec4::splat(self.s.x),
            Vec4::splat(self.s.y),
            Vec4::splat(self.s.z),
        );
        let shear = |k: usize| {
            let p = &tris.v[k];
            let (x, y, z) = (p[kx] - o[kx], p[ky] - o[ky], p[kz] - o[kz]);
            (x - sx * z, y - sy * z, sz * z)
        };
        let (ax, ay, az) = shear(0);
        let (bx, by, bz) = shear(1);
        let (cx, cy, cz) = shear(2);
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = Vec4::ZERO;
        let on_edge = u.cmpeq(zero) | v.cmpeq(zero) | w.cmpeq(zero);
        let neg = u.cmplt(zero) | v.cmplt(zero) | w.cmplt(zero);
        let pos = u.cmpgt(zero) | v.cmpgt(zero) | w.cmpgt(zero);
        let det = u + v + w;
        let t_scaled = u * az + v * bz + w * cz;
        let flip = det.cmplt(zero);
        let (t_scaled, det) = (
            Vec4::select(flip, -t_scaled, t_scaled),
            Vec4::select(flip, -det, det),
        );
        let miss = (neg & pos)
            | det.cmpeq(zero)
            | t_scaled.cmple(zero)
            | t_scaled.cmpge(Vec4::splat(t_max) * det);
        let mut hit = (!(miss | on_edge)).bitmask();
        let mut edge = on_edge.bitmask();
        while edge != 0 {
            let lane = edge.trailing_zeros() as usize;
            edge &= edge - 1;
            let [a, b, c] = tris.lane(lane);
            if self.intersect(a, b, c, 0.0, t_max).is_some() {
                hit |= 1 << lane;
            }
        }
        hit
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

    /// A small deterministic generator for the randomised checks.
    fn lcg(state: &mut u64) -> f32 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*state >> 40) as f32) / (1u64 << 24) as f32
    }

    #[test]
    fn four_wide_test_equals_four_scalar_tests() {
        let mut st = 7u64;
        let r = |st: &mut u64, s: f32| (lcg(st) * 2.0 - 1.0) * s;
        let mut hits = 0;
        let mut edge_cases = 0;
        for round in 0..4000 {
            // Random triangles, and every tenth round a fan of triangles sharing vertices and
            // edges on a lattice, hit by rays through lattice points (zero edge functions).
            let tris: Vec<[Vec3A; 3]> = if round % 10 == 0 {
                let c = Vec3A::new(r(&mut st, 1.0).round(), r(&mut st, 1.0).round(), 0.0);
                (0..4)
                    .map(|k| {
                        let a = k as f32 * std::f32::consts::FRAC_PI_2;
                        let p = c + Vec3A::new(a.cos().round(), a.sin().round(), 0.0);
                        let q = c + Vec3A::new(-a.sin().round(), a.cos().round(), 0.0);
                        [c, p, q]
                    })
                    .collect()
            } else {
                (0..1 + round % 4)
                    .map(|_| {
                        [0, 1, 2]
                            .map(|_| Vec3A::new(r(&mut st, 2.0), r(&mut st, 2.0), r(&mut st, 2.0)))
                    })
                    .collect()
            };
            let target = if round % 10 == 0 {
                edge_cases += 1;
                tris[0][round / 10 % 3]
            } else {
                Vec3A::new(r(&mut st, 1.5), r(&mut st, 1.5), r(&mut st, 1.5))
            };
            let mut d = Vec3A::new(r(&mut st, 1.0), r(&mut st, 1.0), r(&mut st, 1.0));
            if round % 7 == 0 {
                d = Vec3A::new(0.0, 0.0, -1.0);
            }
            let Some(d) = d.try_normalize() else { continue };
            let o = target - d * (1.0 + lcg(&mut st));
            let ray = ShearedRay::new(o, d);
            let pack = Triangles4::pack(&tris);
            let t_max = 0.5 + 3.0 * lcg(&mut st);
            let wide = ray.intersect4(&pack, t_max);
            for lane in 0..4 {
                let [a, b, c] = tris.get(lane).copied().unwrap_or(tris[0]);
                let scalar = ray.intersect(a, b, c, 0.0, t_max).is_some();
                assert_eq!(wide & (1 << lane) != 0, scalar, "round {round} lane {lane}");
                hits += usize::from(scalar);
            }
        }
        assert!(hits > 500 && edge_cases > 100, "{hits} {edge_cases}");
    }
}
