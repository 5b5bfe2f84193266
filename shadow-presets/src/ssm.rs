//! Shadow-map presets. Budgets are the errors measured against the stratified reference with
//! the margins of [`Budget::from_measured`]: these baselines are approximations by design, and
//! the tables say how far from the reference each scene takes them.

use shadow_ssm::backprojection::Backprojection;
use shadow_ssm::{Contours, Filter, PEELING_MAX_BIAS, ScreenSpace, ShadowMapFilter};

use crate::{Budget, Preset};

use crate::budgets::ssm as budgets;

/// The measured budget of `scene`, its false-shadow bound included (measured share plus 25%
/// and 0.002, as [`Budget::from_measured`] treats the share over 0.1).
fn budget(table: &[(&str, [f64; 5])], false_shadow: &[(&str, f64)], scene: &str) -> Option<Budget> {
    let mut b = Budget::lookup(table, scene)?;
    if let Some(fs) = crate::table_row(false_shadow, scene) {
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
            known_limitations: &[],
        },
        Preset {
            name: "pcss",
            description: "PCSS: blocker search (GBP07 eq. 1), then PCF of the penumbra width, 1024^2 map",
            make: |_| Box::new(ShadowMapFilter::new("pcss", Filter::Pcss, RESOLUTION)),
            budget: |s| budget(budgets::PCSS, budgets::PCSS_FALSE_SHADOW, s),
            with_samples: None,
            known_limitations: &[],
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
                        union: false,
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
            known_limitations: &[],
        },
        Preset {
            name: "ssm-peeling",
            description: "Soft shadow mapping with 3 depth-peeled layers and midpoint depths (BCS06 section 4), every occluding layer's back-projection united over the light (not summed), no gap filling, 1024^2 map",
            make: |_| {
                Box::new(ShadowMapFilter::new(
                    "ssm-peeling",
                    Filter::Backprojection(Backprojection {
                        max_nspp: 1024,
                        gap_filling: false,
                        peeling_max_bias: Some(PEELING_MAX_BIAS),
                        union: true,
                    }),
                    RESOLUTION,
                ))
            },
            budget: |s| budget(budgets::PEELING, budgets::PEELING_FALSE_SHADOW, s),
            with_samples: None,
            known_limitations: &[],
        },
        Preset {
            name: "ssm-contours",
            description: "Soft shadow mapping with contour edges (t = 0) integrated radially (GBP07 section 4), kernels above 256 texels on coarser levels, 1024^2 map",
            make: |_| {
                Box::new(ShadowMapFilter::new(
                    "ssm-contours",
                    Filter::Contours(CONTOURS),
                    RESOLUTION,
                ))
            },
            budget: |s| budget(budgets::CONTOURS, budgets::CONTOURS_FALSE_SHADOW, s),
            with_samples: None,
            known_limitations: &[],
        },
        Preset {
            name: "ssm-adaptive",
            description: "Contours with light-space multi-resolution (t_k = 32, beta = 0.05) and screen-space selection (s_min = 16, 4x4 pattern) with pull-push (GBP07 section 5), 1024^2 map",
            make: |_| {
                Box::new(
                    ShadowMapFilter::new("ssm-adaptive", Filter::Contours(ADAPTIVE), RESOLUTION)
                        .with_screen_space(ScreenSpace {
                            s_min: 16.0,
                            pattern: 4,
                        }),
                )
            },
            budget: |s| budget(budgets::ADAPTIVE, budgets::ADAPTIVE_FALSE_SHADOW, s),
            with_samples: None,
            known_limitations: &[],
        },
    ]
}

/// Contours at full resolution: `t = 0` (GBP07's recommendation); eq. 2 moves only kernels
/// above 256 texels to a coarser level, so the cost per receiver stays bounded.
pub const CONTOURS: Contours = Contours {
    t: 0.0,
    max_kernel: 256.0,
    beta: 0.05,
};

/// The adaptive scheme's light-space settings: kernels of about 32 texels per level (16 loses thin occluders such as grass blades: RMSE 0.046 against 0.032 at 32).
pub const ADAPTIVE: Contours = Contours {
    t: 0.0,
    max_kernel: 32.0,
    beta: 0.05,
};
