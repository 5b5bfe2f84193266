//! The occlusion structure. A binned SAH build ([`crate::sah`]) gives the binary tree, `obvhs`
//! reinserts its nodes and compresses it into a wide BVH (CWBVH, Ylitie et al. 2017); the
//! queries are:
//!
//! * binary occlusion on the wide tree (sixteen children per node) collapsed from the same
//!   BVH2 ([`crate::wide`]),
//!   with the project's watertight triangle test four triangles at a time; the CWBVH's
//!   `ray_traverse_miss` answers the same query ([`OcclusionBvh::occluded_cwbvh`], tested to
//!   agree on every segment) and takes over when a tree is too deep for the wide tree's stack;
//! * the transmittance product through semi-opaque occluders with `ray_traverse_anyhit`;
//! * beam culling: one traversal of the wide tree with a receiver's pyramid
//!   ([`crate::beam`]) gives its candidate triangles, packed four to a test.
//!
//! Triangle boxes are padded by a relative epsilon before the build, so the float slab tests of
//! the traversal cannot reject a ray that the exact triangle test would accept (flat boxes of
//! axis-aligned triangles and rays through box faces).

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb as BvhAabb;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::bvh2_to_cwbvh::bvh2_to_cwbvh;
use obvhs::ray::Ray;
use shadow_core::Scene;

use crate::beam::Beam;
use crate::watertight::{ShearedRay, Triangles4};
use crate::wide::WideBvh;

/// A BVH over a scene's triangles answering occlusion queries.
pub struct OcclusionBvh {
    bvh: CwBvh,
    /// Triangles in BVH order (`primitive_indices` applied): three corners and the original id
    /// in one 64-byte record, so a leaf test touches one cache line.
    tris: Vec<BvhTriangle>,
    /// The same tree collapsed to four children per node, for the single-ray occlusion query
    /// (`None` when it cannot be represented; the CWBVH answers then), and the triangles in its
    /// leaf order.
    wide: Option<WideBvh>,
    wide_leaves: Vec<WideLeaf>,
    /// Triangles and transmittances by scene id (candidate tests).
    by_id: Vec<[Vec3A; 3]>,
    transmittance_by_id: Vec<f32>,
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

/// The candidate triangles of one beam, packed four to a [`Triangles4`] so each segment tests
/// four at once; a partly filled last pack repeats its first triangle.
#[derive(Debug, Clone, Default)]
pub struct BeamCandidates {
    packs: Vec<Triangles4>,
    ids: Vec<u32>,
}

impl BeamCandidates {
    /// Number of candidates.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    fn clear(&mut self) {
        self.packs.clear();
        self.ids.clear();
    }

    fn push(&mut self, tri: [Vec3A; 3], id: u32) {
        let lane = self.ids.len() % 4;
        if lane == 0 {
            self.packs.push(Triangles4::pack(&[tri]));
        } else if let Some(p) = self.packs.last_mut() {
            p.set_lane(lane, tri);
        }
        self.ids.push(id);
    }

    /// Lanes of pack `k` that hold candidates.
    fn valid(&self, k: usize) -> u32 {
        let n = self.ids.len() - 4 * k;
        if n >= 4 { 0xf } else { (1 << n) - 1 }
    }
}

/// A leaf of the wide tree: its triangles for the four-triangle test and their scene ids
/// (padding lanes repeat the first triangle and its id).
#[derive(Clone, Copy)]
struct WideLeaf {
    tris: Triangles4,
    id: [u32; 4],
    /// Lanes that hold triangles.
    valid: u32,
}

/// Most triangles per leaf of the wide tree (measured: see `docs/benchmarks.md`).
const WIDE_LEAF: usize = 4;

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
        // Each triangle's box, padded by its own rounding and a millionth of the scene.
        let boxes: Vec<BvhAabb> = (0..scene.triangle_count())
            .map(|t| {
                let [a, b, c] = scene.triangle(t).map(Vec3A::from);
                let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
                let slack = (hi.abs().max(lo.abs())) * 4.0 * f32::EPSILON;
                BvhAabb::new(lo - pad - slack, hi + pad + slack)
            })
            .collect();
        // obvhs's `build_cwbvh`, step by step, keeping the BVH2 for beam culling; the BVH2
        // from the binned SAH build rather than PLOC (quadratic on needle fans, `crate::sah`).
        let params = BvhBuildParams::slow_build();
        let mut bvh2 = crate::sah::build(&boxes);
        ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
        let bvh = bvh2_to_cwbvh(&bvh2, params.max_prims_per_leaf.clamp(1, 3), true, false);
        let wide = WideBvh::collapse(&bvh2, WIDE_LEAF);
        let record = |t: u32| BvhTriangle {
            v: scene.triangle(t as usize).map(Vec3A::from),
            id: t,
        };
        let wide_leaves = wide.as_ref().map_or_else(Vec::new, |w| {
            w.leaves()
                .map(|ids| {
                    let tris: Vec<[Vec3A; 3]> = ids
                        .iter()
                        .map(|&t| scene.triangle(t as usize).map(Vec3A::from))
                        .collect();
                    let mut id = [ids[0]; 4];
                    id[..ids.len()].copy_from_slice(ids);
                    WideLeaf {
                        tris: Triangles4::pack(&tris),
                        id,
                        valid: (1 << ids.len()) - 1,
                    }
                })
                .collect()
        });
        let by_id: Vec<[Vec3A; 3]> = (0..scene.triangle_count())
            .map(|t| scene.triangle(t).map(Vec3A::from))
            .collect();
        let transmittance_by_id: Vec<f32> = scene.opacities().iter().map(|o| 1.0 - o).collect();
        let ids = &bvh.primitive_indices;
        let tris = ids.iter().map(|&t| record(t)).collect();
        Self {
            bvh,
            tris,
            wide,
            wide_leaves,
            by_id,
            transmittance_by_id,
        }
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// True when some triangle other than `ignore` (the receiver's own triangle, or
    /// `u32::MAX`) lies strictly between `origin` and `origin + dir * t_max`. Traverses the
    /// wide tree ([`crate::wide`]) when there is one, else the CWBVH.
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32, ignore: u32) -> bool {
        let mut last = u32::MAX;
        self.occluded_cached(origin, dir, t_max, ignore, &mut last)
    }

    /// The same query on the `obvhs` CWBVH with `ray_traverse_miss`, whatever the wide tree
    /// (for cross-checks and the benchmark).
    pub fn occluded_cwbvh(&self, origin: Vec3, dir: Vec3, t_max: f32, ignore: u32) -> bool {
        let (o, d) = ray_parts(origin, dir);
        let sheared = ShearedRay::new(o, d);
        self.cwbvh_blocker(&sheared, o, d, t_max, ignore).is_some()
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
        let found = match &self.wide {
            Some(w) => {
                let mut found = None;
                w.any_hit(o, d, t_max, |leaf| {
                    let leaf = &self.wide_leaves[leaf];
                    let mut hits = sheared.intersect4(&leaf.tris, t_max);
                    while hits != 0 {
                        let id = leaf.id[hits.trailing_zeros() as usize];
                        hits &= hits - 1;
                        if id != ignore {
                            found = Some(id);
                            return true;
                        }
                    }
                    false
                });
                found
            }
            None => self.cwbvh_blocker(&sheared, o, d, t_max, ignore),
        };
        if let Some(id) = found {
            *last = id;
        }
        found.is_some()
    }

    /// A triangle (scene id) blocking the segment, found on the CWBVH.
    fn cwbvh_blocker(
        &self,
        sheared: &ShearedRay,
        o: Vec3A,
        d: Vec3A,
        t_max: f32,
        ignore: u32,
    ) -> Option<u32> {
        let ray = Ray::new(o, d, 0.0, t_max);
        let mut found = None;
        self.bvh.ray_traverse_miss(ray, |_, id| {
            let tri = &self.tris[id];
            if tri.id == ignore {
                return f32::INFINITY;
            }
            let [a, b, c] = tri.v;
            match sheared.intersect(a, b, c, 0.0, t_max) {
                Some(t) => {
                    found = Some(tri.id);
                    t
                }
                None => f32::INFINITY,
            }
        });
        found
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

    /// Collects into `out` the triangles (`ignore` excepted) that may touch `beam`, traversing
    /// the wide tree with four-wide box and triangle tests; stops at `limit` candidates.
    /// Without a wide tree every beam is [`BeamResult::TooMany`] (the per-segment query on
    /// the CWBVH answers).
    pub fn beam_candidates(
        &self,
        beam: &Beam,
        ignore: u32,
        limit: usize,
        out: &mut BeamCandidates,
    ) -> BeamResult {
        out.clear();
        if self.tris.is_empty() {
            return BeamResult::Clear;
        }
        let Some(w) = &self.wide else {
            return BeamResult::TooMany;
        };
        let complete = w.visit(
            |b| beam.boxes_outside4(b),
            |leaf| {
                let leaf = &self.wide_leaves[leaf];
                let mut keep = leaf.valid & !beam.triangles_outside4(&leaf.tris);
                while keep != 0 {
                    let lane = keep.trailing_zeros() as usize;
                    keep &= keep - 1;
                    if leaf.id[lane] == ignore {
                        continue;
                    }
                    if out.len() == limit {
                        return false;
                    }
                    out.push(leaf.tris.lane(lane), leaf.id[lane]);
                }
                true
            },
        );
        if !complete {
            BeamResult::TooMany
        } else if out.is_empty() {
            BeamResult::Clear
        } else {
            BeamResult::Candidates(out.len())
        }
    }

    /// Segment test against a candidate list: true when one of them blocks it.
    pub fn occluded_by(
        &self,
        candidates: &BeamCandidates,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
    ) -> bool {
        let (o, d) = ray_parts(origin, dir);
        let sheared = ShearedRay::new(o, d);
        candidates
            .packs
            .iter()
            .any(|p| sheared.intersect4(p, t_max) != 0)
    }

    /// Transmittance product over the candidates a segment crosses, and their count. The
    /// product runs in increasing triangle id, as in [`OcclusionBvh::transmittance`], so both
    /// paths give bit-identical results.
    pub fn transmittance_by(
        &self,
        candidates: &BeamCandidates,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
    ) -> (f32, u32) {
        let (o, d) = ray_parts(origin, dir);
        let sheared = ShearedRay::new(o, d);
        let mut hits: Vec<u32> = Vec::new();
        for (k, p) in candidates.packs.iter().enumerate() {
            let mut m = sheared.intersect4(p, t_max) & candidates.valid(k);
            while m != 0 {
                let lane = m.trailing_zeros() as usize;
                m &= m - 1;
                hits.push(candidates.ids[4 * k + lane]);
            }
        }
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
