//! Emissive textures as loaded: a bounded size, linear values.

use glam::Vec3;

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
