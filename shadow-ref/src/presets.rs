//! The reference's presets: the reference at 16, 64 and 1024 samples (checked against the
//! reference at 1024 samples with another seed, and against the closed form), and the
//! point-light hard shadow as a baseline.
//!
//! Budgets are errors measured by the conformance suite (64 x 48 pixels, seed 1, reference at
//! 1024 samples; `cargo test -p shadow-tests -- --nocapture` prints them) with the margins of
//! [`Budget::from_measured`]. Textured-light errors are per RGB channel of radiance-weighted
//! visibility (DCS eq. 2), so they are larger in absolute terms.

use shadow_core::prelude::*;

use crate::Reference;

fn stratified(samples: u32, seed: u64) -> Box<dyn ShadowTechnique> {
    let r = Reference::stratified(samples, seed).expect("preset sample counts are valid");
    let name = if samples == 1024 {
        "ref".to_string()
    } else {
        format!("ref-{samples}")
    };
    Box::new(r.named(&name))
}

/// Measured errors: scene, [rmse, penumbra rmse, bias, max, share > 0.1].
const REF_16: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0208, 0.0513, -0.0006, 0.156, 0.0095]),
    (
        "overlapping-occluders",
        [0.0324, 0.0517, 0.0009, 0.200, 0.0212],
    ),
    (
        "large-light-close",
        [0.0399, 0.0454, -0.0003, 0.152, 0.0249],
    ),
    ("bunny", [0.0177, 0.0489, 0.0001, 0.157, 0.0040]),
    ("spot-self-shadow", [0.0249, 0.0492, 0.0002, 0.127, 0.0115]),
    ("grass", [0.0207, 0.0565, -0.0003, 0.160, 0.0113]),
    ("contact", [0.0182, 0.0536, 0.0001, 0.137, 0.0076]),
    ("semi-opaque", [0.0138, 0.0201, 0.0003, 0.082, 0.0]),
    ("textured-light", [0.0548, 0.0548, -0.0001, 0.252, 0.0663]),
    ("sphere-light", [0.0251, 0.0620, 0.0002, 0.221, 0.0173]),
];

const REF_64: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0076, 0.0186, 0.0001, 0.065, 0.0]),
    (
        "overlapping-occluders",
        [0.0113, 0.0180, 0.0002, 0.066, 0.0],
    ),
    ("large-light-close", [0.0147, 0.0166, 0.0001, 0.070, 0.0]),
    ("bunny", [0.0068, 0.0185, 0.0001, 0.062, 0.0]),
    ("spot-self-shadow", [0.0093, 0.0185, -0.0003, 0.061, 0.0]),
    ("grass", [0.0088, 0.0237, 0.0001, 0.069, 0.0]),
    ("contact", [0.0065, 0.0189, 0.0001, 0.063, 0.0]),
    ("semi-opaque", [0.0048, 0.0068, 0.0, 0.046, 0.0]),
    ("textured-light", [0.0192, 0.0192, 0.0003, 0.093, 0.0]),
    ("sphere-light", [0.0095, 0.0234, -0.0001, 0.082, 0.0]),
];

const REF_1024: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0012, 0.0030, 0.0, 0.011, 0.0]),
    (
        "overlapping-occluders",
        [0.0022, 0.0034, -0.0001, 0.012, 0.0],
    ),
    ("large-light-close", [0.0025, 0.0028, 0.0, 0.011, 0.0]),
    ("bunny", [0.0011, 0.0031, 0.0, 0.013, 0.0]),
    ("spot-self-shadow", [0.0016, 0.0032, 0.0, 0.013, 0.0]),
    ("grass", [0.0022, 0.0059, 0.0, 0.021, 0.0]),
    ("contact", [0.0010, 0.0030, 0.0, 0.008, 0.0]),
    ("semi-opaque", [0.0009, 0.0013, 0.0, 0.006, 0.0]),
    ("textured-light", [0.0019, 0.0019, 0.0, 0.016, 0.0]),
    ("sphere-light", [0.0017, 0.0043, 0.0, 0.019, 0.0]),
];

/// The hard shadow is wrong in every penumbra by design; these bound how wrong.
const REF_HARD: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.1143, 0.2840, 0.0040, 0.679, 0.1182]),
    (
        "overlapping-occluders",
        [0.1771, 0.2867, 0.0023, 0.716, 0.2809],
    ),
    ("large-light-close", [0.1996, 0.2295, 0.0392, 0.737, 0.4363]),
    ("bunny", [0.1108, 0.3091, 0.0020, 0.690, 0.0976]),
    ("spot-self-shadow", [0.1415, 0.2829, 0.0013, 0.666, 0.1917]),
    ("grass", [0.1056, 0.2917, -0.0036, 0.857, 0.0981]),
    ("contact", [0.0775, 0.2293, 0.0115, 0.521, 0.0945]),
    ("semi-opaque", [0.0782, 0.1164, 0.0035, 0.400, 0.1817]),
    ("textured-light", [0.0917, 0.0917, -0.0024, 0.848, 0.0854]),
    ("sphere-light", [0.1285, 0.3188, -0.0045, 0.763, 0.1410]),
];

/// The presets of this crate.
pub fn presets() -> Vec<Preset> {
    vec![
        Preset {
            name: "ref",
            description: "ray-traced reference, 1024 stratified samples per pixel",
            make: |seed| stratified(1024, seed),
            budget: |scene| Budget::lookup(REF_1024, scene),
            with_samples: Some(stratified),
        },
        Preset {
            name: "ref-16",
            description: "ray-traced reference, 16 stratified samples per pixel",
            make: |seed| stratified(16, seed),
            budget: |scene| Budget::lookup(REF_16, scene),
            with_samples: Some(stratified),
        },
        Preset {
            name: "ref-64",
            description: "ray-traced reference, 64 stratified samples per pixel",
            make: |seed| stratified(64, seed),
            budget: |scene| Budget::lookup(REF_64, scene),
            with_samples: Some(stratified),
        },
        Preset {
            name: "ref-hard",
            description: "hard shadow of the light centre (point-light limit), traced",
            make: |_| Box::new(Reference::hard()),
            budget: |scene| Budget::lookup(REF_HARD, scene),
            with_samples: None,
        },
    ]
}
