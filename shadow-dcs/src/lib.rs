//! # shadow-dcs
//!
//! Depth complexity sampling (V. Forest, L. Barthe and M. Paulin, "Accurate Shadows by Depth
//! Complexity Sampling", Eurographics 2008) on the CPU: the number of occluding layers between
//! each view sample and each light sample, integrated from silhouette edges instead of cast
//! rays, then turned into the visibility coefficient (eq. 1), its textured-light form (eq. 2)
//! and the direct illumination (eq. 6).
//!
//! The layout follows the paper. [`stages`] holds its stages, each citing its section:
//! * [`edges`]: scene edges, weights and accurate or standard silhouette detection (section 4.1);
//! * `stages::constant`: the integration constant by the shadow-volume step (section 4.1);
//! * `stages::wedges`: each penumbra wedge's exact bounding planes and weight (section 4.2);
//! * `stages::coverage`: the light samples an edge covers, exactly (Algorithm 1, Fig. 2), in 3D,
//!   and the exact test that an edge seen from a pixel covers part of a planar light at all;
//! * `stages::counters`: packed counters with overflow detection (sections 4.3, 4.4, 5.3), the
//!   paper's lanes and a bit-sliced form;
//! * [`discrete`]: the sector and line tables of section 7.3 (Fig. 8);
//! * `stages::light_shape`: the light as the stages see it (outline or sphere, exact form).
//!
//! `accel` (internal) holds what the technique adds on top, and may import the stages, never
//! the reverse:
//! * `accel::centred_wedges`: the wedges' planes and weights around the light centre in single
//!   precision, as the wedge scan tests them;
//! * `accel::bins`: the box hierarchy over the view samples that finds each wedge's view
//!   samples (blocks, squares, tiles, then the tile's view samples);
//! * `accel::planar`: the coverage test in a planar light's plane, set up per pair from per-edge
//!   vectors in single precision;
//! * `accel::angular`: a per-pixel angular index of the light samples that finds each edge's
//!   candidate samples with two lookups (section 7.3's sector table, per pixel);
//! * `accel::centred`: the per-(pixel, edge) tests in light-centred single precision, with
//!   exact fallbacks;
//! * `accel::lanes`: tiles of 4 x 4 view samples in structure-of-arrays form, on which the
//!   wedge scan tests a wedge's planes and weights for the whole tile at once;
//! * `accel::shared_sets`: light-sample sets shared between pixels (interleaved sampling).
//!
//! [`technique`] is the [`Dcs`] technique that runs both (its configurations are named in
//! `shadow-presets`); [`paper`] is the same algorithm as the paper writes it (Algorithm 1 in f64
//! and plain integers, no search structure, no tables), the oracle the technique is tested
//! against sample by sample (`tests/paper.rs`).
//!
//! # When DCS pays
//!
//! DCS costs per (pixel, silhouette edge) pair and barely per light sample; a ray tracer costs
//! per ray. Measured against the same-samples reference on a 2-core machine at 512x512 (figures,
//! command and date in `docs/benchmarks.md`):
//! * **Few silhouette edges per penumbra pixel** (boxes, planes, a sphere light, most built-in
//!   scenes): 3.6x to 6.8x the reference's speed at 64 samples by instructions; 12.7x on the
//!   sphere light.
//! * **A finely tessellated mesh under a large light** (`bunny`: 28,035 accurate silhouette
//!   edges, 63 pairs per per-sample pixel): 2.65x at 64 samples by instructions (2.4x to 2.8x
//!   in wall time), 2.9x with 4 x 4 interleaved sets (their set-up shared), 5.4x at 256 by
//!   instructions, 0.9x at 16. The pairs grow with the square of the light's size while the
//!   reference's cost barely moves: with the light's sides scaled by 0.35 (`DCS_LIGHT_SCALE`
//!   of the examples), `bunny` is 5.1x at 64 samples by instructions, 6.2x at 0.125, 1.3x at 2.
//! * **Depth complexity in the hundreds** (`grass`): far slower (6x to 27x the reference's
//!   time at 64 samples, 64x48 to 512x384). Every layer is counted; a ray stops at its first
//!   hit. The hybrid presets (`dcs-64-hybrid`, [`Dcs::with_rays`], [`technique`]'s `rays`
//!   module) predict each frame's DCS work from the box hierarchy's (tile, wedge) candidates
//!   before any per-pixel work and trace the frame on the same samples where rays cost less:
//!   the same answers, in 1.1x to 2x the reference's time on `grass` instead of 6x to 27x
//!   (DCS's own preparation and the prediction are what is left), and DCS's time elsewhere.
//! * **Textured lights** weigh every sample of every pixel by its radiance (eq. 2), which both
//!   pay: 1.7x at 64 samples by instructions.
//!
//! ```
//! use shadow_core::prelude::*;
//! use shadow_dcs::Dcs;
//!
//! let setup = shadow_scenes::builtin("quad-over-plane").unwrap();
//! let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 32, 24).unwrap();
//! let dcs = Dcs::new(16, SamplingStrategy::Stratified, 1).unwrap();
//! let prepared = dcs.prepare(setup.scene.clone(), setup.lights[0].clone()).unwrap();
//! let est = prepared.estimate(&view, Outputs::VISIBILITY).unwrap();
//! assert!(est.stats.counter("wedge-pairs").unwrap() > 0);
//! ```

#![deny(missing_docs)]

mod accel;
pub mod paper;
pub mod stages;
pub mod technique;

pub use stages::discrete::{self, CoveredSamples};
pub use stages::edges::{self, Silhouettes};
pub use technique::{Dcs, PerSampleOutput, PreparedDcs, RayChoice};
