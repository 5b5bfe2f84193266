//! AFSM presets and their budgets. Sample-based presets are compared with the reference on the
//! same light samples (the suite does this), so their budgets measure AFSM's own error:
//! * the exact presets (`afsm-128`, `afsm-256`, `afsm-1024`) test every sample against every
//!   plane and must agree with the reference on at least 99.9% of (pixel, sample) pairs, with a
//!   tie budget;
//! * `afsm-128-lut` replaces the per-sample test by the plane table of section 4.2; its
//!   discretisation error is measured per scene ([`crate::budgets::afsm`]) with at least 97%
//!   agreement;
//! * `afsm-hard` is the hard shadow of the light's centre (section 3); against the area
//!   light's reference its error is that of any hard shadow, measured per scene. Its agreement
//!   with the reference's point-light hard shadow is tested separately (`tests/agreement.rs`).
//!
//! Measured tables hold the larger error of two sizes: the budget resolution (128 x 96) and
//! the size at which `cargo test` runs GPU presets (48 x 36, `GPU_TEST_RESOLUTION` in the
//! conformance suite).

use shadow_afsm::Afsm;
use shadow_core::prelude::*;

use crate::{Budget, Preset};

use crate::budgets::afsm as budgets;

const INTERLEAVED: SamplingStrategy = SamplingStrategy::Interleaved { tile: 4 };

fn exact(samples: u32, seed: u64, name: &str) -> Box<dyn ShadowTechnique> {
    Box::new(
        Afsm::new(samples, INTERLEAVED, seed)
            .expect("preset parameters are valid")
            .named(name),
    )
}

/// Numerical ties only: a handful of flipped samples.
fn tie_budget(samples: u32, scene: &str) -> Option<Budget> {
    shadow_scenes::is_named_scene(scene).then_some(Budget {
        rmse: 0.004,
        penumbra_rmse: 0.006,
        bias: 0.001,
        max_abs: (2.0 / samples as f64).max(0.02),
        share_over_0_1: 0.001,
        false_shadow: 0.001,
        min_sample_agreement: Some(0.999),
    })
}

/// Every AFSM preset.
pub fn presets() -> Vec<Preset> {
    vec![
        Preset {
            name: "afsm-hard",
            description: "AFSM hard shadows of the light's centre (section 3), no bias",
            make: |_| Box::new(Afsm::hard()),
            budget: |s| Budget::lookup(budgets::AFSM_HARD, s),
            with_samples: None,
            known_limitations: &[],
        },
        Preset {
            name: "afsm-128",
            description: "AFSM soft shadows, 128 samples in 4x4 interleaved sets, exact plane tests",
            make: |seed| exact(128, seed, "afsm-128"),
            budget: |s| tie_budget(128, s),
            with_samples: Some(|n, seed| {
                Ok(Box::new(Afsm::new(n, INTERLEAVED, seed)?.named("afsm")))
            }),
            known_limitations: &[],
        },
        Preset {
            name: "afsm-256",
            description: "AFSM soft shadows, 256 samples in 4x4 interleaved sets, exact plane tests",
            make: |seed| exact(256, seed, "afsm-256"),
            budget: |s| tie_budget(256, s),
            with_samples: None,
            known_limitations: &[],
        },
        Preset {
            name: "afsm-1024",
            description: "AFSM soft shadows, 1024 samples in 4x4 interleaved sets, exact plane tests",
            make: |seed| exact(1024, seed, "afsm-1024"),
            budget: |s| tie_budget(1024, s),
            with_samples: None,
            known_limitations: &[],
        },
        Preset {
            name: "afsm-128-lut",
            description: "AFSM soft shadows, 128 correlated samples, the plane lookup table of section 4.2",
            make: |seed| {
                Box::new(
                    Afsm::new(128, SamplingStrategy::Correlated, seed)
                        .and_then(Afsm::with_lut)
                        .expect("preset parameters are valid")
                        .named("afsm-128-lut"),
                )
            },
            budget: |s| {
                Budget::lookup(budgets::AFSM_128_LUT, s).map(|mut b| {
                    b.min_sample_agreement = Some(0.97);
                    b
                })
            },
            with_samples: None,
            known_limitations: &[],
        },
    ]
}
