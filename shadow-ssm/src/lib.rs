//! # shadow-ssm
//!
//! Shadow-map soft shadows. This first part of the soft shadow mapping family holds the
//! light-centre shadow map of GBP07 section 3 ([`shadow_map`]), its hierarchical min/max version
//! with GBP07's converging kernel ([`hierarchy`]), and the single-sample baselines a
//! renderer would otherwise pick, PCF and PCSS ([`technique`]); back-projection (GBP06),
//! depth peeling (BCS06), contours and the adaptive scheme (GBP07 sections 4 and 5) build on the
//! same map.
//!
//! ```
//! use shadow_core::prelude::*;
//! use shadow_ssm::{Filter, ShadowMapFilter};
//!
//! let setup = shadow_core::scenes::builtin("quad-over-plane").unwrap();
//! let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 32, 24).unwrap();
//! let mut pcss = ShadowMapFilter::new("pcss", Filter::Pcss, 256);
//! pcss.prepare(setup.scene.clone(), setup.lights[0].clone()).unwrap();
//! let est = pcss.estimate(&view).unwrap();
//! assert!(est.stats.counter("pixels-umbra") > 0);
//! ```

#![deny(missing_docs)]

pub mod backprojection;
mod budgets;
pub mod contours;
pub mod hierarchy;
pub mod light_domain;
pub mod light_frame;
pub mod light_space;
mod presets;
pub mod screen_space;
pub mod shadow_map;
pub mod technique;

pub use light_space::Contours;
pub use presets::presets;
pub use screen_space::ScreenSpace;
pub use technique::{Filter, ShadowMapFilter};
