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
    /// one vector operation each (the same values as on `Vec3`). Stored with the first column
    /// repeated after the last and the first row after the last (`(width + 1) x (height + 1)`),
    /// so that a lookup's right and lower neighbours need no wrapping of their own.
    texels: Arc<[Vec3A]>,
    /// `width` and `height` as floats.
    size_f: Vec2,
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
        let (w, h) = (width as usize, height as usize);
        let padded = (0..=h)
            .flat_map(|y| (0..=w).map(move |x| (x % w, y % h)))
            .map(|(x, y)| Vec3A::from(texels[y * w + x]))
            .collect();
        let mut t = Self {
            width,
            height,
            texels: padded,
            size_f: Vec2::new(width as f32, height as f32),
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
        self.lookup(uv)
    }

    /// [`TexturedRadiance::at`] at every uv of `uvs`, appended to `out`: the lookup inlined in
    /// one loop (a call per lookup saves and restores registers for a tenth of its cost).
    pub fn extend_at(&self, uvs: impl Iterator<Item = Vec2>, out: &mut Vec<Vec3>) {
        out.extend(uvs.map(|uv| self.lookup(uv)));
    }

    /// The lookup of [`TexturedRadiance::at`].
    #[inline(always)]
    pub(crate) fn lookup(&self, uv: Vec2) -> Vec3 {
        let st = self.texture_from_light.transform_point2(uv);
        let x = st.x * self.size_f.x - 0.5;
        let y = st.y * self.size_f.y - 0.5;
        let ((x0, xa), (y0, ya)) = (floor_wrapped(x, self.width), floor_wrapped(y, self.height));
        let (fx, fy) = (x - x0, y - y0);
        // The four texels from the padded rows: `xa + 1` and `ya + 1` are the wrapped
        // neighbours. One bounds check for the four loads.
        let stride = self.width as usize + 1;
        let base = ya * stride + xa;
        let q = &self.texels[base..base + stride + 2];
        let a = q[0].lerp(q[1], fx);
        let b = q[stride].lerp(q[stride + 1], fx);
        Vec3::from(a.lerp(b, fy) * Vec3A::from(self.scale))
    }
}

/// `1.5 * 2^23`: adding it to a float below `2^22` in magnitude rounds the float to an integer
/// held in the sum's low mantissa bits.
const ROUNDER: f32 = 12_582_912.0;

/// `x.floor()` and that integer wrapped into `0..n` (repeat addressing). Below `2^22` in
/// magnitude (every coordinate of a texture that fits in memory) the floor comes from one
/// rounding addition and a correction, and the integer from the sum's bits, with no float to
/// integer conversion (whose saturating form costs several instructions per use on x86-64); a
/// division only where the integer falls outside `0..n`.
#[inline]
fn floor_wrapped(x: f32, n: u32) -> (f32, usize) {
    let (f, i) = if x.abs() < 4_194_304.0 {
        let m = x + ROUNDER;
        let r = m - ROUNDER;
        let down = r > x;
        let f = if down { r - 1.0 } else { r };
        let i = i64::from(m.to_bits() as i32 - ROUNDER.to_bits() as i32) - i64::from(down);
        (f, i)
    } else {
        let f = floor_f32(x);
        (f, f as i64)
    };
    let n = u64::from(n);
    // A negative `i` reads as a huge unsigned value, so one comparison covers both ends.
    let wrapped = if (i as u64) < n {
        i as usize
    } else {
        i.rem_euclid(n as i64) as usize
    };
    (f, wrapped)
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
        xs.extend([
            4_194_303.5f32,
            -4_194_303.5,
            4_194_304.0,
            -4_194_304.0,
            2.5,
            -2.5,
            3.5,
        ]);
        for x in xs {
            for n in [1u32, 3, 5, 1 << 20] {
                let (f, i) = floor_wrapped(x, n);
                // Equal values (the floor of -0 comes out as +0, as through `floor_f32`).
                assert_eq!(f, x.floor(), "{x}");
                assert_eq!(f.to_bits(), floor_f32(x).to_bits(), "{x}");
                assert_eq!(
                    i,
                    (x.floor() as i64).rem_euclid(i64::from(n)) as usize,
                    "{x} {n}"
                );
            }
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
