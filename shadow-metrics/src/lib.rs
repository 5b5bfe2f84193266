//! Error metrics between an estimate and a reference visibility buffer over the pixels both
//! call valid (DESIGN section 6).

use serde::Serialize;
use thiserror::Error;

use shadow_core::visibility::VisibilityBuffer;

/// Reference values strictly between these bounds count as penumbra.
pub const PENUMBRA_RANGE: (f32, f32) = (0.02, 0.98);

/// Why two buffers cannot be compared.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum MetricsError {
    /// Different image sizes.
    #[error("image sizes differ: {0}x{1} against {2}x{3}")]
    Size(u32, u32, u32, u32),
    /// The buffers disagree on which pixels are valid.
    #[error("valid masks differ at pixel {0}")]
    Mask(usize),
    /// Different per-sample counts.
    #[error("per-sample counts differ: {0} against {1}")]
    Samples(u32, u32),
}

/// Errors of an estimate against a reference.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Metrics {
    /// Valid pixels compared.
    pub pixels: u64,
    /// Root mean square error over valid pixels.
    pub rmse: f64,
    /// RMSE over pixels whose reference lies strictly inside [`PENUMBRA_RANGE`] (`None` when
    /// there are none).
    pub penumbra_rmse: Option<f64>,
    /// Penumbra pixels.
    pub penumbra_pixels: u64,
    /// Mean signed error (estimate - reference): negative = too dark.
    pub bias: f64,
    /// Largest absolute error.
    pub max_abs: f64,
    /// Share of valid pixels off by more than 0.1.
    pub share_over_0_1: f64,
    /// Share of (pixel, sample) pairs with the same binary visibility, when both buffers carry
    /// per-sample visibility.
    pub sample_agreement: Option<f64>,
}

/// Compares `estimate` with `reference`. RGB buffers are compared channel by channel (each
/// channel counts as a value).
///
/// # Errors
/// [`MetricsError`] when sizes, masks or sample counts disagree.
pub fn compare(
    estimate: &dyn VisibilityBuffer,
    reference: &dyn VisibilityBuffer,
) -> Result<Metrics, MetricsError> {
    if estimate.width() != reference.width() || estimate.height() != reference.height() {
        return Err(MetricsError::Size(
            estimate.width(),
            estimate.height(),
            reference.width(),
            reference.height(),
        ));
    }
    let rgb = estimate.is_rgb() || reference.is_rgb();
    let (mut n, mut sq, mut sum, mut max, mut over) = (0u64, 0.0f64, 0.0f64, 0.0f64, 0u64);
    let (mut pn, mut psq) = (0u64, 0.0f64);
    for i in 0..estimate.len() {
        let (ve, vr) = (estimate.is_valid(i), reference.is_valid(i));
        if ve != vr {
            return Err(MetricsError::Mask(i));
        }
        if !ve {
            continue;
        }
        let pairs: Vec<(f32, f32)> = if rgb {
            let (a, b) = (estimate.rgb(i), reference.rgb(i));
            vec![(a.x, b.x), (a.y, b.y), (a.z, b.z)]
        } else {
            vec![(estimate.value(i), reference.value(i))]
        };
        let penumbra = {
            let r = reference.value(i);
            r > PENUMBRA_RANGE.0 && r < PENUMBRA_RANGE.1
        };
        for (a, b) in pairs {
            let e = a as f64 - b as f64;
            n += 1;
            sq += e * e;
            sum += e;
            max = max.max(e.abs());
            if e.abs() > 0.1 {
                over += 1;
            }
            if penumbra {
                pn += 1;
                psq += e * e;
            }
        }
    }
    let channels = if rgb { 3 } else { 1 };
    let sample_agreement = match (estimate.per_sample(), reference.per_sample()) {
        (Some(a), Some(b)) => {
            if a.samples() != b.samples() {
                return Err(MetricsError::Samples(a.samples(), b.samples()));
            }
            let (mut same, mut total) = (0u64, 0u64);
            for i in (0..estimate.len()).filter(|&i| estimate.is_valid(i)) {
                for k in 0..a.samples() {
                    total += 1;
                    same += u64::from(a.visible(i, k) == b.visible(i, k));
                }
            }
            Some(if total == 0 {
                1.0
            } else {
                same as f64 / total as f64
            })
        }
        _ => None,
    };
    let nf = n.max(1) as f64;
    Ok(Metrics {
        pixels: n / channels,
        rmse: (sq / nf).sqrt(),
        penumbra_rmse: (pn > 0).then(|| (psq / pn as f64).sqrt()),
        penumbra_pixels: pn / channels,
        bias: sum / nf,
        max_abs: max,
        share_over_0_1: over as f64 / nf,
        sample_agreement,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use shadow_core::visibility::{Coefficients, PerSampleVisibility, VisibilityImage};

    fn buf(values: &[f32], valid: &[bool]) -> VisibilityImage {
        VisibilityImage::from_parts(
            values.len() as u32,
            1,
            valid.to_vec(),
            Coefficients::Scalar(values.to_vec()),
            None,
            None,
        )
        .unwrap()
    }

    #[test]
    fn hand_computed_metrics() {
        // Reference: lit, penumbra 0.5, umbra, background. Estimate errors: +0.2, -0.05, 0.
        let r = buf(&[1.0, 0.5, 0.0, 0.0], &[true, true, true, false]);
        let e = buf(&[0.8, 0.55, 0.0, 0.0], &[true, true, true, false]);
        let m = compare(&e, &r).unwrap();
        assert_eq!(m.pixels, 3);
        // errors: -0.2, +0.05, 0
        assert_relative_eq!(m.rmse, ((0.04 + 0.0025) / 3.0f64).sqrt(), epsilon = 1e-6);
        assert_relative_eq!(m.bias, (-0.2 + 0.05) / 3.0, epsilon = 1e-6);
        assert_relative_eq!(m.max_abs, 0.2, epsilon = 1e-6);
        assert_relative_eq!(m.share_over_0_1, 1.0 / 3.0, epsilon = 1e-9);
        assert_eq!(m.penumbra_pixels, 1);
        assert_relative_eq!(m.penumbra_rmse.unwrap(), 0.05, epsilon = 1e-6);
        assert_eq!(m.sample_agreement, None);
    }

    #[test]
    fn mismatched_buffers_are_errors() {
        let a = buf(&[1.0, 0.5], &[true, true]);
        let b = buf(&[1.0, 0.5], &[true, false]);
        assert_eq!(compare(&a, &b), Err(MetricsError::Mask(1)));
        let c = buf(&[1.0], &[true]);
        assert!(matches!(compare(&a, &c), Err(MetricsError::Size(..))));
    }

    #[test]
    fn sample_agreement_counts_pairs() {
        let mut a = buf(&[0.5, 0.5], &[true, true]);
        let mut b = buf(&[0.5, 0.5], &[true, true]);
        a.set_per_sample(PerSampleVisibility::Counters {
            samples: 2,
            counts: vec![0, 1, 0, 1],
        })
        .unwrap();
        b.set_per_sample(PerSampleVisibility::Counters {
            samples: 2,
            counts: vec![0, 1, 1, 0],
        })
        .unwrap();
        let m = compare(&a, &b).unwrap();
        assert_relative_eq!(m.sample_agreement.unwrap(), 0.5);
    }
}
