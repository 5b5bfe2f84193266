//! Temporal jittering (section 4.2, Fig. 7): successive frames evaluate rotated sample sets
//! ([`PreparedAfsm::set_frame`]) and their visibility buffers are averaged, converging toward the
//! visibility of all the frames' samples together for a static scene and camera.

use glam::Vec3;
use shadow_core::prelude::*;
use shadow_core::visibility::Coefficients;

use crate::technique::PreparedAfsm;

/// A running average of visibility buffers.
#[derive(Debug, Clone, Default)]
pub struct TemporalAccumulator {
    sum: Vec<f64>,
    rgb: Vec<Vec3>,
    frames: u32,
}

impl TemporalAccumulator {
    /// An empty accumulator.
    pub fn new() -> Self {
        Self::default()
    }

    /// Frames accumulated.
    pub fn frames(&self) -> u32 {
        self.frames
    }

    /// Adds one frame's buffer (the same view every time).
    ///
    /// # Errors
    /// [`TechniqueError::InvalidInput`] when the buffer's size or kind changed.
    pub fn add(&mut self, v: &VisibilityImage) -> Result<(), TechniqueError> {
        match v.coefficients() {
            Coefficients::Scalar(s) => {
                if self.frames == 0 {
                    self.sum = vec![0.0; s.len()];
                }
                if self.sum.len() != s.len() || !self.rgb.is_empty() {
                    return Err(TechniqueError::InvalidInput("frame size changed".into()));
                }
                for (a, b) in self.sum.iter_mut().zip(s) {
                    *a += *b as f64;
                }
            }
            Coefficients::Rgb(s) => {
                if self.frames == 0 {
                    self.rgb = vec![Vec3::ZERO; s.len()];
                }
                if self.rgb.len() != s.len() || !self.sum.is_empty() {
                    return Err(TechniqueError::InvalidInput("frame size changed".into()));
                }
                for (a, b) in self.rgb.iter_mut().zip(s) {
                    *a += *b;
                }
            }
        }
        self.frames = self.frames.checked_add(1).ok_or_else(|| {
            TechniqueError::InvalidInput("more than u32::MAX frames accumulated".into())
        })?;
        Ok(())
    }

    /// The average so far as a buffer for `view`.
    ///
    /// # Errors
    /// [`TechniqueError::InvalidInput`] before the first frame.
    pub fn average(&self, view: &ViewSamples) -> Result<VisibilityImage, TechniqueError> {
        if self.frames == 0 {
            return Err(TechniqueError::InvalidInput("no frame accumulated".into()));
        }
        let k = self.frames as f64;
        let out = if self.rgb.is_empty() {
            let mut v = VisibilityImage::scalar(view);
            for (o, s) in v.scalars_mut().iter_mut().zip(&self.sum) {
                *o = (*s / k) as f32;
            }
            v
        } else {
            let mut v = VisibilityImage::rgb_buffer(view);
            for (o, s) in v.rgbs_mut().iter_mut().zip(&self.rgb) {
                *o = *s / k as f32;
            }
            v
        };
        out.validate()?;
        Ok(out)
    }
}

/// Runs frames `0..frames` of `tech` (prepared) on `view` and returns their average.
///
/// # Errors
/// The technique's errors.
pub fn accumulate(
    tech: &mut PreparedAfsm,
    view: &ViewSamples,
    frames: u64,
) -> Result<VisibilityImage, TechniqueError> {
    let mut acc = TemporalAccumulator::new();
    for k in 0..frames {
        tech.set_frame(k)?;
        acc.add(&tech.estimate(view, Outputs::VISIBILITY)?.visibility)?;
    }
    tech.set_frame(0)?;
    acc.average(view)
}
