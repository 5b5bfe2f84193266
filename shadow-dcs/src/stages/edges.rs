//! Scene edges and silhouette detection per light (DCS section 4.1).
//!
//! Depth complexity here is the weighted number of surfaces a segment from a view sample `p` to
//! a light sample crosses, counting on a closed, consistently oriented mesh only the faces
//! turned away from `p` (one per silhouette loop the segment passes through, as the paper
//! counts) and on any other mesh every face: an open surface is treated as a two-sided closed
//! shell, so the count stays a correct number of occluding layers whatever the topology. A closed
//! mesh that contains the light centre is treated as two-sided as well (a segment may enter it
//! without leaving), and so is one whose bounds overlap the light's: a light sample inside it,
//! or a light partly set into it, is reached by a segment that enters the mesh and never
//! leaves, which the one-sided count would miss (`Sides`); a face the light passes through
//! is tested against each sample's segment instead. Weights are 1 for opaque scenes; with semi-opaque occluders each face
//! weighs its opacity in units of `1/OPACITY_UNITS` (the paper's discretised opaqueness, section
//! 4.4).
//!
//! An edge changes the depth complexity seen from `p` only where it is a silhouette of the
//! crossing point (both adjacent faces on one side of the plane through the point and the
//! edge). Detection keeps the edges for which that can happen somewhere on the light:
//! * **accurate** (after Laine et al. 2005, as DCS section 4.1 adopts it): part of the light lies
//!   on the positive side of one face's plane and part on the negative side of the other's;
//! * **standard**: the edge is a silhouette seen from the light centre (the single-sample
//!   detection whose under-estimated penumbra is the artifact of Fig. 4).
//!
//! Boundary and non-manifold edges, and edges whose faces differ in weight, always count.

use glam::DVec3;
use shadow_core::geometry::Aabb;
use shadow_core::scene::Scene;
use shadow_core::topology::EdgeKind;

use crate::stages::light_shape::LightShape;

/// Opacity units of one fully opaque surface when the scene has semi-opaque occluders.
pub const OPACITY_UNITS: u32 = 255;

/// How silhouette edges are detected (DCS section 4.1, Fig. 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Silhouettes {
    /// Against the whole light: no single-light-sample artifact.
    Accurate,
    /// From the light centre only (the classic shadow-volume silhouette).
    Standard,
}

/// One face next to an edge.
#[derive(Debug, Clone, Copy)]
pub(crate) struct EdgeFace {
    /// The face's vertex opposite the edge.
    pub third: DVec3,
    /// Plane of the face with its stored winding: `normal . x + offset > 0` in front.
    pub normal: DVec3,
    pub offset: f64,
    /// Weight of one crossing (1, or opacity units).
    pub weight: u32,
    /// Counted from both sides (open meshes and the like).
    pub two_sided: bool,
}

/// An edge with its faces.
#[derive(Debug, Clone)]
pub(crate) struct SceneEdge {
    pub a: DVec3,
    pub b: DVec3,
    pub faces: Vec<EdgeFace>,
    pub always: bool,
}

/// Signed volume `det[b - a, c - a, d - a]` (positive when `d` lies on the side of plane
/// `a, b, c` its normal `(b - a) x (c - a)` points to).
#[inline]
pub(crate) fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    (b - a).cross(c - a).dot(d - a)
}

impl SceneEdge {
    /// A boundary edge `a b` of one two-sided face with third vertex `third` (always a
    /// silhouette): what tests build edges from.
    #[cfg(test)]
    pub fn boundary(a: DVec3, b: DVec3, third: DVec3) -> Self {
        let normal = (b - a).cross(third - a);
        Self {
            a,
            b,
            faces: vec![EdgeFace {
                third,
                normal,
                offset: -normal.dot(a),
                weight: 1,
                two_sided: true,
            }],
            always: true,
        }
    }

    /// `k_e`: the change of a depth complexity when a segment from the fixed end `x` sweeps
    /// across the edge, its other end leaving the side of plane `(x, a, b)` where `from` lies.
    /// Each counted face adds its weight when the sweep moves onto the face's side and subtracts
    /// it when the sweep moves off it. Every face of a two-sided mesh counts; a face of a
    /// one-sided mesh counts when `x` sees its back (`x` is a view sample: the faces crossed
    /// toward the light are turned away from it) or, with `x_is_light`, its front (`x` is the
    /// light centre). `None` on a tie (`from` or a face on the plane).
    pub fn sweep_weight(&self, x: DVec3, from: DVec3, x_is_light: bool) -> Option<i64> {
        let m = (self.a - x).cross(self.b - x);
        let side_from = m.dot(from - x);
        if side_from == 0.0 || !side_from.is_finite() {
            return None;
        }
        let mut k = 0i64;
        for f in &self.faces {
            let front = f.normal.dot(x) + f.offset > 0.0;
            let counted = f.two_sided || front == x_is_light;
            if !counted {
                continue;
            }
            let side = m.dot(f.third - x);
            if side == 0.0 {
                return None;
            }
            // Moving from `from`'s side to the other: onto the face's side when it differs.
            if (side > 0.0) == (side_from > 0.0) {
                k -= f.weight as i64;
            } else {
                k += f.weight as i64;
            }
        }
        Some(k)
    }
}

/// How a light's depth complexities count the scene's faces: which components count from one
/// side, and which triangles the pass tests against every sample explicitly.
#[derive(Debug, Clone, Default)]
pub(crate) struct Sides {
    /// Per topology component: a closed, consistently oriented mesh whose bounding box does
    /// not overlap the light's counts only the faces turned away from the receiver. A segment
    /// from a receiver outside such a mesh to a light sample outside it leaves it as often as
    /// it enters, so that counts each layer once; a mesh that holds the light centre, a light
    /// sample or part of the light (a lamp in a closed housing, a panel set into a ceiling
    /// slab) breaks it, and counts both sides.
    pub one_sided: Vec<bool>,
    /// Per triangle: the triangle may meet the light itself, or shares an edge with one that
    /// may. Where the light's surface passes through a face, a segment's end crosses the face
    /// as the light sample moves, with no silhouette edge between (the count jumps along the
    /// light, not at a wedge): such faces weigh nothing in the edges and the integration
    /// constant and are tested against each sample's segment instead
    /// ([`Sides::explicit_list`]).
    pub explicit: Vec<bool>,
    /// The indices of the `explicit` triangles.
    pub explicit_list: Vec<u32>,
}

impl Sides {
    /// The sides for the light of `shape` in `scene`.
    pub(crate) fn new(scene: &dyn Scene, shape: &LightShape) -> Self {
        let topo = scene.topology();
        let mut bounds = vec![Aabb::empty(); topo.components().len()];
        for t in 0..scene.triangle_count() {
            let b = &mut bounds[topo.component_of(t)];
            for p in scene.triangle(t) {
                *b = b.grow(p);
            }
        }
        let light = Aabb::from_points(&shape.hull).grow(shape.center);
        let one_sided = topo
            .components()
            .iter()
            .zip(&bounds)
            .map(|(comp, b)| comp.closed && comp.consistently_oriented && !overlap(b, &light))
            .collect();
        let meets: Vec<bool> = (0..scene.triangle_count())
            .map(|t| may_meet_light(scene.triangle(t), shape, &light))
            .collect();
        // With their neighbours across an edge: the edges a meeting face shares lie on the
        // light or through its centre (a panel flush with a face, a light centred on a wall),
        // where a wedge from the centre degenerates; the neighbours' far edges do not.
        let mut explicit = meets.clone();
        if meets.iter().any(|m| *m) {
            for e in 0..topo.edge_count() {
                let faces = topo.faces(e);
                if faces.iter().any(|&t| meets[t as usize]) {
                    for &t in faces {
                        explicit[t as usize] = true;
                    }
                }
            }
        }
        let explicit_list = (0..explicit.len() as u32)
            .filter(|&t| explicit[t as usize])
            .collect();
        Self {
            one_sided,
            explicit,
            explicit_list,
        }
    }

    /// Every closed mesh one-sided and no explicit triangle (tests of the grid alone).
    #[cfg(test)]
    pub(crate) fn closed_one_sided(scene: &dyn Scene) -> Self {
        let topo = scene.topology();
        Self {
            one_sided: topo
                .components()
                .iter()
                .map(|c| c.closed && c.consistently_oriented)
                .collect(),
            explicit: vec![false; scene.triangle_count()],
            explicit_list: Vec::new(),
        }
    }
}

fn overlap(a: &Aabb, b: &Aabb) -> bool {
    !(a.max.cmplt(b.min).any() || b.max.cmplt(a.min).any())
}

/// Whether triangle `t` may meet the light of `shape` (bounds `light`): the boxes overlap and
/// the triangle's plane passes through the light's hull (conservative: a triangle that does not
/// is never reported).
fn may_meet_light(t: [glam::Vec3; 3], shape: &LightShape, light: &Aabb) -> bool {
    if !overlap(&Aabb::from_points(&t), light) {
        return false;
    }
    let [a, b, c] = t.map(|v| v.as_dvec3());
    let n = (b - a).cross(c - a);
    let (mut below, mut above) = (false, false);
    for p in shape.hull.iter().chain(std::iter::once(&shape.center)) {
        let d = n.dot(p.as_dvec3() - a);
        below |= d <= 0.0;
        above |= d >= 0.0;
    }
    below && above
}

/// Every edge of the scene with its faces, weights and two-sidedness under `sides`.
pub(crate) fn scene_edges(scene: &dyn Scene, sides: &Sides) -> (Vec<SceneEdge>, u32) {
    let one_sided = &sides.one_sided;
    let topo = scene.topology();
    let positions = scene.positions();
    let tris = scene.triangles();
    let opac = scene.opacities();
    let semi = scene.has_semi_opaque();
    let units = if semi { OPACITY_UNITS } else { 1 };
    let weight = |t: usize| -> u32 {
        if sides.explicit[t] {
            0
        } else if semi {
            (opac[t].clamp(0.0, 1.0) * OPACITY_UNITS as f32).ceil() as u32
        } else {
            1
        }
    };
    let mut out = Vec::with_capacity(topo.edge_count());
    for e in 0..topo.edge_count() {
        let [ia, ib] = topo.edge(e);
        let a = positions[ia as usize].as_dvec3();
        let b = positions[ib as usize].as_dvec3();
        let faces: Vec<EdgeFace> = topo
            .faces(e)
            .iter()
            .map(|&t| {
                let t = t as usize;
                let [i0, i1, i2] = tris[t];
                let third = [i0, i1, i2]
                    .into_iter()
                    .find(|&v| v != ia && v != ib)
                    .unwrap_or(i2);
                let (v0, v1, v2) = (
                    positions[i0 as usize].as_dvec3(),
                    positions[i1 as usize].as_dvec3(),
                    positions[i2 as usize].as_dvec3(),
                );
                let normal = (v1 - v0).cross(v2 - v0);
                EdgeFace {
                    third: positions[third as usize].as_dvec3(),
                    normal,
                    offset: -normal.dot(v0),
                    weight: weight(t),
                    two_sided: !one_sided[topo.component_of(t)],
                }
            })
            .collect();
        let always = topo.kind(e) != EdgeKind::Manifold
            || faces.windows(2).any(|w| w[0].weight != w[1].weight);
        if faces.iter().all(|f| f.weight == 0) {
            continue;
        }
        out.push(SceneEdge {
            a,
            b,
            faces,
            always,
        });
    }
    (out, units)
}

/// The silhouette edges of `edges` for a light (indices into `edges`).
pub(crate) fn silhouettes(edges: &[SceneEdge], light: &LightShape, mode: Silhouettes) -> Vec<u32> {
    let c = light.center.as_dvec3();
    edges
        .iter()
        .enumerate()
        .filter(|(_, e)| {
            if e.always {
                return true;
            }
            let [f1, f2] = [&e.faces[0], &e.faces[1]];
            // f_i(q) = orient(q, a, b, w_i): linear in q; the edge is a silhouette from q when
            // both faces lie on one side of the plane through q and the edge.
            let plane = |w: DVec3| {
                // orient(q, a, b, w) = -orient(w, a, b, q) = -((a - w) x (b - w)) . (q - w)
                let n = -(e.a - w).cross(e.b - w);
                (n, -n.dot(w))
            };
            let (n1, d1) = plane(f1.third);
            let (n2, d2) = plane(f2.third);
            match mode {
                Silhouettes::Standard => {
                    let g1 = n1.dot(c) + d1;
                    let g2 = n2.dot(c) + d2;
                    g1 * g2 > 0.0
                }
                Silhouettes::Accurate => {
                    let (lo1, hi1) = light.range(n1, d1);
                    let (lo2, hi2) = light.range(n2, d2);
                    (hi1 > 0.0 && hi2 > 0.0) || (lo1 < 0.0 && lo2 < 0.0)
                }
            }
        })
        .map(|(i, _)| i as u32)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use shadow_core::light::{Radiance, RectLight};
    use shadow_core::prelude::*;
    use shadow_scenes::procedural;

    fn scene_of(m: procedural::Mesh) -> TriangleScene {
        let mut b = SceneBuilder::new();
        b.push_mesh(MeshDesc::new(m.0, m.1)).unwrap();
        b.build().unwrap()
    }

    /// Silhouette from `q` by the definition: both faces on one side of the plane through `q`
    /// and the edge.
    fn fold_from(e: &SceneEdge, q: DVec3) -> bool {
        let s1 = orient(q, e.a, e.b, e.faces[0].third);
        let s2 = orient(q, e.a, e.b, e.faces[1].third);
        s1 * s2 > 0.0
    }

    #[test]
    fn silhouettes_of_a_cube_and_a_sphere_match_brute_force() {
        let light = RectLight::facing(
            Vec3::new(0.3, 3.0, 0.2),
            Vec3::NEG_Y,
            2.0,
            1.5,
            Radiance::constant(Vec3::ONE).unwrap(),
        )
        .unwrap();
        let shape = LightShape::new(&light, "test").unwrap();
        let corners = light.corners();
        for mesh in [
            procedural::cuboid(Vec3::splat(-0.5), Vec3::splat(0.5), false),
            procedural::uv_sphere(Vec3::ZERO, 0.6, 10, 16),
        ] {
            let scene = scene_of(mesh);
            let (edges, _) = scene_edges(&scene, &Sides::new(&scene, &shape));
            let accurate = silhouettes(&edges, &shape, Silhouettes::Accurate);
            let standard = silhouettes(&edges, &shape, Silhouettes::Standard);
            let c = shape.center.as_dvec3();
            // Standard: exactly the edges folded from the centre.
            let want_std: Vec<u32> = (0..edges.len() as u32)
                .filter(|&i| fold_from(&edges[i as usize], c))
                .collect();
            assert_eq!(standard, want_std);
            // Brute force over a dense grid of light points.
            let mut brute = vec![false; edges.len()];
            let n = 40;
            for i in 0..=n {
                for j in 0..=n {
                    let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                    let q =
                        corners[0] + (corners[1] - corners[0]) * u + (corners[3] - corners[0]) * v;
                    for (k, e) in edges.iter().enumerate() {
                        brute[k] |= fold_from(e, q.as_dvec3());
                    }
                }
            }
            let brute: Vec<u32> = (0..edges.len() as u32)
                .filter(|&i| brute[i as usize])
                .collect();
            // Accurate detection finds every silhouette of some light point, and more than
            // the centre's.
            assert!(brute.iter().all(|e| accurate.contains(e)));
            assert!(accurate.len() > standard.len());
            // The per-plane test is conservative (the two faces may see opposite sides of the
            // light from different points); it never keeps an edge whose faces both see the
            // whole light from one side of their planes.
            for &i in &accurate {
                let e = &edges[i as usize];
                let sides: Vec<(bool, bool)> = corners
                    .iter()
                    .map(|q| {
                        let q = q.as_dvec3();
                        let f = |w: DVec3| orient(q, e.a, e.b, w) > 0.0;
                        (f(e.faces[0].third), f(e.faces[1].third))
                    })
                    .collect();
                let (p1, n1) = (sides.iter().any(|s| s.0), sides.iter().any(|s| !s.0));
                let (p2, n2) = (sides.iter().any(|s| s.1), sides.iter().any(|s| !s.1));
                assert!((p1 && p2) || (n1 && n2), "edge {i}");
            }
        }
    }
}
