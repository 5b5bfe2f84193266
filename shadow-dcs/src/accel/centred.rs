//! Light-centred single-precision forms of the per-(pixel, edge) work of the wedge pass (DCS
//! section 4.2), with exact double-precision fallbacks.
//!
//! Every quantity a pair needs is an affine or bilinear function of the view sample `p`; written
//! relative to the light centre `c` (`x' = x - c`), so that it is as precise far from the origin
//! as near it:
//! * the wedge's bounding planes and the three planes through the edge's line that decide its
//!   weight `k_e(p)`: through `c` (which side of the shadow-volume quad) and through each
//!   adjacent face (is the edge a silhouette from `p`, does `p` see the face's back) are
//!   evaluated in `f32` with an error bound; a value inside the bound sends the pixel to the
//!   exact [`SceneEdge::sweep_weight`];
//! * the covered-sample test ([`EdgeTest`]) needs one cross product per end point and one for
//!   the edge: `(a - p) x (c - p) = p' x a'`, `(p - a) x (b - a) = p' x e - a' x b'`, with the
//!   orientation `orient(a, b, p, c) = (p' x e) . a'` (in double precision, like
//!   [`EdgeTest::new`], whose tie rule it keeps).

use glam::{DVec3, Vec3, Vec4};

use crate::accel::lanes::{LANES, LaneMask, QUADS, TileQuads};
use crate::stages::coverage::EdgeTest;
use crate::stages::edges::SceneEdge;

/// Relative error bound of an `f32` plane evaluation, against `|n|_1 |x'|_1 + |d|`. The value
/// carries the rounding of `n` and `d` to `f32` (one unit in the last place, `6e-8`, each), of
/// the centred point (one more) and of three products and three sums: at most about
/// `6 * 6e-8 = 3.6e-7` of that scale; the bound keeps a wide margin above it (2e-6 was
/// tried: fewer exact fallbacks, no measurable time gained).
const PLANE_BOUND: f32 = 1e-5;

/// An affine function `n . x' + d` of a light-centred point.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CentredPlane {
    n: Vec3,
    d: f32,
    /// `PLANE_BOUND |n|_1` and `PLANE_BOUND |d|`.
    bound_n: f32,
    bound_d: f32,
}

impl CentredPlane {
    /// The plane `n . x + d` (world coordinates, double precision) around centre `c`.
    pub fn new(n: DVec3, d: f64, c: DVec3) -> Self {
        let scale = n.abs().max_element();
        let (n, d) = if scale > 0.0 && scale.is_finite() {
            (n / scale, (d + n.dot(c)) / scale)
        } else {
            (n, d + n.dot(c))
        };
        let (n, d) = (n.as_vec3(), d as f32);
        Self {
            n,
            d,
            bound_n: PLANE_BOUND * n.abs().element_sum(),
            bound_d: PLANE_BOUND * d.abs(),
        }
    }

    /// The normal and offset (`n . x' + d`).
    #[inline]
    pub fn coefficients(&self) -> (Vec3, f32) {
        (self.n, self.d)
    }

    /// The values at the four lane quads of a tile.
    #[inline(always)]
    pub fn eval_quads(&self, t: &TileQuads) -> [Vec4; QUADS] {
        let (nx, ny, nz, d) = (
            Vec4::splat(self.n.x),
            Vec4::splat(self.n.y),
            Vec4::splat(self.n.z),
            Vec4::splat(self.d),
        );
        std::array::from_fn(|q| nx * t.x[q] + ny * t.y[q] + nz * t.z[q] + d)
    }

    /// The lanes of `lanes` whose magnitude of `v` exceeds this plane's error bound there (a
    /// certain sign; NaN fails).
    #[inline(always)]
    fn certain_quads(&self, t: &TileQuads, v: &[Vec4; QUADS]) -> LaneMask {
        let (bn, bd) = (Vec4::splat(self.bound_n), Vec4::splat(self.bound_d));
        let mut m = 0;
        for q in 0..QUADS {
            m |= (v[q].abs().cmpgt(bn * t.l1[q] + bd).bitmask() as LaneMask) << (4 * q);
        }
        m
    }
}

/// One adjacent face of an edge for the fast weight.
#[derive(Debug, Clone, Copy)]
struct FaceSign {
    /// `N_f . (x - a)`, `N_f = (b - a) x (third - a)`.
    plane: CentredPlane,
    /// Whether the face's stored front side is where `plane` is positive.
    front_positive: bool,
    two_sided: bool,
    weight: i64,
}

/// `k_e(p)` of an edge with one or two faces from three plane signs.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FastWeight {
    /// `N_c . (x - a)`, `N_c = (b - a) x (c - a)`.
    through_center: CentredPlane,
    faces: [Option<FaceSign>; 2],
}

impl FastWeight {
    /// The fast weight of `e` around centre `c`; `None` for edges with more than two faces.
    pub fn new(e: &SceneEdge, c: DVec3) -> Option<Self> {
        if e.faces.is_empty() || e.faces.len() > 2 {
            return None;
        }
        let ab = e.b - e.a;
        let plane_through = |w: DVec3| {
            let n = ab.cross(w - e.a);
            CentredPlane::new(n, -n.dot(e.a), c)
        };
        let mut faces = [None; 2];
        for (slot, f) in faces.iter_mut().zip(&e.faces) {
            let n = ab.cross(f.third - e.a);
            *slot = Some(FaceSign {
                plane: plane_through(f.third),
                front_positive: n.dot(f.normal) > 0.0,
                two_sided: f.two_sided,
                weight: f.weight as i64,
            });
        }
        Some(Self {
            through_center: plane_through(c),
            faces,
        })
    }

    /// The planes of the edge's two faces, as the weight evaluates them (`N_f . (x - a)`,
    /// `N_f = (b - a) x (third - a)`), for an edge with two faces. The wedge scan's fold test
    /// evaluates these same planes, so that [`FastWeight::weight_lanes`] can take its values.
    pub fn face_planes(&self) -> Option<(CentredPlane, CentredPlane)> {
        match self.faces {
            [Some(f1), Some(f2)] => Some((f1.plane, f2.plane)),
            _ => None,
        }
    }
}

/// `k_e` at every lane of a tile, with the mask of lanes whose signs are all certain (lanes
/// outside it must take the exact weight) and the mask of lanes whose weight is not zero. Face
/// weights are at most [`LANE_WEIGHT_MAX`], so that a lane's sum is exact in single precision
/// and converts to an integer exactly.
pub(crate) struct LaneWeights {
    k: [f32; LANES],
    pub certain: LaneMask,
    /// Lanes whose `k_e` is not zero (certain or not).
    pub nonzero: LaneMask,
}

impl LaneWeights {
    /// `k_e` at lane `j`.
    #[inline]
    pub fn k(&self, j: usize) -> i32 {
        // A whole number of magnitude below `2^22` plus `1.5 * 2^23` keeps itself in the low
        // bits (no saturating conversion): the face weights are at most `2^20`.
        const MAGIC: f32 = 12_582_912.0;
        (self.k[j] + MAGIC).to_bits() as i32 - MAGIC.to_bits() as i32
    }
}

/// The largest face weight the lane form takes (larger ones go through the exact weight): two
/// of them add up exactly in single precision, and their sum converts through
/// [`LaneWeights::k`]'s bits.
const LANE_WEIGHT_MAX: i64 = 1 << 20;

impl FastWeight {
    /// `k_e` at every lane of a tile by the rule of [`SceneEdge::sweep_weight`] from a view
    /// sample toward `c`: that rule's side of `c` is the sign of `-N_c . (x - a)` and a face's
    /// side that of `-N_f . (x - a)`; a one-sided face counts only from behind. Four lanes at a
    /// time in packed single precision (the weights are whole numbers well inside its range).
    /// `None` when a face weight exceeds [`LANE_WEIGHT_MAX`]. `faces`, when given, holds the
    /// two face planes' values at the lanes, as [`CentredPlane::eval_quads`] computes them
    /// (the wedge scan's fold test has them at hand: [`FastWeight::face_planes`]).
    #[inline]
    pub fn weight_lanes(
        &self,
        t: &TileQuads,
        faces: Option<&[[Vec4; QUADS]; 2]>,
    ) -> Option<LaneWeights> {
        let zero = Vec4::ZERO;
        let v = self.through_center.eval_quads(t);
        let mut certain = self.through_center.certain_quads(t, &v);
        let from_negative = v.map(|x| x.cmplt(zero));
        let mut k = [zero; QUADS];
        for (i, f) in self.faces.iter().enumerate() {
            let Some(f) = f else { continue };
            if f.weight > LANE_WEIGHT_MAX {
                return None;
            }
            let w = Vec4::splat(f.weight as f32);
            let v = match faces {
                Some(values) => values[i],
                None => f.plane.eval_quads(t),
            };
            certain &= f.plane.certain_quads(t, &v);
            for q in 0..QUADS {
                let positive = v[q].cmpgt(zero);
                let front = if f.front_positive {
                    positive
                } else {
                    !positive
                };
                // Moving off the face's side (same side as the centre's) subtracts its weight.
                let same = !(v[q].cmplt(zero) ^ from_negative[q]);
                let signed = Vec4::select(same, -w, w);
                k[q] += if f.two_sided {
                    signed
                } else {
                    Vec4::select(front, zero, signed)
                };
            }
        }
        let mut out = [0.0f32; LANES];
        let mut nonzero: LaneMask = 0;
        for q in 0..QUADS {
            out[4 * q..4 * q + 4].copy_from_slice(&k[q].to_array());
            // Whole numbers: zero as floats where zero as integers.
            nonzero |= (k[q].cmpne(zero).bitmask() as LaneMask) << (4 * q);
        }
        Some(LaneWeights {
            k: out,
            certain,
            nonzero,
        })
    }
}

/// An edge relative to the light centre, for [`EdgeTest`]s from many view samples: three cross
/// products per test instead of four, and no per-test differences of world positions.
#[derive(Debug, Clone, Copy)]
pub(crate) struct CentredEdge {
    a: DVec3,
    b: DVec3,
    e: DVec3,
    /// `a' x b'`.
    ab: DVec3,
    /// `(b - a) x (c - a)`.
    h1: DVec3,
}

impl CentredEdge {
    /// Edge `e` around centre `c`.
    pub fn new(e: &SceneEdge, c: DVec3) -> Self {
        let (a, b) = (e.a - c, e.b - c);
        Self {
            a,
            b,
            e: b - a,
            ab: a.cross(b),
            h1: (b - a).cross(-a),
        }
    }

    /// The end points relative to the centre.
    #[inline]
    pub fn ends(&self) -> (DVec3, DVec3) {
        (self.a, self.b)
    }

    /// Whether `orient(a, b, p, c)` is positive from the centred view sample `p` (the covered
    /// cone's orientation); `None` on the tie of [`EdgeTest::new`].
    #[inline]
    pub fn orientation(&self, p: DVec3) -> Option<bool> {
        let k0 = p.cross(self.e).dot(self.a);
        (k0 != 0.0 && k0.is_finite()).then_some(k0 > 0.0)
    }

    /// The covered-sample test from the centred view sample `p`; `None` on the tie of
    /// [`EdgeTest::new`] (the edge's line meets the line from `p` to `c`).
    #[inline]
    pub fn test(&self, p: DVec3) -> Option<EdgeTest> {
        let u = p.cross(self.e);
        let k0 = u.dot(self.a);
        if k0 == 0.0 || !k0.is_finite() {
            return None;
        }
        let ga = p.cross(self.a);
        let gb = p.cross(self.b);
        let k1 = self.h1.dot(p - self.a);
        Some(EdgeTest::from_parts(
            ga.as_vec3(),
            gb.as_vec3(),
            (u - self.ab).as_vec3(),
            self.h1.as_vec3(),
            k1 as f32,
            k0 > 0.0,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::lanes::{TILE_H, TILE_W, TileLanes, rect_lanes};
    use crate::stages::edges::EdgeFace;
    use shadow_core::sampling::{hash_words, unit_float};

    fn face(a: DVec3, b: DVec3, third: DVec3, flip: bool, two_sided: bool) -> EdgeFace {
        let (v0, v1, v2) = if flip { (a, third, b) } else { (a, b, third) };
        let normal = (v1 - v0).cross(v2 - v0);
        EdgeFace {
            third,
            normal,
            offset: -normal.dot(v0),
            weight: 1,
            two_sided,
        }
    }

    /// Face weights for case `k`: one, a semi-opaque occluder's units, the lane form's largest.
    /// A tile whose every lane holds one of `centred` (one per lane, in lane order).
    fn full_tile(centred: &[Vec3]) -> TileLanes {
        let mut tiles = Vec::new();
        rect_lanes(
            TILE_W,
            (0, TILE_W - 1),
            (0, TILE_H - 1),
            centred,
            &[true; LANES],
            &mut tiles,
        );
        tiles[0]
    }

    fn weights(k: u64) -> [u32; 2] {
        let w = [1, 1, 255, LANE_WEIGHT_MAX as u32];
        [w[(k % 4) as usize], w[(k / 4 % 4) as usize]]
    }

    /// Case `k`: a light centre and below it an edge with two faces (their orientations
    /// flipped by `flips`), everything moved by `offset` along the diagonal.
    fn random_edge(
        k: u64,
        offset: f64,
        flips: (bool, bool),
        two_sided: bool,
    ) -> (DVec3, SceneEdge) {
        let r = |i: u64| unit_float(hash_words(&[k, i])) as f64 * 2.0 - 1.0;
        let o = DVec3::splat(offset);
        let c = o + DVec3::new(r(0), 3.0 + r(1), r(2));
        let a = o + DVec3::new(r(3), 1.0 + r(4) * 0.5, r(5));
        let b = a + DVec3::new(r(6), r(7), r(8)) * 0.3;
        let t1 = a + DVec3::new(r(9), r(10), r(11)) * 0.3;
        let t2 = a + DVec3::new(r(12), r(13), r(14)) * 0.3;
        let edge = SceneEdge {
            a,
            b,
            faces: vec![
                face(a, b, t1, flips.0, two_sided),
                face(b, a, t2, flips.1, two_sided),
            ],
            always: false,
        };
        (c, edge)
    }

    /// On full tiles every lane with certain signs gets the exact weight, whatever its
    /// neighbours, and almost every lane is certain.
    #[test]
    fn lane_weights_equal_the_exact_weight_on_full_tiles() {
        let (mut certain, mut total) = (0, 0);
        for k in 0..400u64 {
            let r = |i: u64| unit_float(hash_words(&[k, i])) as f64 * 2.0 - 1.0;
            let (c, mut edge) = random_edge(k, 0.0, (k % 2 == 0, k % 4 < 2), k % 3 == 0);
            for (f, w) in edge.faces.iter_mut().zip(weights(k / 3)) {
                f.weight = w;
            }
            let points: Vec<DVec3> = (0..LANES as u64)
                .map(|j| {
                    DVec3::new(
                        r(20 + 3 * j) * 2.0,
                        r(21 + 3 * j) * 0.2,
                        r(22 + 3 * j) * 2.0,
                    )
                })
                .collect();
            let centred: Vec<Vec3> = points.iter().map(|p| (*p - c).as_vec3()).collect();
            let tile = full_tile(&centred);
            let lanes = FastWeight::new(&edge, c)
                .unwrap()
                .weight_lanes(&tile.quads(), None)
                .unwrap();
            for (j, p) in points.iter().enumerate() {
                total += 1;
                // The scan keeps the lanes of this mask as pairs.
                assert_eq!(
                    lanes.nonzero >> j & 1 == 1,
                    lanes.k(j) != 0,
                    "case {k} lane {j}: non-zero mask"
                );
                if lanes.certain >> j & 1 == 1 {
                    certain += 1;
                    assert_eq!(
                        Some(i64::from(lanes.k(j))),
                        edge.sweep_weight(*p, c, false),
                        "case {k} lane {j}"
                    );
                }
            }
        }
        assert!(certain * 100 > total * 99, "{certain} of {total}");
        // A face weight above the lane form's bound goes to the exact weight.
        let (c, mut edge) = random_edge(1, 0.0, (false, false), false);
        edge.faces[0].weight = LANE_WEIGHT_MAX as u32 + 1;
        let tile = TileLanes::at(Vec3::ONE);
        assert!(
            FastWeight::new(&edge, c)
                .unwrap()
                .weight_lanes(&tile.quads(), None)
                .is_none()
        );
    }

    /// Given its face planes' values (as the wedge scan's fold test computes them), the lane
    /// weight is the one it computes itself: the same weights and the same certain lanes.
    #[test]
    fn lane_weights_from_the_fold_values_are_the_same() {
        let mut compared = 0;
        for k in 0..300u64 {
            let r = |i: u64| unit_float(hash_words(&[k, i])) as f64 * 2.0 - 1.0;
            let (c, mut edge) = random_edge(k, 0.0, (k % 2 == 0, k % 4 < 2), k % 3 == 0);
            for (f, w) in edge.faces.iter_mut().zip(weights(k / 3)) {
                f.weight = w;
            }
            let fast = FastWeight::new(&edge, c).unwrap();
            let (f1, f2) = fast.face_planes().expect("two faces");
            let lanes: Vec<Vec3> = (0..LANES as u64)
                .map(|j| {
                    let p = DVec3::new(
                        r(20 + 3 * j) * 2.0,
                        r(21 + 3 * j) * 0.2,
                        r(22 + 3 * j) * 2.0,
                    );
                    (p - c).as_vec3()
                })
                .collect();
            let t = full_tile(&lanes).quads();
            let values = [f1.eval_quads(&t), f2.eval_quads(&t)];
            match (
                fast.weight_lanes(&t, None),
                fast.weight_lanes(&t, Some(&values)),
            ) {
                (Some(a), Some(b)) => {
                    assert_eq!(a.certain, b.certain, "case {k}");
                    assert_eq!(a.nonzero, b.nonzero, "case {k}");
                    for j in 0..LANES {
                        assert_eq!(a.k(j), b.k(j), "case {k} lane {j}");
                    }
                    compared += 1;
                }
                (None, None) => {}
                _ => panic!("case {k}: one form answers, the other not"),
            }
        }
        assert!(compared > 200, "{compared}");
    }

    /// The single-precision weight and test agree with the double-precision ones wherever
    /// they answer, far from the origin too, and answer almost everywhere.
    #[test]
    fn centred_forms_equal_the_exact_ones() {
        let (mut answered, mut total, mut compared, mut differ) = (0, 0, 0, 0);
        for (k, offset) in (0..3000u64).zip([0.0, 1e3, 1e5].into_iter().cycle()) {
            let r = |i: u64| unit_float(hash_words(&[k, i])) as f64 * 2.0 - 1.0;
            let o = DVec3::splat(offset);
            let (c, edge) = random_edge(k, offset, (k % 2 == 0, k % 3 == 0), k % 5 == 0);
            let (a, b) = (edge.a, edge.b);
            let p = o + DVec3::new(r(15) * 2.0, r(16) * 0.2, r(17) * 2.0);
            let pc = (p - c).as_vec3();
            let fast = FastWeight::new(&edge, c).unwrap();
            total += 1;
            let lanes = fast.weight_lanes(&TileLanes::at(pc).quads(), None).unwrap();
            if lanes.certain & 1 == 1 {
                answered += 1;
                let k = i64::from(lanes.k(0));
                assert_eq!(Some(k), edge.sweep_weight(p, c, false), "case {k}");
            }
            let centred = CentredEdge::new(&edge, c);
            if let (Some(t), Some(exact)) = (centred.test(p - c), EdgeTest::new(p, c, a, b)) {
                // Same covered samples on a grid of light points.
                for j in 0..64 {
                    let s =
                        c + DVec3::new((j % 8) as f64 / 4.0 - 0.9, 0.0, (j / 8) as f64 / 4.0 - 0.9);
                    let d = (s - p).as_vec3();
                    compared += 1;
                    differ += usize::from(t.covers_offset(d) != exact.covers_offset(d));
                }
            }
        }
        assert!(answered * 100 > total * 99, "{answered} of {total}");
        // Rounding may only flip samples within about 1e-6 of an edge's boundary.
        assert!(
            compared > 100_000 && differ * 10_000 <= compared,
            "{differ} of {compared}"
        );
    }
}
