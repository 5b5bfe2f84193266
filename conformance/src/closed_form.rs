//! Closed-form visibility of the `quad-over-plane` scene: a square light over a parallel square
//! occluder, seen from the floor. `V(p) = 1 - |proj(occluder) ∩ light| / |light|`, the occluder
//! projected from `p` onto the light's plane (a scaling by `h_l / h_o` about `p`).

use glam::Vec3;
use shadow_core::prelude::*;
use shadow_core::visibility::Coefficients;
use shadow_scenes::quad_over_plane as q;

fn overlap(a0: f64, a1: f64, b0: f64, b1: f64) -> f64 {
    (a1.min(b1) - a0.max(b0)).max(0.0)
}

/// Exact visibility at a floor point `p` (y = 0) of `quad-over-plane`.
pub fn quad_over_plane_visibility(p: Vec3) -> f64 {
    let (hl, ho) = (q::LIGHT_HEIGHT as f64, q::OCCLUDER_HEIGHT as f64);
    let k = (hl - p.y as f64) / (ho - p.y as f64);
    let (px, pz) = (p.x as f64, p.z as f64);
    let half_o = 0.5 * q::OCCLUDER_SIDE as f64 * k;
    let (cx, cz) = (px * (1.0 - k), pz * (1.0 - k));
    let half_l = 0.5 * q::LIGHT_SIDE as f64;
    let covered = overlap(cx - half_o, cx + half_o, -half_l, half_l)
        * overlap(cz - half_o, cz + half_o, -half_l, half_l);
    1.0 - covered / (q::LIGHT_SIDE as f64).powi(2)
}

/// A visibility buffer holding the closed form on the floor pixels of `view`; other pixels
/// (the occluder itself) are marked invalid so metrics skip them.
pub fn quad_over_plane_buffer(view: &ViewSamples) -> (VisibilityImage, Vec<bool>) {
    let mut valid = vec![false; view.len()];
    let mut values = vec![0.0f32; view.len()];
    for i in 0..view.len() {
        if let Some(s) = view.get(i)
            && s.position.y.abs() < 1e-6
        {
            valid[i] = true;
            values[i] = quad_over_plane_visibility(s.position) as f32;
        }
    }
    let img = VisibilityImage::from_parts(
        view.width(),
        view.height(),
        valid.clone(),
        Coefficients::Scalar(values),
        None,
        None,
    )
    .expect("closed form values lie in [0, 1]");
    (img, valid)
}

/// `estimate` restricted to the pixels of `mask` (so it can be compared with a closed form).
pub fn masked(estimate: &VisibilityImage, mask: &[bool]) -> VisibilityImage {
    let values = (0..estimate.len())
        .map(|i| if mask[i] { estimate.value(i) } else { 0.0 })
        .collect();
    VisibilityImage::from_parts(
        estimate.width(),
        estimate.height(),
        mask.to_vec(),
        Coefficients::Scalar(values),
        None,
        None,
    )
    .expect("a valid buffer restricted to a mask stays valid")
}
