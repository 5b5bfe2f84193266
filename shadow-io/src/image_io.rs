//! Image output: float32 EXR (visibility as RGBA with A = 1 on valid pixels and 0 on background;
//! position and geometric-normal AOVs the same way) and 8-bit PNG views (visibility, signed
//! error with a diverging colour map, and shaded = albedo x V x cosine).

use std::path::Path;

use glam::Vec3;
use image::{ImageFormat, Rgb, RgbImage, Rgba, Rgba32FImage};
use thiserror::Error;

use shadow_core::light::AreaLight;
use shadow_core::scene::Scene;
use shadow_core::view_samples::ViewSamples;
use shadow_core::visibility::VisibilityBuffer;

/// An image could not be written.
#[derive(Debug, Error)]
pub enum ImageError {
    /// Encoder or file-system failure.
    #[error("writing {path}: {source}")]
    Write {
        /// Destination.
        path: String,
        /// Cause.
        source: image::ImageError,
    },
    /// Buffer sizes differ.
    #[error("image sizes differ")]
    Size,
    /// A file could not be read as a float RGBA image.
    #[error("reading {path}: {reason}")]
    Read {
        /// Source.
        path: String,
        /// Why.
        reason: String,
    },
}

/// A per-pixel RGB quantity read back from a float EXR of the layout this module writes (A is
/// the validity): `(width, height, values, valid)`, row-major.
pub type Aov = (u32, u32, Vec<Vec3>, Vec<bool>);

/// Reads a float RGBA EXR as an [`Aov`]: any renderer's G-buffer in the layout
/// [`write_position_exr`] and [`write_normal_exr`] write (alpha above one half is a valid
/// pixel). At most `max_pixels` pixels are decoded.
///
/// # Errors
/// [`ImageError::Read`] for a file that is missing, is not an image, is larger than
/// `max_pixels`, or holds a non-finite value in a valid pixel.
pub fn read_aov_exr(path: &Path, max_pixels: u64) -> Result<Aov, ImageError> {
    let err = |reason: String| ImageError::Read {
        path: path.display().to_string(),
        reason,
    };
    let reader = image::ImageReader::open(path)
        .map_err(|e| err(e.to_string()))?
        .with_guessed_format()
        .map_err(|e| err(e.to_string()))?;
    let (w, h) = reader.into_dimensions().map_err(|e| err(e.to_string()))?;
    if u64::from(w) * u64::from(h) > max_pixels {
        return Err(err(format!(
            "{w}x{h} pixels, above the limit of {max_pixels}"
        )));
    }
    let img = image::open(path)
        .map_err(|e| err(e.to_string()))?
        .to_rgba32f();
    let mut values = Vec::with_capacity((w * h) as usize);
    let mut valid = Vec::with_capacity((w * h) as usize);
    for (i, p) in img.pixels().enumerate() {
        let [r, g, b, a] = p.0;
        let ok = a > 0.5;
        let v = Vec3::new(r, g, b);
        if ok && !v.is_finite() {
            return Err(err(format!("pixel {i} holds a non-finite value")));
        }
        values.push(if ok { v } else { Vec3::ZERO });
        valid.push(ok);
    }
    Ok((w, h, values, valid))
}

fn save_rgba32(
    path: &Path,
    w: u32,
    h: u32,
    f: impl Fn(usize) -> [f32; 4],
) -> Result<(), ImageError> {
    let img = Rgba32FImage::from_fn(w, h, |x, y| Rgba(f((y * w + x) as usize)));
    img.save_with_format(path, ImageFormat::OpenExr)
        .map_err(|source| ImageError::Write {
            path: path.display().to_string(),
            source,
        })
}

/// An 8-bit sRGB image of the linear colours `f(pixel index)`.
fn rgb8(w: u32, h: u32, f: impl Fn(usize) -> Vec3) -> RgbImage {
    RgbImage::from_fn(w, h, |x, y| {
        let c = f((y * w + x) as usize);
        Rgb(c.to_array().map(|v| (srgb_encode(v) * 255.0 + 0.5) as u8))
    })
}

fn save_rgb8(path: &Path, w: u32, h: u32, f: impl Fn(usize) -> Vec3) -> Result<(), ImageError> {
    save_png(path, &rgb8(w, h, f))
}

fn save_png(path: &Path, img: &RgbImage) -> Result<(), ImageError> {
    img.save_with_format(path, ImageFormat::Png)
        .map_err(|source| ImageError::Write {
            path: path.display().to_string(),
            source,
        })
}

/// Linear to sRGB transfer, clamped to [0, 1].
pub fn srgb_encode(v: f32) -> f32 {
    let v = if v.is_finite() {
        v.clamp(0.0, 1.0)
    } else {
        0.0
    };
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Writes the visibility buffer as float32 EXR: RGB = coefficient, A = validity.
///
/// # Errors
/// [`ImageError`] when the file cannot be written.
pub fn write_visibility_exr(path: &Path, v: &dyn VisibilityBuffer) -> Result<(), ImageError> {
    save_rgba32(path, v.width(), v.height(), |i| {
        if v.is_valid(i) {
            let c = v.rgb(i);
            [c.x, c.y, c.z, 1.0]
        } else {
            [0.0; 4]
        }
    })
}

/// Writes world positions as float32 EXR (A = validity).
///
/// # Errors
/// [`ImageError`] when the file cannot be written.
pub fn write_position_exr(path: &Path, view: &ViewSamples) -> Result<(), ImageError> {
    write_aov(path, view, view.positions())
}

/// Writes geometric normals (camera-facing) as float32 EXR (A = validity).
///
/// # Errors
/// [`ImageError`] when the file cannot be written.
pub fn write_normal_exr(path: &Path, view: &ViewSamples) -> Result<(), ImageError> {
    write_aov(path, view, view.geometric_normals())
}

/// Writes any per-pixel RGB quantity of `view` (direct illumination, for instance) as float32
/// EXR, A = validity.
///
/// # Errors
/// [`ImageError::Size`] when `data` does not have one value per pixel; write failures.
pub fn write_rgb_exr(path: &Path, view: &ViewSamples, data: &[Vec3]) -> Result<(), ImageError> {
    if data.len() != view.len() {
        return Err(ImageError::Size);
    }
    write_aov(path, view, data)
}

/// Writes per-pixel linear RGB radiance as an 8-bit sRGB PNG, scaled so the brightest valid
/// pixel is white.
///
/// # Errors
/// [`ImageError::Size`] when `data` does not have one value per pixel; write failures.
pub fn write_radiance_png(
    path: &Path,
    view: &ViewSamples,
    data: &[Vec3],
) -> Result<(), ImageError> {
    if data.len() != view.len() {
        return Err(ImageError::Size);
    }
    let m = (0..view.len())
        .filter(|&i| view.is_valid(i))
        .map(|i| data[i].max_element())
        .filter(|v| v.is_finite())
        .fold(0.0f32, f32::max);
    let scale = if m > 0.0 { 1.0 / m } else { 1.0 };
    save_rgb8(path, view.width(), view.height(), |i| {
        if view.is_valid(i) {
            data[i] * scale
        } else {
            BACKGROUND
        }
    })
}

fn write_aov(path: &Path, view: &ViewSamples, data: &[Vec3]) -> Result<(), ImageError> {
    save_rgba32(path, view.width(), view.height(), |i| {
        if view.is_valid(i) {
            let c = data[i];
            [c.x, c.y, c.z, 1.0]
        } else {
            [0.0; 4]
        }
    })
}

/// Background colour of PNG views.
const BACKGROUND: Vec3 = Vec3::new(0.05, 0.07, 0.12);

/// Writes the visibility as an 8-bit PNG (sRGB-encoded; RGB buffers divided by their largest
/// value so the image is not clipped).
///
/// # Errors
/// [`ImageError`] when the file cannot be written.
pub fn write_visibility_png(path: &Path, v: &dyn VisibilityBuffer) -> Result<(), ImageError> {
    let scale = if v.is_rgb() {
        let m = (0..v.len())
            .filter(|&i| v.is_valid(i))
            .map(|i| v.rgb(i).max_element())
            .fold(0.0f32, f32::max);
        if m > 0.0 { 1.0 / m } else { 1.0 }
    } else {
        1.0
    };
    save_rgb8(path, v.width(), v.height(), |i| {
        if v.is_valid(i) {
            v.rgb(i) * scale
        } else {
            BACKGROUND
        }
    })
}

/// Diverging colour map for a signed error in `[-range, range]`: blue (too dark), white (exact),
/// red (too bright). Returns linear RGB.
pub fn diverging(e: f32, range: f32) -> Vec3 {
    let t = if e.is_finite() {
        (e / range).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let white = Vec3::ONE;
    if t >= 0.0 {
        white.lerp(Vec3::new(0.7, 0.02, 0.02), t)
    } else {
        white.lerp(Vec3::new(0.02, 0.1, 0.7), -t)
    }
}

/// Writes the signed error `estimate - reference` as a PNG with [`diverging`] over `[-range,
/// range]`.
///
/// # Errors
/// [`ImageError::Size`] when the buffers differ in size; write failures.
pub fn write_error_png(
    path: &Path,
    estimate: &dyn VisibilityBuffer,
    reference: &dyn VisibilityBuffer,
    range: f32,
) -> Result<(), ImageError> {
    if estimate.width() != reference.width() || estimate.height() != reference.height() {
        return Err(ImageError::Size);
    }
    save_rgb8(path, estimate.width(), estimate.height(), |i| {
        if estimate.is_valid(i) && reference.is_valid(i) {
            diverging(estimate.value(i) - reference.value(i), range)
        } else {
            BACKGROUND
        }
    })
}

/// Writes a shaded view under every light ([`shaded_image_lights`]) as a PNG.
///
/// # Errors
/// [`ImageError`] on size mismatch or write failure.
pub fn write_shaded_png(
    path: &Path,
    scene: &dyn Scene,
    view: &ViewSamples,
    lights: &[(&dyn AreaLight, &dyn VisibilityBuffer)],
) -> Result<(), ImageError> {
    save_png(path, &shaded_image_lights(scene, view, lights)?)
}

/// A shaded view in 8-bit sRGB: albedo x V x cos(shading normal, direction to the light
/// centre), scaled by the light's mean radiance normalised to its largest channel. The images
/// the conformance report compares with FLIP.
///
/// # Errors
/// [`ImageError::Size`] when `v` and `view` differ in size.
pub fn shaded_image(
    scene: &dyn Scene,
    view: &ViewSamples,
    light: &dyn AreaLight,
    v: &dyn VisibilityBuffer,
) -> Result<RgbImage, ImageError> {
    shaded_image_lights(scene, view, &[(light, v)])
}

/// [`shaded_image`] under several lights, each with its own V: their terms summed, each
/// light's mean radiance normalised to the largest channel of the brightest light.
///
/// # Errors
/// [`ImageError::Size`] when a buffer and `view` differ in size.
pub fn shaded_image_lights(
    scene: &dyn Scene,
    view: &ViewSamples,
    lights: &[(&dyn AreaLight, &dyn VisibilityBuffer)],
) -> Result<RgbImage, ImageError> {
    if lights
        .iter()
        .any(|(_, v)| v.width() != view.width() || v.height() != view.height())
    {
        return Err(ImageError::Size);
    }
    let brightest = lights
        .iter()
        .map(|(l, _)| l.radiance().mean().max_element())
        .fold(0.0f32, f32::max);
    let tints: Vec<Vec3> = lights
        .iter()
        .map(|(l, _)| {
            if brightest > 0.0 {
                l.radiance().mean() / brightest
            } else {
                Vec3::ONE
            }
        })
        .collect();
    Ok(rgb8(view.width(), view.height(), |i| match view.get(i) {
        Some(s) => {
            let albedo = s.albedo_in(scene);
            let lit: Vec3 = lights
                .iter()
                .zip(&tints)
                .map(|((light, v), tint)| {
                    let l = (light.center() - s.position).normalize_or_zero();
                    let cos = s.shading_normal.dot(l).max(0.0);
                    let vis = if v.is_rgb() {
                        v.rgb(i)
                    } else {
                        Vec3::splat(v.value(i)) * *tint
                    };
                    vis * cos
                })
                .sum();
            albedo * lit + Vec3::splat(0.02)
        }
        None => BACKGROUND,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_and_diverging_endpoints() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        assert_eq!(srgb_encode(f32::NAN), 0.0);
        assert_eq!(diverging(0.0, 1.0), Vec3::ONE);
        assert!(diverging(1.0, 1.0).x > diverging(1.0, 1.0).z);
        assert!(diverging(-1.0, 1.0).z > diverging(-1.0, 1.0).x);
    }
}
