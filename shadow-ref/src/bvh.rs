//! The occlusion structure: an `obvhs` compressed wide BVH (CWBVH, Ylitie et al. 2017) over the
//! scene's triangles, traversed with `ray_traverse_miss` for binary occlusion and
//! `ray_traverse_anyhit` for the transmittance product through semi-opaque occluders, with the
//! project's watertight triangle test.
//!
//! Triangle boxes are padded by a relative epsilon before the build, so the float slab tests of
//! the traversal cannot reject a ray that the exact triangle test would accept (flat boxes of
//! axis-aligned triangles and rays through box faces).

use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::aabb::Aabb as BvhAabb;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::Ray;
use obvhs::{Boundable, BvhBuildParams};
use shadow_core::Scene;

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
    /// Transmittance (1 - opacity) in BVH order.
    transmittance: Vec<f32>,
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
        let bvh = obvhs::cwbvh::builder::build_cwbvh(
            &prims,
            BvhBuildParams::slow_build(),
            &mut Duration::default(),
        );
        let ids = &bvh.primitive_indices;
        let tris = ids
            .iter()
            .map(|&t| BvhTriangle {
                v: scene.triangle(t as usize).map(Vec3A::from),
                id: t,
            })
            .collect();
        let transmittance = ids
            .iter()
            .map(|&t| 1.0 - scene.opacities()[t as usize])
            .collect();
        Self {
            bvh,
            tris,
            transmittance,
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

    /// Product of `1 - opacity` over every distinct triangle strictly between `origin` and
    /// `origin + dir * t_max`, `ignore` excepted (0 as soon as an opaque triangle is crossed), and the number of
    /// surfaces crossed.
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
                hits.push(id as u32);
            }
        });
        hits.sort_unstable();
        hits.dedup();
        let t = hits
            .iter()
            .fold(1.0f32, |acc, &h| acc * self.transmittance[h as usize]);
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
