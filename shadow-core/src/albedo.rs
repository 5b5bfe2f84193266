//! Base-colour textures (issue 52 item 7): the diffuse albedo of the shaded and direct output
//! varies over a surface as glTF's `baseColorTexture` times `baseColorFactor` says. Visibility
//! never reads albedo; the images a viewer sees (shaded views, DCS eq. 6's direct light) do,
//! through [`crate::scene::Scene::albedo_at`].
//!
//! A texture is filtered bilinearly with repeat addressing (glTF's default sampler), by the
//! same lookup as textured lights ([`TexturedRadiance`]), with the factor as its scale.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::light::TexturedRadiance;

/// An RGB albedo texture: linear texels times a factor, each channel clamped to `[0, 1]`.
#[derive(Debug, Clone, PartialEq)]
pub struct AlbedoTexture {
    lookup: TexturedRadiance,
}

impl AlbedoTexture {
    /// A `width x height` texture of linear RGB texels (row 0 at `v = 0`) times `factor`.
    ///
    /// # Errors
    /// A message when the image is empty, its size does not match, or a texel or the factor is
    /// negative or not finite.
    pub fn new(width: u32, height: u32, texels: Vec<Vec3>, factor: Vec3) -> Result<Self, String> {
        TexturedRadiance::new(width, height, texels, factor, glam::Affine2::IDENTITY)
            .map(|lookup| Self { lookup })
            .map_err(|e| e.to_string())
    }

    /// The albedo at texture coordinate `uv` (repeating outside `[0, 1]^2`).
    pub fn at(&self, uv: Vec2) -> Vec3 {
        self.lookup.at(uv).clamp(Vec3::ZERO, Vec3::ONE)
    }

    /// Image size.
    pub fn size(&self) -> (u32, u32) {
        self.lookup.size()
    }
}

/// A mesh's albedo texture and its texture coordinates, one per vertex.
#[derive(Debug, Clone)]
pub struct TexturedAlbedo {
    /// The texture (shared between meshes that use the same image and factor).
    pub texture: Arc<AlbedoTexture>,
    /// Texture coordinates, one per vertex of the mesh.
    pub texcoords: Vec<Vec2>,
}

/// Which triangles of a scene are textured, with which texture and coordinates.
#[derive(Debug, Clone, Default)]
pub(crate) struct AlbedoMaps {
    textures: Vec<Arc<AlbedoTexture>>,
    /// Per triangle: its index into `textures`, or [`AlbedoMaps::NONE`].
    texture_of: Vec<u32>,
    /// Per triangle: the texture coordinates of its corners, in its winding.
    uvs: Vec<[Vec2; 3]>,
}

impl AlbedoMaps {
    const NONE: u32 = u32::MAX;

    /// Maps for `n` untextured triangles.
    pub(crate) fn untextured(n: usize) -> Self {
        let mut m = Self::default();
        m.push_untextured(n);
        m
    }

    /// Appends `n` untextured triangles.
    pub(crate) fn push_untextured(&mut self, n: usize) {
        self.texture_of.extend(std::iter::repeat_n(Self::NONE, n));
        self.uvs.extend(std::iter::repeat_n([Vec2::ZERO; 3], n));
    }

    /// Appends triangles textured by `texture` with corner coordinates `uvs`.
    pub(crate) fn push_textured(
        &mut self,
        texture: &Arc<AlbedoTexture>,
        uvs: impl Iterator<Item = [Vec2; 3]>,
    ) {
        let id = match self.textures.iter().position(|t| Arc::ptr_eq(t, texture)) {
            Some(i) => i,
            None => {
                self.textures.push(Arc::clone(texture));
                self.textures.len() - 1
            }
        } as u32;
        let before = self.uvs.len();
        self.uvs.extend(uvs);
        self.texture_of
            .extend(std::iter::repeat_n(id, self.uvs.len() - before));
    }

    /// The maps of the triangles `keep` (indices in order), as a builder drops degenerate ones.
    pub(crate) fn kept(&self, keep: &[usize]) -> Self {
        Self {
            textures: self.textures.clone(),
            texture_of: keep.iter().map(|&t| self.texture_of[t]).collect(),
            uvs: keep.iter().map(|&t| self.uvs[t]).collect(),
        }
    }

    /// The same maps for triangles whose winding was reversed (`[a, b, c]` stored as
    /// `[a, c, b]` by a mirroring transform).
    pub(crate) fn mirrored(&self) -> Self {
        Self {
            textures: self.textures.clone(),
            texture_of: self.texture_of.clone(),
            uvs: self.uvs.iter().map(|&[a, b, c]| [a, c, b]).collect(),
        }
    }

    /// The textured albedo of triangle `t` (corners `corners`) at point `p` on it, or `None`
    /// when the triangle has no texture.
    pub(crate) fn at(&self, t: usize, corners: [Vec3; 3], p: Vec3) -> Option<Vec3> {
        let id = *self.texture_of.get(t)?;
        if id == Self::NONE {
            return None;
        }
        let [wa, wb, wc] = barycentric(corners, p);
        let [ua, ub, uc] = self.uvs[t];
        Some(self.textures[id as usize].at(ua * wa + ub * wb + uc * wc))
    }
}

/// Barycentric weights of `p` projected onto the triangle, clamped into it (a view sample lies
/// on its triangle up to rounding).
fn barycentric([a, b, c]: [Vec3; 3], p: Vec3) -> [f32; 3] {
    let (e0, e1, d) = ((b - a).as_dvec3(), (c - a).as_dvec3(), (p - a).as_dvec3());
    let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
    let (d20, d21) = (d.dot(e0), d.dot(e1));
    let den = d00 * d11 - d01 * d01;
    if !(den > 0.0) {
        return [1.0 / 3.0; 3];
    }
    let v = ((d11 * d20 - d01 * d21) / den).clamp(0.0, 1.0);
    let w = ((d00 * d21 - d01 * d20) / den).clamp(0.0, 1.0 - v);
    [(1.0 - v - w) as f32, v as f32, w as f32]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_albedo_follows_the_interpolated_coordinates() {
        // Two texels along u: red then blue, factor one half.
        let tex =
            Arc::new(AlbedoTexture::new(2, 1, vec![Vec3::X, Vec3::Z], Vec3::splat(0.5)).unwrap());
        let mut maps = AlbedoMaps::untextured(1);
        let corners = [Vec3::ZERO, Vec3::X, Vec3::Y];
        maps.push_textured(&tex, std::iter::once([Vec2::ZERO, Vec2::X, Vec2::Y]));
        assert!(maps.at(0, corners, Vec3::new(0.2, 0.2, 0.0)).is_none());
        // At texture u = 0.25 (the red texel's centre), v anywhere: red times the factor.
        let a = maps.at(1, corners, Vec3::new(0.25, 0.5, 0.0)).unwrap();
        assert!((a - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-5, "{a}");
        let b = maps.at(1, corners, Vec3::new(0.75, 0.1, 0.0)).unwrap();
        assert!((b - Vec3::new(0.0, 0.0, 0.5)).length() < 1e-5, "{b}");
        // Only triangle 1 kept.
        let k = maps.kept(&[1]);
        assert_eq!(k.at(0, corners, Vec3::new(0.25, 0.5, 0.0)), Some(a));
        assert!(AlbedoTexture::new(0, 1, vec![], Vec3::ONE).is_err());
        assert!(AlbedoTexture::new(1, 1, vec![Vec3::NAN], Vec3::ONE).is_err());
    }
}
