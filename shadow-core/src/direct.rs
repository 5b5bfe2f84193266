//! Direct illumination from per-sample visibility, the estimator of DCS eq. 6 for the rendering
//! equation restricted to the light (DCS eq. 4): diffuse BRDF `albedo / pi`, cosines at the
//! receiver (shading normal) and at the light (clamped: planar lights emit from their front,
//! a sphere light from the half facing the receiver), inverse squared distance, light area over
//! the sample count. A point light (area 0) uses its radiance as intensity: `I cos / d^2`.

use glam::Vec3;

use crate::light::{AreaLight, LightSample};
use crate::view_samples::ViewSample;

/// The contribution of one light sample to the outgoing radiance at `p`, before the visibility
/// factor and the `area / N` weight: `albedo / pi * L * cos_p * cos_y / d^2`.
pub fn sample_term(p: &ViewSample, albedo: Vec3, sample: &LightSample, point_light: bool) -> Vec3 {
    let d = sample.position - p.position;
    let d2 = d.length_squared();
    if !(d2 > 0.0) || !d2.is_finite() {
        return Vec3::ZERO;
    }
    let w = d / d2.sqrt();
    let cos_p = p.shading_normal.dot(w).max(0.0);
    let cos_y = if point_light {
        1.0
    } else {
        sample.normal.dot(-w).max(0.0)
    };
    albedo * std::f32::consts::FRAC_1_PI * sample.radiance * (cos_p * cos_y / d2)
}

/// Accumulates DCS eq. 6 over a pixel's samples: `visibility(k)` in [0, 1] is the (binary or
/// transmittance) visibility of sample `k`.
pub fn pixel_direct(
    p: &ViewSample,
    albedo: Vec3,
    light: &dyn AreaLight,
    samples: &[LightSample],
    visibility: impl Fn(usize) -> f32,
) -> Vec3 {
    if samples.is_empty() {
        return Vec3::ZERO;
    }
    let point = light.area() == 0.0;
    let mut sum = Vec3::ZERO;
    for (k, s) in samples.iter().enumerate() {
        let v = visibility(k);
        if v > 0.0 {
            sum += v * sample_term(p, albedo, s, point);
        }
    }
    let weight = if point {
        1.0
    } else {
        light.area() / samples.len() as f32
    };
    sum * weight
}
