//! The reference's presets: the reference at low sample counts (checked against the reference at
//! 1024 samples) and the point-light hard shadow as a baseline.

use shadow_core::prelude::*;

use crate::Reference;

fn stratified(samples: u32, seed: u64) -> Box<dyn ShadowTechnique> {
    Box::new(
        Reference::stratified(samples, seed)
            .expect("preset sample counts are valid")
            .named(&format!("ref-{samples}")),
    )
}

/// Budgets of the low-sample reference: stratified Monte Carlo noise only, no bias. Measured
/// with `cargo xtask conformance` at the suite's image size; see docs/benchmarks.md.
fn low_sample_budget(samples: u32) -> fn(&str) -> Option<Budget> {
    match samples {
        16 => |_| {
            Some(Budget {
                rmse: 0.06,
                penumbra_rmse: 0.12,
                bias: 0.01,
                max_abs: 0.5,
                share_over_0_1: 0.12,
                false_shadow: 0.0,
                min_sample_agreement: None,
            })
        },
        _ => |_| {
            Some(Budget {
                rmse: 0.03,
                penumbra_rmse: 0.06,
                bias: 0.005,
                max_abs: 0.3,
                share_over_0_1: 0.03,
                false_shadow: 0.0,
                min_sample_agreement: None,
            })
        },
    }
}

/// The presets of this crate.
pub fn presets() -> Vec<Preset> {
    vec![
        Preset {
            name: "ref-16",
            description: "ray-traced reference, 16 stratified samples per pixel",
            make: |seed| stratified(16, seed),
            budget: low_sample_budget(16),
            with_samples: Some(stratified),
        },
        Preset {
            name: "ref-64",
            description: "ray-traced reference, 64 stratified samples per pixel",
            make: |seed| stratified(64, seed),
            budget: low_sample_budget(64),
            with_samples: Some(stratified),
        },
        Preset {
            name: "ref-hard",
            description: "hard shadow of the light centre (point-light limit), traced",
            make: |_| Box::new(Reference::hard()),
            // A hard shadow is wrong in every penumbra by design; the budget bounds how wrong.
            budget: |_| {
                Some(Budget {
                    rmse: 0.5,
                    penumbra_rmse: 0.7,
                    bias: 0.3,
                    max_abs: 1.0,
                    share_over_0_1: 0.6,
                    false_shadow: 0.05,
                    min_sample_agreement: None,
                })
            },
            with_samples: None,
        },
    ]
}
