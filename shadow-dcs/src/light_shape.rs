//! What DCS needs to know about a light's shape: its centre (the integration constant's light
//! sample, section 4.1), the exact range of a linear function over the light (accurate
//! silhouette detection and horizon tests), and points whose convex hull contains the light
//! (conservative wedge hulls, section 4.2).

use glam::{DVec3, Vec3};
use shadow_core::light::{AreaLight, LightGeometry};
use shadow_core::technique::TechniqueError;

/// Sides of the regular polygon circumscribing a disk light.
const DISK_SIDES: usize = 16;

/// A light's shape as DCS uses it.
#[derive(Debug, Clone)]
pub(crate) struct LightShape {
    /// The centre sample `c` of the integration constant.
    pub center: Vec3,
    /// Radius of a ball around `center` holding the light.
    pub radius: f32,
    /// Points whose convex hull holds the light.
    pub hull: Vec<Vec3>,
    exact: Exact,
}

#[derive(Debug, Clone)]
enum Exact {
    /// Convex hull of these vertices (rectangles, polygons: extremes lie at vertices).
    Vertices(Vec<DVec3>),
    Disk {
        center: DVec3,
        normal: DVec3,
        radius: f64,
    },
    Sphere {
        center: DVec3,
        radius: f64,
    },
}

impl LightShape {
    /// The shape of `light`.
    ///
    /// # Errors
    /// [`TechniqueError::Unsupported`] for point lights (no area, no penumbra).
    pub fn new(light: &dyn AreaLight, technique: &str) -> Result<Self, TechniqueError> {
        let center = light.center();
        let (hull, exact) = match light.geometry() {
            LightGeometry::Rectangle {
                center: c,
                half_u,
                half_v,
                ..
            } => {
                let v = vec![
                    c - half_u - half_v,
                    c + half_u - half_v,
                    c + half_u + half_v,
                    c - half_u + half_v,
                ];
                let e = Exact::Vertices(v.iter().map(|p| p.as_dvec3()).collect());
                (v, e)
            }
            LightGeometry::Polygon { outline, .. } => (
                outline.to_vec(),
                Exact::Vertices(outline.iter().map(|p| p.as_dvec3()).collect()),
            ),
            LightGeometry::Disk {
                center: c,
                normal,
                radius,
            } => {
                let (t1, t2) = shadow_core::geometry::orthonormal_basis(normal);
                let r = radius / (std::f32::consts::PI / DISK_SIDES as f32).cos() * 1.0001;
                let v = (0..DISK_SIDES)
                    .map(|k| {
                        let a = k as f32 * std::f32::consts::TAU / DISK_SIDES as f32;
                        c + (t1 * a.cos() + t2 * a.sin()) * r
                    })
                    .collect();
                (
                    v,
                    Exact::Disk {
                        center: c.as_dvec3(),
                        normal: normal.as_dvec3(),
                        radius: radius as f64,
                    },
                )
            }
            LightGeometry::Sphere { center: c, radius } => {
                let r = radius * 1.0001;
                let v = (0..8)
                    .map(|k| {
                        c + Vec3::new(
                            if k & 1 == 0 { -r } else { r },
                            if k & 2 == 0 { -r } else { r },
                            if k & 4 == 0 { -r } else { r },
                        )
                    })
                    .collect();
                (
                    v,
                    Exact::Sphere {
                        center: c.as_dvec3(),
                        radius: radius as f64,
                    },
                )
            }
            LightGeometry::Point { .. } => {
                return Err(TechniqueError::Unsupported {
                    technique: technique.into(),
                    reason: "point lights have no area: there is no penumbra to sample".into(),
                });
            }
        };
        let radius = hull
            .iter()
            .map(|p: &Vec3| (*p - center).length())
            .fold(0.0f32, f32::max);
        Ok(Self {
            center,
            radius,
            hull,
            exact,
        })
    }

    /// Minimum and maximum of `n . q + d` over the light's points `q` (exact).
    pub fn range(&self, n: DVec3, d: f64) -> (f64, f64) {
        match &self.exact {
            Exact::Vertices(v) => v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |r, q| {
                let f = n.dot(*q) + d;
                (r.0.min(f), r.1.max(f))
            }),
            Exact::Disk {
                center,
                normal,
                radius,
            } => {
                let f = n.dot(*center) + d;
                let tangential = (n - *normal * n.dot(*normal)).length() * radius;
                (f - tangential, f + tangential)
            }
            Exact::Sphere { center, radius } => {
                let f = n.dot(*center) + d;
                let r = n.length() * radius;
                (f - r, f + r)
            }
        }
    }
}
