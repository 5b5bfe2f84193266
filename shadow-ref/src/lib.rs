//! # shadow-ref
//!
//! The ground truth every technique is checked against: a ray-traced estimate of the visibility
//! coefficient `V(p)` of area lights (DCS eq. 1; eq. 2 for textured lights), the direct
//! illumination (DCS eq. 6), semi-opaque occluders by the exact transmittance product, and the
//! point-light hard shadow.
//!
//! * [`beam`]: conservative beam culling of a receiver's segments to a planar light;
//! * [`bvh`]: the occlusion structure (binned SAH build, `obvhs` reinsertion and CWBVH) with
//!   occlusion, any-hit and beam queries;
//! * [`wide`]: the wide tree (sixteen SoA child boxes per node) the occlusion and beam queries
//!   traverse;
//! * [`watertight`]: the watertight ray-triangle test of Woop, Benthin and Wald (JCGT 2013),
//!   one triangle or four at a time;
//! * [`offset`]: robust ray origins after Wachter and Binder (Ray Tracing Gems ch. 6);
//! * [`mod@reference`]: the [`Reference`] technique;
//! * [`adaptive`]: the [`AdaptiveReference`] (`ref-adaptive-*`), per-pixel stratified batches
//!   toward a standard-error target.
//!
//! ```
//! use shadow_core::prelude::*;
//! use shadow_ref::{Reference, RefCounter};
//!
//! let setup = shadow_scenes::builtin("quad-over-plane").unwrap();
//! let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 24, 18).unwrap();
//! let r = Reference::stratified(64, 1).unwrap();
//! let prepared = r.prepare(setup.scene.clone(), setup.lights[0].clone()).unwrap();
//! let est = prepared.estimate(&view, Outputs::VISIBILITY).unwrap();
//! assert!(est.stats.counter(RefCounter::OcclusionRays).unwrap() > 0);
//! ```

#![deny(missing_docs)]

pub mod adaptive;
mod allocation;
pub mod beam;
pub mod bvh;
pub mod offset;
pub mod rays;
pub mod reference;
pub mod sah;
pub mod statistics;
pub mod watertight;
pub mod wide;

pub use adaptive::AdaptiveReference;
pub use rays::BvhRays;
pub use reference::{PixelScratch, PreparedReference, Reference};
pub use statistics::{RefCounter, RefGauge, RefPhase};
