//! The [`Scene`] trait and the standard [`TriangleScene`], built only through validating
//! constructors (DESIGN section 3): non-finite coordinates, out-of-range indices, zero-area
//! triangles and opacities outside [0, 1] are typed errors, never passed on to a technique.

use glam::{Affine3A, DVec3, Vec3};
use thiserror::Error;

use crate::albedo::AlbedoMaps;
use crate::geometry::{Aabb, triangle_cross_f64, triangle_normal};
use crate::topology::Topology;

pub use crate::mesh::{MeshDesc, PerTriangle};

/// The largest coordinate magnitude a scene may hold: two points within it are at most
/// `3.5e18` apart, whose square (`1.2e37`) stays inside `f32`'s range, so bounds, ray lengths
/// and offsets never overflow to infinity.
pub const MAX_COORDINATE: f32 = 1e18;

/// Why a scene was rejected.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SceneError {
    /// The scene holds no triangle.
    #[error("the scene has no triangles")]
    Empty,
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {index} has a non-finite coordinate {value:?}")]
    NonFiniteVertex {
        /// Vertex index.
        index: usize,
        /// The offending position.
        value: [f32; 3],
    },
    /// A vertex coordinate is so large that squared distances between scene points overflow
    /// `f32` (the BVH's bounds, ray lengths and offsets all square them).
    #[error(
        "vertex {index} at {value:?} is beyond the largest supported coordinate magnitude \
         {limit:e} (squared distances would overflow single precision)"
    )]
    CoordinateTooLarge {
        /// Vertex index.
        index: usize,
        /// The offending position.
        value: [f32; 3],
        /// [`MAX_COORDINATE`].
        limit: f32,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "triangle {triangle} refers to vertex {vertex}, but there are only {vertex_count} vertices"
    )]
    IndexOutOfRange {
        /// Triangle index.
        triangle: usize,
        /// The offending vertex index.
        vertex: u32,
        /// Number of vertices.
        vertex_count: usize,
    },
    /// A triangle has no area (repeated or collinear vertices).
    #[error("triangle {triangle} has zero area (vertices {vertices:?})")]
    DegenerateTriangle {
        /// Triangle index.
        triangle: usize,
        /// Its vertex indices.
        vertices: [u32; 3],
    },
    /// An opacity is NaN or outside [0, 1].
    #[error("triangle {triangle} has opacity {value}, outside [0, 1]")]
    InvalidOpacity {
        /// Triangle index.
        triangle: usize,
        /// The offending value.
        value: f32,
    },
    /// An albedo is NaN, negative or above 1.
    #[error("triangle {triangle} has albedo {value:?}, outside [0, 1]")]
    InvalidAlbedo {
        /// Triangle index.
        triangle: usize,
        /// The offending value.
        value: [f32; 3],
    },
    /// A shading normal is non-finite or has zero length.
    #[error("shading normal {index} is {value:?}: not a finite non-zero vector")]
    InvalidNormal {
        /// Vertex index.
        index: usize,
        /// The offending value.
        value: [f32; 3],
    },
    /// A per-vertex or per-triangle array has the wrong length.
    #[error("{what} has {got} entries, expected {expected}")]
    LengthMismatch {
        /// Which array.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The length it must have.
        expected: usize,
    },
    /// More vertices or triangles than 32-bit indices can address.
    #[error("{what} count {count} exceeds the 32-bit index range")]
    TooLarge {
        /// Vertices or triangles.
        what: &'static str,
        /// The count.
        count: usize,
    },
    /// A transform is not finite or not invertible.
    #[error("mesh transform is not finite and invertible")]
    InvalidTransform,
    /// Texture coordinates of an albedo texture are not finite.
    #[error("texture coordinate {index} is {value:?}: not finite")]
    InvalidTexcoord {
        /// Vertex index in the mesh.
        index: usize,
        /// The offending value.
        value: [f32; 2],
    },
}

/// A scene of triangles as every technique sees it.
///
/// Contract for implementors: positions are finite, indices valid, every triangle has a non-zero
/// area, opacities lie in [0, 1] (1 = opaque) and shading normals, when present, are unit vectors.
/// [`TriangleScene`] guarantees all of this through its constructors.
pub trait Scene: Send + Sync {
    /// Vertex positions (world space, metres, Y up).
    fn positions(&self) -> &[Vec3];
    /// Triangles as vertex indices, counter-clockwise = front.
    fn triangles(&self) -> &[[u32; 3]];
    /// Per-triangle opacity in [0, 1].
    fn opacities(&self) -> &[f32];
    /// Optional per-vertex unit shading normals.
    fn shading_normals(&self) -> Option<&[Vec3]>;
    /// Edge adjacency and closedness.
    fn topology(&self) -> &Topology;
    /// Bounds of all vertices.
    fn bounds(&self) -> Aabb;

    /// Per-triangle diffuse albedo, used only for shaded images (default 0.8 grey).
    fn albedo(&self, _triangle: usize) -> Vec3 {
        Vec3::splat(0.8)
    }
    /// The diffuse albedo at point `p` of triangle `triangle` (a view sample's position), for
    /// shaded images and direct light: a base-colour texture where the triangle has one,
    /// else [`Scene::albedo`].
    fn albedo_at(&self, triangle: usize, _p: Vec3) -> Vec3 {
        self.albedo(triangle)
    }
    /// Number of triangles.
    fn triangle_count(&self) -> usize {
        self.triangles().len()
    }
    /// The three corners of a triangle.
    fn triangle(&self, t: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles()[t];
        let p = self.positions();
        [p[a as usize], p[b as usize], p[c as usize]]
    }
    /// Unit geometric normal of a triangle (counter-clockwise front).
    fn geometric_normal(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.triangle(t);
        triangle_normal(a, b, c).unwrap_or(Vec3::Z)
    }
    /// True when some triangle is not fully opaque, so opacity handling is needed (implementors
    /// should cache it: techniques ask per pixel).
    fn has_semi_opaque(&self) -> bool {
        self.opacities().iter().any(|&o| o < 1.0)
    }
    /// True when the connected mesh holding triangle `t` is closed.
    fn is_closed_at(&self, t: usize) -> bool {
        let topo = self.topology();
        topo.components()[topo.component_of(t)].closed
    }
}

/// What a scene builder does with zero-area triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DegeneratePolicy {
    /// Reject the scene with [`SceneError::DegenerateTriangle`].
    #[default]
    Reject,
    /// Drop them and count them in [`TriangleScene::dropped_degenerate`] (for scanned meshes).
    Drop,
}

/// The standard validated triangle scene.
#[derive(Debug, Clone)]
pub struct TriangleScene {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    opacities: Vec<f32>,
    albedos: Vec<Vec3>,
    normals: Option<Vec<Vec3>>,
    /// Base-colour textures, when any mesh has one.
    albedo_maps: Option<AlbedoMaps>,
    topology: Topology,
    bounds: Aabb,
    dropped_degenerate: usize,
    semi_opaque: bool,
}

impl TriangleScene {
    /// An opaque scene from positions and triangles.
    ///
    /// # Errors
    /// Any [`SceneError`] describing the first invalid element.
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self, SceneError> {
        let mut b = SceneBuilder::new();
        b.push_mesh(MeshDesc::new(positions, triangles))?;
        b.build()
    }

    /// Number of zero-area triangles dropped under [`DegeneratePolicy::Drop`].
    pub fn dropped_degenerate(&self) -> usize {
        self.dropped_degenerate
    }

    /// A copy of the scene with every vertex moved by `f` (used for scaled and translated stress
    /// variants), validated again.
    ///
    /// # Errors
    /// As [`SceneBuilder::build`] when the transform produces invalid geometry.
    pub fn transformed(&self, world_from_scene: Affine3A) -> Result<Self, SceneError> {
        let mut b = SceneBuilder::new();
        b.push_mesh(MeshDesc {
            positions: self.positions.clone(),
            triangles: self.triangles.clone(),
            normals: self.normals.clone(),
            opacity: PerTriangle::Each(self.opacities.clone()),
            albedo: PerTriangle::Each(self.albedos.clone()),
            albedo_texture: None,
            transform: world_from_scene,
            name: None,
            texcoords: None,
        })?;
        // Degenerate triangles are rejected, so the triangles keep their order and the
        // textures theirs (a mirroring transform reverses every winding, corners and
        // coordinates alike).
        let mut scene = b.build()?;
        scene.albedo_maps = self.albedo_maps.as_ref().map(|m| {
            if world_from_scene.matrix3.determinant() < 0.0 {
                m.mirrored()
            } else {
                m.clone()
            }
        });
        Ok(scene)
    }
}

impl Scene for TriangleScene {
    fn positions(&self) -> &[Vec3] {
        &self.positions
    }
    fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }
    fn opacities(&self) -> &[f32] {
        &self.opacities
    }
    fn shading_normals(&self) -> Option<&[Vec3]> {
        self.normals.as_deref()
    }
    fn topology(&self) -> &Topology {
        &self.topology
    }
    fn bounds(&self) -> Aabb {
        self.bounds
    }
    fn albedo(&self, triangle: usize) -> Vec3 {
        self.albedos[triangle]
    }
    fn albedo_at(&self, triangle: usize, p: Vec3) -> Vec3 {
        self.albedo_maps
            .as_ref()
            .and_then(|m| m.at(triangle, self.triangle(triangle), p))
            .unwrap_or(self.albedos[triangle])
    }
    fn has_semi_opaque(&self) -> bool {
        self.semi_opaque
    }
}

/// Collects meshes and validates them into a [`TriangleScene`].
#[derive(Debug, Default)]
pub struct SceneBuilder {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    opacities: Vec<f32>,
    albedos: Vec<Vec3>,
    normals: Vec<Option<Vec3>>,
    any_normals: bool,
    albedo_maps: Option<AlbedoMaps>,
    policy: DegeneratePolicy,
}

impl SceneBuilder {
    /// An empty builder rejecting zero-area triangles.
    pub fn new() -> Self {
        Self::default()
    }

    /// Chooses what to do with zero-area triangles.
    #[must_use]
    pub fn degenerate_policy(mut self, policy: DegeneratePolicy) -> Self {
        self.policy = policy;
        self
    }

    /// Adds a mesh, transformed to world space. Indices are checked here; geometry in
    /// [`SceneBuilder::build`].
    ///
    /// # Errors
    /// Index, length or transform errors of this mesh (indices are reported relative to the
    /// mesh).
    pub fn push_mesh(&mut self, mesh: MeshDesc) -> Result<&mut Self, SceneError> {
        let nv = mesh.positions.len();
        let nt = mesh.triangles.len();
        if !mesh.transform.is_finite() || mesh.transform.matrix3.determinant() == 0.0 {
            return Err(SceneError::InvalidTransform);
        }
        for (t, tri) in mesh.triangles.iter().enumerate() {
            if let Some(&v) = tri.iter().find(|&&v| v as usize >= nv) {
                return Err(SceneError::IndexOutOfRange {
                    triangle: t,
                    vertex: v,
                    vertex_count: nv,
                });
            }
        }
        let check_len = |what, got, expected| {
            if got == expected {
                Ok(())
            } else {
                Err(SceneError::LengthMismatch {
                    what,
                    got,
                    expected,
                })
            }
        };
        if let PerTriangle::Each(v) = &mesh.opacity {
            check_len("opacity", v.len(), nt)?;
        }
        if let PerTriangle::Each(v) = &mesh.albedo {
            check_len("albedo", v.len(), nt)?;
        }
        if let Some(n) = &mesh.normals {
            check_len("normals", n.len(), nv)?;
        }
        if let Some(t) = &mesh.albedo_texture {
            check_len("texture coordinates", t.texcoords.len(), nv)?;
            if let Some(i) = t.texcoords.iter().position(|c| !c.is_finite()) {
                return Err(SceneError::InvalidTexcoord {
                    index: i,
                    value: t.texcoords[i].to_array(),
                });
            }
        }
        let base = self.positions.len();
        if base + nv > u32::MAX as usize {
            return Err(SceneError::TooLarge {
                what: "vertex",
                count: base + nv,
            });
        }
        if self.triangles.len() + nt > u32::MAX as usize {
            return Err(SceneError::TooLarge {
                what: "triangle",
                count: self.triangles.len() + nt,
            });
        }
        let normal_from_mesh = mesh.transform.matrix3.inverse().transpose();
        for (i, p) in mesh.positions.iter().enumerate() {
            if !p.is_finite() {
                return Err(SceneError::NonFiniteVertex {
                    index: base + i,
                    value: p.to_array(),
                });
            }
            self.positions.push(mesh.transform.transform_point3(*p));
        }
        match &mesh.normals {
            Some(ns) => {
                self.any_normals = true;
                for (i, n) in ns.iter().enumerate() {
                    let w = normal_from_mesh * glam::Vec3A::from(*n);
                    let len = w.length();
                    if !(n.is_finite() && len > 0.0 && len.is_finite()) {
                        return Err(SceneError::InvalidNormal {
                            index: base + i,
                            value: n.to_array(),
                        });
                    }
                    self.normals.push(Some(Vec3::from(w / len)));
                }
            }
            None => self.normals.extend(std::iter::repeat_n(None, nv)),
        }
        let flip = mesh.transform.matrix3.determinant() < 0.0;
        for tri in &mesh.triangles {
            let [a, b, c] = tri.map(|v| v + base as u32);
            self.triangles
                .push(if flip { [a, c, b] } else { [a, b, c] });
        }
        let t0 = self.triangles.len() - nt;
        match (&mesh.albedo_texture, &mut self.albedo_maps) {
            (Some(t), maps) => {
                let uv = |v: u32| t.texcoords[v as usize];
                maps.get_or_insert_with(|| AlbedoMaps::untextured(t0))
                    .push_textured(
                        &t.texture,
                        mesh.triangles.iter().map(|&[a, b, c]| {
                            // In the winding the triangle was stored with.
                            if flip {
                                [uv(a), uv(c), uv(b)]
                            } else {
                                [uv(a), uv(b), uv(c)]
                            }
                        }),
                    );
            }
            (None, Some(maps)) => maps.push_untextured(nt),
            (None, None) => {}
        }
        match mesh.opacity {
            PerTriangle::All(o) => self.opacities.extend(std::iter::repeat_n(o, nt)),
            PerTriangle::Each(v) => self.opacities.extend(v),
        }
        match mesh.albedo {
            PerTriangle::All(a) => self.albedos.extend(std::iter::repeat_n(a, nt)),
            PerTriangle::Each(v) => self.albedos.extend(v),
        }
        debug_assert_eq!(self.opacities.len(), t0 + nt);
        Ok(self)
    }

    /// Validates everything and builds the scene (adjacency included).
    ///
    /// # Errors
    /// [`SceneError::Empty`], [`SceneError::NonFiniteVertex`] (a transform overflowed),
    /// [`SceneError::InvalidOpacity`], [`SceneError::InvalidAlbedo`], or
    /// [`SceneError::DegenerateTriangle`] under [`DegeneratePolicy::Reject`].
    pub fn build(self) -> Result<TriangleScene, SceneError> {
        let Self {
            positions,
            triangles,
            opacities,
            albedos,
            normals,
            any_normals,
            albedo_maps,
            policy,
        } = self;
        for (i, p) in positions.iter().enumerate() {
            if !p.is_finite() {
                return Err(SceneError::NonFiniteVertex {
                    index: i,
                    value: p.to_array(),
                });
            }
        }
        // After the non-finite check, so that an overflowed transform reads as one.
        for (i, p) in positions.iter().enumerate() {
            if p.abs().max_element() > MAX_COORDINATE {
                return Err(SceneError::CoordinateTooLarge {
                    index: i,
                    value: p.to_array(),
                    limit: MAX_COORDINATE,
                });
            }
        }
        for (t, &o) in opacities.iter().enumerate() {
            if !(0.0..=1.0).contains(&o) {
                return Err(SceneError::InvalidOpacity {
                    triangle: t,
                    value: o,
                });
            }
        }
        for (t, a) in albedos.iter().enumerate() {
            if !(a.is_finite() && a.min_element() >= 0.0 && a.max_element() <= 1.0) {
                return Err(SceneError::InvalidAlbedo {
                    triangle: t,
                    value: a.to_array(),
                });
            }
        }
        let mut keep = Vec::with_capacity(triangles.len());
        let mut dropped = 0;
        for (t, tri) in triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|v| positions[v as usize]);
            let cross = triangle_cross_f64(a, b, c).length();
            let degenerate = !(cross > 0.0) || triangle_normal(a, b, c).is_none();
            if degenerate {
                match policy {
                    DegeneratePolicy::Reject => {
                        return Err(SceneError::DegenerateTriangle {
                            triangle: t,
                            vertices: *tri,
                        });
                    }
                    DegeneratePolicy::Drop => dropped += 1,
                }
            } else {
                keep.push(t);
            }
        }
        if keep.is_empty() {
            return Err(SceneError::Empty);
        }
        let pick = |v: &[f32]| keep.iter().map(|&t| v[t]).collect::<Vec<_>>();
        let opacities = pick(&opacities);
        let albedos = keep.iter().map(|&t| albedos[t]).collect();
        let triangles: Vec<[u32; 3]> = keep.iter().map(|&t| triangles[t]).collect();
        // Vertices without a shading normal (from meshes that gave none) take the area-weighted
        // average of their faces' normals, so the array is complete when any mesh has normals.
        let normals = any_normals.then(|| {
            let mut acc = vec![Vec3::ZERO; positions.len()];
            for tri in &triangles {
                let [a, b, c] = tri.map(|v| positions[v as usize]);
                let n = triangle_cross_f64(a, b, c).as_vec3();
                for &v in tri {
                    acc[v as usize] += n;
                }
            }
            normals
                .iter()
                .zip(acc)
                .map(|(n, a)| n.unwrap_or_else(|| a.try_normalize().unwrap_or(Vec3::Y)))
                .collect()
        });
        let topology = Topology::build(&triangles);
        let bounds = Aabb::from_points(&positions);
        let semi_opaque = opacities.iter().any(|&o| o < 1.0);
        let albedo_maps = albedo_maps.map(|m| m.kept(&keep));
        Ok(TriangleScene {
            positions,
            triangles,
            opacities,
            albedos,
            normals,
            albedo_maps,
            topology,
            bounds,
            dropped_degenerate: dropped,
            semi_opaque,
        })
    }
}

/// For each topology component flagged in `among` (indexed by component), whether it holds
/// `p`: the parity of a ray's crossings with its triangles, along a direction no regular mesh
/// is aligned with. Meaningful for closed meshes; `false` for components not flagged.
pub fn components_containing(scene: &dyn Scene, p: DVec3, among: &[bool]) -> Vec<bool> {
    let topo = scene.topology();
    let dir = DVec3::new(0.577_215_664_9, 0.312_029_995_7, 0.759_134_812_3).normalize();
    let mut inside = vec![false; among.len()];
    if !among.iter().any(|c| *c) {
        return inside;
    }
    for t in 0..scene.triangle_count() {
        let c = topo.component_of(t);
        if among[c] {
            let [a, b, v] = scene.triangle(t).map(|q| q.as_dvec3());
            if crate::geometry::ray_hits_triangle(p, dir, a, b, v, f64::INFINITY) {
                inside[c] = !inside[c];
            }
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        (
            vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }

    #[test]
    fn valid_quad_builds() {
        let (p, t) = quad();
        let s = TriangleScene::new(p, t).unwrap();
        assert_eq!(s.triangle_count(), 2);
        assert_eq!(s.topology().boundary_edges().count(), 4);
        assert!(!s.is_closed_at(0));
        assert!((s.geometric_normal(0) - Vec3::Z).length() < 1e-6);
    }

    /// Issue 51, item 4: a coordinate above about 1e20 made the BVH's bounds overflow and
    /// panic downstream; the scene refuses it with the limit in the message.
    #[test]
    fn coordinates_beyond_the_supported_magnitude_are_refused() {
        let (p, t) = quad();
        let mut far = p.clone();
        far[3] = Vec3::new(0.0, 1e20, 0.0);
        let e = TriangleScene::new(far, t.clone()).unwrap_err();
        assert!(
            matches!(e, SceneError::CoordinateTooLarge { index: 3, .. }),
            "{e}"
        );
        assert!(e.to_string().contains("1e18"), "{e}");
        let mut edge = p.clone();
        edge[3] = Vec3::new(0.0, MAX_COORDINATE, 0.0);
        assert!(TriangleScene::new(edge, t).is_ok());
    }

    #[test]
    fn every_invalid_input_is_a_typed_error() {
        let (p, t) = quad();
        let mut bad = p.clone();
        bad[2].y = f32::NAN;
        assert!(matches!(
            TriangleScene::new(bad, t.clone()),
            Err(SceneError::NonFiniteVertex { index: 2, .. })
        ));
        let mut bad = p.clone();
        bad[1].x = f32::INFINITY;
        assert!(matches!(
            TriangleScene::new(bad, t.clone()),
            Err(SceneError::NonFiniteVertex { index: 1, .. })
        ));
        assert!(matches!(
            TriangleScene::new(p.clone(), vec![[0, 1, 7]]),
            Err(SceneError::IndexOutOfRange { vertex: 7, .. })
        ));
        assert!(matches!(
            TriangleScene::new(p.clone(), vec![[0, 1, 1]]),
            Err(SceneError::DegenerateTriangle { triangle: 0, .. })
        ));
        let mut collinear = p.clone();
        collinear[2] = Vec3::new(2.0, 0.0, 0.0);
        assert!(matches!(
            TriangleScene::new(collinear, vec![[0, 1, 2]]),
            Err(SceneError::DegenerateTriangle { .. })
        ));
        assert!(matches!(
            TriangleScene::new(p.clone(), vec![]),
            Err(SceneError::Empty)
        ));
        let mut b = SceneBuilder::new();
        b.push_mesh(MeshDesc::new(p.clone(), t.clone()).with_opacity(1.5))
            .unwrap();
        assert!(matches!(b.build(), Err(SceneError::InvalidOpacity { .. })));
        let mut b = SceneBuilder::new();
        b.push_mesh(MeshDesc::new(p.clone(), t.clone()).with_opacity(f32::NAN))
            .unwrap();
        assert!(matches!(b.build(), Err(SceneError::InvalidOpacity { .. })));
        let mut b = SceneBuilder::new();
        let err = b
            .push_mesh(MeshDesc::new(p.clone(), t.clone()).with_normals(vec![Vec3::ZERO; 4]))
            .unwrap_err();
        assert!(matches!(err, SceneError::InvalidNormal { index: 0, .. }));
        let mut b = SceneBuilder::new();
        let err = b
            .push_mesh(MeshDesc::new(p.clone(), t.clone()).with_normals(vec![Vec3::Z; 3]))
            .unwrap_err();
        assert!(matches!(
            err,
            SceneError::LengthMismatch {
                what: "normals",
                ..
            }
        ));
        let mut b = SceneBuilder::new();
        let err = b
            .push_mesh(
                MeshDesc::new(p.clone(), t.clone())
                    .with_transform(Affine3A::from_scale(Vec3::ZERO)),
            )
            .unwrap_err();
        assert_eq!(err, SceneError::InvalidTransform);
        // A finite transform that overflows f32 produces infinite world positions.
        let mut b = SceneBuilder::new();
        b.push_mesh(
            MeshDesc::new(p.clone(), t.clone())
                .with_transform(Affine3A::from_scale(Vec3::splat(1e30)))
                .with_opacity(1.0),
        )
        .unwrap();
        let mut far = p.clone();
        far[2] = Vec3::splat(1e30);
        b.push_mesh(MeshDesc::new(far, t).with_transform(Affine3A::from_scale(Vec3::splat(1e30))))
            .unwrap();
        assert!(matches!(b.build(), Err(SceneError::NonFiniteVertex { .. })));
    }

    #[test]
    fn degenerate_triangles_can_be_dropped_and_counted() {
        let (p, mut t) = quad();
        t.push([0, 0, 1]);
        let mut b = SceneBuilder::new().degenerate_policy(DegeneratePolicy::Drop);
        b.push_mesh(MeshDesc::new(p, t)).unwrap();
        let s = b.build().unwrap();
        assert_eq!(s.triangle_count(), 2);
        assert_eq!(s.dropped_degenerate(), 1);
    }

    #[test]
    fn mirroring_transform_keeps_front_faces() {
        let (p, t) = quad();
        let mut b = SceneBuilder::new();
        b.push_mesh(
            MeshDesc::new(p, t).with_transform(Affine3A::from_scale(Vec3::new(-1.0, 1.0, 1.0))),
        )
        .unwrap();
        let s = b.build().unwrap();
        assert!((s.geometric_normal(0) - Vec3::Z).length() < 1e-6);
    }

    #[test]
    fn sliver_triangles_are_kept() {
        let p = vec![
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.5, 1e-6, 0.0),
        ];
        let s = TriangleScene::new(p, vec![[0, 1, 2]]).unwrap();
        assert_eq!(s.triangle_count(), 1);
    }
}
