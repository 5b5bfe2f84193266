//! Mesh lights: an emissive triangle mesh of any shape (issue 52), for the emissive details of
//! models that are neither planar nor spheres.
//!
//! Sampling is area-weighted: `u.x` picks a triangle through the cumulative areas and is
//! rescaled inside that triangle's interval, then `(u.x', u.y)` maps onto the triangle by the
//! square-root map (`p = (1 - sqrt(s)) a + sqrt(s) (1 - t) b + sqrt(s) t c`), which is
//! area-uniform and continuous inside each triangle, so a stratified pattern stays stratified
//! per triangle (DCS section 5).
//!
//! Conventions (DESIGN section 3, extended):
//! * Each triangle emits from its front side only (counter-clockwise winding): a light sample
//!   whose triangle faces away from a receiver, or is edge-on to it, contributes nothing, as a
//!   receiver behind a planar light gets nothing.
//! * Like every light, a mesh light is an emitter, not an occluder: its own triangles do not
//!   shadow each other. `V(p)` is the share of the whole emitting area that is visible from `p`
//!   through the scene and faces `p`. For a convex emitter this is exactly the visible share;
//!   for a concave one, emitter triangles that face `p` but hide behind other emitter triangles
//!   count as visible. A user who wants the emitter to cast shadows loads it as ordinary
//!   geometry (`--emissive-as-geometry`) or models the fixture around it.

use glam::{Vec2, Vec3};

use super::{AreaLight, LightError, LightGeometry, Radiance, check_finite3};
use crate::geometry::Aabb;

/// An emissive triangle mesh as a light (see the module docs for its conventions).
#[derive(Debug, Clone)]
pub struct MeshLight {
    triangles: Vec<[Vec3; 3]>,
    /// Unit front normal per triangle.
    normals: Vec<Vec3>,
    /// Cumulative area share at the end of each triangle; the last is exactly 1.
    cdf: Vec<f32>,
    /// Texture coordinates per triangle corner, for a textured radiance.
    texcoords: Option<Vec<[Vec2; 3]>>,
    area: f32,
    center: Vec3,
    bounds: Aabb,
    radiance: Radiance,
}

impl MeshLight {
    /// A light from world-space triangles, counter-clockwise around the side they emit to.
    /// Zero-area triangles are dropped (they emit nothing). With `texcoords` (one triple per
    /// input triangle), a textured `radiance` is looked up at the interpolated texture
    /// coordinate (its uv transform should be the identity).
    ///
    /// # Errors
    /// [`LightError::NonFinite`] for a non-finite vertex, [`LightError::InvalidPolygon`] when
    /// no triangle has area or `texcoords` does not match the triangles.
    pub fn new(
        triangles: &[[Vec3; 3]],
        texcoords: Option<&[[Vec2; 3]]>,
        radiance: Radiance,
    ) -> Result<Self, LightError> {
        if texcoords.is_some_and(|t| t.len() != triangles.len()) {
            return Err(LightError::InvalidPolygon(
                "mesh light: one texture-coordinate triple per triangle is needed".into(),
            ));
        }
        let mut kept = Vec::with_capacity(triangles.len());
        let mut kept_tc = texcoords.map(|_| Vec::with_capacity(triangles.len()));
        let mut normals = Vec::with_capacity(triangles.len());
        let mut areas = Vec::with_capacity(triangles.len());
        for (i, t) in triangles.iter().enumerate() {
            for v in t {
                check_finite3(*v, "mesh light vertex")?;
            }
            let c = crate::geometry::triangle_cross_f64(t[0], t[1], t[2]);
            let double_area = c.length();
            if !(double_area > 0.0) || !double_area.is_finite() {
                continue;
            }
            kept.push(*t);
            normals.push((c / double_area).as_vec3());
            areas.push(0.5 * double_area);
            if let (Some(out), Some(tc)) = (kept_tc.as_mut(), texcoords) {
                out.push(tc[i]);
            }
        }
        let total: f64 = areas.iter().sum();
        if kept.is_empty() || !(total > 0.0) || !total.is_finite() {
            return Err(LightError::InvalidPolygon(
                "mesh light has no triangle with area".into(),
            ));
        }
        let mut acc = 0.0;
        let mut cdf: Vec<f32> = areas
            .iter()
            .map(|a| {
                acc += a;
                (acc / total) as f32
            })
            .collect();
        *cdf.last_mut().expect("at least one triangle") = 1.0;
        let center = kept
            .iter()
            .zip(&areas)
            .fold(glam::DVec3::ZERO, |s, (t, a)| {
                s + (t[0].as_dvec3() + t[1].as_dvec3() + t[2].as_dvec3()) * (a / 3.0)
            })
            / total;
        let bounds = Aabb::from_points(&kept.iter().flatten().copied().collect::<Vec<_>>());
        Ok(Self {
            triangles: kept,
            normals,
            cdf,
            texcoords: kept_tc,
            area: total as f32,
            center: center.as_vec3(),
            bounds,
            radiance,
        })
    }

    /// The emitting triangles (zero-area ones dropped), counter-clockwise around their front.
    pub fn triangles(&self) -> &[[Vec3; 3]] {
        &self.triangles
    }

    /// The triangle `u.x` falls in and `u.x` rescaled to `[0, 1]` inside its interval.
    fn pick(&self, x: f32) -> (usize, f32) {
        let i = self
            .cdf
            .partition_point(|c| *c <= x)
            .min(self.cdf.len() - 1);
        let lo = if i == 0 { 0.0 } else { self.cdf[i - 1] };
        let width = self.cdf[i] - lo;
        let s = if width > 0.0 { (x - lo) / width } else { 0.5 };
        (i, s.clamp(0.0, 1.0))
    }
}

impl AreaLight for MeshLight {
    fn geometry(&self) -> LightGeometry<'_> {
        LightGeometry::Mesh {
            triangles: &self.triangles,
            texcoords: self.texcoords.as_deref(),
        }
    }
    fn area(&self) -> f32 {
        self.area
    }
    fn center(&self) -> Vec3 {
        self.center
    }
    fn bounds(&self) -> Aabb {
        self.bounds
    }
    fn point_at(&self, u: Vec2) -> (Vec3, Vec3, Vec2) {
        let (i, s) = self.pick(u.x);
        let r = s.sqrt();
        let (wa, wb, wc) = (1.0 - r, r * (1.0 - u.y), r * u.y);
        let [a, b, c] = self.triangles[i];
        let p = a * wa + b * wb + c * wc;
        let uv = match &self.texcoords {
            Some(tc) => {
                let [ta, tb, tc] = tc[i];
                ta * wa + tb * wb + tc * wc
            }
            None => u,
        };
        (p, self.normals[i], uv)
    }
    fn radiance(&self) -> &Radiance {
        &self.radiance
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tetra_open() -> Vec<[Vec3; 3]> {
        // Three faces of a tetrahedron (a bent, open mesh) plus one degenerate triangle.
        let (o, x, y, z) = (Vec3::ZERO, Vec3::X, Vec3::Y, 2.0 * Vec3::Z);
        vec![[o, y, x], [o, x, z], [o, z, y], [x, x, y]]
    }

    #[test]
    fn samples_are_area_uniform_on_the_surface() {
        let l = MeshLight::new(&tetra_open(), None, Radiance::Constant(Vec3::ONE)).unwrap();
        assert_eq!(l.triangles().len(), 3);
        assert!((l.area() - (0.5 + 1.0 + 1.0)).abs() < 1e-6);
        // A 64x64 stratified grid: the share landing on each face is its area share.
        let n = 64;
        let mut on = [0usize; 3];
        for j in 0..n {
            for i in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let (p, nrm, _) = l.point_at(u);
                let face = if p.z.abs() < 1e-6 {
                    assert_eq!(nrm, Vec3::NEG_Z);
                    0
                } else if p.y.abs() < 1e-6 {
                    assert!((nrm - Vec3::NEG_Y).length() < 1e-6);
                    1
                } else {
                    assert!(p.x.abs() < 1e-6);
                    assert!((nrm - Vec3::NEG_X).length() < 1e-6);
                    2
                };
                on[face] += 1;
                let b = l.bounds();
                assert!(p.cmpge(b.min - 1e-6).all() && p.cmple(b.max + 1e-6).all());
            }
        }
        let share = on.map(|c| c as f32 / (n * n) as f32);
        assert!((share[0] - 0.2).abs() < 0.01, "{share:?}");
        assert!((share[1] - 0.4).abs() < 0.01, "{share:?}");
        // The centre is the area-weighted centroid.
        let c = l.center();
        assert!(c.is_finite());
    }

    #[test]
    fn texture_coordinates_are_interpolated_and_bad_input_refused() {
        let tris = [[Vec3::ZERO, Vec3::X, Vec3::Y]];
        let tc = [[Vec2::ZERO, Vec2::X, Vec2::Y]];
        let l = MeshLight::new(&tris, Some(&tc), Radiance::Constant(Vec3::ONE)).unwrap();
        let (p, _, uv) = l.point_at(Vec2::new(0.3, 0.6));
        assert!((Vec2::new(p.x, p.y) - uv).length() < 1e-6);
        assert!(MeshLight::new(&[[Vec3::ZERO; 3]], None, Radiance::Constant(Vec3::ONE)).is_err());
        assert!(MeshLight::new(&tris, Some(&[]), Radiance::Constant(Vec3::ONE)).is_err());
        let nan = [[Vec3::NAN, Vec3::X, Vec3::Y]];
        assert!(MeshLight::new(&nan, None, Radiance::Constant(Vec3::ONE)).is_err());
    }
}
