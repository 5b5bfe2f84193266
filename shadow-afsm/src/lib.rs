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
//!   (section 4.3).
//! * [`lut`]: the plane lookup table of section 4.2; [`sample_grid`]: light samples bucketed
//!   on a planar light so the exact test visits only those a triangle's projection covers.
//! * [`technique`]: the [`Afsm`] technique (hard shadows of section 3 and soft shadows of
//!   section 4 with N = 1 to 1024 samples), [`temporal`]: temporal jittering (Fig. 7).
//! * [`params`]: the data layout shared with the shaders.
//!
//! The GPU comes from `shadow-core`'s `gpu` feature: the adapter is chosen from
//! `WGPU_BACKEND` and `WGPU_ADAPTER_NAME`, with the software Vulkan adapter (lavapipe) as the
//! fallback. Without any adapter, `prepare` reports the technique unsupported (or fails when
//! `SHADOW_REQUIRE_GPU` is set).

#![deny(missing_docs)]

pub mod budgets;
pub mod frame;
pub mod influence;
pub mod lut;
pub mod params;
pub mod passes;
mod presets;
pub mod sample_grid;
pub mod technique;
pub mod temporal;

pub use presets::presets;
pub use technique::{Afsm, PlaneTest};
pub use temporal::{TemporalAccumulator, accumulate};
