//! DCS presets and their budgets. Every comparison is against the reference evaluating the same
//! light samples (the suite does this for sample-based techniques), so budgets measure DCS's own
//! error, not sampling noise:
//! * exact presets (`dcs-16`, `dcs-64`, `dcs-256`) must agree on at least 99.9% of (pixel,
//!   sample) pairs and get a tie budget (RMSE 0.004: at 512 x 512 on `bunny` two pixels of
//!   155 000 whose centre lies exactly on a shadow-volume quad's border get a wrong integration
//!   constant, RMSE 0.0026; at most two flipped samples in a pixel at the budget size);
//!   on `semi-opaque` their error is the saturating opacity sum against the exact product
//!   (section 3), measured in [`crate::budgets::dcs`] with the margins of [`Budget::from_measured`];
//! * `dcs-64-interleaved` finds covered samples with the tables of section 7.3 and exact borders
//!   ([`CoveredSamples::Refined`]): exact, so it gets the tie budget too;
//! * `dcs-64-discrete` uses the paper's tables alone, whose discretisation error is measured per
//!   scene, with at least 99% agreement;
//! * `dcs-standard-silhouettes` shows the single-light-sample artifact of Fig. 4; its measured
//!   error is its budget.

use std::sync::Arc;

use shadow_core::prelude::*;
use shadow_dcs::{CoveredSamples, Dcs, RayChoice, Silhouettes};
use shadow_ref::BvhRays;

use crate::{Budget, Preset};

use crate::budgets::dcs as budgets;

/// A preset's DCS; its fixed sample counts are in the sampler's range.
fn make(samples: u32, strategy: SamplingStrategy, seed: u64) -> Dcs {
    Dcs::new(samples, strategy, seed).expect("preset sample counts are valid")
}

/// The budget of an exact preset with `samples` samples: numerical ties only, except on
/// semi-opaque scenes (`semi` holds the measured approximation error).
fn exact_budget(samples: u32, semi: &[(&str, [f64; 5])], scene: &str) -> Option<Budget> {
    let mut b = match Budget::lookup(semi, scene) {
        Some(b) => b,
        None if shadow_scenes::is_named_scene(scene) => Budget {
            rmse: 0.004,
            penumbra_rmse: 0.004,
            bias: 0.001,
            max_abs: 2.0 / samples as f64,
            share_over_0_1: 0.001,
            false_shadow: 0.001,
            min_sample_agreement: None,
        },
        None => return None,
    };
    b.min_sample_agreement = Some(0.999);
    Some(b)
}

/// Every DCS preset.
pub fn presets() -> Vec<Preset> {
    vec![
        Preset {
            name: "dcs-16",
            description: "DCS, 16 stratified samples, accurate silhouettes, exact covered samples",
            make: |seed| Box::new(make(16, SamplingStrategy::Stratified, seed).named("dcs-16")),
            budget: |s| exact_budget(16, budgets::DCS_16_SEMI, s),
            with_samples: Some(|n, seed| {
                Ok(Box::new(Dcs::new(n, SamplingStrategy::Stratified, seed)?))
            }),
            known_limitations: &[],
        },
        Preset {
            name: "dcs-64",
            description: "DCS, 64 stratified samples, accurate silhouettes, exact covered samples",
            make: |seed| Box::new(make(64, SamplingStrategy::Stratified, seed).named("dcs-64")),
            budget: |s| exact_budget(64, budgets::DCS_64_SEMI, s),
            with_samples: None,
            known_limitations: &[],
        },
        Preset {
            name: "dcs-64-interleaved",
            description: "DCS, 64 samples in 4x4 interleaved sets, covered samples by the section 7.3 tables with exact borders",
            make: |seed| {
                Box::new(
                    make(64, SamplingStrategy::Interleaved { tile: 4 }, seed)
                        .with_covered_samples(CoveredSamples::Refined)
                        .expect("interleaved sets take the tables")
                        .named("dcs-64-interleaved"),
                )
            },
            budget: |s| exact_budget(64, budgets::DCS_64_INTERLEAVED_SEMI, s),
            with_samples: None,
            known_limitations: &[],
        },
        Preset {
            name: "dcs-64-discrete",
            description: "DCS, 64 samples in 4x4 interleaved sets, the paper's discrete covered-sample tables (section 7.3, Fig. 8)",
            make: |seed| {
                Box::new(
                    make(64, SamplingStrategy::Interleaved { tile: 4 }, seed)
                        .with_covered_samples(CoveredSamples::Discrete)
                        .expect("interleaved sets take the tables")
                        .named("dcs-64-discrete"),
                )
            },
            budget: |s| {
                Budget::lookup(budgets::DCS_64_DISCRETE, s).map(|mut b| {
                    b.min_sample_agreement = Some(0.99);
                    b
                })
            },
            with_samples: None,
            known_limitations: &[(
                "light-larger-than-scene",
                "the line table of DCS section 7.3 spans the light's square, so on a light 300 \
                 times the occluder one cell is wider than the projected occluder; the exact and \
                 refined modes hold",
            )],
        },
        Preset {
            name: "dcs-64-hybrid",
            description: "DCS, 64 stratified samples, exact covered samples; squares where shadow rays cost less are traced on the same samples",
            make: |seed| {
                Box::new(
                    make(64, SamplingStrategy::Stratified, seed)
                        .with_rays(RayChoice::default(), Arc::new(BvhRays))
                        .named("dcs-64-hybrid"),
                )
            },
            budget: |s| exact_budget(64, budgets::DCS_64_SEMI, s),
            with_samples: Some(|n, seed| {
                Ok(Box::new(
                    Dcs::new(n, SamplingStrategy::Stratified, seed)?
                        .with_rays(RayChoice::default(), Arc::new(BvhRays))
                        .named(&format!("dcs-hybrid-{n}")),
                ))
            }),
            known_limitations: &[],
        },
        Preset {
            name: "dcs-256",
            description: "DCS, 256 stratified samples, exact covered samples",
            make: |seed| Box::new(make(256, SamplingStrategy::Stratified, seed).named("dcs-256")),
            budget: |s| exact_budget(256, budgets::DCS_256_SEMI, s),
            with_samples: None,
            known_limitations: &[],
        },
        Preset {
            name: "dcs-standard-silhouettes",
            description: "DCS, 64 stratified samples, silhouettes from the light centre only (Fig. 4 artifact)",
            make: |seed| {
                Box::new(
                    make(64, SamplingStrategy::Stratified, seed)
                        .with_silhouettes(Silhouettes::Standard)
                        .named("dcs-standard-silhouettes"),
                )
            },
            budget: |s| Budget::lookup(budgets::DCS_STANDARD, s),
            with_samples: None,
            known_limitations: &[(
                "light-larger-than-scene",
                "silhouettes seen from the centre of a light 300 times the occluder miss most of \
                 the penumbra (DCS Fig. 4, the artifact the preset exists to show)",
            )],
        },
    ]
}
