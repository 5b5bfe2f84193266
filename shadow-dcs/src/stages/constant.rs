//! The integration constant (DCS section 4.1): the depth complexity from each view sample `p`
//! toward the light centre `c`, computed as in a shadow-volume renderer from the silhouettes
//! alone, never by casting a ray from `p` against the triangles.
//!
//! The shadow-volume quad of a silhouette edge `(a, b)` is the part of the plane through `c`
//! and the edge beyond the edge, away from `c`. The depth complexity `D(x, c)` of a point `x`
//! changes only when `x` crosses such a quad (the segment `x c` sweeps across the edge), by the
//! edge's weight `k_e` (`SceneEdge::sweep_weight`), or when `x` crosses a surface.
//! The segment from the eye to a visible point crosses no surface, so (z-pass):
//!
//! `D(p, c) = D(eye, c) + sum of k_e over the quads the eye segment crosses before p`.
//!
//! Quads are scan-converted whole into the camera image (`CoveredPolygon`: one run of pixels
//! per row and quad) with the core rasterizer's coverage rule (a pixel on an edge shared by
//! two quads is counted once); at each covered pixel an exact
//! orientation test decides whether the quad's plane lies between the eye and the view sample
//! (the depth test of a stencil shadow volume). `D(eye, c)` is the only ray-cast value: one
//! segment per frame. Quads end at a radius from `c` beyond every view sample and the eye, with
//! the far vertices shared between neighbouring quads, and the camera's near plane is moved
//! to almost zero, so no crossing is lost to clipping.

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use shadow_core::clip::clip_polygon;
use shadow_core::raster::{CoveredPolygon, Projection, RasterView};
use shadow_core::scene::Scene;

use shadow_core::geometry::ray_hits_triangle;

use crate::stages::edges::{SceneEdge, Sides};

/// Far vertices lie at this many times the largest eye or sample distance from `c`: a quad's
/// far edge is a chord, and it stays beyond every view sample unless the edge subtends more
/// than 178 degrees from the light centre (an occluder touching the centre).
const FAR_FACTOR: f64 = 64.0;

/// Relative error bound of a quad's plane value in single precision around the light centre,
/// against `|n| . |p'|`: the rounding of the normal, of the centred point and of three products
/// and two sums is below `1e-6` of it.
const SIDE_BOUND: f32 = 1e-5;

/// Rows per band of the parallel quad rasterization.
const SV_BAND: u32 = 8;

/// `D(eye, c)`: the weighted crossings of the segment from the eye to the light centre, with the
/// faces counted from the light's side (front faces of one-sided meshes, every face of
/// two-sided ones).
pub(crate) fn eye_constant(
    scene: &dyn Scene,
    edges_units: u32,
    sides: &Sides,
    eye: Vec3,
    c: Vec3,
) -> i64 {
    let (o, target) = (eye.as_dvec3(), c.as_dvec3());
    let d = target - o;
    let rule = CrossingRule::new(scene, edges_units, sides, target);
    (0..scene.triangle_count())
        .into_par_iter()
        .map(|t| {
            let [a, b, cc] = scene.triangle(t).map(|v| v.as_dvec3());
            if !ray_hits_triangle(o, d, a, b, cc, 1.0) {
                return 0;
            }
            rule.weight(t)
        })
        .sum()
}

/// What a segment toward the light centre adds to a depth complexity where it crosses a
/// triangle (section 4.1 with section 6's opacities).
pub(crate) struct CrossingRule<'s> {
    scene: &'s dyn Scene,
    units: u32,
    /// Which faces count from one side and which are tested explicitly.
    sides: &'s Sides,
    target: DVec3,
    semi: bool,
}

impl<'s> CrossingRule<'s> {
    /// The rule for segments toward `target` in `scene`, opacities in `units` per face, the
    /// faces counted as `sides` says.
    pub(crate) fn new(scene: &'s dyn Scene, units: u32, sides: &'s Sides, target: DVec3) -> Self {
        Self {
            scene,
            units,
            sides,
            target,
            semi: scene.has_semi_opaque(),
        }
    }

    /// The weight of triangle `t`: 0 for the back (from the light) of a one-sided mesh and for
    /// a triangle tested explicitly, else 1, or its opacity in units when the scene is
    /// semi-opaque.
    pub(crate) fn weight(&self, t: usize) -> i64 {
        if self.sides.explicit[t] {
            return 0;
        }
        let [a, b, cc] = self.scene.triangle(t).map(|v| v.as_dvec3());
        let one_sided = self.sides.one_sided[self.scene.topology().component_of(t)];
        let front_from_light = (b - a).cross(cc - a).dot(self.target - a) > 0.0;
        if one_sided && !front_from_light {
            0
        } else if self.semi {
            (self.scene.opacities()[t].clamp(0.0, 1.0) * self.units as f32).ceil() as i64
        } else {
            1
        }
    }
}

/// The integration constant of every pixel (0 for background), by rasterizing the
/// shadow-volume quads of `silhouettes` (edges seen from the light centre).
///
/// Returns the constants and the number of quads rasterized.
#[expect(
    clippy::too_many_arguments,
    reason = "the shadow-volume step reads the edges, the light centre, the eye and three per-pixel arrays together"
)]
pub(crate) fn integration_constants(
    edges: &[SceneEdge],
    silhouettes: &[u32],
    c: Vec3,
    eye: Vec3,
    eye_constant: i64,
    view: &RasterView,
    origins: &[Vec3],
    centred: &[Vec3],
    valid: &[bool],
) -> (Vec<i64>, u64) {
    let cd = c.as_dvec3();
    let eyed = eye.as_dvec3();
    // The farthest view sample from the centre and the box around the eye and the view
    // samples, in one parallel pass.
    let (reach, (lo, hi)) = origins
        .par_iter()
        .zip(valid)
        .filter(|(_, v)| **v)
        .map(|(p, _)| {
            let p = p.as_dvec3();
            ((p - cd).length(), (p, p))
        })
        .reduce(
            || ((eyed - cd).length(), (eyed, eyed)),
            |(r1, (lo1, hi1)), (r2, (lo2, hi2))| (r1.max(r2), (lo1.min(lo2), hi1.max(hi2))),
        );
    let far_radius = reach * FAR_FACTOR;
    // Every crossing that counts lies on a segment from the eye to a view sample, so inside the
    // box around the eye and the view samples: quads are clipped to it (with a margin that keeps
    // counted crossings away from the cut).
    let margin = DVec3::splat((hi - lo).length() * 1e-3 + 1e-9 * reach.max(1.0));
    let (lo, hi) = (lo - margin, hi + margin);
    // The quads with a non-zero weight, seen from the eye, clipped to the box.
    let far = |v: DVec3| -> Option<DVec3> {
        let d = v - cd;
        let l = d.length();
        (l > 0.0).then(|| cd + d * (far_radius / l))
    };
    type Quad = (Vec<Vec3>, i64, DVec3, bool);
    let quads: Vec<Quad> = silhouettes
        .par_iter()
        .filter_map(|&i| {
            let e = &edges[i as usize];
            let k = e.sweep_weight(cd, eyed, true)?;
            if k == 0 {
                return None;
            }
            let eye_side = super::edges::orient(cd, e.a, e.b, eyed);
            if eye_side == 0.0 {
                return None;
            }
            let (af, bf) = (far(e.a)?, far(e.b)?);
            let poly = clip_to_box(&[e.a, e.b, bf, af], lo, hi);
            if poly.len() < 3 {
                return None;
            }
            Some((
                poly.iter().map(|v| v.as_vec3()).collect(),
                k,
                // orient(c, a, b, x) = normal . (x - c), the normal computed once.
                (e.a - cd).cross(e.b - cd),
                eye_side > 0.0,
            ))
        })
        .collect();
    let near_view = near_zero(view, far_radius);
    let w = view.width as usize;
    let n = origins.len();
    // Each quad set up once as a whole polygon (one run per row, not one per fan triangle),
    // then binned by bands of rows: every band sums its own rows, so no image-sized
    // accumulator is merged.
    let polygons: Vec<CoveredPolygon> = quads
        .par_iter()
        .map(|(q, ..)| CoveredPolygon::new(&near_view, q))
        .collect();
    let bands = view.height.div_ceil(SV_BAND) as usize;
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); bands];
    for (qi, poly) in polygons.iter().enumerate() {
        if let Some((y0, y1)) = poly.rows() {
            let last = ((y1 / SV_BAND) as usize).min(bands.saturating_sub(1));
            for bin in &mut bins[(y0 / SV_BAND) as usize..=last] {
                bin.push(qi as u32);
            }
        }
    }
    // The quads' planes in single precision around the light centre, with the bound of the
    // rounding of a plane value there (`SIDE_BOUND |n| . |p'|`); a value within it is taken
    // again in double precision.
    let sides: Vec<(Vec3, Vec3)> = quads
        .iter()
        .map(|(_, _, normal, _)| {
            let scale = normal.abs().max_element();
            let n = if scale > 0.0 {
                *normal / scale
            } else {
                *normal
            };
            (n.as_vec3(), n.abs().as_vec3() * SIDE_BOUND)
        })
        .collect();
    let mut sums = vec![0i64; n];
    sums.par_chunks_mut(SV_BAND as usize * w)
        .zip(&bins)
        .enumerate()
        .for_each(|(band, (acc, bin))| {
            let y0 = band as u32 * SV_BAND;
            let y1 = y0 + SV_BAND - 1;
            let first = y0 as usize * w;
            for &qi in bin {
                let (_, k, normal, eye_positive) = &quads[qi as usize];
                let (nf, bound) = sides[qi as usize];
                polygons[qi as usize].for_each_span_in_rows(y0, y1, |y, x0, x1| {
                    let row = y as usize * w;
                    for i in row + x0 as usize..=row + x1 as usize {
                        if !valid[i] {
                            continue;
                        }
                        // orient(c, a, b, p) = normal . (p - c): which side of the quad's plane.
                        let pc = centred[i];
                        let v = nf.dot(pc);
                        let side = if v.abs() > bound.dot(pc.abs()) {
                            f64::from(v)
                        } else {
                            normal.dot(origins[i].as_dvec3() - cd)
                        };
                        if side != 0.0 && (side > 0.0) != *eye_positive {
                            acc[i - first] += k;
                        }
                    }
                });
            }
        });
    let out = sums
        .into_par_iter()
        .zip(valid)
        .map(|(s, v)| if *v { s + eye_constant } else { 0 })
        .collect();
    (out, quads.len() as u64)
}

/// The part of the convex planar polygon `poly` inside the box `lo..hi` (Sutherland-Hodgman).
/// Each crossing is interpolated from the lexicographically smaller end point of its segment,
/// so polygons sharing an edge get bit-identical clipped vertices there and the rasterizer's
/// shared-edge rule still counts a pixel on it once.
fn clip_to_box(poly: &[DVec3], lo: DVec3, hi: DVec3) -> Vec<DVec3> {
    let mut cur: Vec<DVec3> = poly.to_vec();
    let mut next = Vec::with_capacity(poly.len() + 6);
    for axis in 0..3 {
        for (bound, keep_below) in [(lo[axis], false), (hi[axis], true)] {
            if cur.is_empty() {
                return cur;
            }
            let inside = |v: DVec3| {
                if keep_below {
                    v[axis] <= bound
                } else {
                    v[axis] >= bound
                }
            };
            let crossing = |a: DVec3, b: DVec3| {
                let (p, q) = if a.to_array() < b.to_array() {
                    (a, b)
                } else {
                    (b, a)
                };
                let t = (bound - p[axis]) / (q[axis] - p[axis]);
                let mut x = p + (q - p) * t;
                x[axis] = bound;
                x
            };
            clip_polygon(&cur, &mut next, inside, crossing);
            std::mem::swap(&mut cur, &mut next);
        }
    }
    cur
}

/// The camera view with its near plane moved to almost zero (perspective), so that quads
/// crossing the eye segment just in front of the eye are not clipped away.
fn near_zero(view: &RasterView, scale: f64) -> RasterView {
    let mut v = *view;
    if let Projection::Perspective { near, .. } = &mut v.projection {
        *near = near.min((scale * 1e-9) as f32).max(f32::MIN_POSITIVE * 1e6);
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stages::edges::{Sides, Silhouettes, scene_edges, silhouettes};
    use crate::stages::light_shape::LightShape;
    use shadow_core::light::{Radiance, RectLight};
    use shadow_core::prelude::*;
    use shadow_scenes::procedural;

    /// The integration constant equals the ray-cast count of faces turned away from `p` that
    /// the segment from `p` to the light centre crosses, on closed meshes.
    #[test]
    fn integration_constant_matches_ray_cast_crossings_on_closed_meshes() {
        let mut b = SceneBuilder::new();
        for m in [
            procedural::floor(6.0, 0.0),
            procedural::cuboid(Vec3::new(-0.8, 0.6, -0.5), Vec3::new(0.2, 1.0, 0.4), false),
            procedural::uv_sphere(Vec3::new(0.4, 1.6, 0.2), 0.35, 12, 18),
            procedural::cuboid(Vec3::new(-0.3, 2.2, -0.6), Vec3::new(0.9, 2.4, 0.5), false),
        ] {
            b.push_mesh(MeshDesc::new(m.0, m.1)).unwrap();
        }
        let scene = b.build().unwrap();
        let light = RectLight::facing(
            Vec3::new(0.1, 4.0, 0.0),
            Vec3::NEG_Y,
            1.0,
            1.0,
            Radiance::constant(Vec3::ONE).unwrap(),
        )
        .unwrap();
        let cam = Camera::look_at(
            Vec3::new(0.0, 3.0, 6.0),
            Vec3::new(0.0, 0.6, 0.0),
            Vec3::Y,
            0.9,
        )
        .unwrap();
        let view = ViewSamples::render(&scene, &cam, 64, 48).unwrap();
        let shape = LightShape::new(&light, "test").unwrap();
        let one_sided = Sides::new(&scene, &shape);
        let (edges, units) = scene_edges(&scene, &one_sided);
        let sil = silhouettes(&edges, &shape, Silhouettes::Accurate);
        let origins: Vec<Vec3> = (0..view.len())
            .map(|i| {
                view.get(i)
                    .map_or(Vec3::ZERO, |s| s.position + s.geometric_normal * 1e-4)
            })
            .collect();
        let valid = view.valid_mask();
        let (eye, camera) = view.perspective().unwrap();
        let eye_c = eye_constant(&scene, units, &one_sided, eye, shape.center);
        let centred: Vec<Vec3> = origins
            .iter()
            .map(|o| (o.as_dvec3() - shape.center.as_dvec3()).as_vec3())
            .collect();
        let (got, quads) = integration_constants(
            &edges,
            &sil,
            shape.center,
            eye,
            eye_c,
            camera,
            &origins,
            &centred,
            &valid,
        );
        assert!(quads > 10);
        let c = shape.center.as_dvec3();
        let (mut checked, mut shadowed) = (0, 0);
        for i in 0..view.len() {
            if !valid[i] {
                continue;
            }
            let p = origins[i].as_dvec3();
            let mut want = 0i64;
            for t in 0..scene.triangle_count() {
                let [a, b, cc] = scene.triangle(t).map(|v| v.as_dvec3());
                let back = (b - a).cross(cc - a).dot(p - a) < 0.0;
                let closed = one_sided.one_sided[scene.topology().component_of(t)];
                if (!closed || back) && ray_hits_triangle(p, c - p, a, b, cc, 1.0) {
                    want += 1;
                }
            }
            assert_eq!(got[i], want, "pixel {i}");
            checked += 1;
            shadowed += (want > 0) as u32;
        }
        assert!(checked > 1000 && shadowed > 100, "{checked} {shadowed}");
    }
}
