//! Planar polygon lights, convex or concave, triangulated with `spade`'s constrained Delaunay
//! triangulation so that sampling is area-uniform over any simple outline.

use glam::{DVec2, Vec2, Vec3};

use super::{AreaLight, LightError, LightGeometry, Radiance, check_finite3};
use crate::geometry::{Aabb, orthonormal_basis, polygon_signed_area};

/// A planar simple polygon light, counter-clockwise around its normal.
#[derive(Debug, Clone)]
pub struct PolygonLight {
    outline: Vec<Vec3>,
    normal: Vec3,
    origin: Vec3,
    tangent: Vec3,
    bitangent: Vec3,
    /// uv = (local - uv_min) / uv_size.
    uv_min: Vec2,
    uv_size: Vec2,
    /// Triangles in local 2D coordinates with their cumulative area fractions.
    triangles: Vec<[Vec2; 3]>,
    cdf: Vec<f32>,
    area: f32,
    center: Vec3,
    radiance: Radiance,
}

impl PolygonLight {
    /// A polygon light from its outline (either winding; the normal follows the winding by the
    /// right-hand rule).
    ///
    /// # Errors
    /// [`LightError::InvalidPolygon`] when the outline has fewer than three vertices, is not
    /// planar (a vertex further than 1e-4 of its diameter from the best-fit plane), repeats a
    /// vertex, intersects itself or has no area; [`LightError::NonFinite`] for NaN or Inf.
    pub fn new(outline: Vec<Vec3>, radiance: Radiance) -> Result<Self, LightError> {
        if outline.len() < 3 {
            return Err(LightError::InvalidPolygon(format!(
                "{} vertices, need at least 3",
                outline.len()
            )));
        }
        for p in &outline {
            check_finite3(*p, "polygon vertex")?;
        }
        // Newell's normal: robust for concave outlines.
        let mut n = glam::DVec3::ZERO;
        for i in 0..outline.len() {
            let (p, q) = (
                outline[i].as_dvec3(),
                outline[(i + 1) % outline.len()].as_dvec3(),
            );
            n += glam::DVec3::new(
                (p.y - q.y) * (p.z + q.z),
                (p.z - q.z) * (p.x + q.x),
                (p.x - q.x) * (p.y + q.y),
            );
        }
        let normal = n
            .try_normalize()
            .ok_or_else(|| LightError::InvalidPolygon("outline has no area".into()))?
            .as_vec3();
        let origin = outline.iter().fold(Vec3::ZERO, |a, p| a + *p) / outline.len() as f32;
        let diameter = Aabb::from_points(&outline).diagonal();
        if let Some(p) = outline
            .iter()
            .find(|p| (**p - origin).dot(normal).abs() > 1e-4 * diameter)
        {
            return Err(LightError::InvalidPolygon(format!(
                "vertex {p:?} is off the polygon's plane"
            )));
        }
        let (tangent, bitangent) = orthonormal_basis(normal);
        let local: Vec<Vec2> = outline
            .iter()
            .map(|p| Vec2::new((*p - origin).dot(tangent), (*p - origin).dot(bitangent)))
            .collect();
        let signed = polygon_signed_area(&local);
        if !(signed > 0.0) {
            return Err(LightError::InvalidPolygon("outline has no area".into()));
        }
        let outline2: Vec<glam::DVec2> = local.iter().map(|p| p.as_dvec2()).collect();
        let triangles: Vec<[Vec2; 3]> = crate::triangulate::triangulate_simple(&outline2)
            .map_err(|e| LightError::InvalidPolygon(e.to_string()))?
            .into_iter()
            .map(|t| t.map(|i| local[i]))
            .collect();
        let areas: Vec<f64> = triangles
            .iter()
            .map(|t| 0.5 * (t[1] - t[0]).as_dvec2().perp_dot((t[2] - t[0]).as_dvec2()))
            .collect();
        let total: f64 = areas.iter().sum();
        let mut acc = 0.0;
        let cdf = areas
            .iter()
            .map(|a| {
                acc += a;
                (acc / total) as f32
            })
            .collect();
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for p in &local {
            lo = lo.min(*p);
            hi = hi.max(*p);
        }
        let centroid = area_centroid(&local);
        Ok(Self {
            center: origin + centroid.x * tangent + centroid.y * bitangent,
            outline,
            normal,
            origin,
            tangent,
            bitangent,
            uv_min: lo,
            uv_size: (hi - lo).max(Vec2::splat(f32::MIN_POSITIVE)),
            triangles,
            cdf,
            area: signed as f32,
            radiance,
        })
    }

    /// The same light with another radiance.
    #[must_use]
    pub fn with_radiance(mut self, radiance: Radiance) -> Self {
        self.radiance = radiance;
        self
    }

    /// Number of triangles of the internal triangulation.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Maps a world point on the light's plane to the light's uv.
    pub fn uv_of(&self, p: Vec3) -> Vec2 {
        let l = Vec2::new(
            (p - self.origin).dot(self.tangent),
            (p - self.origin).dot(self.bitangent),
        );
        (l - self.uv_min) / self.uv_size
    }
}

fn area_centroid(poly: &[Vec2]) -> Vec2 {
    let (mut c, mut a) = (DVec2::ZERO, 0.0);
    for i in 0..poly.len() {
        let (p, q) = (poly[i].as_dvec2(), poly[(i + 1) % poly.len()].as_dvec2());
        let cross = p.perp_dot(q);
        a += cross;
        c += (p + q) * cross;
    }
    (c / (3.0 * a)).as_vec2()
}

impl AreaLight for PolygonLight {
    fn geometry(&self) -> LightGeometry<'_> {
        LightGeometry::Polygon {
            outline: &self.outline,
            normal: self.normal,
        }
    }
    fn area(&self) -> f32 {
        self.area
    }
    fn center(&self) -> Vec3 {
        self.center
    }
    fn bounds(&self) -> Aabb {
        Aabb::from_points(&self.outline)
    }
    fn point_at(&self, u: Vec2) -> (Vec3, Vec3, Vec2) {
        // Pick the triangle with u.x through the area CDF, reuse the remainder of u.x so the
        // map stays a bijection, then map uniformly onto the triangle.
        let k = self
            .cdf
            .partition_point(|&c| c <= u.x)
            .min(self.cdf.len() - 1);
        let lo = if k == 0 { 0.0 } else { self.cdf[k - 1] };
        let width = (self.cdf[k] - lo).max(f32::MIN_POSITIVE);
        let ux = ((u.x - lo) / width).clamp(0.0, 1.0);
        let [a, b, c] = self.triangles[k];
        let s = ux.sqrt();
        let l = a * (1.0 - s) + b * (s * (1.0 - u.y)) + c * (s * u.y);
        let p = self.origin + l.x * self.tangent + l.y * self.bitangent;
        (p, self.normal, (l - self.uv_min) / self.uv_size)
    }
    fn radiance(&self) -> &Radiance {
        &self.radiance
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn l_shape() -> Vec<Vec3> {
        [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ]
        .iter()
        .map(|&(x, z)| Vec3::new(x, 1.0, z))
        .collect()
    }

    #[test]
    fn concave_polygon_area_and_triangulation() {
        let l = PolygonLight::new(l_shape(), Radiance::Constant(Vec3::ONE)).unwrap();
        assert!((l.area() - 3.0).abs() < 1e-5);
        let tri_area: f32 = l
            .triangles
            .iter()
            .map(|t| 0.5 * (t[1] - t[0]).perp_dot(t[2] - t[0]))
            .sum();
        assert!((tri_area - 3.0).abs() < 1e-5);
        assert_eq!(l.triangle_count(), 4);
    }

    /// Issue 51 item 16: the simplicity test was quadratic (43 s for 100,000 vertices).
    #[test]
    fn a_star_of_a_hundred_thousand_vertices_is_a_light() {
        let n = 100_000;
        let outline: Vec<Vec3> = (0..n)
            .map(|k| {
                let a = std::f32::consts::TAU * k as f32 / n as f32;
                let r = if k % 2 == 0 { 1.0 } else { 0.9 };
                Vec3::new(r * a.cos(), 2.0, -r * a.sin())
            })
            .collect();
        let l = PolygonLight::new(outline, Radiance::Constant(Vec3::ONE)).unwrap();
        assert_eq!(l.triangle_count(), n - 2);
        assert!(l.area() > 0.9 * 0.9 * std::f32::consts::PI && l.area() < std::f32::consts::PI);
    }

    #[test]
    fn invalid_outlines_are_rejected() {
        let w = Radiance::Constant(Vec3::ONE);
        let bowtie = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        assert!(matches!(
            PolygonLight::new(bowtie, w.clone()),
            Err(LightError::InvalidPolygon(_))
        ));
        let mut bent = l_shape();
        bent[3].y += 0.5;
        assert!(PolygonLight::new(bent, w.clone()).is_err());
        assert!(PolygonLight::new(l_shape()[..2].to_vec(), w.clone()).is_err());
        let collinear = vec![Vec3::ZERO, Vec3::X, 2.0 * Vec3::X];
        assert!(PolygonLight::new(collinear, w).is_err());
    }
}
