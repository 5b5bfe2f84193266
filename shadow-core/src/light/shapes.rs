//! Rectangle, disk, sphere and point lights.

use std::f32::consts::{FRAC_PI_4, PI, TAU};

use glam::{Vec2, Vec3};

use super::{AreaLight, LightError, LightGeometry, Radiance, check_finite3, check_positive, unit};
use crate::geometry::{Aabb, orthonormal_basis};

/// A rectangular light: centre and two orthogonal half-extent axes; normal `u x v`.
#[derive(Debug, Clone)]
pub struct RectLight {
    center: Vec3,
    half_u: Vec3,
    half_v: Vec3,
    normal: Vec3,
    radiance: Radiance,
}

impl RectLight {
    /// A rectangle centred at `center` spanning `center ± half_u ± half_v`.
    ///
    /// # Errors
    /// Non-finite input, a zero-length axis, or axes that are not orthogonal (within 1e-4 of
    /// their lengths' product).
    pub fn new(
        center: Vec3,
        half_u: Vec3,
        half_v: Vec3,
        radiance: Radiance,
    ) -> Result<Self, LightError> {
        check_finite3(center, "center")?;
        check_finite3(half_u, "half_u")?;
        check_finite3(half_v, "half_v")?;
        check_positive(half_u.length(), "half_u length")?;
        check_positive(half_v.length(), "half_v length")?;
        if half_u.dot(half_v).abs() > 1e-4 * half_u.length() * half_v.length() {
            return Err(LightError::DegenerateFrame(
                "rectangle axes are not orthogonal",
            ));
        }
        let normal = unit(half_u.cross(half_v), "normal")?;
        Ok(Self {
            center,
            half_u,
            half_v,
            normal,
            radiance,
        })
    }

    /// A `width x height` rectangle centred at `center` facing `normal`.
    ///
    /// # Errors
    /// As [`RectLight::new`].
    pub fn facing(
        center: Vec3,
        normal: Vec3,
        width: f32,
        height: f32,
        radiance: Radiance,
    ) -> Result<Self, LightError> {
        let n = unit(normal, "normal")?;
        check_positive(width, "width")?;
        check_positive(height, "height")?;
        let (t, b) = orthonormal_basis(n);
        Self::new(center, t * (0.5 * width), b * (0.5 * height), radiance)
    }

    /// The same light with another radiance.
    #[must_use]
    pub fn with_radiance(mut self, radiance: Radiance) -> Self {
        self.radiance = radiance;
        self
    }

    /// The light's uv of a point on its plane (`[0, 1]^2` inside the rectangle).
    pub fn uv_of(&self, p: Vec3) -> Vec2 {
        let d = p - self.center;
        let s = d.dot(self.half_u) / self.half_u.length_squared();
        let t = d.dot(self.half_v) / self.half_v.length_squared();
        0.5 * (Vec2::new(s, t) + Vec2::ONE)
    }

    /// The four corners, counter-clockwise around the normal.
    pub fn corners(&self) -> [Vec3; 4] {
        let (c, u, v) = (self.center, self.half_u, self.half_v);
        [c - u - v, c + u - v, c + u + v, c - u + v]
    }
}

impl AreaLight for RectLight {
    fn geometry(&self) -> LightGeometry<'_> {
        LightGeometry::Rectangle {
            center: self.center,
            half_u: self.half_u,
            half_v: self.half_v,
            normal: self.normal,
        }
    }
    fn area(&self) -> f32 {
        4.0 * self.half_u.length() * self.half_v.length()
    }
    fn center(&self) -> Vec3 {
        self.center
    }
    fn bounds(&self) -> Aabb {
        Aabb::from_points(&self.corners())
    }
    fn point_at(&self, u: Vec2) -> (Vec3, Vec3, Vec2) {
        let p = self.center + (2.0 * u.x - 1.0) * self.half_u + (2.0 * u.y - 1.0) * self.half_v;
        (p, self.normal, u)
    }
    fn radiance(&self) -> &Radiance {
        &self.radiance
    }
}

/// A disk light.
#[derive(Debug, Clone)]
pub struct DiskLight {
    center: Vec3,
    normal: Vec3,
    radius: f32,
    tangent: Vec3,
    bitangent: Vec3,
    radiance: Radiance,
}

impl DiskLight {
    /// A disk of `radius` centred at `center` facing `normal`.
    ///
    /// # Errors
    /// Non-finite input, a zero normal or a non-positive radius.
    pub fn new(
        center: Vec3,
        normal: Vec3,
        radius: f32,
        radiance: Radiance,
    ) -> Result<Self, LightError> {
        check_finite3(center, "center")?;
        let normal = unit(normal, "normal")?;
        check_positive(radius, "radius")?;
        let (tangent, bitangent) = orthonormal_basis(normal);
        Ok(Self {
            center,
            normal,
            radius,
            tangent,
            bitangent,
            radiance,
        })
    }

    /// The same light with another radiance.
    #[must_use]
    pub fn with_radiance(mut self, radiance: Radiance) -> Self {
        self.radiance = radiance;
        self
    }

    /// The light's uv of a point on its plane (`[0, 1]^2` over the disk's bounding square).
    pub fn uv_of(&self, p: Vec3) -> Vec2 {
        let d = (p - self.center) / self.radius;
        0.5 * (Vec2::new(d.dot(self.tangent), d.dot(self.bitangent)) + Vec2::ONE)
    }

    /// Same disk with an explicit in-plane tangent (the uv frame of a textured disk).
    ///
    /// # Errors
    /// When `tangent` is not finite or is parallel to the normal.
    pub fn with_tangent(mut self, tangent: Vec3) -> Result<Self, LightError> {
        let t = unit(tangent - self.normal * tangent.dot(self.normal), "tangent")?;
        self.tangent = t;
        self.bitangent = self.normal.cross(t);
        Ok(self)
    }
}

/// Shirley and Chiu's concentric map from the unit square to the unit disk: area-preserving
/// and continuous, so stratification survives.
pub(crate) fn concentric_disk(u: Vec2) -> Vec2 {
    let a = 2.0 * u - Vec2::ONE;
    if a == Vec2::ZERO {
        return Vec2::ZERO;
    }
    let (r, theta) = if a.x.abs() > a.y.abs() {
        (a.x, FRAC_PI_4 * (a.y / a.x))
    } else {
        (a.y, 0.5 * PI - FRAC_PI_4 * (a.x / a.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

impl AreaLight for DiskLight {
    fn geometry(&self) -> LightGeometry<'_> {
        LightGeometry::Disk {
            center: self.center,
            normal: self.normal,
            radius: self.radius,
        }
    }
    fn area(&self) -> f32 {
        PI * self.radius * self.radius
    }
    fn center(&self) -> Vec3 {
        self.center
    }
    fn bounds(&self) -> Aabb {
        // Extent of a disk along axis i: r * sqrt(1 - n_i^2).
        let e = self.radius
            * (Vec3::ONE - self.normal * self.normal)
                .max(Vec3::ZERO)
                .powf(0.5);
        Aabb {
            min: self.center - e,
            max: self.center + e,
        }
    }
    fn point_at(&self, u: Vec2) -> (Vec3, Vec3, Vec2) {
        let d = concentric_disk(u);
        let p = self.center + self.radius * (d.x * self.tangent + d.y * self.bitangent);
        (p, self.normal, 0.5 * (d + Vec2::ONE))
    }
    fn radiance(&self) -> &Radiance {
        &self.radiance
    }
}

/// An omni-directional spherical light (an emitting shell that does not occlude itself).
#[derive(Debug, Clone)]
pub struct SphereLight {
    center: Vec3,
    radius: f32,
    radiance: Radiance,
}

impl SphereLight {
    /// A sphere of `radius` at `center`.
    ///
    /// # Errors
    /// Non-finite input or a non-positive radius.
    pub fn new(center: Vec3, radius: f32, radiance: Radiance) -> Result<Self, LightError> {
        check_finite3(center, "center")?;
        check_positive(radius, "radius")?;
        Ok(Self {
            center,
            radius,
            radiance,
        })
    }
}

impl AreaLight for SphereLight {
    fn geometry(&self) -> LightGeometry<'_> {
        LightGeometry::Sphere {
            center: self.center,
            radius: self.radius,
        }
    }
    fn area(&self) -> f32 {
        4.0 * PI * self.radius * self.radius
    }
    fn center(&self) -> Vec3 {
        self.center
    }
    fn bounds(&self) -> Aabb {
        Aabb {
            min: self.center - Vec3::splat(self.radius),
            max: self.center + Vec3::splat(self.radius),
        }
    }
    fn point_at(&self, u: Vec2) -> (Vec3, Vec3, Vec2) {
        // Archimedes: z uniform in [-1, 1] and phi uniform give area-uniform points.
        let z = 1.0 - 2.0 * u.x;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = TAU * u.y;
        let n = Vec3::new(r * phi.cos(), z, r * phi.sin());
        (self.center + self.radius * n, n, u)
    }
    fn radiance(&self) -> &Radiance {
        &self.radiance
    }
}

/// A point light: the zero-size limit of every area light, giving the hard shadow.
#[derive(Debug, Clone)]
pub struct PointLight {
    position: Vec3,
    radiance: Radiance,
}

impl PointLight {
    /// A point light at `position`; its "radiance" is the intensity.
    ///
    /// # Errors
    /// Non-finite position.
    pub fn new(position: Vec3, radiance: Radiance) -> Result<Self, LightError> {
        check_finite3(position, "position")?;
        Ok(Self { position, radiance })
    }
}

impl AreaLight for PointLight {
    fn geometry(&self) -> LightGeometry<'_> {
        LightGeometry::Point {
            position: self.position,
        }
    }
    fn area(&self) -> f32 {
        0.0
    }
    fn center(&self) -> Vec3 {
        self.position
    }
    fn bounds(&self) -> Aabb {
        Aabb::from_points(&[self.position])
    }
    fn point_at(&self, u: Vec2) -> (Vec3, Vec3, Vec2) {
        (self.position, Vec3::ZERO, u)
    }
    fn radiance(&self) -> &Radiance {
        &self.radiance
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn concentric_map_stays_in_disk_and_hits_the_rim() {
        for j in 0..=16 {
            for i in 0..=16 {
                let d = concentric_disk(Vec2::new(i as f32 / 16.0, j as f32 / 16.0));
                assert!(d.length() <= 1.0 + 1e-6);
            }
        }
        assert!((concentric_disk(Vec2::new(1.0, 0.5)).length() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn invalid_lights_are_rejected() {
        let w = Radiance::Constant(Vec3::ONE);
        assert!(RectLight::new(Vec3::ZERO, Vec3::X, Vec3::X, w.clone()).is_err());
        assert!(RectLight::new(Vec3::NAN, Vec3::X, Vec3::Y, w.clone()).is_err());
        assert!(RectLight::facing(Vec3::ZERO, Vec3::Y, 0.0, 1.0, w.clone()).is_err());
        assert!(DiskLight::new(Vec3::ZERO, Vec3::ZERO, 1.0, w.clone()).is_err());
        assert!(DiskLight::new(Vec3::ZERO, Vec3::Y, -1.0, w.clone()).is_err());
        assert!(SphereLight::new(Vec3::ZERO, f32::INFINITY, w.clone()).is_err());
        assert!(PointLight::new(Vec3::INFINITY, w).is_err());
    }

    #[test]
    fn bounds_contain_samples() {
        let w = Radiance::Constant(Vec3::ONE);
        let lights: Vec<Box<dyn AreaLight>> = vec![
            Box::new(
                RectLight::facing(Vec3::ONE, Vec3::new(1.0, 2.0, 3.0), 2.0, 1.0, w.clone())
                    .unwrap(),
            ),
            Box::new(DiskLight::new(Vec3::ONE, Vec3::new(1.0, -2.0, 0.5), 0.7, w.clone()).unwrap()),
            Box::new(SphereLight::new(Vec3::ONE, 0.3, w).unwrap()),
        ];
        for l in &lights {
            let b = l.bounds();
            for j in 0..10 {
                for i in 0..10 {
                    let (p, _, _) = l.point_at(Vec2::new(i as f32 / 9.0, j as f32 / 9.0));
                    assert!((p - b.min).min_element() > -1e-5 && (b.max - p).min_element() > -1e-5);
                }
            }
        }
    }
}
