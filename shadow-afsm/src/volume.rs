//! Each caster's penumbra volume, bounded by planes: the set of points from which the caster
//! hides some part of the light. Cluster culling (`tile_pairs.wgsl`) tests the boxes of a
//! tile's and of a texel's view-sample origins against it, so that only (caster, texel) pairs
//! whose samples may lie in the caster's shadow reach the occlusion pass.
//!
//! A point `o` is hidden from a light point `y` by the caster when the segment `[o, y]` meets
//! the caster: `o = t + s (t - y)` for a caster point `t` and some `s >= 0`. So for any plane
//! `f(x) = n . x - w` with the caster on its non-negative side and the light (a polytope `L`
//! bounding it) on its non-positive side, a *separating plane*, every such `o` has
//! `f(o) = (1 + s) f(t) - s f(y) >= 0`. The separating planes through an edge of the caster and
//! a vertex of `L`, or through a vertex of the caster and an edge of `L`, with the caster's own
//! plane when `L` lies on one side of it, bound the volume: these are the faces of the
//! penumbra's outer boundary (the survey's penumbra wedges, Assarsson and Akenine-Möller's
//! construction, seen from the caster as a whole). A closed mesh's caster adds its front
//! half-space, since only samples in front of it count (section 3.3 of the AFSM paper).
//!
//! Every plane kept is a bound, so dropping planes (past [`VOLUME_PLANES`]) only makes the
//! test looser, never wrong. Planes are built in double precision; the shader's margin covers
//! their rounding to `f32`.

use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec3};

use crate::params::{Caster, KIND_DISK, KIND_POINT, KIND_SPHERE, LightBounds};

/// Planes kept per caster (a triangle under an octagon has at most 1 + 1 + 3 + 8 faces).
pub const VOLUME_PLANES: usize = 12;

/// The plane every point is inside of (`dot(0, x) >= -1`): an unused slot.
const ALWAYS: [f32; 4] = [0.0, 0.0, 0.0, -1.0];

/// A caster's penumbra volume (`Volume` in `tile_pairs.wgsl`): points `x` with
/// `dot(n, x) >= w` for every plane `(n, w)`, `n` of unit length.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Volume {
    /// The planes; unused slots are `(0, 0, 0, -1)`.
    pub planes: [[f32; 4]; VOLUME_PLANES],
}

impl Volume {
    /// No bound at all: every point is inside.
    pub const EVERYWHERE: Self = Self {
        planes: [ALWAYS; VOLUME_PLANES],
    };

    /// Whether `x` is inside every plane, with `margin` (the shader's test, for tests).
    pub fn holds(&self, x: Vec3, margin: f32) -> bool {
        self.planes
            .iter()
            .all(|p| Vec3::new(p[0], p[1], p[2]).dot(x) - p[3] >= -margin)
    }
}

/// Points whose convex hull holds the light: a polygon's outline, the octagon around a disk
/// (as `light_points` in `common.wgsl`), the cube around a sphere, or the point itself.
pub fn light_polytope(bounds: &LightBounds) -> Vec<Vec3> {
    let c = bounds.center;
    match bounds.kind {
        KIND_DISK => {
            let rad = bounds.radius / (std::f32::consts::PI / 8.0).cos();
            let [u, v] = bounds.axes;
            (0..8)
                .map(|j| {
                    let a = j as f32 * std::f32::consts::FRAC_PI_4;
                    c + rad * (a.cos() * u + a.sin() * v)
                })
                .collect()
        }
        KIND_SPHERE => {
            let r = bounds.radius;
            (0..8)
                .map(|k| {
                    let s = |bit: u32| if k & bit == 0 { -r } else { r };
                    c + Vec3::new(s(1), s(2), s(4))
                })
                .collect()
        }
        KIND_POINT => vec![c],
        _ => bounds.outline.clone(),
    }
}

/// The plane `f(x) = n . (x - p)` oriented with `on` (the caster's points) at or above zero and
/// `off` (the light's) at or below, if it separates them; `None` when it does not or is
/// degenerate (zero normal, or every point on it).
fn separating(n: DVec3, p: DVec3, on: &[DVec3], off: &[DVec3]) -> Option<(DVec3, DVec3)> {
    let len = n.length();
    if len == 0.0 || !len.is_finite() {
        return None;
    }
    let reach = on
        .iter()
        .chain(off)
        .map(|x| (*x - p).length())
        .fold(0.0, f64::max);
    let tol = 1e-12 * len * reach;
    let f = |x: &DVec3| n.dot(*x - p);
    let side = |pts: &[DVec3]| {
        pts.iter().fold((f64::MAX, f64::MIN), |(lo, hi), x| {
            let v = f(x);
            (lo.min(v), hi.max(v))
        })
    };
    let (on_lo, on_hi) = side(on);
    let (off_lo, off_hi) = side(off);
    // Something must lie off the plane, or it bounds nothing.
    if on_hi
        .abs()
        .max(on_lo.abs())
        .max(off_hi.abs())
        .max(off_lo.abs())
        <= tol
    {
        return None;
    }
    if on_lo >= -tol && off_hi <= tol {
        Some((n / len, p))
    } else if on_hi <= tol && off_lo >= -tol {
        Some((-n / len, p))
    } else {
        None
    }
}

/// The penumbra volume of `caster` under the light bounded by the convex hull of `light`.
pub fn penumbra_volume(caster: &Caster, light: &[Vec3]) -> Volume {
    let t = caster.vertices().map(|v| v.as_dvec3());
    let l: Vec<DVec3> = light.iter().map(|y| y.as_dvec3()).collect();
    let nt = (t[1] - t[0]).cross(t[2] - t[0]);
    let mut planes: Vec<(DVec3, DVec3)> = Vec::new();
    if caster.closed() && nt.length() > 0.0 {
        // Only view samples in front of a closed mesh's caster count (section 3.3).
        planes.push((nt.normalize(), t[0]));
    }
    if !l.is_empty() {
        // The caster's own plane, with the light on one side of it.
        planes.extend(separating(nt, t[0], &t, &l));
        // An edge of the caster and a vertex of the light.
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            for y in &l {
                planes.extend(separating((b - a).cross(*y - a), a, &t, &l));
            }
        }
        // A vertex of the caster and two of the light's points (only an edge of the light's
        // hull can separate; other pairs split the light).
        for v in &t {
            for (j, p) in l.iter().enumerate() {
                for q in &l[j + 1..] {
                    planes.extend(separating((*p - *v).cross(*q - *v), *v, &t, &l));
                }
            }
        }
    }
    let mut out = Volume::EVERYWHERE;
    let mut kept = 0;
    for (n, p) in planes {
        if kept == VOLUME_PLANES {
            break;
        }
        let plane = [n.x as f32, n.y as f32, n.z as f32, n.dot(p) as f32];
        let same = |q: &[f32; 4]| {
            (0..3).all(|k| (q[k] - plane[k]).abs() <= 1e-6)
                && (q[3] - plane[3]).abs() <= 1e-6 * (1.0 + plane[3].abs())
        };
        if plane.iter().all(|x| x.is_finite()) && !out.planes[..kept].iter().any(same) {
            out.planes[kept] = plane;
            kept += 1;
        }
    }
    out
}

/// The volumes of `casters` under `bounds`.
pub fn volumes(casters: &[Caster], bounds: &LightBounds) -> Vec<Volume> {
    use rayon::prelude::*;
    let light = light_polytope(bounds);
    casters
        .par_iter()
        .map(|c| penumbra_volume(c, &light))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad_light() -> Vec<Vec3> {
        vec![
            Vec3::new(-1.0, -1.0, 4.0),
            Vec3::new(1.0, -1.0, 4.0),
            Vec3::new(1.0, 1.0, 4.0),
            Vec3::new(-1.0, 1.0, 4.0),
        ]
    }

    /// Whether the segment from `o` to `y` crosses triangle `t` (Möller-Trumbore).
    fn crosses(o: DVec3, y: DVec3, t: [DVec3; 3]) -> bool {
        let d = y - o;
        let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det.abs() < 1e-12 {
            return false;
        }
        let s = o - t[0];
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = d.dot(q) / det;
        let h = e2.dot(q) / det;
        u >= 0.0 && v >= 0.0 && u + v <= 1.0 && h > 0.0 && h < 1.0
    }

    /// Points the caster shadows from some light point are inside its volume; points it
    /// shadows from none are mostly outside (the volume is tight up to the light's hull).
    #[test]
    fn the_volume_holds_every_shadowed_point_and_little_else() {
        let light = quad_light();
        let tri = Caster::new(
            [
                Vec3::new(-0.3, -0.2, 2.0),
                Vec3::new(0.4, -0.1, 2.1),
                Vec3::new(0.0, 0.5, 1.9),
            ],
            0,
            false,
        );
        let vol = penumbra_volume(&tri, &light);
        let t = tri.vertices().map(|v| v.as_dvec3());
        let lights: Vec<DVec3> = (0..16)
            .flat_map(|i| (0..16).map(move |j| (i, j)))
            .map(|(i, j)| {
                DVec3::new(
                    -1.0 + (i as f64 + 0.5) / 8.0,
                    -1.0 + (j as f64 + 0.5) / 8.0,
                    4.0,
                )
            })
            .collect();
        let (mut shadowed, mut lit_inside, mut lit) = (0, 0, 0);
        for i in 0..40 {
            for j in 0..40 {
                let o = DVec3::new(-4.0 + 0.2 * i as f64, -4.0 + 0.2 * j as f64, 0.0);
                let hit = lights.iter().any(|y| crosses(o, *y, t));
                let inside = vol.holds(o.as_vec3(), 1e-5);
                if hit {
                    shadowed += 1;
                    assert!(inside, "shadowed point {o} outside the volume");
                } else {
                    lit += 1;
                    lit_inside += inside as u32;
                }
            }
        }
        assert!(shadowed > 50, "{shadowed}");
        // Only the margin between the sample grid and the light's edge is loose.
        assert!(
            lit_inside * 10 < lit,
            "{lit_inside} of {lit} lit points inside"
        );
    }

    /// A closed mesh's caster facing the light casts on nothing: its front half-space and the
    /// half-space beyond it from the light are disjoint.
    #[test]
    fn a_closed_caster_facing_the_light_has_an_empty_volume() {
        let light = quad_light();
        // Counter-clockwise seen from above: the normal points up, to the light.
        let tri = Caster::new(
            [
                Vec3::new(-0.5, -0.5, 2.0),
                Vec3::new(0.5, -0.5, 2.0),
                Vec3::new(0.0, 0.5, 2.0),
            ],
            0,
            true,
        );
        let vol = penumbra_volume(&tri, &light);
        for z in [-1.0, 0.0, 1.0, 1.99, 2.01, 3.0] {
            assert!(!vol.holds(Vec3::new(0.0, 0.0, z), 1e-5), "z {z}");
        }
        let open = penumbra_volume(&Caster::new(tri.vertices(), 0, false), &light);
        assert!(open.holds(Vec3::new(0.0, 0.0, 0.0), 1e-5));
    }

    /// A light that straddles the caster's plane keeps points on both sides.
    #[test]
    fn a_light_across_the_casters_plane_bounds_both_sides() {
        let light = vec![
            Vec3::new(-1.0, 0.0, 2.0),
            Vec3::new(1.0, 0.0, 2.0),
            Vec3::new(1.0, 0.0, 4.0),
            Vec3::new(-1.0, 0.0, 4.0),
        ];
        // A vertical caster in the plane x = 0, which cuts the light in two.
        let tri = Caster::new(
            [
                Vec3::new(0.0, 1.0, 2.5),
                Vec3::new(0.0, 2.0, 2.5),
                Vec3::new(0.0, 1.5, 3.5),
            ],
            0,
            false,
        );
        let vol = penumbra_volume(&tri, &light);
        // Behind the caster as seen from either half of the light.
        assert!(vol.holds(Vec3::new(0.5, 3.0, 3.0), 1e-5));
        assert!(vol.holds(Vec3::new(-0.5, 3.0, 3.0), 1e-5));
        // Before the light's side of the caster.
        assert!(!vol.holds(Vec3::new(0.0, -1.0, 3.0), 1e-5));
    }

    /// A point light's volume is the caster's shadow frustum.
    #[test]
    fn a_point_lights_volume_is_the_shadow_frustum() {
        let light = vec![Vec3::new(0.0, 0.0, 4.0)];
        let tri = Caster::new(
            [
                Vec3::new(-1.0, -1.0, 2.0),
                Vec3::new(1.0, -1.0, 2.0),
                Vec3::new(0.0, 1.0, 2.0),
            ],
            0,
            false,
        );
        let vol = penumbra_volume(&tri, &light);
        assert!(vol.holds(Vec3::new(0.0, 0.0, 0.0), 1e-5));
        assert!(vol.holds(Vec3::new(1.9, -1.9, 0.0), 1e-4));
        assert!(!vol.holds(Vec3::new(2.1, -2.1, 0.0), 1e-4));
        assert!(!vol.holds(Vec3::new(0.0, 0.0, 3.0), 1e-5));
    }

    /// The pair test's whole-light classification (`occlude.wgsl`): true when one of the four
    /// planes through `o` (the caster's, and one per edge) has the whole light outside.
    fn classified_empty(v: [Vec3; 3], o: Vec3, light: &[Vec3]) -> bool {
        let [a, b, c] = v;
        let nt = (b - a).cross(c - a);
        let so = nt.dot(o - a);
        let e1 = (a - o).cross(b - o);
        let sigma = if e1.dot(c - o) > 0.0 { 1.0 } else { -1.0 };
        let planes = [
            (if so > 0.0 { -nt } else { nt }, a),
            (sigma * e1, o),
            (sigma * (b - o).cross(c - o), o),
            (sigma * (c - o).cross(a - o), o),
        ];
        planes.iter().any(|(m, base)| {
            let d = m.dot(*base);
            light.iter().all(|y| m.dot(*y) - d < 0.0)
        })
    }

    /// Over random small triangles under a quad light, the volume holds every point that some
    /// light point's segment shows the triangle from (it is conservative), and no point the
    /// pair test's whole-light classification finds empty (it is as tight as that test).
    #[test]
    fn the_volume_agrees_with_the_pair_tests_classification() {
        let light = quad_light();
        let mut seed = 1u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 40) as f32 / (1u64 << 24) as f32
        };
        let grid: Vec<DVec3> = (0..64)
            .map(|k| {
                let (i, j) = ((k % 8) as f64, (k / 8) as f64);
                DVec3::new(-1.0 + (i + 0.5) / 4.0, -1.0 + (j + 0.5) / 4.0, 4.0)
            })
            .collect();
        let (mut empty, mut empty_inside, mut shadowing) = (0, 0, 0);
        for _ in 0..1000 {
            let c = Vec3::new(rnd() * 4.0 - 2.0, rnd() * 4.0 - 2.0, rnd() * 3.0);
            let mut corner = || c + 0.3 * Vec3::new(rnd(), rnd(), rnd());
            let v = [corner(), corner(), corner()];
            let vol = penumbra_volume(&Caster::new(v, 0, false), &light);
            for _ in 0..50 {
                let o = Vec3::new(rnd() * 8.0 - 4.0, rnd() * 8.0 - 4.0, rnd() * 3.0 - 1.0);
                let inside = vol.holds(o, 1e-5);
                if classified_empty(v, o, &light) {
                    empty += 1;
                    empty_inside += inside as u32;
                }
                let t = v.map(|x| x.as_dvec3());
                if grid.iter().any(|y| crosses(o.as_dvec3(), *y, t)) {
                    shadowing += 1;
                    assert!(inside, "{v:?}: {o} shadowed, outside the volume");
                }
            }
        }
        assert!(empty > 10_000 && shadowing > 500, "{empty} {shadowing}");
        assert_eq!(empty_inside, 0, "of {empty} empty");
    }
}
