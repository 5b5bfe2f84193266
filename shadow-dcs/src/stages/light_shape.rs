//! What DCS needs to know about a light's shape: its centre (the integration constant's light
//! sample, section 4.1), the exact range of a linear function over the light (accurate
//! silhouette detection and horizon tests), and points whose convex hull contains the light
//! (conservative wedge hulls, section 4.2).

use glam::{DVec3, Vec3};
use shadow_core::light::{AreaLight, LightGeometry};
use shadow_core::technique::{TechniqueError, UnsupportedReason};

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
    /// The light plane's frame and a convex polygon around the light, for planar lights.
    pub plane: Option<LightPlane>,
    exact: Exact,
}

/// A planar light's frame and a convex polygon holding it, with the centre strictly inside:
/// what the per-pixel light-plane tests need ([`crate::stages::coverage::EdgeTest::may_cover`],
/// [`crate::accel::angular`]).
#[derive(Debug, Clone)]
pub(crate) struct LightPlane {
    /// First in-plane axis (unit).
    pub u: Vec3,
    /// Second in-plane axis (unit, `normal x u`).
    pub v: Vec3,
    /// Convex polygon in the light plane holding the light, counter-clockwise in `(u, v)`.
    pub polygon: Vec<Vec3>,
}

impl LightPlane {
    /// The frame of a light with unit `normal` and first axis `u`, and the convex hull of the
    /// in-plane points `points`; `None` when the centre is not strictly inside it.
    fn new(center: Vec3, normal: Vec3, u: Vec3, points: &[Vec3]) -> Option<Self> {
        let u = u.normalize();
        let v = normal.cross(u).normalize();
        let c = center.as_dvec3();
        let (ud, vd) = (u.as_dvec3(), v.as_dvec3());
        let flat: Vec<glam::DVec2> = points
            .iter()
            .map(|p| {
                let d = p.as_dvec3() - c;
                glam::DVec2::new(d.dot(ud), d.dot(vd))
            })
            .collect();
        let hull = shadow_core::geometry::convex_hull(flat);
        let n = hull.len();
        // Counter-clockwise, with the centre (the origin) strictly inside.
        let inside = n >= 3
            && (0..n).all(|i| {
                let (a, b) = (hull[i], hull[(i + 1) % n]);
                a.perp_dot(b) > 1e-9 * a.length() * b.length()
            });
        inside.then(|| Self {
            u,
            v,
            polygon: hull
                .iter()
                .map(|q| (c + ud * q.x + vd * q.y).as_vec3())
                .collect(),
        })
    }
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
        let frame = match light.geometry() {
            LightGeometry::Rectangle { normal, half_u, .. } => Some((normal, half_u)),
            LightGeometry::Disk { normal, .. } | LightGeometry::Polygon { normal, .. } => {
                Some((normal, shadow_core::geometry::orthonormal_basis(normal).0))
            }
            _ => None,
        };
        let geometry = light.geometry();
        // The outline shared with the other techniques; a disk's polygon holds the disk.
        let outline = || {
            geometry
                .planar_outline(DISK_SIDES as u32, |r| {
                    r / (std::f32::consts::PI / DISK_SIDES as f32).cos() * 1.0001
                })
                .expect("a planar light has an outline")
        };
        let (hull, exact) = match geometry {
            LightGeometry::Rectangle { .. } | LightGeometry::Polygon { .. } => {
                let v = outline();
                let e = Exact::Vertices(v.iter().map(|p| p.as_dvec3()).collect());
                (v, e)
            }
            LightGeometry::Disk {
                center: c,
                normal,
                radius,
            } => (
                outline(),
                Exact::Disk {
                    center: c.as_dvec3(),
                    normal: normal.as_dvec3(),
                    radius: radius as f64,
                },
            ),
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
                return Err(TechniqueError::unsupported(
                    technique,
                    UnsupportedReason::Light {
                        kind: light.kind(),
                        detail: Some(
                            "point lights have no area: there is no penumbra to sample".into(),
                        ),
                    },
                ));
            }
            LightGeometry::Mesh { .. } => {
                return Err(TechniqueError::unsupported(
                    technique,
                    UnsupportedReason::Light {
                        kind: light.kind(),
                        detail: Some(
                            "a mesh light is no planar or spherical light domain: DCS's \
                             silhouettes and wedges (sections 4.1-4.2) need one"
                                .into(),
                        ),
                    },
                ));
            }
        };
        let radius = hull
            .iter()
            .map(|p: &Vec3| (*p - center).length())
            .fold(0.0f32, f32::max);
        let plane = frame.and_then(|(n, u)| LightPlane::new(center, n, u, &hull));
        Ok(Self {
            center,
            radius,
            hull,
            plane,
            exact,
        })
    }

    /// The centre and radius of a sphere light.
    pub fn sphere(&self) -> Option<(DVec3, f64)> {
        match self.exact {
            Exact::Sphere { center, radius } => Some((center, radius)),
            _ => None,
        }
    }

    /// [`LightShape::range`] for two offsets `d1`, `d2` of one normal, with the same values as
    /// two calls: for a polygon the dot products are taken once, and since rounding is
    /// monotonic, the extremes of the sums `n . q + d` are the sums of the extremes of `n . q`.
    pub fn ranges(&self, n: DVec3, d1: f64, d2: f64) -> [(f64, f64); 2] {
        match &self.exact {
            Exact::Vertices(v) => {
                let (lo, hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |r, q| {
                    widen(r, n.dot(*q))
                });
                [(lo + d1, hi + d1), (lo + d2, hi + d2)]
            }
            _ => [self.range(n, d1), self.range(n, d2)],
        }
    }

    /// Minimum and maximum of `n . q + d` over the light's points `q` (exact).
    pub fn range(&self, n: DVec3, d: f64) -> (f64, f64) {
        match &self.exact {
            Exact::Vertices(v) => v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |r, q| {
                widen(r, n.dot(*q) + d)
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

/// The range `r` widened to hold `f`: `(r.0.min(f), r.1.max(f))` by compare and select, the
/// same values (a NaN `f` leaves the range as it is) without `f64::min`/`max`'s NaN handling,
/// which costs more than the comparison in code run once per pixel.
#[inline(always)]
fn widen(r: (f64, f64), f: f64) -> (f64, f64) {
    (if f < r.0 { f } else { r.0 }, if f > r.1 { f } else { r.1 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use shadow_core::light::{DiskLight, RectLight, SphereLight};
    use shadow_core::prelude::Radiance;

    /// `ranges` gives exactly the values of two `range` calls (rectangle, disk, sphere), with
    /// offsets of very different sizes so that the sums round.
    #[test]
    fn ranges_equal_two_range_calls() {
        let r = || Radiance::constant(Vec3::ONE).unwrap();
        let rect =
            RectLight::facing(Vec3::new(0.2, 3.0, -0.1), Vec3::NEG_Y, 1.2, 0.8, r()).unwrap();
        let disk = DiskLight::new(Vec3::new(-1.0, 2.5, 0.3), Vec3::NEG_Y, 0.7, r()).unwrap();
        let sphere = SphereLight::new(Vec3::new(0.5, 4.0, 1.0), 0.4, r()).unwrap();
        let lights: [&dyn AreaLight; 3] = [&rect, &disk, &sphere];
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for light in lights {
            let shape = LightShape::new(light, "test").unwrap();
            for k in 0..2000 {
                let n = DVec3::new(next(), next(), next());
                let scale = 10f64.powi(k % 9 - 4);
                let (d1, d2) = (next() * scale, next() * 3.0);
                let want = [shape.range(n, d1), shape.range(n, d2)];
                assert_eq!(shape.ranges(n, d1, d2), want, "{n} {d1} {d2}");
            }
        }
    }
}
