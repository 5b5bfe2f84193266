//! The reference's presets: the reference at 16, 64 and 1024 samples (checked against the
//! reference at 1024 samples with another seed, and against the closed form), and the
//! point-light hard shadow as a baseline.
//!
//! Budgets are errors measured by the conformance suite (128 x 96 pixels, seed 1, reference at
//! 1024 samples; `cargo test -p shadow-tests --test conformance -- conformance/` prints them) with the margins of
//! [`Budget::from_measured`]; `scripts/measure_budgets.py` regenerates the tables.
//! The `corpus` row of each table holds the largest error over the 44 scenes of the corpus of
//! real meshes (`cargo xtask conformance --quick --scenes corpus`, folded by `scripts/measure_budgets.py --report ... --corpus`): the promise on any of them
//! ([`crate::CORPUS_ROW`]).
//! Textured-light errors are per RGB channel of radiance-weighted visibility (DCS eq. 2), so
//! they are larger in absolute terms.

use shadow_core::prelude::*;
use shadow_ref::adaptive::{DEFAULT_BATCH, DEFAULT_CAP};
use shadow_ref::{AdaptiveReference, Reference};

use crate::{Budget, Preset};

/// The stratified reference at `samples` samples, named `ref` at 1024 and `ref-N` otherwise.
///
/// # Errors
/// [`TechniqueError::InvalidInput`] for a count outside the sampler's range.
fn stratified(samples: u32, seed: u64) -> Result<Box<dyn ShadowTechnique>, TechniqueError> {
    let r = Reference::stratified(samples, seed)?;
    let name = if samples == 1024 {
        "ref".to_string()
    } else {
        format!("ref-{samples}")
    };
    Ok(Box::new(r.named(&name)))
}

/// The adaptive reference toward image RMSE `target`, named `name`.
fn adaptive(name: &str, target: f32, seed: u64) -> Box<dyn ShadowTechnique> {
    Box::new(
        AdaptiveReference::new(target, DEFAULT_BATCH, DEFAULT_CAP, seed)
            .expect("the preset's target, batch and cap are valid")
            .named(name),
    )
}

/// Measured errors: scene, [rmse, penumbra rmse, bias, max, share > 0.1].
const ADAPTIVE_01: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0093, 0.0231, -0.0001, 0.096, 0.0000]),
    (
        "overlapping-occluders",
        [0.0107, 0.0170, 0.0000, 0.064, 0.0000],
    ),
    (
        "large-light-close",
        [0.0107, 0.0120, -0.0001, 0.062, 0.0000],
    ),
    ("bunny", [0.0096, 0.0265, 0.0000, 0.095, 0.0000]),
    ("spot-self-shadow", [0.0100, 0.0196, 0.0002, 0.078, 0.0000]),
    ("grass", [0.0103, 0.0270, -0.0001, 0.108, 0.0002]),
    ("contact", [0.0092, 0.0271, 0.0000, 0.098, 0.0000]),
    ("semi-opaque", [0.0081, 0.0116, 0.0001, 0.051, 0.0000]),
    ("textured-light", [0.0060, 0.0060, 0.0000, 0.034, 0.0000]),
    ("sphere-light", [0.0103, 0.0254, -0.0000, 0.108, 0.0002]),
    ("cornell-box", [0.0108, 0.0173, -0.0001, 0.086, 0.0000]),
    ("mesh-light", [0.0099, 0.0150, -0.0001, 0.095, 0.0000]),
    ("spot-lamp", [0.0087, 0.0303, -0.0002, 0.120, 0.0004]),
    ("interior", [0.0081, 0.0273, -0.0000, 0.119, 0.0003]),
    ("interior-window", [0.0112, 0.0210, -0.0001, 0.116, 0.0001]),
    ("corpus", [0.0101, 0.0440, -0.0002, 0.133, 0.0007]),
];

const ADAPTIVE_003: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0035, 0.0084, 0.0000, 0.058, 0.0000]),
    (
        "overlapping-occluders",
        [0.0038, 0.0061, 0.0000, 0.051, 0.0000],
    ),
    ("large-light-close", [0.0039, 0.0044, 0.0001, 0.054, 0.0000]),
    ("bunny", [0.0038, 0.0104, 0.0000, 0.074, 0.0000]),
    ("spot-self-shadow", [0.0036, 0.0070, 0.0000, 0.031, 0.0000]),
    ("grass", [0.0048, 0.0126, 0.0000, 0.074, 0.0000]),
    ("contact", [0.0036, 0.0105, 0.0000, 0.059, 0.0000]),
    ("semi-opaque", [0.0032, 0.0046, 0.0000, 0.025, 0.0000]),
    ("textured-light", [0.0020, 0.0020, -0.0000, 0.015, 0.0000]),
    ("sphere-light", [0.0038, 0.0092, 0.0000, 0.058, 0.0000]),
    ("cornell-box", [0.0039, 0.0060, 0.0000, 0.047, 0.0000]),
    ("mesh-light", [0.0037, 0.0055, 0.0000, 0.032, 0.0000]),
    ("spot-lamp", [0.0033, 0.0112, -0.0000, 0.044, 0.0000]),
    ("interior", [0.0033, 0.0110, -0.0000, 0.070, 0.0000]),
    ("interior-window", [0.0042, 0.0078, -0.0000, 0.116, 0.0001]),
    ("corpus", [0.0039, 0.0354, 0.0001, 0.102, 0.0001]),
];

const REF_16: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0214, 0.0531, -0.0001, 0.189, 0.0114]),
    (
        "overlapping-occluders",
        [0.0316, 0.0506, -0.0001, 0.200, 0.0202],
    ),
    ("large-light-close", [0.0409, 0.0462, 0.0003, 0.232, 0.0265]),
    ("bunny", [0.0184, 0.0514, 0.0000, 0.199, 0.0065]),
    ("spot-self-shadow", [0.0246, 0.0487, 0.0000, 0.156, 0.0100]),
    ("grass", [0.0206, 0.0545, 0.0000, 0.171, 0.0088]),
    ("contact", [0.0165, 0.0492, 0.0000, 0.146, 0.0048]),
    ("semi-opaque", [0.0139, 0.0203, 0.0002, 0.119, 0.0003]),
    ("textured-light", [0.0543, 0.0543, 0.0002, 0.255, 0.0650]),
    ("sphere-light", [0.0261, 0.0650, 0.0004, 0.247, 0.0202]),
    ("cornell-box", [0.0333, 0.0545, 0.0000, 0.202, 0.0244]),
    ("mesh-light", [0.0277, 0.0430, -0.0006, 0.279, 0.0212]),
    ("spot-lamp", [0.0152, 0.0528, 0.0004, 0.180, 0.0051]),
    ("interior", [0.0153, 0.0517, 0.0002, 0.180, 0.0046]),
    ("interior-window", [0.0335, 0.0629, -0.0005, 0.235, 0.0312]),
    ("corpus", [0.0275, 0.0608, 0.0005, 0.252, 0.0151]),
];

const REF_64: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0075, 0.0186, 0.0002, 0.070, 0.0000]),
    (
        "overlapping-occluders",
        [0.0114, 0.0181, 0.0002, 0.076, 0.0000],
    ),
    (
        "large-light-close",
        [0.0145, 0.0163, -0.0000, 0.064, 0.0000],
    ),
    ("bunny", [0.0064, 0.0179, 0.0001, 0.068, 0.0000]),
    ("spot-self-shadow", [0.0091, 0.0181, 0.0002, 0.076, 0.0000]),
    ("grass", [0.0094, 0.0251, -0.0000, 0.098, 0.0000]),
    ("contact", [0.0061, 0.0183, 0.0001, 0.056, 0.0000]),
    ("semi-opaque", [0.0052, 0.0075, 0.0001, 0.062, 0.0000]),
    ("textured-light", [0.0192, 0.0192, 0.0001, 0.093, 0.0000]),
    ("sphere-light", [0.0093, 0.0230, -0.0001, 0.088, 0.0000]),
    ("cornell-box", [0.0127, 0.0205, 0.0002, 0.087, 0.0000]),
    ("mesh-light", [0.0098, 0.0153, -0.0001, 0.117, 0.0003]),
    ("spot-lamp", [0.0053, 0.0183, 0.0000, 0.055, 0.0000]),
    ("interior", [0.0054, 0.0181, 0.0001, 0.071, 0.0000]),
    ("interior-window", [0.0126, 0.0236, 0.0001, 0.094, 0.0000]),
    ("corpus", [0.0099, 0.0234, 0.0002, 0.089, 0.0000]),
];

const REF_1024: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0014, 0.0034, -0.0000, 0.013, 0.0000]),
    (
        "overlapping-occluders",
        [0.0020, 0.0032, 0.0000, 0.015, 0.0000],
    ),
    (
        "large-light-close",
        [0.0026, 0.0029, -0.0000, 0.013, 0.0000],
    ),
    ("bunny", [0.0012, 0.0033, -0.0000, 0.013, 0.0000]),
    ("spot-self-shadow", [0.0017, 0.0033, 0.0000, 0.011, 0.0000]),
    ("grass", [0.0023, 0.0060, 0.0000, 0.025, 0.0000]),
    ("contact", [0.0011, 0.0032, -0.0000, 0.010, 0.0000]),
    ("semi-opaque", [0.0009, 0.0012, -0.0000, 0.007, 0.0000]),
    ("textured-light", [0.0019, 0.0019, -0.0000, 0.016, 0.0000]),
    ("sphere-light", [0.0017, 0.0042, 0.0000, 0.018, 0.0000]),
    ("cornell-box", [0.0023, 0.0035, -0.0000, 0.017, 0.0000]),
    ("mesh-light", [0.0018, 0.0028, 0.0000, 0.021, 0.0000]),
    ("spot-lamp", [0.0009, 0.0030, 0.0000, 0.011, 0.0000]),
    ("interior", [0.0010, 0.0033, 0.0000, 0.013, 0.0000]),
    ("interior-window", [0.0022, 0.0041, -0.0000, 0.019, 0.0000]),
    ("corpus", [0.0017, 0.0041, -0.0000, 0.019, 0.0000]),
];

/// The hard shadow is wrong in every penumbra by design; these bound how wrong.
const REF_HARD: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.1169, 0.2919, 0.0011, 0.729, 0.1189]),
    (
        "overlapping-occluders",
        [0.1764, 0.2852, 0.0040, 0.743, 0.2808],
    ),
    ("large-light-close", [0.2044, 0.2329, 0.0356, 0.747, 0.4399]),
    ("bunny", [0.1057, 0.2974, -0.0010, 0.801, 0.0970]),
    ("spot-self-shadow", [0.1411, 0.2832, -0.0005, 0.697, 0.1918]),
    ("grass", [0.1110, 0.2988, -0.0041, 0.871, 0.1028]),
    ("contact", [0.0784, 0.2353, 0.0109, 0.714, 0.0923]),
    ("semi-opaque", [0.0790, 0.1175, 0.0003, 0.478, 0.1861]),
    ("textured-light", [0.0870, 0.0870, 0.0007, 0.851, 0.0842]),
    ("sphere-light", [0.1279, 0.3193, -0.0046, 0.778, 0.1393]),
    ("cornell-box", [0.1446, 0.2407, 0.0421, 0.720, 0.2232]),
    ("mesh-light", [0.2691, 0.4234, 0.1247, 0.750, 0.3519]),
    ("spot-lamp", [0.0811, 0.2846, -0.0036, 0.720, 0.0646]),
    ("interior", [0.0857, 0.2927, -0.0037, 0.762, 0.0669]),
    ("interior-window", [0.1694, 0.3185, -0.0122, 0.848, 0.2443]),
    ("corpus", [0.1804, 0.3501, 0.0639, 0.931, 0.2117]),
];

/// The presets of this crate.
pub fn presets() -> Vec<Preset> {
    vec![
        Preset {
            name: "ref",
            description: "ray-traced reference, 1024 stratified samples per pixel",
            make: |seed| stratified(1024, seed).expect("the preset\'s sample count is valid"),
            budget: |scene| Budget::lookup(REF_1024, scene),
            with_samples: Some(stratified),
            known_limitations: &[],
        },
        Preset {
            name: "ref-16",
            description: "ray-traced reference, 16 stratified samples per pixel",
            make: |seed| stratified(16, seed).expect("the preset\'s sample count is valid"),
            budget: |scene| Budget::lookup(REF_16, scene),
            with_samples: Some(stratified),
            known_limitations: &[],
        },
        Preset {
            name: "ref-64",
            description: "ray-traced reference, 64 stratified samples per pixel",
            make: |seed| stratified(64, seed).expect("the preset\'s sample count is valid"),
            budget: |scene| Budget::lookup(REF_64, scene),
            with_samples: Some(stratified),
            known_limitations: &[],
        },
        Preset {
            name: "ref-adaptive-0.01",
            description: "adaptive reference: per-pixel stratified counts planned toward image RMSE 0.01",
            make: |seed| adaptive("ref-adaptive-0.01", 0.01, seed),
            budget: |scene| Budget::lookup(ADAPTIVE_01, scene),
            with_samples: None,
            known_limitations: &[],
        },
        Preset {
            name: "ref-adaptive-0.003",
            description: "adaptive reference: per-pixel stratified counts planned toward image RMSE 0.003",
            make: |seed| adaptive("ref-adaptive-0.003", 0.003, seed),
            budget: |scene| Budget::lookup(ADAPTIVE_003, scene),
            with_samples: None,
            known_limitations: &[],
        },
        Preset {
            name: "ref-hard",
            description: "hard shadow of the light centre (point-light limit), traced",
            make: |_| Box::new(Reference::hard()),
            budget: |scene| Budget::lookup(REF_HARD, scene),
            with_samples: None,
            known_limitations: &[],
        },
    ]
}
