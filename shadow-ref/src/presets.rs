//! The reference's presets: the reference at 16, 64 and 1024 samples (checked against the
//! reference at 1024 samples with another seed, and against the closed form), and the
//! point-light hard shadow as a baseline.
//!
//! Budgets are errors measured by the conformance suite (64 x 48 pixels, seed 1, reference at
//! 1024 samples; `cargo test -p shadow-tests -- --nocapture` prints them) with the margins of
//! [`Budget::from_measured`]; `scripts/measure_budgets.py` regenerates the tables.
//! Textured-light errors are per RGB channel of radiance-weighted visibility (DCS eq. 2), so
//! they are larger in absolute terms.

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
    ("quad-over-plane", [0.0202, 0.0498, 0.0007, 0.188, 0.0086]),
    (
        "overlapping-occluders",
        [0.0327, 0.0524, 0.0005, 0.208, 0.0248],
    ),
    ("large-light-close", [0.0400, 0.0455, 0.0003, 0.190, 0.0249]),
    ("bunny", [0.0194, 0.0537, 0.0003, 0.162, 0.0086]),
    ("spot-self-shadow", [0.0238, 0.0470, -0.0003, 0.152, 0.0085]),
    ("grass", [0.0205, 0.0550, -0.0003, 0.151, 0.0074]),
    ("contact", [0.0177, 0.0520, 0.0001, 0.159, 0.0058]),
    ("semi-opaque", [0.0137, 0.0197, 0.0006, 0.084, 0.0000]),
    ("textured-light", [0.0539, 0.0539, -0.0003, 0.215, 0.0635]),
    ("sphere-light", [0.0252, 0.0625, 0.0010, 0.211, 0.0166]),
];

const REF_64: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0071, 0.0172, -0.0002, 0.053, 0.0000]),
    (
        "overlapping-occluders",
        [0.0115, 0.0183, 0.0003, 0.068, 0.0000],
    ),
    (
        "large-light-close",
        [0.0140, 0.0159, -0.0001, 0.070, 0.0000],
    ),
    ("bunny", [0.0067, 0.0186, -0.0001, 0.055, 0.0000]),
    ("spot-self-shadow", [0.0090, 0.0178, 0.0000, 0.073, 0.0000]),
    ("grass", [0.0086, 0.0233, 0.0002, 0.068, 0.0000]),
    ("contact", [0.0065, 0.0188, -0.0001, 0.059, 0.0000]),
    ("semi-opaque", [0.0048, 0.0069, -0.0001, 0.033, 0.0000]),
    ("textured-light", [0.0190, 0.0190, 0.0001, 0.084, 0.0000]),
    ("sphere-light", [0.0098, 0.0241, -0.0002, 0.087, 0.0000]),
];

const REF_1024: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0013, 0.0031, -0.0000, 0.012, 0.0000]),
    (
        "overlapping-occluders",
        [0.0021, 0.0032, -0.0000, 0.013, 0.0000],
    ),
    ("large-light-close", [0.0025, 0.0028, 0.0000, 0.012, 0.0000]),
    ("bunny", [0.0011, 0.0029, 0.0000, 0.011, 0.0000]),
    ("spot-self-shadow", [0.0016, 0.0031, -0.0000, 0.013, 0.0000]),
    ("grass", [0.0022, 0.0060, 0.0000, 0.017, 0.0000]),
    ("contact", [0.0011, 0.0032, 0.0000, 0.010, 0.0000]),
    ("semi-opaque", [0.0009, 0.0013, 0.0000, 0.006, 0.0000]),
    ("textured-light", [0.0019, 0.0019, 0.0000, 0.014, 0.0000]),
    ("sphere-light", [0.0016, 0.0040, -0.0000, 0.012, 0.0000]),
];

/// The hard shadow is wrong in every penumbra by design; these bound how wrong.
const REF_HARD: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.1144, 0.2829, 0.0040, 0.678, 0.1173]),
    (
        "overlapping-occluders",
        [0.1770, 0.2869, 0.0022, 0.716, 0.2809],
    ),
    ("large-light-close", [0.1995, 0.2293, 0.0393, 0.732, 0.4319]),
    ("bunny", [0.1108, 0.3097, 0.0021, 0.688, 0.0970]),
    ("spot-self-shadow", [0.1415, 0.2829, 0.0013, 0.669, 0.1917]),
    ("grass", [0.1056, 0.2918, -0.0036, 0.863, 0.0986]),
    ("contact", [0.0776, 0.2299, 0.0115, 0.522, 0.0945]),
    ("semi-opaque", [0.0782, 0.1163, 0.0035, 0.401, 0.1826]),
    ("textured-light", [0.0916, 0.0916, -0.0024, 0.845, 0.0851]),
    ("sphere-light", [0.1286, 0.3192, -0.0045, 0.757, 0.1413]),
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
