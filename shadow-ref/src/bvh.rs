//! The occlusion structure: an `obvhs` compressed wide BVH (CWBVH, Ylitie et al. 2017) over the
//! scene's triangles, traversed with `ray_traverse_miss` for binary occlusion and
//! `ray_traverse_anyhit` for the transmittance product through semi-opaque occluders, with the
//! project's watertight triangle test.
//!
//! Triangle boxes are padded by a relative epsilon before the build, so the float slab tests of
//! the traversal cannot reject a ray that the exact triangle test would accept (flat boxes of
//! axis-aligned triangles and rays through box faces).

use glam::{Vec3, Vec3A};
use obvhs::aabb::Aabb as BvhAabb;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
use obvhs::ploc::PlocBuilder;
use obvhs::ray::Ray;
use obvhs::{Boundable, BvhBuildParams};
use shadow_core::Scene;

use crate::beam::Beam;
use crate::watertight::ShearedRay;

#[derive(Clone, Copy)]
struct PaddedTriangle {
    min: Vec3A,
    max: Vec3A,
}

impl Boundable for PaddedTriangle {
    fn aabb(&self) -> BvhAabb {
        BvhAabb::new(self.min, self.max)
    }
}

/// A BVH over a scene's triangles answering occlusion queries.
pub struct OcclusionBvh {
    bvh: CwBvh,
    /// Triangles in BVH order (`primitive_indices` applied): three corners and the original id
    /// in one 64-byte record, so a leaf test touches one cache line.
    tris: Vec<BvhTriangle>,
    /// The BVH2 the CWBVH was made from, for beam traversal.
    beam_nodes: Vec<BeamNode>,
    beam_prims: Vec<u32>,
    /// Triangles and transmittances by scene id (candidate tests).
    by_id: Vec<[Vec3A; 3]>,
    transmittance_by_id: Vec<f32>,
}

#[derive(Clone, Copy)]
struct BeamNode {
    min: Vec3A,
    max: Vec3A,
    prim_count: u32,
    first: u32,
}

/// What a beam traversal found for one receiver.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BeamResult {
    /// No triangle can touch the beam: every segment inside it is unoccluded.
    Clear,
    /// These many candidates (written to the output list) may block segments.
    Candidates(usize),
    /// More candidates than the limit: use the per-segment BVH query.
    TooMany,
}

#[derive(Clone, Copy)]
#[repr(C, align(64))]
struct BvhTriangle {
    v: [Vec3A; 3],
    id: u32,
}

impl std::fmt::Debug for OcclusionBvh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OcclusionBvh")
            .field("triangles", &self.tris.len())
            .field("nodes", &self.bvh.nodes.len())
            .finish()
    }
}

impl OcclusionBvh {
    /// Builds the BVH over every triangle of `scene`.
    pub fn build(scene: &dyn Scene) -> Self {
        let extent = scene.bounds().diagonal().max(f32::MIN_POSITIVE);
        let pad = Vec3A::splat(extent * 1e-6);
        let prims: Vec<PaddedTriangle> = (0..scene.triangle_count())
            .map(|t| {
                let [a, b, c] = scene.triangle(t).map(Vec3A::from);
                let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
                let slack = (hi.abs().max(lo.abs())) * 4.0 * f32::EPSILON;
                PaddedTriangle {
                    min: lo - pad - slack,
                    max: hi + pad + slack,
                }
            })
            .collect();
        // obvhs's `build_cwbvh`, step by step, keeping the BVH2 for beam culling.
        let params = BvhBuildParams::slow_build();
        let mut bvh2 = PlocBuilder::with_capacity(prims.len()).build(
            params.ploc_search_distance,
            &prims,
            (0..prims.len() as u32).collect::<Vec<_>>(),
            params.sort_precision,
            params.search_depth_threshold,
        );
        ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
        let bvh = bvh2_to_cwbvh(&bvh2, params.max_prims_per_leaf.clamp(1, 3), true, false);
        let beam_nodes = bvh2
            .nodes
            .iter()
            .map(|n| BeamNode {
                min: n.aabb.min,
                max: n.aabb.max,
                prim_count: n.prim_count,
                first: n.first_index,
            })
            .collect::<Vec<_>>();
        let beam_prims = bvh2.primitive_indices.clone();
        let by_id: Vec<[Vec3A; 3]> = (0..scene.triangle_count())
            .map(|t| scene.triangle(t).map(Vec3A::from))
            .collect();
        let transmittance_by_id: Vec<f32> = scene.opacities().iter().map(|o| 1.0 - o).collect();
        let ids = &bvh.primitive_indices;
        let tris = ids
            .iter()
            .map(|&t| BvhTriangle {
                v: scene.triangle(t as usize).map(Vec3A::from),
                id: t,
            })
            .collect();
        Self {
            bvh,
            tris,
            beam_nodes,
            beam_prims,
            by_id,
            transmittance_by_id,
        }
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// True when some triangle other than `ignore` (the receiver's own triangle, or
    /// `u32::MAX`) lies strictly between `origin` and `origin + dir * t_max`.
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32, ignore: u32) -> bool {
        let (o, d) = ray_parts(origin, dir);
        let sheared = ShearedRay::new(o, d);
        let ray = Ray::new(o, d, 0.0, t_max);
        !self.bvh.ray_traverse_miss(ray, |_, id| {
            let tri = &self.tris[id];
            if tri.id == ignore {
                return f32::INFINITY;
            }
            let [a, b, c] = tri.v;
            sheared
                .intersect(a, b, c, 0.0, t_max)
                .unwrap_or(f32::INFINITY)
        })
    }

    /// The occlusion query with a shadow cache: `last` (a scene triangle id, or `u32::MAX`) is
    /// tested first, and updated to the blocking triangle when the traversal finds one.
    /// Neighbouring samples of a receiver are usually blocked by the same triangle.
    pub fn occluded_cached(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        ignore: u32,
        last: &mut u32,
    ) -> bool {
        let (o, d) = ray_parts(origin, dir);
        let sheared = ShearedRay::new(o, d);
        if *last != u32::MAX {
            let [a, b, c] = self.by_id[*last as usize];
            if sheared.intersect(a, b, c, 0.0, t_max).is_some() {
                return true;
            }
        }
        let ray = Ray::new(o, d, 0.0, t_max);
        let found = std::cell::Cell::new(u32::MAX);
        let miss = self.bvh.ray_traverse_miss(ray, |_, id| {
            let tri = &self.tris[id];
            if tri.id == ignore {
                return f32::INFINITY;
            }
            let [a, b, c] = tri.v;
            match sheared.intersect(a, b, c, 0.0, t_max) {
                Some(t) => {
                    found.set(tri.id);
                    t
                }
                None => f32::INFINITY,
            }
        });
        if !miss {
            *last = found.get();
        }
        !miss
    }

    /// Product of `1 - opacity` over every distinct triangle strictly between `origin` and
    /// `origin + dir * t_max`, `ignore` excepted (0 once an opaque triangle is crossed), and the
    /// number of surfaces crossed.
    pub fn transmittance(&self, origin: Vec3, dir: Vec3, t_max: f32, ignore: u32) -> (f32, u32) {
        let (o, d) = ray_parts(origin, dir);
        let sheared = ShearedRay::new(o, d);
        let ray = Ray::new(o, d, 0.0, t_max);
        let mut hits: Vec<u32> = Vec::new();
        self.bvh.ray_traverse_anyhit(ray, |_, id| {
            let tri = &self.tris[id];
            if tri.id == ignore {
                return;
            }
            let [a, b, c] = tri.v;
            if sheared.intersect(a, b, c, 0.0, t_max).is_some() {
                hits.push(tri.id);
            }
        });
        hits.sort_unstable();
        hits.dedup();
        let t = hits.iter().fold(1.0f32, |acc, &id| {
            acc * self.transmittance_by_id[id as usize]
        });
        (t, hits.len() as u32)
    }

    /// Collects into `out` the triangles (scene ids, `ignore` excepted) that may touch `beam`,
    /// traversing the BVH2; stops at `limit` candidates.
    pub fn beam_candidates(
        &self,
        beam: &Beam,
        ignore: u32,
        limit: usize,
        out: &mut Vec<u32>,
    ) -> BeamResult {
        out.clear();
        if self.beam_nodes.is_empty() {
            return BeamResult::Clear;
        }
        let mut stack = [0u32; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.beam_nodes[stack[top] as usize];
            if beam.box_outside(node.min, node.max) {
                continue;
            }
            if node.prim_count > 0 {
                for k in node.first..node.first + node.prim_count {
                    let id = self.beam_prims[k as usize];
                    if id != ignore && !beam.triangle_outside(&self.by_id[id as usize]) {
                        if out.len() == limit {
                            return BeamResult::TooMany;
                        }
                        out.push(id);
                    }
                }
            } else if top + 2 <= stack.len() {
                stack[top] = node.first;
                stack[top + 1] = node.first + 1;
                top += 2;
            } else {
                // Deeper than the stack: give up on the beam, the per-segment query is exact.
                return BeamResult::TooMany;
            }
        }
        if out.is_empty() {
            BeamResult::Clear
        } else {
            BeamResult::Candidates(out.len())
        }
    }

    /// Segment test against a candidate list: true when one of them blocks it.
    pub fn occluded_by(&self, candidates: &[u32], origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        let (o, d) = ray_parts(origin, dir);
        let sheared = ShearedRay::new(o, d);
        candidates.iter().any(|&id| {
            let [a, b, c] = self.by_id[id as usize];
            sheared.intersect(a, b, c, 0.0, t_max).is_some()
        })
    }

    /// Transmittance product over the candidates a segment crosses, and their count. The
    /// product runs in increasing triangle id, as in [`OcclusionBvh::transmittance`], so both
    /// paths give bit-identical results.
    pub fn transmittance_by(
        &self,
        candidates: &[u32],
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
    ) -> (f32, u32) {
        let (o, d) = ray_parts(origin, dir);
        let sheared = ShearedRay::new(o, d);
        let mut hits: Vec<u32> = candidates
            .iter()
            .copied()
            .filter(|&id| {
                let [a, b, c] = self.by_id[id as usize];
                sheared.intersect(a, b, c, 0.0, t_max).is_some()
            })
            .collect();
        hits.sort_unstable();
        let t = hits.iter().fold(1.0f32, |acc, &id| {
            acc * self.transmittance_by_id[id as usize]
        });
        (t, hits.len() as u32)
    }

    /// Original triangle ids of every triangle the segment crosses (brute-force checks).
    pub fn crossed_triangles(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Vec<u32> {
        let (o, d) = ray_parts(origin, dir);
        let sheared = ShearedRay::new(o, d);
        let mut out: Vec<u32> = (0..self.tris.len())
            .filter(|&i| {
                let [a, b, c] = self.tris[i].v;
                sheared.intersect(a, b, c, 0.0, t_max).is_some()
            })
            .map(|i| self.tris[i].id)
            .collect();
        out.sort_unstable();
        out
    }
}

/// The ray in `obvhs` form. Negative zeros in the direction become positive: `obvhs` takes the
/// octant from `d < 0` but the inverse from the sign bit, and a `-0.0` component would make the
/// two disagree and the slab test reject every box.
fn ray_parts(origin: Vec3, dir: Vec3) -> (Vec3A, Vec3A) {
    (Vec3A::from(origin), Vec3A::from(dir) + Vec3A::ZERO)
}
