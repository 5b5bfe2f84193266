//! # shadow-ssm
//!
//! Soft shadow mapping: every filter reads one light-centre shadow map (GBP07 section 3,
//! [`shadow_map`], its frustum from [`light_view`]) and its min/max pyramid with GBP07's
//! converging kernel ([`hierarchy`]).
//!
//! * Baselines a renderer would otherwise pick: PCF and PCSS ([`technique`]).
//! * Back-projection with gap filling (GBP06 as BCS06 section 2 summarises it) and depth peeling
//!   with midpoint layers (BCS06 section 4): [`backprojection`].
//! * Contours integrated radially (GBP07 section 4): [`contours`], [`light_domain`].
//! * The adaptive scheme (GBP07 section 5): light-space multi-resolution ([`light_space`]) and
//!   screen-space selection with pull-push ([`screen_space`]).
//! * Rectangle, disk and polygon lights; textured rectangle lights for the filters that
//!   integrate over the light (radiance integrated over the uncovered area).
//!
//! Presets: `pcf`, `pcss`, `ssm-backprojection`, `ssm-peeling`, `ssm-contours`,
//! `ssm-adaptive`.
//!
//! ```
//! use shadow_core::prelude::*;
//! use shadow_ssm::{Filter, ShadowMapFilter, SsmCounter};
//!
//! let setup = shadow_scenes::builtin("quad-over-plane").unwrap();
//! let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 32, 24).unwrap();
//! let pcss = ShadowMapFilter::new("pcss", Filter::Pcss, 256);
//! let prepared = pcss.prepare(setup.scene.clone(), setup.lights[0].clone()).unwrap();
//! let est = prepared.estimate(&view, Outputs::VISIBILITY).unwrap();
//! assert!(est.stats.counter(SsmCounter::PixelsUmbra).unwrap() > 0);
//! ```

#![deny(missing_docs)]

pub mod backprojection;
pub mod contours;
pub mod hierarchy;
pub mod light_domain;
pub mod light_frame;
pub mod light_space;
pub mod light_view;
pub mod rect_union;
pub mod screen_space;
pub mod shadow_map;
pub mod statistics;
pub mod technique;

pub use light_space::Contours;
pub use statistics::{SsmCounter, SsmPhase};

/// The cap on a midpoint's distance beyond its layer (BCS06 Fig. 5b) that the `ssm-peeling`
/// preset uses, in world units: about a tenth of the built-in scenes' occluder heights.
pub const PEELING_MAX_BIAS: f32 = 0.05;
pub use screen_space::ScreenSpace;
pub use technique::{Filter, ShadowMapFilter};
