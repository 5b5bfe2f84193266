//! Visibility buffers: per pixel the visibility coefficient `V(p)` (DCS eq. 1; RGB for textured
//! lights, DCS eq. 2), an optional lit / umbra / penumbra / skipped classification, and for
//! sample-based techniques the per-sample visibility (bitmasks or depth-complexity counters).

use glam::Vec3;
use serde::Serialize;
use thiserror::Error;

use crate::view_samples::ViewSamples;

/// How a technique classified a pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[repr(u8)]
pub enum PixelClass {
    /// No surface (background).
    Background,
    /// The whole light is visible.
    Lit,
    /// No part of the light is visible.
    Umbra,
    /// Partly visible: the technique did exact work here.
    Penumbra,
    /// The technique skipped the pixel (e.g. a receiver facing away from the whole light).
    Skipped,
}

/// Per-sample visibility of a sample-based technique, `samples` values per pixel.
#[derive(Debug, Clone, PartialEq)]
pub enum PerSampleVisibility {
    /// One bit per sample (1 = visible), `ceil(samples / 64)` words per pixel, sample `k` in bit
    /// `k % 64` of word `k / 64`.
    Bits {
        /// Samples per pixel.
        samples: u32,
        /// The words.
        words: Vec<u64>,
    },
    /// Depth complexity per sample (0 = visible), DCS section 3.
    Counters {
        /// Samples per pixel.
        samples: u32,
        /// The counts.
        counts: Vec<u32>,
    },
}

impl PerSampleVisibility {
    /// An all-occluded bitmask buffer for `pixels` pixels.
    pub fn bits(pixels: usize, samples: u32) -> Self {
        Self::Bits {
            samples,
            words: vec![0; pixels * samples.div_ceil(64) as usize],
        }
    }
    /// Samples per pixel.
    pub fn samples(&self) -> u32 {
        match self {
            Self::Bits { samples, .. } | Self::Counters { samples, .. } => *samples,
        }
    }
    /// Whether sample `k` of pixel `pixel` sees the light.
    pub fn visible(&self, pixel: usize, k: u32) -> bool {
        match self {
            Self::Bits { samples, words } => {
                let wpp = samples.div_ceil(64) as usize;
                words[pixel * wpp + (k / 64) as usize] >> (k % 64) & 1 == 1
            }
            Self::Counters { samples, counts } => {
                counts[pixel * *samples as usize + k as usize] == 0
            }
        }
    }
    /// Number of pixels covered.
    pub fn pixels(&self) -> usize {
        match self {
            Self::Bits { samples, words } => words.len() / samples.div_ceil(64).max(1) as usize,
            Self::Counters { samples, counts } => counts.len() / (*samples).max(1) as usize,
        }
    }
}

/// Read access to a visibility buffer (implemented by [`VisibilityImage`]; a GPU-resident
/// buffer may implement it too).
pub trait VisibilityBuffer {
    /// Width in pixels.
    fn width(&self) -> u32;
    /// Height in pixels.
    fn height(&self) -> u32;
    /// True when pixel `i` holds a surface.
    fn is_valid(&self, i: usize) -> bool;
    /// Scalar coefficient of pixel `i` (the channel mean for RGB buffers); 0 for background.
    fn value(&self, i: usize) -> f32;
    /// RGB coefficient of pixel `i` (the scalar on all channels for scalar buffers).
    fn rgb(&self, i: usize) -> Vec3;
    /// True for RGB (textured-light) buffers.
    fn is_rgb(&self) -> bool;
    /// The classification of pixel `i`, when the technique made one.
    fn class(&self, i: usize) -> Option<PixelClass>;
    /// Per-sample visibility, for sample-based techniques.
    fn per_sample(&self) -> Option<&PerSampleVisibility>;
    /// Number of pixels.
    fn len(&self) -> usize {
        (self.width() * self.height()) as usize
    }
    /// True for an empty buffer.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Visibility coefficients, scalar or RGB.
#[derive(Debug, Clone, PartialEq)]
pub enum Coefficients {
    /// `V(p)` in [0, 1].
    Scalar(Vec<f32>),
    /// Radiance-weighted visibility (DCS eq. 2), non-negative.
    Rgb(Vec<Vec3>),
}

/// A buffer value was NaN, infinite or out of range.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum VisibilityError {
    /// A value is NaN or infinite.
    #[error("pixel {pixel} holds a non-finite visibility")]
    NonFinite {
        /// Pixel index.
        pixel: usize,
    },
    /// A scalar value lies outside [0, 1] or an RGB value is negative.
    #[error("pixel {pixel} holds {value}, outside the valid range")]
    OutOfRange {
        /// Pixel index.
        pixel: usize,
        /// The value.
        value: f32,
    },
    /// Array sizes do not match the image.
    #[error("buffer sizes do not match: {0}")]
    Size(String),
}

/// The standard visibility buffer.
#[derive(Debug, Clone, PartialEq)]
pub struct VisibilityImage {
    width: u32,
    height: u32,
    valid: Vec<bool>,
    coefficients: Coefficients,
    classes: Option<Vec<PixelClass>>,
    per_sample: Option<PerSampleVisibility>,
}

impl VisibilityImage {
    /// Sets pixel `i` to "no light at all": `V = 0`, every sample occluded (a depth complexity
    /// of 1 where the buffer holds counters), class [`PixelClass::Skipped`] where the technique
    /// classifies. Background pixels are left as they are.
    pub fn darken(&mut self, i: usize) {
        if !self.valid.get(i).copied().unwrap_or(false) {
            return;
        }
        match &mut self.coefficients {
            Coefficients::Scalar(v) => v[i] = 0.0,
            Coefficients::Rgb(v) => v[i] = Vec3::ZERO,
        }
        if let Some(c) = &mut self.classes {
            c[i] = PixelClass::Skipped;
        }
        match &mut self.per_sample {
            Some(PerSampleVisibility::Bits { samples, words }) => {
                let wpp = samples.div_ceil(64) as usize;
                words[i * wpp..(i + 1) * wpp].fill(0);
            }
            Some(PerSampleVisibility::Counters { samples, counts }) => {
                let n = *samples as usize;
                for c in &mut counts[i * n..(i + 1) * n] {
                    *c = (*c).max(1);
                }
            }
            None => {}
        }
    }

    /// A scalar buffer for `view`, all zero.
    pub fn scalar(view: &ViewSamples) -> Self {
        Self {
            width: view.width(),
            height: view.height(),
            valid: view.valid_mask(),
            coefficients: Coefficients::Scalar(vec![0.0; view.len()]),
            classes: None,
            per_sample: None,
        }
    }

    /// An RGB buffer for `view`, all zero.
    pub fn rgb_buffer(view: &ViewSamples) -> Self {
        Self {
            coefficients: Coefficients::Rgb(vec![Vec3::ZERO; view.len()]),
            ..Self::scalar(view)
        }
    }

    /// A buffer from explicit parts, validated.
    ///
    /// # Errors
    /// [`VisibilityError`] when sizes disagree or a value is invalid.
    pub fn from_parts(
        width: u32,
        height: u32,
        valid: Vec<bool>,
        coefficients: Coefficients,
        classes: Option<Vec<PixelClass>>,
        per_sample: Option<PerSampleVisibility>,
    ) -> Result<Self, VisibilityError> {
        let n = width as usize * height as usize;
        let cn = match &coefficients {
            Coefficients::Scalar(v) => v.len(),
            Coefficients::Rgb(v) => v.len(),
        };
        if valid.len() != n || cn != n || classes.as_ref().is_some_and(|c| c.len() != n) {
            return Err(VisibilityError::Size(format!(
                "{width}x{height} image, {} mask entries, {cn} coefficients",
                valid.len()
            )));
        }
        if let Some(ps) = &per_sample
            && ps.pixels() != n
        {
            return Err(VisibilityError::Size(format!(
                "per-sample visibility covers {} pixels, image has {n}",
                ps.pixels()
            )));
        }
        let img = Self {
            width,
            height,
            valid,
            coefficients,
            classes,
            per_sample,
        };
        img.validate()?;
        Ok(img)
    }

    /// Checks every valid pixel: finite, scalar in [0, 1], RGB non-negative; background is 0.
    ///
    /// # Errors
    /// The first offending pixel.
    pub fn validate(&self) -> Result<(), VisibilityError> {
        for i in 0..self.valid.len() {
            let (v, lo_ok, hi_ok) = match &self.coefficients {
                Coefficients::Scalar(c) => (c[i], c[i] >= 0.0, c[i] <= 1.0),
                Coefficients::Rgb(c) => (c[i].min_element(), c[i].min_element() >= 0.0, true),
            };
            let finite = match &self.coefficients {
                Coefficients::Scalar(c) => c[i].is_finite(),
                Coefficients::Rgb(c) => c[i].is_finite(),
            };
            if !finite {
                return Err(VisibilityError::NonFinite { pixel: i });
            }
            if !(lo_ok && hi_ok) {
                return Err(VisibilityError::OutOfRange { pixel: i, value: v });
            }
        }
        Ok(())
    }

    /// Scalar coefficients, mutable (panics-free: empty slice for RGB buffers).
    pub fn scalars_mut(&mut self) -> &mut [f32] {
        match &mut self.coefficients {
            Coefficients::Scalar(v) => v,
            Coefficients::Rgb(_) => &mut [],
        }
    }
    /// RGB coefficients, mutable (empty slice for scalar buffers).
    pub fn rgbs_mut(&mut self) -> &mut [Vec3] {
        match &mut self.coefficients {
            Coefficients::Rgb(v) => v,
            Coefficients::Scalar(_) => &mut [],
        }
    }
    /// The coefficients.
    pub fn coefficients(&self) -> &Coefficients {
        &self.coefficients
    }
    /// The valid mask.
    pub fn valid_mask(&self) -> &[bool] {
        &self.valid
    }
    /// Attaches a classification.
    ///
    /// # Errors
    /// [`VisibilityError::Size`] when its length differs from the image.
    pub fn set_classes(&mut self, classes: Vec<PixelClass>) -> Result<(), VisibilityError> {
        if classes.len() != self.valid.len() {
            return Err(VisibilityError::Size("classification".into()));
        }
        self.classes = Some(classes);
        Ok(())
    }
    /// Attaches per-sample visibility.
    ///
    /// # Errors
    /// [`VisibilityError::Size`] when it covers another pixel count.
    pub fn set_per_sample(&mut self, ps: PerSampleVisibility) -> Result<(), VisibilityError> {
        if ps.pixels() != self.valid.len() {
            return Err(VisibilityError::Size("per-sample visibility".into()));
        }
        self.per_sample = Some(ps);
        Ok(())
    }
    /// Pixel counts per class (background, lit, umbra, penumbra, skipped), when classified.
    pub fn class_counts(&self) -> Option<[u64; 5]> {
        self.classes.as_ref().map(|c| {
            let mut n = [0u64; 5];
            for k in c {
                n[*k as usize] += 1;
            }
            n
        })
    }
}

impl VisibilityBuffer for VisibilityImage {
    fn width(&self) -> u32 {
        self.width
    }
    fn height(&self) -> u32 {
        self.height
    }
    fn is_valid(&self, i: usize) -> bool {
        self.valid[i]
    }
    fn value(&self, i: usize) -> f32 {
        match &self.coefficients {
            Coefficients::Scalar(v) => v[i],
            Coefficients::Rgb(v) => (v[i].x + v[i].y + v[i].z) / 3.0,
        }
    }
    fn rgb(&self, i: usize) -> Vec3 {
        match &self.coefficients {
            Coefficients::Scalar(v) => Vec3::splat(v[i]),
            Coefficients::Rgb(v) => v[i],
        }
    }
    fn is_rgb(&self) -> bool {
        matches!(self.coefficients, Coefficients::Rgb(_))
    }
    fn class(&self, i: usize) -> Option<PixelClass> {
        self.classes.as_ref().map(|c| c[i])
    }
    fn per_sample(&self) -> Option<&PerSampleVisibility> {
        self.per_sample.as_ref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_parts_validates() {
        let ok = VisibilityImage::from_parts(
            2,
            1,
            vec![true, false],
            Coefficients::Scalar(vec![0.5, 0.0]),
            None,
            None,
        );
        assert!(ok.is_ok());
        let nan = VisibilityImage::from_parts(
            2,
            1,
            vec![true, true],
            Coefficients::Scalar(vec![f32::NAN, 0.0]),
            None,
            None,
        );
        assert_eq!(nan, Err(VisibilityError::NonFinite { pixel: 0 }));
        let big = VisibilityImage::from_parts(
            1,
            1,
            vec![true],
            Coefficients::Scalar(vec![1.5]),
            None,
            None,
        );
        assert!(matches!(big, Err(VisibilityError::OutOfRange { .. })));
        let size = VisibilityImage::from_parts(
            2,
            2,
            vec![true],
            Coefficients::Scalar(vec![0.0]),
            None,
            None,
        );
        assert!(matches!(size, Err(VisibilityError::Size(_))));
    }

    #[test]
    fn per_sample_bits_and_counters() {
        let mut b = PerSampleVisibility::bits(2, 70);
        if let PerSampleVisibility::Bits { words, .. } = &mut b {
            words[2 + 1] |= 1 << 5; // pixel 1, sample 69
        }
        assert!(b.visible(1, 69));
        assert!(!b.visible(1, 68) && !b.visible(0, 69));
        assert_eq!(b.pixels(), 2);
        let c = PerSampleVisibility::Counters {
            samples: 2,
            counts: vec![0, 3, 1, 0],
        };
        assert!(c.visible(0, 0) && !c.visible(0, 1) && !c.visible(1, 0) && c.visible(1, 1));
    }
}
