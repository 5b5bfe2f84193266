//! A planar light as shadow mapping sees it: its centre, emission axis, in-plane basis, outline
//! (a polygon; a disk as a regular 64-gon inside which the error is below 0.2% of its area) and
//! width, plus the exact fraction of the light above a receiver's tangent plane.

use glam::{DVec3, Vec3};
use shadow_core::clip::{Keep, clip_by_side};
use shadow_core::light::AreaLight;
use shadow_core::technique::{TechniqueError, UnsupportedReason};

/// Sides of the polygon standing for a disk light.
const DISK_SIDES: usize = 64;

/// A planar light's frame.
#[derive(Debug, Clone)]
pub struct LightFrame {
    /// Centre (the shadow map's eye).
    pub center: Vec3,
    /// Unit emission normal (the shadow map's viewing axis).
    pub axis: Vec3,
    /// In-plane unit axes.
    pub basis: (Vec3, Vec3),
    /// Outline, counter-clockwise around `axis`.
    pub outline: Vec<Vec3>,
    /// Width `w_l` of GBP07 eq. 1: twice the outline's largest reach from the centre along the
    /// basis axes.
    pub width: f32,
}

impl LightFrame {
    /// The frame of a planar light.
    ///
    /// # Errors
    /// [`TechniqueError::Unsupported`] for sphere and point lights.
    pub fn new(light: &dyn AreaLight, technique: &str) -> Result<Self, TechniqueError> {
        let geometry = light.geometry();
        let (axis, outline) = match (
            geometry.plane_normal(),
            geometry.planar_outline(DISK_SIDES as u32, |r| r),
        ) {
            // The outline shared with the other techniques; a disk's is inscribed.
            (Some(normal), Some(outline)) => (normal, outline),
            _ => {
                return Err(TechniqueError::unsupported(
                    technique,
                    UnsupportedReason::Light {
                        kind: light.kind(),
                        detail: Some(
                            "shadow mapping needs a planar light (its near plane is parallel \
                             to the light, GBP07 section 3); sphere, point and mesh lights have none"
                                .into(),
                        ),
                    },
                ));
            }
        };
        let center = light.center();
        let basis = shadow_core::geometry::orthonormal_basis(axis);
        // Twice the farthest reach from the centre, so a kernel centred on a receiver's
        // projection covers the light even when the centre is off its middle.
        let extent = |t: Vec3| {
            2.0 * outline
                .iter()
                .map(|p| (*p - center).dot(t).abs())
                .fold(0.0f32, f32::max)
        };
        let width = extent(basis.0).max(extent(basis.1));
        Ok(Self {
            center,
            axis,
            basis,
            outline,
            width,
        })
    }

    /// The fraction of the light's area above the plane through `p` with normal `n` (the
    /// part of the light a receiver can see at all; the reference counts the rest occluded).
    pub fn fraction_above(&self, p: Vec3, n: Vec3) -> f32 {
        let (t1, t2) = (self.basis.0.as_dvec3(), self.basis.1.as_dvec3());
        let c = self.center.as_dvec3();
        let side = |q: DVec3| (q - p.as_dvec3()).dot(n.as_dvec3());
        // Most receivers see the whole light or none of it: then the clip would keep every
        // point or none, and the fraction is 1 or 0 without it (the same values).
        let above = self
            .outline
            .iter()
            .filter(|v| side(v.as_dvec3()) > 0.0)
            .count();
        if above == 0 {
            return 0.0;
        }
        let pts: Vec<DVec3> = self.outline.iter().map(|v| v.as_dvec3()).collect();
        let area = |poly: &[DVec3]| -> f64 {
            let m = poly.len();
            let mut s = 0.0;
            for i in 0..m {
                let (a, b) = (poly[i] - c, poly[(i + 1) % m] - c);
                s += a.dot(t1) * b.dot(t2) - b.dot(t1) * a.dot(t2);
            }
            (0.5 * s).abs()
        };
        let total = area(&pts);
        if !(total > 0.0) {
            return 0.0;
        }
        if above == pts.len() {
            return 1.0;
        }
        let mut clipped = Vec::with_capacity(pts.len() + 2);
        clip_by_side(&pts, &mut clipped, side, Keep::Positive);
        if clipped.len() < 3 {
            return 0.0;
        }
        ((area(&clipped) / total) as f32).clamp(0.0, 1.0)
    }
}
