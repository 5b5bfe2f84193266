//! Textures as loaded from glTF (emissive and base-colour): decoded within the limits, a
//! bounded size, linear values.

use std::path::Path;

use glam::Vec3;

use super::uri::{decode_data_uri, resolve};
use super::{LoadError, LoadLimits, read_limited};

/// Longest side an emissive texture keeps: larger ones are box-filtered down to it when
/// loaded. A light's radiance is integrated over regions of the light, and a block mean keeps
/// every integral over whole blocks; an 8192 x 8192 texture (a 218 KB PNG) took 2.9 GB as
/// floats, where 2048 x 2048 takes 64 MB (issue 51).
pub const EMISSIVE_TEXTURE_SIDE: u32 = 2048;

/// `img` as linear RGB texels (`to_linear` applied to each decoded texel before averaging),
/// box-filtered by the smallest whole factor that brings its longest side to at most `side`
/// (blocks at the right and bottom edges average the texels they hold). Converts a strip of
/// rows at a time, so no full-size float copy is made.
pub(super) fn box_filtered(
    img: &image::DynamicImage,
    side: u32,
    to_linear: impl Fn(Vec3) -> Vec3,
) -> (u32, u32, Vec<Vec3>) {
    let (w, h) = (img.width(), img.height());
    let f = w.max(h).div_ceil(side.max(1)).max(1);
    let (ow, oh) = (w.div_ceil(f), h.div_ceil(f));
    let mut texels = Vec::with_capacity(ow as usize * oh as usize);
    for by in 0..oh {
        let (y0, rows) = (by * f, f.min(h - by * f));
        let strip = img.crop_imm(0, y0, w, rows).to_rgb32f();
        for bx in 0..ow {
            let (x0, cols) = (bx * f, f.min(w - bx * f));
            let mut sum = Vec3::ZERO;
            for y in 0..rows {
                for x in x0..x0 + cols {
                    sum += to_linear(Vec3::from(strip.get_pixel(x, y).0));
                }
            }
            texels.push(sum / (rows * cols) as f32);
        }
    }
    (ow, oh, texels)
}

/// The sRGB transfer function's inverse (texels of 8- and 16-bit images are sRGB in glTF).
fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

pub(super) fn load_image(
    buffers: &[Vec<u8>],
    image: gltf::Image,
    base: Option<&Path>,
    limits: &LoadLimits,
) -> Result<LoadedImage, LoadError> {
    let bytes: Vec<u8> = match image.source() {
        gltf::image::Source::View { view, .. } => {
            let buf = buffers
                .get(view.buffer().index())
                .ok_or_else(|| LoadError::Missing(format!("buffer {}", view.buffer().index())))?;
            let (o, l) = (view.offset(), view.length());
            o.checked_add(l)
                .and_then(|end| buf.get(o..end))
                .ok_or_else(|| {
                    LoadError::Texture(format!("image view {} exceeds its buffer", view.index()))
                })?
                .to_vec()
        }
        gltf::image::Source::Uri { uri, .. } => {
            match decode_data_uri(uri, limits.max_buffer_bytes)? {
                Some(d) => d,
                None => read_limited(&resolve(base, uri)?, limits.max_buffer_bytes)?,
            }
        }
    };
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| LoadError::Texture(e.to_string()))?;
    let mut lim = image::Limits::default();
    let side = (limits.max_image_pixels as f64).sqrt().ceil() as u32;
    lim.max_image_width = Some(side.max(1) * 4);
    lim.max_image_height = Some(side.max(1) * 4);
    lim.max_alloc = Some(limits.max_image_pixels * 16);
    reader.limits(lim);
    let img = reader
        .decode()
        .map_err(|e| LoadError::Texture(e.to_string()))?;
    let (w, h) = (img.width(), img.height());
    if w as u64 * h as u64 > limits.max_image_pixels {
        return Err(LoadError::Limit {
            what: "the texture's pixel count".into(),
            size: w as u64 * h as u64,
            limit: limits.max_image_pixels,
        });
    }
    let linear = !matches!(
        img,
        image::DynamicImage::ImageRgb8(_)
            | image::DynamicImage::ImageRgba8(_)
            | image::DynamicImage::ImageLuma8(_)
            | image::DynamicImage::ImageLumaA8(_)
            | image::DynamicImage::ImageRgb16(_)
            | image::DynamicImage::ImageRgba16(_)
    );
    let to_linear = |c: Vec3| {
        if linear {
            c
        } else {
            Vec3::new(
                srgb_to_linear(c.x),
                srgb_to_linear(c.y),
                srgb_to_linear(c.z),
            )
        }
    };
    let (width, height, texels) = box_filtered(&img, EMISSIVE_TEXTURE_SIDE, to_linear);
    Ok(LoadedImage {
        width,
        height,
        texels,
        decoded: (w, h),
    })
}

/// A texture as loaded: linear RGB texels, and the size the file had.
pub(super) struct LoadedImage {
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) texels: Vec<Vec3>,
    pub(super) decoded: (u32, u32),
}
