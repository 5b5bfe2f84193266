//! Area lights (DESIGN section 3): the [`AreaLight`] trait and its shapes, rectangle, disk,
//! polygon (convex or concave, triangulated with `spade`), sphere (omni-directional), the
//! point light as the zero-size limit, and the emissive triangle mesh of any shape
//! ([`MeshLight`]), each with constant or textured radiance.
//!
//! Every light maps the unit square area-uniformly onto its surface ([`AreaLight::sample`]), so
//! a stratified pattern in the unit square stays stratified on the light (DCS section 5).
//!
//! Conventions shared by every technique and the reference:
//! * Planar lights emit from the side their normal points to; the visibility coefficient
//!   `V(p)` ignores the emission side (it is the visible fraction of the light's area), the
//!   direct illumination uses the clamped cosine at the light.
//! * A sphere light is an emitting shell that does not occlude itself (DCS section 7.1
//!   parametrises omni-directional lights in 2D): `V(p)` is the fraction of its whole surface
//!   visible through the scene, while only the half facing `p` contributes to direct illumination.

mod mesh;
mod polygon;
mod radiance;
mod shapes;

pub use mesh::MeshLight;
pub use polygon::PolygonLight;
pub use radiance::{Radiance, TexturedRadiance};
pub use shapes::{DiskLight, PointLight, RectLight, SphereLight};

use std::fmt::Debug;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use serde::Serialize;
use thiserror::Error;

use crate::geometry::Aabb;

/// Why a light could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LightError {
    /// A position, direction or size is NaN or infinite.
    #[error("light parameter `{what}` is not finite")]
    NonFinite {
        /// Which parameter.
        what: &'static str,
    },
    /// A size is zero or negative.
    #[error("light parameter `{what}` must be positive, got {value}")]
    NonPositive {
        /// Which parameter.
        what: &'static str,
        /// The offending value.
        value: f32,
    },
    /// Two axes of a rectangle are parallel or a normal has zero length.
    #[error("light frame is degenerate: {0}")]
    DegenerateFrame(&'static str),
    /// A polygon outline is not a simple polygon with at least three vertices.
    #[error("polygon light outline is invalid: {0}")]
    InvalidPolygon(String),
    /// A radiance is negative or not finite.
    #[error("light radiance must be finite and non-negative, got {0:?}")]
    InvalidRadiance([f32; 3]),
    /// A radiance texture is empty or holds invalid texels.
    #[error("light texture is invalid: {0}")]
    InvalidTexture(String),
}

/// One point on a light, as the samplers produce it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSample {
    /// Position on the light surface (world space).
    pub position: Vec3,
    /// Unit emission normal at the sample.
    pub normal: Vec3,
    /// The light's own parametrisation of the sample in `[0, 1]^2` (texture lookup).
    pub uv: Vec2,
    /// Emitted radiance at the sample (RGB).
    pub radiance: Vec3,
}

/// A description of a light's shape, for techniques that need the exact geometry (outlines for
/// back-projection, wedges, influence regions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LightGeometry<'a> {
    /// A rectangle: centre, two half-extent axes (orthogonal), unit normal `= normalize(u x v)`.
    Rectangle {
        /// Centre.
        center: Vec3,
        /// Half-extent along the first axis.
        half_u: Vec3,
        /// Half-extent along the second axis.
        half_v: Vec3,
        /// Unit normal.
        normal: Vec3,
    },
    /// A disk: centre, unit normal, radius.
    Disk {
        /// Centre.
        center: Vec3,
        /// Unit normal.
        normal: Vec3,
        /// Radius.
        radius: f32,
    },
    /// A planar simple polygon, counter-clockwise around `normal`.
    Polygon {
        /// Outline in world space.
        outline: &'a [Vec3],
        /// Unit normal.
        normal: Vec3,
    },
    /// A sphere (omni-directional light).
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
    },
    /// A point light (zero-size limit: hard shadows).
    Point {
        /// Position.
        position: Vec3,
    },
    /// An emissive triangle mesh of any shape ([`MeshLight`]): each triangle emits from its
    /// front (counter-clockwise) side.
    Mesh {
        /// The emitting triangles in world space.
        triangles: &'a [[Vec3; 3]],
        /// Texture coordinates per triangle corner, when the radiance is a texture.
        texcoords: Option<&'a [[Vec2; 3]]>,
    },
}

/// Which family a light belongs to, for capability checks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, PartialOrd, Ord)]
pub enum LightKind {
    /// [`RectLight`].
    Rectangle,
    /// [`DiskLight`].
    Disk,
    /// [`PolygonLight`].
    Polygon,
    /// [`SphereLight`].
    Sphere,
    /// [`PointLight`].
    Point,
    /// [`MeshLight`].
    Mesh,
}

impl LightKind {
    /// Every family, for techniques that take them all.
    pub const ALL: [LightKind; 6] = [
        LightKind::Rectangle,
        LightKind::Disk,
        LightKind::Polygon,
        LightKind::Sphere,
        LightKind::Point,
        LightKind::Mesh,
    ];
}

impl LightGeometry<'_> {
    /// The family of this shape.
    pub fn kind(&self) -> LightKind {
        match self {
            Self::Rectangle { .. } => LightKind::Rectangle,
            Self::Disk { .. } => LightKind::Disk,
            Self::Polygon { .. } => LightKind::Polygon,
            Self::Sphere { .. } => LightKind::Sphere,
            Self::Point { .. } => LightKind::Point,
            Self::Mesh { .. } => LightKind::Mesh,
        }
    }

    /// The plane a one-sided (planar) light emits from: a point on it and its unit normal,
    /// the side light leaves by. `None` for spheres and points, which emit all around, and for
    /// meshes, whose triangles face many ways.
    pub fn emitting_plane(&self) -> Option<(Vec3, Vec3)> {
        match *self {
            Self::Rectangle { center, normal, .. } | Self::Disk { center, normal, .. } => {
                Some((center, normal))
            }
            Self::Polygon { outline, normal } => outline.first().map(|p| (*p, normal)),
            Self::Sphere { .. } | Self::Point { .. } | Self::Mesh { .. } => None,
        }
    }

    /// True when `p` gets no light at all from this light because it lies behind the plane a
    /// planar light emits from, or in that plane (up to a grazing angle of `1e-6` radians, so
    /// that rounding of a receiver level with the light cannot decide it). Planar lights emit
    /// from their front side only (DESIGN section 3), so every technique gives such a receiver
    /// `V = 0` ([`crate::technique::Estimate::darken_behind_light`]).
    pub fn behind(&self, p: Vec3) -> bool {
        self.emitting_plane().is_some_and(|(o, n)| {
            let d = p - o;
            d.dot(n) <= 1e-6 * d.length()
        })
    }

    /// A bounding rectangle of a planar light in its own plane, corners in order: the
    /// rectangle itself, the square around a disk, the bounding rectangle of a polygon. `None`
    /// for spheres, points and meshes.
    pub fn bounding_quad(&self) -> Option<[Vec3; 4]> {
        let quad = |o: Vec3, t: Vec3, b: Vec3, lo: glam::Vec2, hi: glam::Vec2| {
            let at = |x: f32, y: f32| o + t * x + b * y;
            [
                at(lo.x, lo.y),
                at(hi.x, lo.y),
                at(hi.x, hi.y),
                at(lo.x, hi.y),
            ]
        };
        let (one, minus) = (glam::Vec2::ONE, -glam::Vec2::ONE);
        match *self {
            Self::Rectangle {
                center,
                half_u,
                half_v,
                ..
            } => Some(quad(center, half_u, half_v, minus, one)),
            Self::Disk {
                center,
                normal,
                radius,
            } => {
                let (t, b) = crate::geometry::orthonormal_basis(normal);
                Some(quad(center, t * radius, b * radius, minus, one))
            }
            Self::Polygon { outline, normal } => {
                let (t, b) = crate::geometry::orthonormal_basis(normal);
                let o = outline[0];
                let (mut lo, mut hi) = (
                    glam::Vec2::splat(f32::INFINITY),
                    glam::Vec2::splat(f32::NEG_INFINITY),
                );
                for p in outline {
                    let l = glam::Vec2::new((*p - o).dot(t), (*p - o).dot(b));
                    lo = lo.min(l);
                    hi = hi.max(l);
                }
                Some(quad(o, t, b, lo, hi))
            }
            Self::Sphere { .. } | Self::Point { .. } | Self::Mesh { .. } => None,
        }
    }

    /// The outline of a planar light, counter-clockwise around its normal: a rectangle's four
    /// corners, a polygon's outline, and for a disk `disk_sides` points at angles
    /// `k 2 pi / disk_sides` from the first axis of [`crate::geometry::orthonormal_basis`] on
    /// the circle of radius `disk_radius(radius)` (the radius itself for an inscribed polygon;
    /// `radius / cos(pi / disk_sides)` or more for one that holds the disk). `None` for
    /// spheres, points and meshes. The one outline every technique that needs a polygon of
    /// the light takes (DCS's wedges, the shadow maps' back-projection).
    pub fn planar_outline(
        &self,
        disk_sides: u32,
        disk_radius: impl Fn(f32) -> f32,
    ) -> Option<Vec<Vec3>> {
        match *self {
            Self::Rectangle {
                center: c,
                half_u,
                half_v,
                ..
            } => Some(vec![
                c - half_u - half_v,
                c + half_u - half_v,
                c + half_u + half_v,
                c - half_u + half_v,
            ]),
            Self::Polygon { outline, .. } => Some(outline.to_vec()),
            Self::Disk {
                center,
                normal,
                radius,
            } => {
                let (t1, t2) = crate::geometry::orthonormal_basis(normal);
                let r = disk_radius(radius);
                Some(
                    (0..disk_sides)
                        .map(|k| {
                            let a = k as f32 * std::f32::consts::TAU / disk_sides as f32;
                            center + (t1 * a.cos() + t2 * a.sin()) * r
                        })
                        .collect(),
                )
            }
            Self::Sphere { .. } | Self::Point { .. } | Self::Mesh { .. } => None,
        }
    }

    /// The plane normal of planar lights, `None` for spheres, points and meshes.
    pub fn plane_normal(&self) -> Option<Vec3> {
        match *self {
            Self::Rectangle { normal, .. }
            | Self::Disk { normal, .. }
            | Self::Polygon { normal, .. } => Some(normal),
            Self::Sphere { .. } | Self::Point { .. } | Self::Mesh { .. } => None,
        }
    }
}

/// An emitting surface.
///
/// Contract: [`AreaLight::sample`] maps `u` in `[0, 1)^2` to a point on the surface with a
/// density proportional to area (uniform), continuously enough that a stratified `u` pattern
/// stays stratified; it is deterministic and never returns a non-finite value. `area()` is 0
/// only for the point light.
pub trait AreaLight: Send + Sync + Debug {
    /// The exact shape.
    fn geometry(&self) -> LightGeometry<'_>;
    /// Surface area (0 for a point light).
    fn area(&self) -> f32;
    /// A central point (the point standard shadow maps and DCS's integration constant use).
    fn center(&self) -> Vec3;
    /// Bounds of the surface.
    fn bounds(&self) -> Aabb;
    /// Maps `u` in `[0, 1)^2` area-uniformly onto the light (position, normal, uv only).
    fn point_at(&self, u: Vec2) -> (Vec3, Vec3, Vec2);
    /// The emitted radiance.
    fn radiance(&self) -> &Radiance;

    /// The full light sample at `u`, radiance included.
    fn sample(&self, u: Vec2) -> LightSample {
        let (position, normal, uv) = self.point_at(u);
        LightSample {
            position,
            normal,
            uv,
            radiance: self.radiance().at(uv),
        }
    }
    /// The samples at every `u` of `units`, appended to `out`: one dynamic call for a whole
    /// set, inside which [`AreaLight::sample`] is a static call the compiler can inline.
    fn sample_into(&self, units: &[Vec2], out: &mut Vec<LightSample>) {
        // The radiance's kind is settled once per set, not per sample.
        match self.radiance() {
            Radiance::Constant(c) => samples_with(self, units, |_| *c, out),
            Radiance::Textured(t) => samples_with(self, units, |uv| t.lookup(uv), out),
        }
    }
    /// The radiances at every `u` of `units` (those of [`AreaLight::sample_into`]), appended to
    /// `out`, one dynamic call for a whole set: for callers that need no positions (the
    /// radiance-weighted visibility of a pixel whose samples all see the light), so that only
    /// the texture coordinates of [`AreaLight::point_at`] are computed.
    fn radiances_into(&self, units: &[Vec2], out: &mut Vec<Vec3>) {
        match self.radiance() {
            Radiance::Constant(c) => out.extend(std::iter::repeat_n(*c, units.len())),
            Radiance::Textured(t) => t.extend_at(units.iter().map(|u| self.point_at(*u).2), out),
        }
    }
    /// The positions at every `u` of `units` ([`AreaLight::point_at`]), appended to `out`, one
    /// dynamic call for a whole set.
    fn positions_into(&self, units: &[Vec2], out: &mut Vec<Vec3>) {
        out.extend(units.iter().map(|u| self.point_at(*u).0));
    }
    /// Family of the light.
    fn kind(&self) -> LightKind {
        self.geometry().kind()
    }
    /// True when the radiance varies over the light.
    fn is_textured(&self) -> bool {
        matches!(self.radiance(), Radiance::Textured(_))
    }
}

/// [`AreaLight::sample_into`] with the radiance at uv given by `radiance`.
#[inline(always)]
fn samples_with<L: AreaLight + ?Sized>(
    light: &L,
    units: &[Vec2],
    radiance: impl Fn(Vec2) -> Vec3,
    out: &mut Vec<LightSample>,
) {
    out.extend(units.iter().map(|u| {
        let (position, normal, uv) = light.point_at(*u);
        LightSample {
            position,
            normal,
            uv,
            radiance: radiance(uv),
        }
    }));
}

/// A shared, immutable light as scenes and techniques pass it around.
pub type Light = Arc<dyn AreaLight>;

pub(crate) fn check_finite3(v: Vec3, what: &'static str) -> Result<(), LightError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(LightError::NonFinite { what })
    }
}

pub(crate) fn check_positive(value: f32, what: &'static str) -> Result<(), LightError> {
    if !value.is_finite() {
        Err(LightError::NonFinite { what })
    } else if value <= 0.0 {
        Err(LightError::NonPositive { what, value })
    } else {
        Ok(())
    }
}

pub(crate) fn unit(v: Vec3, what: &'static str) -> Result<Vec3, LightError> {
    check_finite3(v, what)?;
    v.try_normalize()
        .ok_or(LightError::DegenerateFrame("zero-length direction"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 51 item 12: one light-side rule for every technique.
    #[test]
    fn planar_lights_light_only_their_front_side() {
        let r = RectLight::facing(
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::NEG_Y,
            1.0,
            1.0,
            Radiance::Constant(Vec3::ONE),
        )
        .unwrap();
        let g = r.geometry();
        assert!(!g.behind(Vec3::ZERO));
        assert!(g.behind(Vec3::new(0.0, 3.0, 0.0)));
        // Level with the light (a ceiling around a recessed panel): no light.
        assert!(g.behind(Vec3::new(5.0, 2.0, 1.0)));
        assert!(!g.behind(Vec3::new(5.0, 1.99, 1.0)));
        let s = SphereLight::new(Vec3::ZERO, 1.0, Radiance::Constant(Vec3::ONE)).unwrap();
        assert!(!s.geometry().behind(Vec3::new(0.0, -5.0, 0.0)));
    }
}
