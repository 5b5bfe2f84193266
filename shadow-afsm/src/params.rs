//! The data the compute passes share, laid out as the WGSL of `shaders/common.wgsl` declares
//! it, and [`LightBounds`]: the light's shape reduced to what the passes need (its support
//! function for plane classification, section 4.3, and the points whose projections bound
//! influence regions, section 4.1).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use shadow_core::light::{AreaLight, LightGeometry};

/// Light kinds as the shaders number them.
pub const KIND_POINTS: u32 = 0;
/// A disk: exact support function, octagon bound.
pub const KIND_DISK: u32 = 1;
/// A sphere: exact support function, hexagons around its silhouette.
pub const KIND_SPHERE: u32 = 2;
/// A point (hard shadows).
pub const KIND_POINT: u32 = 3;

/// Uniform block of every pass (`Params` in `common.wgsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Params {
    /// Light frame centre.
    pub center: [f32; 4],
    /// Map plane axis u.
    pub axis_u: [f32; 4],
    /// Map plane axis v.
    pub axis_v: [f32; 4],
    /// Frustum axis; w = far plane distance.
    pub axis_d: [f32; 4],
    /// x0, y0, texels per unit in x and y.
    pub map: [f32; 4],
    /// Light plane normal; w = radius (disk, sphere).
    pub light_n: [f32; 4],
    /// Light axis u; w = bounding radius about the centre.
    pub light_u: [f32; 4],
    /// Light axis v.
    pub light_v: [f32; 4],
    /// side, listed receivers, samples N, words W.
    pub dims: [u32; 4],
    /// casters in the batch, light kind, outline points, LUT mode.
    pub kind: [u32; 4],
    /// LUT bins (theta, phi, delta), textured flag.
    pub lut: [u32; 4],
    /// Occlusion work of one caster range: first caster, caster count, tiles, pairs.
    pub work: [u32; 4],
    /// x = 1 when the silhouette stencil restricts per-sample work; y = 1 when semi-opaque
    /// casters accumulate per-sample optical depths; z = buckets per side of the sample grid
    /// (0: none); w = 1 when cluster culling is on.
    pub options: [u32; 4],
    /// Sample grid origin (u, v) and buckets per unit (u, v) in the light's plane.
    pub grid: [f32; 4],
    /// Points bounding the light.
    pub outline: [[f32; 4]; 8],
}

/// A view sample as the passes read it (`Receiver` in `common.wgsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Receiver {
    /// Offset ray origin.
    pub origin: [f32; 3],
    /// Sample set index.
    pub set_index: u32,
    /// Surface point.
    pub position: [f32; 3],
    /// Own triangle.
    pub triangle: u32,
    /// Geometric normal.
    pub normal: [f32; 3],
    /// Padding.
    pub pad: u32,
}

impl Receiver {
    /// Packs a receiver.
    pub fn new(origin: Vec3, set: u32, position: Vec3, triangle: u32, normal: Vec3) -> Self {
        Self {
            origin: origin.to_array(),
            set_index: set,
            position: position.to_array(),
            triangle,
            normal: normal.to_array(),
            pad: 0,
        }
    }
    /// The offset origin.
    pub fn origin(&self) -> Vec3 {
        Vec3::from_array(self.origin)
    }
    /// The floats that must be finite before upload.
    pub fn floats(&self) -> [f32; 9] {
        let (o, p, n) = (self.origin, self.position, self.normal);
        [o[0], o[1], o[2], p[0], p[1], p[2], n[0], n[1], n[2]]
    }
}

/// A caster triangle (`Caster` in `common.wgsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Caster {
    /// Vertex a.
    pub a: [f32; 3],
    /// Triangle id.
    pub id: u32,
    /// Vertex b.
    pub b: [f32; 3],
    /// 1 when its mesh is closed.
    pub closed: u32,
    /// Vertex c.
    pub c: [f32; 3],
    /// Optical depth of one crossing, `-ln(1 - opacity)` in units of `1 / DEPTH_SCALE`, or
    /// [`OPAQUE`].
    pub optical_depth: u32,
}

/// Fixed-point units per nat of optical depth (`2^20`: a crossing's transmittance is kept to
/// a relative 5e-7).
pub const DEPTH_SCALE: f32 = 1_048_576.0;

/// `optical_depth` of an opaque caster: its occluded samples go to the bitmask.
pub const OPAQUE: u32 = u32::MAX;

impl Caster {
    /// Packs an opaque triangle.
    pub fn new(v: [Vec3; 3], id: u32, closed: bool) -> Self {
        Self {
            a: v[0].to_array(),
            id,
            b: v[1].to_array(),
            closed: closed as u32,
            c: v[2].to_array(),
            optical_depth: OPAQUE,
        }
    }

    /// Gives the triangle an opacity in (0, 1): each crossing multiplies a light sample's
    /// transmittance by `1 - opacity` (at least one fixed-point unit, so that a crossed sample
    /// never counts as unobstructed); opacity 1 keeps it opaque. A semi-opaque triangle
    /// counts from both sides (a segment through a closed semi-opaque mesh crosses it twice).
    pub fn with_opacity(mut self, opacity: f32) -> Self {
        if opacity < 1.0 {
            let depth = -(1.0 - opacity.max(0.0)).ln() * DEPTH_SCALE;
            self.optical_depth = (depth.round() as u32).clamp(1, OPAQUE - 1);
            self.closed = 0;
        }
        self
    }
    /// The vertices.
    pub fn vertices(&self) -> [Vec3; 3] {
        [
            Vec3::from_array(self.a),
            Vec3::from_array(self.b),
            Vec3::from_array(self.c),
        ]
    }
    /// True when its mesh is closed.
    pub fn closed(&self) -> bool {
        self.closed == 1
    }
}

/// An influence region as the influence pass writes it (`Region` in `common.wgsl`).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct Region {
    /// Inclusive texel box (x0, y0, x1, y1); x1 < x0 when culled.
    pub bbox: [i32; 4],
    /// Hull vertex count, flag (1 whole map, 2 box only), pad, pad.
    pub info: [u32; 4],
    /// Hull vertices in texel coordinates, counter-clockwise.
    pub pts: [[f32; 2]; 28],
}

/// The light reduced to its bounds: kind, frame, bounding radius and bounding points.
#[derive(Debug, Clone, PartialEq)]
pub struct LightBounds {
    /// Shader kind ([`KIND_POINTS`], ...).
    pub kind: u32,
    /// Centre (the light's own centre point).
    pub center: Vec3,
    /// Unit normal (planar lights), else +z.
    pub normal: Vec3,
    /// In-plane axes (any orthonormal pair for spheres and points).
    pub axes: [Vec3; 2],
    /// Disk or sphere radius.
    pub radius: f32,
    /// Largest distance of the light's surface from the centre.
    pub bound: f32,
    /// Points whose convex hull contains the light (rectangle and polygon lights).
    pub outline: Vec<Vec3>,
}

fn perpendicular(n: Vec3) -> [Vec3; 2] {
    let u = n.any_orthonormal_vector();
    [u, n.cross(u)]
}

impl LightBounds {
    /// The bounds of `light`, or of its centre alone when `hard`.
    pub fn new(light: &dyn AreaLight, hard: bool) -> Self {
        let center = light.center();
        if hard {
            return Self::point(center);
        }
        let geometry = light.geometry();
        let quad = || {
            geometry
                .bounding_quad()
                .map_or_else(Vec::new, |q| q.to_vec())
        };
        match geometry {
            LightGeometry::Rectangle {
                center,
                half_u,
                half_v,
                normal,
            } => Self {
                kind: KIND_POINTS,
                center,
                normal,
                axes: [half_u.normalize(), half_v.normalize()],
                radius: 0.0,
                bound: (half_u + half_v).length(),
                outline: quad(),
            },
            LightGeometry::Disk {
                center,
                normal,
                radius,
            } => Self {
                kind: KIND_DISK,
                center,
                normal,
                axes: perpendicular(normal),
                radius,
                bound: radius,
                outline: Vec::new(),
            },
            LightGeometry::Polygon { outline, normal } => {
                let u = (outline[1] - outline[0]).normalize();
                let axes = [u, normal.cross(u)];
                // Up to 8 outline points, or the polygon's bounding rectangle.
                let points = if outline.len() <= 8 {
                    outline.to_vec()
                } else {
                    quad()
                };
                let bound = points
                    .iter()
                    .map(|p| (*p - center).length())
                    .fold(0.0, f32::max);
                Self {
                    kind: KIND_POINTS,
                    center,
                    normal,
                    axes,
                    radius: 0.0,
                    bound,
                    outline: points,
                }
            }
            LightGeometry::Sphere { center, radius } => Self {
                kind: KIND_SPHERE,
                center,
                normal: Vec3::Z,
                axes: [Vec3::X, Vec3::Y],
                radius,
                bound: radius,
                outline: Vec::new(),
            },
            LightGeometry::Point { position } => Self::point(position),
            // Refused by `Afsm::capabilities` (the per-sample masks assume one emitting plane
            // or a sphere); a sphere around the mesh would still bound its influence.
            LightGeometry::Mesh { .. } => Self {
                kind: KIND_SPHERE,
                center,
                normal: Vec3::Z,
                axes: [Vec3::X, Vec3::Y],
                radius: 0.5 * light.bounds().diagonal(),
                bound: 0.5 * light.bounds().diagonal(),
                outline: Vec::new(),
            },
        }
    }

    fn point(center: Vec3) -> Self {
        Self {
            kind: KIND_POINT,
            center,
            normal: Vec3::Z,
            axes: [Vec3::X, Vec3::Y],
            radius: 0.0,
            bound: 0.0,
            outline: Vec::new(),
        }
    }

    /// The range of `m . y` over the light (`light_range` in `common.wgsl`).
    pub fn range(&self, m: Vec3) -> (f32, f32) {
        let c = m.dot(self.center);
        match self.kind {
            KIND_DISK => {
                let t = m - m.dot(self.normal) * self.normal;
                let h = self.radius * t.length();
                (c - h, c + h)
            }
            KIND_SPHERE => {
                let h = self.radius * m.length();
                (c - h, c + h)
            }
            KIND_POINT => (c, c),
            _ => self
                .outline
                .iter()
                .fold((f32::MAX, f32::MIN), |(lo, hi), p| {
                    let d = m.dot(*p);
                    (lo.min(d), hi.max(d))
                }),
        }
    }

    /// Writes the light's part of `params`.
    pub fn write(&self, params: &mut Params) {
        let v4 = |v: Vec3, w: f32| [v.x, v.y, v.z, w];
        params.light_n = v4(self.normal, self.radius);
        params.light_u = v4(self.axes[0], self.bound.max(f32::MIN_POSITIVE));
        params.light_v = v4(self.axes[1], 0.0);
        params.kind[1] = self.kind;
        params.kind[2] = self.outline.len() as u32;
        for (k, p) in self.outline.iter().enumerate() {
            params.outline[k] = v4(*p, 1.0);
        }
    }

    /// Every float the shaders will see, for the finiteness check.
    pub fn floats(&self) -> Vec<f32> {
        let mut v = vec![self.radius, self.bound];
        for p in [self.center, self.normal, self.axes[0], self.axes[1]]
            .iter()
            .chain(&self.outline)
        {
            v.extend(p.to_array());
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shadow_core::light::{DiskLight, Radiance, RectLight, SphereLight};

    /// The support function bounds every sample, and is reached: checked against 4096 samples.
    #[test]
    fn light_range_bounds_the_samples() {
        let lights: Vec<Box<dyn AreaLight>> = vec![
            Box::new(
                RectLight::new(
                    Vec3::new(0.0, 2.0, 0.0),
                    Vec3::new(0.5, 0.0, 0.0),
                    Vec3::new(0.0, 0.0, 0.3),
                    Radiance::constant(Vec3::ONE).unwrap(),
                )
                .unwrap(),
            ),
            Box::new(
                DiskLight::new(
                    Vec3::new(1.0, 2.0, 0.0),
                    Vec3::new(0.0, -1.0, 0.2),
                    0.4,
                    Radiance::constant(Vec3::ONE).unwrap(),
                )
                .unwrap(),
            ),
            Box::new(
                SphereLight::new(
                    Vec3::new(0.0, 3.0, 1.0),
                    0.5,
                    Radiance::constant(Vec3::ONE).unwrap(),
                )
                .unwrap(),
            ),
        ];
        for l in &lights {
            let b = LightBounds::new(l.as_ref(), false);
            for m in [
                Vec3::X,
                Vec3::new(0.3, -0.8, 0.5),
                Vec3::new(-1.0, 2.0, 0.1),
            ] {
                let (lo, hi) = b.range(m);
                let (mut slo, mut shi) = (f32::MAX, f32::MIN);
                for k in 0..4096 {
                    let u = glam::Vec2::new((k % 64) as f32 / 63.0, (k / 64) as f32 / 63.0)
                        .min(glam::Vec2::splat(0.9999));
                    let d = m.dot(l.sample(u).position);
                    slo = slo.min(d);
                    shi = shi.max(d);
                }
                assert!(lo <= slo + 1e-4 && hi >= shi - 1e-4, "{l:?} {m}");
                assert!(
                    shi - slo > 0.9 * (hi - lo) - 1e-3,
                    "{l:?} {m}: loose bounds"
                );
            }
        }
    }
}
