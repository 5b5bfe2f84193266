//! Shadow-map presets. Budgets are the errors measured against the stratified reference with
//! the margins of [`Budget::from_measured`]: these baselines are approximations by design, and
//! the tables say how far from the reference each scene takes them.

use shadow_core::prelude::*;

use crate::backprojection::Backprojection;
use crate::budgets;
use crate::{Filter, ShadowMapFilter};

/// The measured budget of `scene`, its false-shadow bound included (measured share plus 25%
/// and 0.002, as [`Budget::from_measured`] treats the share over 0.1).
fn budget(table: &[(&str, [f64; 5])], false_shadow: &[(&str, f64)], scene: &str) -> Option<Budget> {
    let mut b = Budget::lookup(table, scene)?;
    if let Some((_, fs)) = false_shadow.iter().find(|(s, _)| *s == scene) {
        b.false_shadow = fs * 1.25 + 0.002;
    }
    Some(b)
}

/// Shadow-map resolution of the presets.
pub const RESOLUTION: u32 = 1024;

/// Every shadow-map preset.
pub fn presets() -> Vec<Preset> {
    vec![
        Preset {
            name: "pcf",
            description: "PCF, 5x5 texels, on a 1024^2 light-centre shadow map",
            make: |_| {
                Box::new(ShadowMapFilter::new(
                    "pcf",
                    Filter::Pcf { radius: 2 },
                    RESOLUTION,
                ))
            },
            budget: |s| budget(budgets::PCF, budgets::PCF_FALSE_SHADOW, s),
            with_samples: None,
        },
        Preset {
            name: "pcss",
            description: "PCSS: blocker search (GBP07 eq. 1), then PCF of the penumbra width, 1024^2 map",
            make: |_| Box::new(ShadowMapFilter::new("pcss", Filter::Pcss, RESOLUTION)),
            budget: |s| budget(budgets::PCSS, budgets::PCSS_FALSE_SHADOW, s),
            with_samples: None,
        },
        Preset {
            name: "ssm-backprojection",
            description: "Soft shadow mapping by back-projection with gap filling (GBP06), converged kernel, at most 1024 samples per pixel, 1024^2 map",
            make: |_| {
                Box::new(ShadowMapFilter::new(
                    "ssm-backprojection",
                    Filter::Backprojection(Backprojection {
                        max_nspp: 1024,
                        gap_filling: true,
                        peeling_max_bias: None,
                    }),
                    RESOLUTION,
                ))
            },
            budget: |s| {
                budget(
                    budgets::BACKPROJECTION,
                    budgets::BACKPROJECTION_FALSE_SHADOW,
                    s,
                )
            },
            with_samples: None,
        },
        Preset {
            name: "ssm-peeling",
            description: "Soft shadow mapping with 3 depth-peeled layers and midpoint depths (BCS06 section 4), no gap filling, 1024^2 map",
            make: |_| {
                Box::new(ShadowMapFilter::new(
                    "ssm-peeling",
                    Filter::Backprojection(Backprojection {
                        max_nspp: 1024,
                        gap_filling: false,
                        peeling_max_bias: Some(PEELING_MAX_BIAS),
                    }),
                    RESOLUTION,
                ))
            },
            budget: |s| budget(budgets::PEELING, budgets::PEELING_FALSE_SHADOW, s),
            with_samples: None,
        },
    ]
}

/// The cap on a midpoint's distance beyond its layer (BCS06 Fig. 5b), in world units: about a
/// tenth of the built-in scenes' occluder heights.
pub const PEELING_MAX_BIAS: f32 = 0.05;
