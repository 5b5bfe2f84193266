//! FLIP (Andersson, Nilsson, Akenine-Möller, Oskarsson, Åström, Fairchild, "FLIP: A Difference
//! Evaluator for Alternating Images", HPG 2020), NVIDIA's perceptual image difference, through
//! the `nv-flip` crate (the reference C++ implementation). It compares the shaded images (what
//! a viewer sees), beside RMSE on the visibility: a few wrong pixels on a dark floor and a
//! shifted penumbra edge on a bright wall weigh differently to an eye, not to RMSE.
//!
//! The mean is taken over the pixels that hold a view sample only (the background is identical
//! in both images and would dilute it). Pixels per degree: `nv_flip::DEFAULT_PIXELS_PER_DEGREE`
//! (67, a 4K monitor at 70 cm), the setting FLIP's authors use by default.

use image::RgbImage;
use shadow_core::prelude::*;

/// FLIP of `test` against `reference`: the mean over the view's pixels and the error map
/// (FLIP's magma colour map, black where nothing differs).
pub struct Flip {
    /// Mean FLIP over the pixels holding a view sample, in `[0, 1]`.
    pub mean: f64,
    /// The per-pixel error in FLIP's magma colours.
    pub map: RgbImage,
}

/// FLIP between two shaded images of `view` (same size).
///
/// # Errors
/// When the images' sizes differ from each other or from the view.
pub fn flip(reference: &RgbImage, test: &RgbImage, view: &ViewSamples) -> Result<Flip, String> {
    let (w, h) = reference.dimensions();
    if test.dimensions() != (w, h) || (view.width(), view.height()) != (w, h) {
        return Err(format!(
            "FLIP: images of {w}x{h} and {:?} for a {}x{} view",
            test.dimensions(),
            view.width(),
            view.height()
        ));
    }
    let r = nv_flip::FlipImageRgb8::with_data(w, h, reference.as_raw());
    let t = nv_flip::FlipImageRgb8::with_data(w, h, test.as_raw());
    let errors = nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let values = errors.to_vec();
    let (sum, n) = (0..view.len())
        .filter(|&i| view.get(i).is_some())
        .fold((0.0f64, 0usize), |(s, n), i| {
            (s + f64::from(values[i]), n + 1)
        });
    let colours = errors.apply_color_lut(&nv_flip::magma_lut()).to_vec();
    let map = RgbImage::from_raw(w, h, colours)
        .ok_or_else(|| "FLIP: the error map has the wrong size".to_string())?;
    Ok(Flip {
        mean: if n > 0 { sum / n as f64 } else { 0.0 },
        map,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use shadow_core::visibility::VisibilityImage;
    use shadow_io::image_io::shaded_image;
    use shadow_scenes::builtin;

    /// Identical images give 0; a darkened shadow gives more than a slightly darker one.
    #[test]
    fn flip_is_zero_on_equal_images_and_grows_with_the_difference() {
        let setup = builtin("quad-over-plane").unwrap();
        let view =
            ViewSamples::render(setup.scene.as_ref(), &setup.camera.unwrap(), 64, 48).unwrap();
        let light = setup.lights[0].as_ref();
        let image_at = |v: f32| {
            let mut img = VisibilityImage::scalar(&view);
            for (i, x) in img.scalars_mut().iter_mut().enumerate() {
                *x = if i % 7 == 0 { v } else { 1.0 };
            }
            shaded_image(setup.scene.as_ref(), &view, light, &img).unwrap()
        };
        let reference = image_at(1.0);
        let same = flip(&reference, &reference, &view).unwrap();
        assert!(same.mean.abs() < 1e-6, "{}", same.mean);
        let slight = flip(&reference, &image_at(0.9), &view).unwrap().mean;
        let strong = flip(&reference, &image_at(0.0), &view).unwrap().mean;
        assert!(slight > 0.0 && strong > 2.0 * slight, "{slight} {strong}");
        assert!(strong <= 1.0);
    }
}
