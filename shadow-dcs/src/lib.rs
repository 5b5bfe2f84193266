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
//! per ray. Against the same-samples reference (figures, command, date and machine in
//! `docs/benchmarks.md`):
//! * **Few silhouette edges per penumbra pixel** (boxes, planes, a sphere light, most built-in
//!   scenes): DCS is several times faster at 64 samples, most on sphere lights.
//! * **A finely tessellated mesh under a large light** (`bunny`, tens of thousands of accurate
//!   silhouette edges): faster at 64 and 256 samples, not at 16; the pairs grow with the square
//!   of the light's size while the reference's cost barely moves, so a smaller light widens
//!   the gap and a larger one closes it.
//! * **Depth complexity in the hundreds** (`grass`): far slower, since every layer is counted
//!   where a ray stops at its first hit. The hybrid presets (`dcs-64-hybrid`, [`Dcs::with_rays`],
//!   [`technique`]'s `rays` module) predict each frame's DCS work from the box hierarchy's
//!   (tile, wedge) candidates before any per-pixel work and trace the frame on the same samples
//!   where rays cost less: the same answers, near the reference's time on `grass`, and DCS's
//!   time elsewhere.
//! * **Textured lights** weigh every sample of every pixel by its radiance (eq. 2), which both
//!   pay.
//!
//! ```
//! use shadow_core::prelude::*;
//! use shadow_dcs::{Dcs, DcsCounter};
//!
//! let setup = shadow_scenes::builtin("quad-over-plane").unwrap();
//! let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 32, 24).unwrap();
//! let dcs = Dcs::new(16, SamplingStrategy::Stratified, 1).unwrap();
//! let prepared = dcs.prepare(setup.scene.clone(), setup.lights[0].clone()).unwrap();
//! let est = prepared.estimate(&view, Outputs::VISIBILITY).unwrap();
//! assert!(est.stats.counter(DcsCounter::WedgePairs).unwrap() > 0);
//! ```

#![deny(missing_docs)]

mod accel;
pub mod paper;
pub mod stages;
pub mod statistics;
pub mod technique;

pub use stages::discrete::{self, CoveredSamples};
pub use stages::edges::{self, Silhouettes};
pub use statistics::{DcsCounter, DcsGauge, DcsPhase};
pub use technique::{Dcs, PerSampleOutput, PreparedDcs, RayChoice};
