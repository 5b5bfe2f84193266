//! Light radiance: constant, or an RGB image over the light's `[0, 1]^2` parametrisation
//! (textured lights, DCS eq. 2).

use std::sync::Arc;

use glam::{Affine2, Vec2, Vec3, Vec3A};

use super::LightError;
use crate::rounding::floor_f32;

/// Radiance of a light.
#[derive(Debug, Clone, PartialEq)]
pub enum Radiance {
    /// The same RGB radiance everywhere.
    Constant(Vec3),
    /// An RGB image over the light's uv.
    Textured(TexturedRadiance),
}

impl Radiance {
    /// A constant radiance.
    ///
    /// # Errors
    /// [`LightError::InvalidRadiance`] for negative or non-finite components.
    pub fn constant(rgb: Vec3) -> Result<Self, LightError> {
        if rgb.is_finite() && rgb.min_element() >= 0.0 {
            Ok(Self::Constant(rgb))
        } else {
            Err(LightError::InvalidRadiance(rgb.to_array()))
        }
    }

    /// Radiance at light uv `uv`.
    #[inline]
    pub fn at(&self, uv: Vec2) -> Vec3 {
        match self {
            Self::Constant(c) => *c,
            Self::Textured(t) => t.at(uv),
        }
    }

    /// Mean radiance over the light (for a texture: the mean over its uv square).
    pub fn mean(&self) -> Vec3 {
        match self {
            Self::Constant(c) => *c,
            Self::Textured(t) => t.mean,
        }
    }
}

/// An RGB image mapped onto a light.
///
/// Texture coordinates are `texture_from_light * uv`; the image repeats outside `[0, 1]^2`
/// (the glTF default wrap) and is filtered bilinearly. Texels are linear radiance multiplied by
/// `scale`.
#[derive(Debug, Clone, PartialEq)]
pub struct TexturedRadiance {
    width: u32,
    height: u32,
    /// The texels in 16-byte form: a bilinear lookup's four loads and three blends are then
    /// one vector operation each (the same values as on `Vec3`).
    texels: Arc<[Vec3A]>,
    scale: Vec3,
    texture_from_light: Affine2,
    mean: Vec3,
}

impl TexturedRadiance {
    /// A texture of `width x height` linear RGB texels (row 0 at `v = 0`), scaled by `scale`.
    ///
    /// # Errors
    /// [`LightError::InvalidTexture`] when the image is empty, its size does not match, or a
    /// texel or the scale is negative or non-finite.
    pub fn new(
        width: u32,
        height: u32,
        texels: Vec<Vec3>,
        scale: Vec3,
        texture_from_light: Affine2,
    ) -> Result<Self, LightError> {
        if width == 0 || height == 0 || texels.len() != width as usize * height as usize {
            return Err(LightError::InvalidTexture(format!(
                "{width}x{height} image with {} texels",
                texels.len()
            )));
        }
        if let Some(bad) = texels
            .iter()
            .chain(std::iter::once(&scale))
            .find(|t| !(t.is_finite() && t.min_element() >= 0.0))
        {
            return Err(LightError::InvalidTexture(format!(
                "texel or scale {bad:?} is negative or not finite"
            )));
        }
        if !texture_from_light.is_finite() {
            return Err(LightError::InvalidTexture("non-finite uv transform".into()));
        }
        let mut t = Self {
            width,
            height,
            texels: texels.into_iter().map(Vec3A::from).collect(),
            scale,
            texture_from_light,
            mean: Vec3::ZERO,
        };
        // Mean over the light's uv square, by midpoint integration of the filtered texture.
        let n = 64;
        let mut sum = Vec3::ZERO;
        for j in 0..n {
            for i in 0..n {
                sum += t.at(Vec2::new(
                    (i as f32 + 0.5) / n as f32,
                    (j as f32 + 0.5) / n as f32,
                ));
            }
        }
        t.mean = sum / (n * n) as f32;
        Ok(t)
    }

    /// Image size.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Bilinearly filtered radiance at light uv.
    #[inline]
    pub fn at(&self, uv: Vec2) -> Vec3 {
        let st = self.texture_from_light.transform_point2(uv);
        let x = st.x * self.width as f32 - 0.5;
        let y = st.y * self.height as f32 - 0.5;
        let ((x0, xi), (y0, yi)) = (floor_index(x), floor_index(y));
        let (fx, fy) = (x - x0, y - y0);
        let (xa, xb) = (wrap(xi, self.width), wrap(xi.saturating_add(1), self.width));
        let (ya, yb) = (
            wrap(yi, self.height),
            wrap(yi.saturating_add(1), self.height),
        );
        let w = self.width as usize;
        let (ra, rb) = (&self.texels[ya * w..][..w], &self.texels[yb * w..][..w]);
        let a = ra[xa].lerp(ra[xb], fx);
        let b = rb[xa].lerp(rb[xb], fx);
        Vec3::from(a.lerp(b, fy) * Vec3A::from(self.scale))
    }
}

/// `x.floor()` and the same value as an integer (as `x.floor() as i64` gives it). Within
/// `2^23` (every coordinate of a texture that fits in memory) a truncation through `i32` and a
/// correction for negative fractions, which the compiler keeps branch-free.
#[inline]
fn floor_index(x: f32) -> (f32, i64) {
    if x.abs() < 8_388_608.0 {
        let t = x as i32;
        let t = t - i32::from(t as f32 > x);
        (t as f32, i64::from(t))
    } else {
        let f = floor_f32(x);
        (f, f as i64)
    }
}

/// The texel index `i` wrapped into `0..n` (repeat addressing); a division only outside.
#[inline]
fn wrap(i: i64, n: u32) -> usize {
    let n = i64::from(n);
    if (0..n).contains(&i) {
        i as usize
    } else {
        i.rem_euclid(n) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lookup equals bilinear filtering with `f32::floor` and Euclidean wrapping, inside
    /// the texture and tiled around it, and the fast floor equals `f32::floor`.
    #[test]
    fn lookup_equals_the_plain_bilinear_filter() {
        let (w, h) = (5u32, 3u32);
        let texels: Vec<Vec3> = (0..w * h)
            .map(|k| Vec3::new(k as f32, (k * 7 % 11) as f32, (k * 3 % 5) as f32))
            .collect();
        let tex = TexturedRadiance::new(
            w,
            h,
            texels.clone(),
            Vec3::ONE,
            Affine2::from_scale(Vec2::new(1.5, -2.25)),
        )
        .unwrap();
        let plain = |uv: Vec2| {
            let st = tex.texture_from_light.transform_point2(uv);
            let (x, y) = (st.x * w as f32 - 0.5, st.y * h as f32 - 0.5);
            let (x0, y0) = (x.floor(), y.floor());
            let t = |xi: f32, yi: f32| {
                let xi = (xi as i64).rem_euclid(i64::from(w)) as usize;
                let yi = (yi as i64).rem_euclid(i64::from(h)) as usize;
                texels[yi * w as usize + xi]
            };
            let a = t(x0, y0).lerp(t(x0 + 1.0, y0), x - x0);
            let b = t(x0, y0 + 1.0).lerp(t(x0 + 1.0, y0 + 1.0), x - x0);
            a.lerp(b, y - y0)
        };
        for k in 0..2000u64 {
            let r = |i: u64| crate::sampling::unit_float(crate::sampling::hash_words(&[k, i]));
            let uv = Vec2::new(r(0) * 6.0 - 3.0, r(1) * 6.0 - 3.0);
            assert_eq!(tex.at(uv), plain(uv), "uv {uv}");
        }
        // The floor with its index, on both sides of the fast path's bound and at integers.
        let mut xs = vec![0.0, -0.0, 1.0, -1.0, 0.5, -0.5, 8_388_607.5, -8_388_607.5];
        xs.extend([8_388_608.0f32, -8_388_608.0, 1e9, -1e9, 3e30, -3e30]);
        xs.extend((0..4000u64).map(|k| {
            let u = crate::sampling::unit_float(crate::sampling::hash_words(&[k]));
            (u - 0.5) * 2f32.powi((k % 30) as i32)
        }));
        for x in xs {
            let (f, i) = floor_index(x);
            // Equal values (the floor of -0 comes out as +0, as through `floor_f32`).
            assert_eq!(f, x.floor(), "{x}");
            assert_eq!(f.to_bits(), floor_f32(x).to_bits(), "{x}");
            assert_eq!(i, x.floor() as i64, "{x}");
        }
    }

    #[test]
    fn texture_lookup_and_mean() {
        let tex = TexturedRadiance::new(
            2,
            1,
            vec![Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0)],
            Vec3::splat(2.0),
            Affine2::IDENTITY,
        )
        .unwrap();
        // Texel centres return the texel exactly.
        assert!((tex.at(Vec2::new(0.25, 0.5)) - Vec3::new(2.0, 0.0, 0.0)).length() < 1e-5);
        assert!((tex.at(Vec2::new(0.75, 0.5)) - Vec3::new(0.0, 0.0, 2.0)).length() < 1e-5);
        assert!((tex.mean - Vec3::new(1.0, 0.0, 1.0)).length() < 1e-3);
        assert!(TexturedRadiance::new(0, 0, vec![], Vec3::ONE, Affine2::IDENTITY).is_err());
        assert!(
            TexturedRadiance::new(1, 1, vec![Vec3::NAN], Vec3::ONE, Affine2::IDENTITY).is_err()
        );
        assert!(Radiance::constant(Vec3::new(-1.0, 0.0, 0.0)).is_err());
    }
}
