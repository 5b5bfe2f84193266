//! The light's view for the shadow map (GBP07 section 3: the frustum from the light's centre,
//! near plane parallel to the light) and the window of it a map must cover.
//!
//! **Windows.** A map holds its receivers' projections (points at unit depth) widened by the
//! margin every budget was measured at ([`LightView::fitted`]), and every surface able to stand
//! between one of them and the light. In view coordinates `(x, y, d)` (`d` the depth below the
//! light's plane) the light lies within `|x|, |y| <= w_l / 2` at `d = 0`, and a point
//! `(1 - t) l + t r` of the segment from a light point `l` to a receiver `r` (depth `z_r`, at
//! most the deepest `D`) projecting within `[lo, hi]` has depth `d = t z_r` and satisfies
//! `lo.x d - (1 - d / D) w_l / 2 <= x <= hi.x d + (1 - d / D) w_l / 2` (and likewise in `y`):
//! four half-spaces, whose intersection with `near <= d <= D` holds every occluder (the pyramid
//! of GBP07 eq. 1, bounded by a box). Each triangle is clipped to that region and the map
//! reaches the clipped pieces' projections ([`LightView::occluder_bounds`]). The fitted margin
//! alone, `w_l / (2 z_min)` with `z_min` the nearest vertex in front of the light, missed the
//! nearer points of triangles crossing the light's plane: the walls of a fixture around a
//! recessed light, which shadow the tops of a room's walls.
//!
//! **Reach.** One map from the light's centre cannot hold a scene that spreads to the light's
//! own plane: receivers or occluders `theta` off the light's axis project `tan theta` from it,
//! and the square map that holds them spends its texels on a field `tan theta` wide. Issue 51's
//! Cornell box (a recessed light, walls rising to 9 cm below it, a fixture around it) needs a
//! window reaching 89 degrees off the axis (55 units; 13, or 85.7 degrees, for the receivers
//! alone); on it the shadow-map presets gave RMSE 0.15 to 0.53 against the reference at 48x36
//! and 96x72 with one map, and 0.13 to 0.29 with one map per octave of receiver depth (tried and
//! dropped: `docs/history/ssm-wide-scenes-2026-12-06.md`). The built-in and stress scenes reach
//! at most 79.6 degrees (`large-light-close`, a window 4.95 units wide each side of -0.48),
//! where every preset holds its budget. Beyond [`MAX_OFF_AXIS_DEGREES`] the techniques refuse
//! the scene with that reason rather than give a wrong image.

use glam::{Affine3A, DVec2, DVec3, Vec2, Vec3};
use rayon::prelude::*;
use shadow_core::raster::{Projection, RasterView};
use shadow_core::scene::Scene;

use crate::light_frame::LightFrame;

/// Farthest a map's window may reach off the light's axis, along either of its axes (see the
/// module docs: the built-in and stress scenes reach 79.6 degrees and hold their budgets; the
/// Cornell box's receivers alone reach 85.7 and fail).
pub const MAX_OFF_AXIS_DEGREES: f32 = 82.0;

/// The light's view, shared by every map of a set: the transform into view space (looking
/// down `-Z` along the light's axis), the near plane, and the scene's vertices in
/// `(x, y, depth)` view coordinates.
#[derive(Debug, Clone)]
pub struct LightView {
    /// World to view space.
    pub view_from_world: Affine3A,
    /// Near-plane depth.
    pub near: f32,
    /// Light width `w_l` (GBP07 eq. 1).
    width: f32,
    /// Vertices as `(x, y, depth)`.
    vertices: Vec<Vec3>,
    /// The nearest vertex depth in front of the light's plane.
    z_min: f32,
    /// Every vertex lies in front of the near plane.
    all_in_front: bool,
}

/// A square window of the map's unit-depth plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    /// Centre.
    pub mid: Vec2,
    /// Half side.
    pub half: f32,
}

impl Window {
    /// How far the window reaches off the light's axis along either of its axes, in degrees.
    pub fn off_axis_degrees(&self) -> f32 {
        (self.mid.abs().max_element() + self.half)
            .atan()
            .to_degrees()
    }
}

impl LightView {
    /// The view of `frame` over `scene`.
    pub fn new(scene: &dyn Scene, frame: &LightFrame) -> Self {
        let (mut x, mut y) = frame.basis;
        if x.cross(y).dot(frame.axis) > 0.0 {
            std::mem::swap(&mut x, &mut y);
        }
        let world_from_view = Affine3A::from_cols(
            x.into(),
            y.into(),
            (-frame.axis).into(),
            frame.center.into(),
        );
        let view_from_world = world_from_view.inverse();
        let extent = scene.bounds().diagonal().max(f32::MIN_POSITIVE);
        let vertices: Vec<Vec3> = scene
            .positions()
            .iter()
            .map(|p| {
                let v = view_from_world.transform_point3(*p);
                Vec3::new(v.x, v.y, -v.z)
            })
            .collect();
        // The nearest vertex in front of the light plane sets the near plane.
        let z_min = vertices
            .iter()
            .map(|v| v.z)
            .filter(|d| *d > 0.0)
            .fold(f32::INFINITY, f32::min);
        let near = (1e-3 * extent).min(0.5 * z_min).max(1e-7 * extent);
        let all_in_front = vertices.iter().all(|v| v.z > near);
        Self {
            view_from_world,
            near,
            width: frame.width,
            vertices,
            z_min,
            all_in_front,
        }
    }

    /// The window of receivers at depths up to `deepest` projecting within `[lo, hi]`: the
    /// square bounding the fitted frustum ([`LightView::fitted`]) and every surface that can
    /// stand between one of the receivers and the light ([`LightView::occluder_bounds`]).
    pub fn window(&self, triangles: &[[u32; 3]], lo: Vec2, hi: Vec2, deepest: f32) -> Window {
        let (flo, fhi) = self.fitted(lo, hi);
        let (olo, ohi) = self.occluder_bounds(triangles, lo, hi, deepest);
        let (glo, ghi) = (
            flo.as_dvec2().min(olo).min(lo.as_dvec2()),
            fhi.as_dvec2().max(ohi).max(hi.as_dvec2()),
        );
        Window {
            mid: ((glo + ghi) * 0.5).as_vec2(),
            half: ((ghi - glo).max_element().max(1e-6) * 0.5) as f32,
        }
    }

    /// The frustum every budget was measured at: the receivers' square widened by
    /// `w_l / (2 z_min)`, `z_min` the nearest vertex in front of the light. When that margin is
    /// wider than the receivers' extent, as under a wide light with a small view, the map
    /// reaches as far as the margin (a cap here lost occluders beside the view) and no farther
    /// than the geometry projects. The filters' kernel caps (`MAX_KERNEL`, `MAX_WIDTH`) are
    /// sized for these texels: a much finer map sends kernels past them.
    pub fn fitted(&self, lo: Vec2, hi: Vec2) -> (Vec2, Vec2) {
        let size = (hi - lo).max_element().max(1e-6);
        let margin = self.width / (2.0 * self.z_min.max(self.near));
        if margin <= size {
            let c = (lo + hi) * 0.5;
            let half = size * 0.5 + margin;
            return (c - half, c + half);
        }
        let (mut glo, mut ghi) = (lo - margin, hi + margin);
        // With a vertex behind the near plane a triangle's projection is not bounded by its
        // vertices' projections in front: the margin alone bounds the map then.
        if self.all_in_front {
            let (mut plo, mut phi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
            for v in &self.vertices {
                let q = Vec2::new(v.x / v.z, v.y / v.z);
                plo = plo.min(q);
                phi = phi.max(q);
            }
            if plo.x <= phi.x {
                glo = glo.max(plo.min(lo));
                ghi = ghi.min(phi.max(hi));
            }
        }
        (glo, ghi)
    }

    /// Bounds of the projections of every surface that can stand between the light and a
    /// receiver at depth up to `deepest` projecting within `[lo, hi]` (the region of the module
    /// docs, each triangle clipped to it); empty (infinite bounds) when none can.
    pub fn occluder_bounds(
        &self,
        triangles: &[[u32; 3]],
        lo: Vec2,
        hi: Vec2,
        deepest: f32,
    ) -> (DVec2, DVec2) {
        let (lo, hi) = (lo.as_dvec2(), hi.as_dvec2());
        let half_light = 0.5 * self.width as f64;
        // The light-receiver region as `n . (x, y, d) + c >= 0`; the light's half width
        // shrinks to nothing at the deepest receiver (`s` per unit of depth).
        let s = half_light / deepest as f64;
        let planes = [
            (DVec3::new(1.0, 0.0, -lo.x - s), half_light),
            (DVec3::new(-1.0, 0.0, hi.x - s), half_light),
            (DVec3::new(0.0, 1.0, -lo.y - s), half_light),
            (DVec3::new(0.0, -1.0, hi.y - s), half_light),
            (DVec3::Z, -(self.near as f64)),
            (DVec3::NEG_Z, deepest as f64),
        ];
        let empty = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        triangles
            .par_iter()
            .map(|t| {
                let v = t.map(|i| self.vertices[i as usize].as_dvec3());
                clipped_projection(&v, &planes).unwrap_or(empty)
            })
            .reduce(|| empty, |a, b| (a.0.min(b.0), a.1.max(b.1)))
    }

    /// The raster view of `window` at `resolution` texels a side.
    pub fn raster_view(&self, window: Window, resolution: u32) -> RasterView {
        RasterView {
            width: resolution,
            height: resolution,
            view_from_world: self.view_from_world,
            projection: Projection::Perspective {
                left: window.mid.x - window.half,
                right: window.mid.x + window.half,
                bottom: window.mid.y - window.half,
                top: window.mid.y + window.half,
                near: self.near,
            },
        }
    }
}

/// The bounds of the projection (`(x, y) / depth`) of the part of triangle `v` (view
/// coordinates `(x, y, depth)`) inside `planes` (Sutherland-Hodgman), `None` when nothing is
/// left. The planes keep depth positive, so the clipped polygon projects to the hull of its
/// vertices' projections.
fn clipped_projection(v: &[DVec3; 3], planes: &[(DVec3, f64); 6]) -> Option<(DVec2, DVec2)> {
    // Each plane adds at most one vertex: 3 + 6.
    let mut poly = [DVec3::ZERO; 9];
    let mut next = [DVec3::ZERO; 9];
    poly[..3].copy_from_slice(v);
    let mut n = 3;
    for (normal, offset) in planes {
        let side = |p: DVec3| normal.dot(p) + offset;
        // Most triangles lie wholly inside a plane (the clip would keep every vertex) or
        // wholly outside (it would keep none): the same result without the copies.
        let inside = poly[..n].iter().filter(|&&p| side(p) >= 0.0).count();
        if inside == n {
            continue;
        }
        if inside == 0 {
            return None;
        }
        let mut m = 0;
        for i in 0..n {
            let (a, b) = (poly[i], poly[(i + 1) % n]);
            let (sa, sb) = (side(a), side(b));
            if sa >= 0.0 {
                next[m] = a;
                m += 1;
            }
            if (sa >= 0.0) != (sb >= 0.0) {
                next[m] = a + (b - a) * (sa / (sa - sb));
                m += 1;
            }
        }
        n = m;
        if n == 0 {
            return None;
        }
        poly[..n].copy_from_slice(&next[..n]);
    }
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for p in &poly[..n] {
        let q = DVec2::new(p.x, p.y) / p.z;
        lo = lo.min(q);
        hi = hi.max(q);
    }
    Some((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wall_beside_the_light_enters_the_window_only_where_it_can_occlude() {
        // Light 0.4 wide (reach 0.2); receivers projecting within |q| <= 0.5 down to depth 2.
        // A wall at x = 0.8 from depth 0.1 to 2 can stand between them and the light only where
        // 0.8 <= 0.5 d + 0.2 (1 - d / 2) = 0.4 d + 0.2, i.e. below depth 1.5, where it projects
        // within 0.8 / 2 <= x/d <= 0.8 / 1.5.
        let v = [
            DVec3::new(0.8, -1.0, 0.1),
            DVec3::new(0.8, 1.0, 0.1),
            DVec3::new(0.8, 0.0, 2.0),
        ];
        let planes = [
            (DVec3::new(1.0, 0.0, 0.4), 0.2),
            (DVec3::new(-1.0, 0.0, 0.4), 0.2),
            (DVec3::new(0.0, 1.0, 0.4), 0.2),
            (DVec3::new(0.0, -1.0, 0.4), 0.2),
            (DVec3::Z, -1e-3),
            (DVec3::NEG_Z, 2.0),
        ];
        let (lo, hi) = clipped_projection(&v, &planes).unwrap();
        assert!(
            (hi.x - 0.8 / 1.5).abs() < 1e-9 && (lo.x - 0.4).abs() < 1e-9,
            "{lo} {hi}"
        );
        // Beyond the light's reach: nothing.
        let far = v.map(|p| p + DVec3::new(5.0, 0.0, 0.0));
        assert!(clipped_projection(&far, &planes).is_none());
    }
}
