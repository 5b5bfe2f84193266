//! Lightmap texels as receivers (issue 67): the texels of a mesh's texture layout (glTF
//! `TEXCOORD_0`), each the surface point its centre maps to, for a baker to shadow with any
//! technique that takes receivers without a camera.
//!
//! A texel is a receiver when its centre `((x + 0.5) / N, (y + 0.5) / N)` lies inside a
//! triangle's image in texture space (row `y` holds `v = (y + 0.5) / N`, the glTF convention of
//! `v` growing downward); its position is the barycentric blend of the triangle's corners in
//! world space and its normal the triangle's geometric normal. Where texture islands overlap,
//! the first triangle in the mesh's order keeps the texel. Texels no triangle covers are
//! background; dilating the lightmap into them (against bilinear bleeding at seams) is the
//! caller's step. The receivers are snapped onto the scene like any caller's
//! ([`crate::receivers`]), in texel order.

use glam::{Vec2, Vec3};
use thiserror::Error;

use crate::mesh::MeshDesc;
use crate::receivers::{GBuffer, ReceiverError, Snapping};
use crate::scene::Scene;
use crate::view_samples::{MAX_VIEW_PIXELS, ViewSamples};

/// Why a lightmap's texels could not be made.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LightmapError {
    /// The mesh has no texture coordinates.
    #[error("mesh `{0}` has no texture coordinates (TEXCOORD_0)")]
    NoTexcoords(String),
    /// The coordinates do not match the vertices.
    #[error("mesh `{mesh}` has {texcoords} texture coordinates for {vertices} vertices")]
    Length {
        /// The mesh.
        mesh: String,
        /// Its texture coordinates.
        texcoords: usize,
        /// Its vertices.
        vertices: usize,
    },
    /// A coordinate or a position is NaN or infinite.
    #[error("mesh `{mesh}` vertex {vertex}: its {what} is not finite")]
    NonFinite {
        /// The mesh.
        mesh: String,
        /// The vertex.
        vertex: usize,
        /// Which value.
        what: &'static str,
    },
    /// An index is out of range.
    #[error("mesh `{mesh}` triangle {triangle} indexes past its {vertices} vertices")]
    Index {
        /// The mesh.
        mesh: String,
        /// The triangle.
        triangle: usize,
        /// Its vertex count.
        vertices: usize,
    },
    /// The lightmap's side is zero or its texels too many.
    #[error("a lightmap of side {0} is outside 1 to {max}", max = max_side())]
    Size(u32),
    /// No texel centre falls inside any triangle of the layout.
    #[error("mesh `{0}`: no texel centre lies inside its texture layout at this size")]
    NoTexels(String),
    /// The texels as receivers were refused.
    #[error(transparent)]
    Receivers(#[from] ReceiverError),
}

/// The largest lightmap side: its texels within [`MAX_VIEW_PIXELS`].
pub fn max_side() -> u32 {
    (MAX_VIEW_PIXELS as f64).sqrt() as u32
}

/// A mesh's texture layout in world space: what a lightmap is baked over.
#[derive(Debug, Clone, PartialEq)]
pub struct UvLayout {
    /// The mesh's name.
    pub name: String,
    /// World positions per vertex.
    pub positions: Vec<Vec3>,
    /// Triangles, front face counter-clockwise.
    pub triangles: Vec<[u32; 3]>,
    /// Texture coordinates per vertex.
    pub texcoords: Vec<Vec2>,
}

/// One texel's surface point: where it lies and which way it faces.
#[derive(Debug, Clone, Copy)]
struct Texel {
    position: Vec3,
    normal: Vec3,
}

impl UvLayout {
    /// The layout of `mesh` (named `fallback_name` when it has no name), its positions moved by
    /// its transform.
    ///
    /// # Errors
    /// [`LightmapError`] when the mesh has no coordinates, or they do not match its vertices.
    pub fn of(mesh: &MeshDesc, fallback_name: &str) -> Result<Self, LightmapError> {
        let name = mesh.name.clone().unwrap_or_else(|| fallback_name.into());
        let texcoords = mesh
            .texcoords
            .clone()
            .ok_or_else(|| LightmapError::NoTexcoords(name.clone()))?;
        let positions = mesh
            .positions
            .iter()
            .map(|p| mesh.transform.transform_point3(*p))
            .collect();
        let layout = Self {
            name,
            positions,
            triangles: mesh.triangles.clone(),
            texcoords,
        };
        layout.check()?;
        Ok(layout)
    }

    /// Checks lengths, finiteness and indices.
    fn check(&self) -> Result<(), LightmapError> {
        let mesh = || self.name.clone();
        if self.texcoords.len() != self.positions.len() {
            return Err(LightmapError::Length {
                mesh: mesh(),
                texcoords: self.texcoords.len(),
                vertices: self.positions.len(),
            });
        }
        for (vertex, (p, t)) in self.positions.iter().zip(&self.texcoords).enumerate() {
            let what = if !p.is_finite() {
                "position"
            } else if !t.is_finite() {
                "texture coordinate"
            } else {
                continue;
            };
            return Err(LightmapError::NonFinite {
                mesh: mesh(),
                vertex,
                what,
            });
        }
        let n = self.positions.len();
        if let Some(triangle) = self
            .triangles
            .iter()
            .position(|t| t.iter().any(|&v| v as usize >= n))
        {
            return Err(LightmapError::Index {
                mesh: mesh(),
                triangle,
                vertices: n,
            });
        }
        Ok(())
    }

    /// The texels of a `size` x `size` lightmap as receivers on `scene`, in texel order (row by
    /// row), snapped onto the scene with `snapping`; texels the layout does not cover are
    /// background.
    ///
    /// # Errors
    /// [`LightmapError`] for a bad layout or size, an empty lightmap, or receivers the snapping
    /// refuses.
    pub fn texels(
        &self,
        scene: &dyn Scene,
        size: u32,
        snapping: Snapping,
    ) -> Result<ViewSamples, LightmapError> {
        self.check()?;
        if size == 0 || size > max_side() {
            return Err(LightmapError::Size(size));
        }
        let texels = self.rasterize(size);
        if texels.iter().all(Option::is_none) {
            return Err(LightmapError::NoTexels(self.name.clone()));
        }
        let positions: Vec<Vec3> = texels
            .iter()
            .map(|t| t.map_or(Vec3::ZERO, |t| t.position))
            .collect();
        let normals: Vec<Vec3> = texels
            .iter()
            .map(|t| t.map_or(Vec3::Y, |t| t.normal))
            .collect();
        let valid: Vec<bool> = texels.iter().map(Option::is_some).collect();
        let g = GBuffer {
            width: size,
            height: size,
            positions: &positions,
            geometric_normals: &normals,
            shading_normals: None,
            albedo: None,
            valid: Some(&valid),
            camera: None,
        };
        Ok(ViewSamples::from_gbuffer(scene, &g, snapping)?)
    }

    /// The surface point of every texel centre the layout covers (first triangle wins).
    fn rasterize(&self, size: u32) -> Vec<Option<Texel>> {
        let n = size as usize;
        let mut out = vec![None; n * n];
        let side = size as f32;
        for t in &self.triangles {
            let [a, b, c] = t.map(|v| self.texcoords[v as usize] * side);
            let [pa, pb, pc] = t.map(|v| self.positions[v as usize]);
            let normal = (pb - pa).cross(pc - pa);
            let area = (b - a).perp_dot(c - a);
            if normal.length_squared() == 0.0 || area == 0.0 {
                continue;
            }
            let lo = a.min(b).min(c);
            let hi = a.max(b).max(c);
            let x0 = (lo.x - 0.5).ceil().max(0.0) as usize;
            let y0 = (lo.y - 0.5).ceil().max(0.0) as usize;
            let x1 = ((hi.x - 0.5).floor().min(side - 1.0)).max(-1.0);
            let y1 = ((hi.y - 0.5).floor().min(side - 1.0)).max(-1.0);
            if x1 < 0.0 || y1 < 0.0 {
                continue;
            }
            for y in y0..=y1 as usize {
                for x in x0..=x1 as usize {
                    let i = y * n + x;
                    if out[i].is_some() {
                        continue;
                    }
                    let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                    let wa = (b - p).perp_dot(c - p) / area;
                    let wb = (c - p).perp_dot(a - p) / area;
                    let wc = 1.0 - wa - wb;
                    if wa < 0.0 || wb < 0.0 || wc < 0.0 {
                        continue;
                    }
                    out[i] = Some(Texel {
                        position: pa * wa + pb * wb + pc * wc,
                        normal,
                    });
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SceneBuilder;

    /// A 2 m square floor at y = 0 whose layout maps x to u and z to v.
    fn floor() -> MeshDesc {
        let p = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        MeshDesc::new(
            p.iter().map(|&(x, z)| Vec3::new(x, 0.0, z)).collect(),
            vec![[0, 2, 1], [0, 3, 2]],
        )
        .with_name("floor")
        .with_texcoords(
            p.iter()
                .map(|&(x, z)| Vec2::new(0.5 * (x + 1.0), 0.5 * (z + 1.0)))
                .collect(),
        )
    }

    #[test]
    fn every_texel_of_a_full_layout_is_its_surface_point() {
        let mesh = floor();
        let mut b = SceneBuilder::new();
        b.push_mesh(mesh.clone()).unwrap();
        let scene = b.build().unwrap();
        let layout = UvLayout::of(&mesh, "unnamed").unwrap();
        let view = layout
            .texels(&scene, 8, Snapping::for_scene(&scene))
            .unwrap();
        assert_eq!(
            (view.width(), view.height(), view.valid_count()),
            (8, 8, 64)
        );
        for y in 0..8u32 {
            for x in 0..8u32 {
                let s = view.get_at(x, y).unwrap();
                let want = Vec3::new(
                    (x as f32 + 0.5) / 4.0 - 1.0,
                    0.0,
                    (y as f32 + 0.5) / 4.0 - 1.0,
                );
                assert!((s.position - want).length() < 1e-5, "{x} {y}");
                assert!(s.geometric_normal.y > 0.99);
            }
        }
    }

    #[test]
    fn a_half_layout_leaves_background_and_bad_layouts_are_typed_errors() {
        let mut mesh = floor();
        let mut b = SceneBuilder::new();
        b.push_mesh(mesh.clone()).unwrap();
        let scene = b.build().unwrap();
        // Only the first triangle: the texels on or below its diagonal.
        mesh.triangles.truncate(1);
        let layout = UvLayout::of(&mesh, "x").unwrap();
        let view = layout
            .texels(&scene, 4, Snapping::for_scene(&scene))
            .unwrap();
        assert!(view.valid_count() < 16 && view.valid_count() >= 6);
        let snapping = Snapping::for_scene(&scene);
        assert_eq!(
            layout.texels(&scene, 0, snapping).unwrap_err(),
            LightmapError::Size(0)
        );
        let bare = MeshDesc::new(mesh.positions.clone(), mesh.triangles.clone());
        assert!(matches!(
            UvLayout::of(&bare, "bare"),
            Err(LightmapError::NoTexcoords(n)) if n == "bare"
        ));
        let mut short = floor();
        short.texcoords.as_mut().unwrap().pop();
        assert!(matches!(
            UvLayout::of(&short, "x"),
            Err(LightmapError::Length { .. })
        ));
        let mut nan = floor();
        nan.texcoords.as_mut().unwrap()[2].x = f32::NAN;
        assert!(matches!(
            UvLayout::of(&nan, "x"),
            Err(LightmapError::NonFinite { vertex: 2, .. })
        ));
        let mut outside = floor();
        outside.texcoords = Some(vec![Vec2::splat(3.0); 4]);
        let layout = UvLayout::of(&outside, "x").unwrap();
        assert!(matches!(
            layout.texels(&scene, 4, snapping),
            Err(LightmapError::NoTexels(_))
        ));
    }
}
