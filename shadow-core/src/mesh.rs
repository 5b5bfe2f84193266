//! One mesh as a caller describes it ([`MeshDesc`]), before a
//! [`crate::scene::SceneBuilder`] validates it into a scene.

use glam::{Affine3A, Vec2, Vec3};

use crate::albedo::TexturedAlbedo;

/// A value given once for a whole mesh or once per triangle.
#[derive(Debug, Clone, PartialEq)]
pub enum PerTriangle<T> {
    /// Same value for every triangle.
    All(T),
    /// One value per triangle.
    Each(Vec<T>),
}

/// One mesh to add to a [`crate::scene::SceneBuilder`].
#[derive(Debug, Clone)]
pub struct MeshDesc {
    /// Vertex positions in the mesh's own space.
    pub positions: Vec<Vec3>,
    /// Triangles (indices into `positions`).
    pub triangles: Vec<[u32; 3]>,
    /// Optional per-vertex shading normals in the mesh's own space.
    pub normals: Option<Vec<Vec3>>,
    /// Opacity in [0, 1].
    pub opacity: PerTriangle<f32>,
    /// Diffuse albedo in [0, 1].
    pub albedo: PerTriangle<Vec3>,
    /// A base-colour texture with per-vertex coordinates; it replaces `albedo` in shaded and
    /// direct output ([`crate::scene::Scene::albedo_at`]).
    pub albedo_texture: Option<TexturedAlbedo>,
    /// World from mesh transform.
    pub transform: Affine3A,
    /// The mesh's name (a glTF mesh's), for the caller to find it again (`bake --mesh`).
    pub name: Option<String>,
    /// Per-vertex texture coordinates of the mesh's lightmap layout (glTF `TEXCOORD_0`), read
    /// by [`crate::lightmap::UvLayout`]; the scene itself does not keep them.
    pub texcoords: Option<Vec<Vec2>>,
}

impl MeshDesc {
    /// An opaque, grey mesh with identity transform and no shading normals.
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Self {
        Self {
            positions,
            triangles,
            normals: None,
            opacity: PerTriangle::All(1.0),
            albedo: PerTriangle::All(Vec3::splat(0.8)),
            albedo_texture: None,
            transform: Affine3A::IDENTITY,
            name: None,
            texcoords: None,
        }
    }
    /// Names the mesh.
    #[must_use]
    pub fn with_name(mut self, name: &str) -> Self {
        self.name = Some(name.to_string());
        self
    }
    /// Sets the per-vertex texture coordinates of its lightmap layout.
    #[must_use]
    pub fn with_texcoords(mut self, texcoords: Vec<Vec2>) -> Self {
        self.texcoords = Some(texcoords);
        self
    }
    /// Sets the opacity of every triangle.
    #[must_use]
    pub fn with_opacity(mut self, opacity: f32) -> Self {
        self.opacity = PerTriangle::All(opacity);
        self
    }
    /// Sets the albedo of every triangle.
    #[must_use]
    pub fn with_albedo(mut self, albedo: Vec3) -> Self {
        self.albedo = PerTriangle::All(albedo);
        self
    }
    /// Sets the world-from-mesh transform.
    #[must_use]
    pub fn with_transform(mut self, transform: Affine3A) -> Self {
        self.transform = transform;
        self
    }
    /// Sets per-vertex shading normals.
    #[must_use]
    pub fn with_normals(mut self, normals: Vec<Vec3>) -> Self {
        self.normals = Some(normals);
        self
    }
}
