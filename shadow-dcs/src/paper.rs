//! DCS as the paper writes it: Algorithm 2 for one light with Algorithm 1 inside (Forest,
//! Barthe and Paulin 2008, sections 4.1 and 4.2), in double precision and plain integers, with
//! no search structure, no single-precision forms, no packed counters and no tables. It is the
//! oracle the optimised technique ([`crate::Dcs`]) is checked against, sample by sample, the way
//! the AFSM GPU stages are checked against their CPU computation; it is slow on purpose.
//!
//! 1. The silhouette edges of the scene for the light (section 4.1: accurate or standard).
//! 2. The integration constant `D(p, c)` of every view sample: the depth complexity toward the
//!    light centre from the shadow-volume step (section 4.1), the same stage the technique uses.
//! 3. Algorithm 1, wedge by wedge: for each silhouette edge `e` and each view sample `p` inside
//!    its wedge, the edge's weight `k_e(p)` (positive on the outer part of the wedge, negative on
//!    the inner part, split by the shadow-volume quad); then for every light sample `s`, when
//!    `e` projected from `p` covers `s` (the edge crosses the triangle `(p, c, s)`: the segment
//!    from `p` to a light point moving from `c` to `s` sweeps across `e`), the counter of `s`
//!    changes by `k_e(p)`. The counters are plain `i64`, so no order of outer and inner wedges
//!    (section 4.4) is needed.
//! 4. A sample below the receiver's tangent plane is occluded; a sample is visible when its depth
//!    complexity is 0 (eq. 1).
//!
//! Every orientation that decides a covered sample is compared with a band of `1e-6` of its
//! magnitude; a (pixel, sample) pair that one of them falls in is a numerical tie, reported as
//! such, where rounding may decide either way in any implementation.

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use shadow_core::geometry::ray_hits_triangle;
use shadow_core::light::AreaLight;
use shadow_core::offset::RayOffset;
use shadow_core::prelude::*;
use shadow_core::technique::UnsupportedReason;

use crate::stages::constant::{eye_constant, integration_constants};
use crate::stages::edges::{SceneEdge, Sides, Silhouettes, scene_edges, silhouettes};
use crate::stages::light_shape::LightShape;
use crate::stages::wedges::{Plane, wedge_planes};

/// The depth complexity of a sample below the receiver's tangent plane (occluded without a
/// count).
pub const BELOW_HORIZON: i64 = i64::MAX;

/// Relative band around zero inside which an orientation is a numerical tie.
const TIE_BAND: f64 = 1e-6;

/// Per (pixel, sample) depth complexities of a view, computed as the paper writes it.
#[derive(Debug, Clone)]
pub struct PaperDepthComplexity {
    /// Light samples per pixel.
    pub samples: u32,
    /// Per pixel and sample (pixel-major): the depth complexity in the technique's units (one
    /// per opaque surface, [`crate::stages::edges::OPACITY_UNITS`] per surface with semi-opaque
    /// occluders), [`BELOW_HORIZON`] for a sample below the tangent plane, 0 on background.
    pub depth: Vec<i64>,
    /// Per pixel and sample: a numerical tie decided the count.
    pub tie: Vec<bool>,
    /// Silhouette edges the frame used.
    pub silhouette_edges: usize,
    /// (pixel, edge) pairs whose pixel lies in the edge's wedge.
    pub wedge_pairs: u64,
}

impl PaperDepthComplexity {
    /// Whether sample `k` of pixel `pixel` sees the light.
    pub fn visible(&self, pixel: usize, k: u32) -> bool {
        self.depth[pixel * self.samples as usize + k as usize] == 0
    }
}

/// `orient(p, q, r, s)` and whether it lies within the tie band of its magnitude.
fn orient_tie(p: DVec3, q: DVec3, r: DVec3, s: DVec3) -> (f64, bool) {
    let (u, v, w) = (q - p, r - p, s - p);
    let o = u.cross(v).dot(w);
    let scale = u.length() * v.length() * w.length();
    (o, !(o.abs() > TIE_BAND * scale))
}

/// Whether the edge `a b` crosses the triangle `(p, c, s)`, and whether a tie decided it: `a`
/// and `b` strictly on both sides of the triangle's plane, and the line `a b` strictly inside
/// the triangle's three sides.
fn covers(p: DVec3, c: DVec3, s: DVec3, a: DVec3, b: DVec3) -> (bool, bool) {
    let (da, ta) = orient_tie(p, c, s, a);
    let (db, tb) = orient_tie(p, c, s, b);
    let (s1, t1) = orient_tie(a, b, p, c);
    let (s2, t2) = orient_tie(a, b, c, s);
    let (s3, t3) = orient_tie(a, b, s, p);
    let straddles = (da > 0.0) != (db > 0.0) && da != 0.0 && db != 0.0;
    let inside = (s1 > 0.0 && s2 > 0.0 && s3 > 0.0) || (s1 < 0.0 && s2 < 0.0 && s3 < 0.0);
    // A tie matters only where the other tests leave the answer open.
    let tie = (ta || tb) && inside || (t1 || t2 || t3) && straddles;
    (straddles && inside, tie)
}

/// The depth complexity of every light sample of every view sample of `view` from `light`, by
/// the paper's algorithm with the samples of `sampler` and `detection` silhouettes.
///
/// # Errors
/// [`TechniqueError::Unsupported`] for orthographic views (the shadow-volume step counts quads
/// from an eye point) and for lights without area.
pub fn paper_depth_complexity(
    scene: &dyn Scene,
    light: &dyn AreaLight,
    sampler: &LightSampler,
    detection: Silhouettes,
    view: &ViewSamples,
) -> Result<PaperDepthComplexity, TechniqueError> {
    const NAME: &str = "dcs-paper";
    let (eye, camera) = view.perspective().ok_or_else(|| {
        TechniqueError::unsupported(
            NAME,
            UnsupportedReason::View("orthographic views and receivers without a camera".into()),
        )
    })?;
    let shape = LightShape::new(light, NAME)?;
    let c = shape.center;
    let cd = c.as_dvec3();
    // Section 4.1: silhouettes for the light.
    let one_sided = Sides::new(scene, &shape);
    let (edges, units) = scene_edges(scene, &one_sided);
    let sil = silhouettes(&edges, &shape, detection);
    // The view samples' origins, offset off their surfaces as the reference's are.
    let offset = RayOffset::for_light(light);
    let n = view.len();
    let origins: Vec<Vec3> = (0..n)
        .map(|i| {
            view.get(i).map_or(Vec3::ZERO, |s| {
                offset.offset(s.position, s.geometric_normal)
            })
        })
        .collect();
    let valid: Vec<bool> = (0..n).map(|i| view.get(i).is_some()).collect();
    let centred: Vec<Vec3> = origins
        .iter()
        .map(|o| (o.as_dvec3() - cd).as_vec3())
        .collect();
    // Section 4.1: the integration constant from the shadow-volume step.
    let eye_c = eye_constant(scene, units, &one_sided, eye, c);
    let (constants, _) = integration_constants(
        &edges, &sil, c, eye, eye_c, camera, &origins, &centred, &valid,
    );
    // Algorithm 1, per wedge: the wedge's bounding half-spaces.
    let wedges: Vec<(&SceneEdge, Vec<Plane>)> = sil
        .iter()
        .map(|&i| {
            let e = &edges[i as usize];
            (e, wedge_planes(e, &shape))
        })
        .collect();
    let samples = sampler.count() as usize;
    let per_pixel: Vec<(Vec<i64>, Vec<bool>, u64)> = (0..n)
        .into_par_iter()
        .map(|i| {
            let mut depth = vec![0i64; samples];
            let mut tie = vec![false; samples];
            let Some(s) = view.get(i) else {
                return (depth, tie, 0);
            };
            let origin = origins[i];
            let o = origin.as_dvec3();
            let (mut units_uv, mut lights) = (Vec::new(), Vec::new());
            sampler.unit_samples(s.pixel, &mut units_uv);
            light.sample_into(&units_uv, &mut lights);
            depth.fill(constants[i]);
            let mut pairs = 0u64;
            for (e, planes) in &wedges {
                if !planes.iter().all(|pl| pl.contains(o)) {
                    continue;
                }
                pairs += 1;
                let Some(k) = e.sweep_weight(o, cd, false) else {
                    // The view sample lies on the plane through the edge and the light centre.
                    tie.fill(true);
                    continue;
                };
                if k == 0 {
                    continue;
                }
                for (j, y) in lights.iter().enumerate() {
                    let (covered, t) = covers(o, cd, y.position.as_dvec3(), e.a, e.b);
                    tie[j] |= t;
                    if covered {
                        depth[j] += k;
                    }
                }
            }
            // The faces the light may pass through, each tested against each sample's segment
            // (stopping short of the sample as the reference's does): no wedge carries them.
            for &t in &one_sided.explicit_list {
                let [a, b, cc] = scene.triangle(t as usize).map(|v| v.as_dvec3());
                let k = if units == 1 {
                    1
                } else {
                    (scene.opacities()[t as usize].clamp(0.0, 1.0) * units as f32).ceil() as i64
                };
                for (j, y) in lights.iter().enumerate() {
                    if ray_hits_triangle(o, y.position.as_dvec3() - o, a, b, cc, 1.0 - 1e-6) {
                        depth[j] += k;
                    }
                }
            }
            // Below the tangent plane (from the surface point and from the offset origin, as
            // the reference tests it): occluded.
            let nrm = s.geometric_normal;
            for (j, y) in lights.iter().enumerate() {
                if !((y.position - s.position).dot(nrm) > 0.0
                    && (y.position - origin).dot(nrm) > 0.0)
                {
                    depth[j] = BELOW_HORIZON;
                }
            }
            (depth, tie, pairs)
        })
        .collect();
    let mut out = PaperDepthComplexity {
        samples: samples as u32,
        depth: Vec::with_capacity(n * samples),
        tie: Vec::with_capacity(n * samples),
        silhouette_edges: sil.len(),
        wedge_pairs: 0,
    };
    for (d, t, p) in per_pixel {
        out.depth.extend(d);
        out.tie.extend(t);
        out.wedge_pairs += p;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An edge across the middle of the triangle covers; one beside it, or one short of the
    /// triangle's plane on one side, does not; one through a vertex is a tie.
    #[test]
    fn an_edge_covers_a_sample_when_it_crosses_the_triangle() {
        let (p, c, s) = (
            DVec3::ZERO,
            DVec3::new(0.0, 2.0, 0.0),
            DVec3::new(1.0, 2.0, 0.0),
        );
        // The triangle lies in z = 0; an edge along z through (0.3, 1.5).
        let across = (DVec3::new(0.3, 1.5, -1.0), DVec3::new(0.3, 1.5, 1.0));
        assert_eq!(covers(p, c, s, across.0, across.1), (true, false));
        let beside = (DVec3::new(2.0, 1.5, -1.0), DVec3::new(2.0, 1.5, 1.0));
        assert_eq!(covers(p, c, s, beside.0, beside.1), (false, false));
        let short = (DVec3::new(0.3, 1.5, 0.5), DVec3::new(0.3, 1.5, 1.0));
        assert_eq!(covers(p, c, s, short.0, short.1), (false, false));
        let through_c = (DVec3::new(0.0, 2.0, -1.0), DVec3::new(0.0, 2.0, 1.0));
        assert!(covers(p, c, s, through_c.0, through_c.1).1);
    }
}
