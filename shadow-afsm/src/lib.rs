//! # shadow-afsm
//!
//! Alias-free shadow maps and sample-based visibility for soft shadows (Sintorn, Eisemann and
//! Assarsson, "Sample Based Visibility for Soft Shadows using Alias-free Shadow Maps", EGSR
//! 2008), as wgpu compute shaders in WGSL. WebGPU has no geometry shaders; what the paper did
//! in geometry shaders and CUDA runs here in compute passes.
//!
//! * [`frame`]: the light frustum fitted to the view samples (section 4.3).
//! * [`passes`]: per-texel lists of view samples by atomic counts, a GPU prefix sum and a
//!   scatter (section 3.1); influence regions (section 4.1) conservatively rasterised
//!   (section 3.2); occlusion of each listed view sample by each caster, with light back-facing
//!   casters only for closed meshes (no bias, section 3.3) and light-sample bitmasks combined by
//!   AND over planes and atomic OR over triangles (section 4.2); computations restricted to
//!   non-empty lists, to the planes that cut the light and by conservative back-face culling
//!   (section 4.3). Before any pair, cluster culling tests each caster against a hierarchy of
//!   view-sample clusters (after Sintorn et al. 2014): super-tiles of 4 x 4 map tiles, tiles and
//!   texels, by their depths, the boxes of their ray origins and the caster's penumbra volume
//!   ([`volume`]); only tiles that hold view samples are numbered; and texels, tiles and view
//!   samples already hidden from every light sample drop out of later casters' work.
//! * [`lut`]: the plane lookup table of section 4.2; [`sample_grid`]: light samples bucketed
//!   on a planar light so the exact test visits only those a triangle's projection covers.
//! * [`technique`]: the [`Afsm`] technique (hard shadows of section 3 and soft shadows of
//!   section 4 with N = 1 to 1024 samples), [`temporal`]: temporal jittering (Fig. 7).
//! * [`params`]: the data layout shared with the shaders; [`pipelines`]: the passes' WGSL and
//!   their compiled pipelines.
//!
//! The GPU comes from `shadow-core`'s `gpu` feature: the adapter is chosen from
//! `WGPU_BACKEND` and `WGPU_ADAPTER_NAME`, with the software Vulkan adapter (lavapipe) as the
//! fallback. Without any adapter, `prepare` reports the technique unsupported (or fails when
//! `SHADOW_REQUIRE_GPU` is set).
//!
//! ```
//! use shadow_afsm::{Afsm, AfsmCounter};
//! use shadow_core::prelude::*;
//!
//! let setup = shadow_scenes::builtin("quad-over-plane").unwrap();
//! let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 24, 18).unwrap();
//! let afsm = Afsm::new(32, SamplingStrategy::Correlated, 1).unwrap();
//! match afsm.prepare(setup.scene.clone(), setup.lights[0].clone()) {
//!     Ok(prepared) => {
//!         let est = prepared.estimate(&view, Outputs::VISIBILITY).unwrap();
//!         assert!(est.stats.counter(AfsmCounter::PairsTested).unwrap() > 0);
//!     }
//!     // Without an adapter (and without `SHADOW_REQUIRE_GPU`), AFSM says why.
//!     Err(e) => assert!(matches!(
//!         e.unsupported_reason(),
//!         Some(UnsupportedReason::NoAdapter(_))
//!     )),
//! }
//! ```

#![deny(missing_docs)]

mod batch;
pub mod frame;
pub mod influence;
mod inputs;
pub mod lut;
pub mod params;
pub mod passes;
pub mod pipelines;
pub mod sample_grid;
pub mod statistics;
pub mod technique;
pub mod temporal;
pub mod volume;

pub use statistics::{AfsmCounter, AfsmGauge, AfsmPhase};
pub use technique::{Afsm, PlaneTest, PreparedAfsm};
pub use temporal::{TemporalAccumulator, accumulate};
