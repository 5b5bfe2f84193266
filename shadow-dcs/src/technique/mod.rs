//! The [`Dcs`] technique: depth complexity sampling (Forest, Barthe and Paulin 2008) on the CPU.
//!
//! Per frame (Algorithm 2 for one light):
//! 1. silhouette edges of the scene for the light (prepared once per scene and light,
//!    [`crate::stages::edges`], section 4.1);
//! 2. the integration constant `D(p, c)` of every view sample by the shadow-volume step
//!    (`constant`, section 4.1), and the counter width from its maximum (section 5.3);
//! 3. square by square (16 x 16 pixels), the wedges' view samples and each one's weight
//!    (`wedges` and the box hierarchy of `bins`, section 4.2), with each pair's
//!    light-plane test set up on the way (planar lights, `planar`);
//! 4. per view sample: its light samples (the shared [`LightSampler`], section 5), the samples
//!    each wedge edge covers (the light-plane test or `coverage`'s 3D one, exact; or
//!    the discrete tables of section 7.3), the packed counters updated outer wedges first
//!    (`counters`, sections 4.3-4.4),
//!    then the visibility coefficient (eq. 1), its RGB form for textured lights (eq. 2), the
//!    saturating opacity sum for semi-opaque occluders (section 3) and, on request, the direct
//!    illumination from the per-sample binary visibility (eq. 6).
//!
//! Work a view sample does not need is skipped and counted: a receiver facing away from the
//! whole light is 0 without samples; one in no wedge, or (3D test) whose wedge edges all miss
//! the light (the exact light-overlap test, `wedge-pairs-off-light`), takes its integration
//! constant for every sample (fully lit or umbra, no counters); a pair whose angular sector holds no sample
//! is dropped without a per-sample test (`wedge-pairs-empty-sector`); with the refined tables
//! of section 7.3, a pair with many candidates looks its line up in the line table, which
//! settles every candidate it can (`refined-line-cells`); the texture and opacity paths run only
//! when the light is textured or the scene semi-opaque, a pixel whose caller reads only
//! which samples are visible gets that mask and no per-sample values, and under correlated or
//! interleaved sampling the pixels of one shared set take the part of their samples' set-up
//! that depends on the samples alone from that set, built once (`shared_sets`;
//! `pixels-shared-sample-sets`, `shared-sample-sets-built`).
//!
//! Light samples behind the receiver's tangent plane are occluded, and view samples are offset
//! off their surface, exactly as the reference does ([`shadow_core::offset`]), so that with the
//! same samples the two agree sample by sample up to numerical ties.

use std::sync::{Arc, Mutex};

use glam::{DVec3, UVec2, Vec2, Vec3};
use rayon::prelude::*;
use serde_json::json;
use shadow_core::direct::pixel_direct;
use shadow_core::light::{LightGeometry, LightKind, LightSample};
use shadow_core::offset::RayOffset;
use shadow_core::prelude::*;
use shadow_core::rays::{PreparedRays, RayScratch, ShadowRays};
use shadow_core::spatial_order::in_spatial_order;
use shadow_core::stats::CorePhase;
use shadow_core::technique::{Capabilities, Processor, SceneRef};
use shadow_core::view_samples::ViewSample;
use shadow_core::visibility::PixelClass;

use crate::accel::angular::{BATCH, QuadRanges};
use crate::accel::bins::{
    BlockWedges, Rect, SQUARE, ScanCounts, ScanInput, ScanWedge, SquarePairs, SquareScratch,
    WedgeLanes, square_pairs,
};
use crate::accel::centred::CentredEdge;
use crate::accel::centred_wedges::wedges;
use crate::accel::planar::{PlanarEdge, PlanarTest, RectMap};
use crate::accel::shared_sets::{SampleSet, SetForm, SharedSets};
use crate::stages::constant::{eye_constant, integration_constants};
use crate::stages::counters::{self, BitSliced, Packed, WIDTHS, width_for};
use crate::stages::coverage::{EdgeTest, RelativePolygon, RelativeSamples};
use crate::stages::discrete::{CoveredSamples, DiscreteTables, LineMasks};
use crate::stages::edges::{SceneEdge, Sides, Silhouettes, scene_edges, silhouettes};
use crate::stages::light_shape::LightShape;
use crate::stages::receiver_constant::receiver_constants;
use crate::stages::wedges::{FOLD_SLACK, Pair};

mod frame;
mod output;
mod pixel;
mod rays;

pub use rays::RayChoice;
use rays::{Job, Plan, RayPath};

/// What per-sample visibility an estimate returns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PerSampleOutput {
    /// None (saves memory on large images).
    None,
    /// One bit per sample, set when the sample is visible (depth complexity 0 and above the
    /// receiver's horizon): what the conformance suite compares with the reference.
    Bits,
    /// The depth complexity of each sample (`u32::MAX` for samples below the horizon), in
    /// opacity units with semi-opaque occluders.
    Counters,
}

struct Prepared {
    scene: SceneRef,
    light: Light,
    shape: LightShape,
    edges: Vec<SceneEdge>,
    silhouettes: Vec<u32>,
    units: u32,
    /// How this light's depth complexities count the faces, and the triangles tested against
    /// each sample explicitly ([`Sides`]).
    sides: Sides,
    offset: RayOffset,
    extent: f64,
    tables: Option<DiscreteTables>,
    /// The planar light's convex polygon around its centre, for [`EdgeTest::may_cover`].
    polygon: Option<Vec<Vec3>>,
    /// The silhouette edges around the light centre (same indices as `silhouettes`).
    centred_edges: Vec<CentredEdge>,
    /// What the wedge scan's box tests read of every silhouette edge's wedge (same indices).
    scan: Vec<ScanWedge>,
    /// What the view samples' pass reads of the same wedges.
    scan_lanes: Vec<WedgeLanes>,
    /// The light-plane form of the silhouette edges, for planar lights.
    planar: Option<PlanarLight>,
    /// A constant rectangle light's half sides on the light plane's axes: its samples' plane
    /// coordinates come straight from the unit samples.
    rect: Option<RectMap>,
    /// The shadow-ray side of a hybrid ([`rays`]); `None` for DCS alone.
    rays: Option<RayPath>,
}

/// A planar light's frame, for the light-plane test ([`crate::accel::planar`]).
struct PlanarLight {
    u: Vec3,
    v: Vec3,
    normal: Vec3,
}

/// Depth complexity sampling: a configuration ([`ShadowTechnique::prepare`] or
/// [`Dcs::prepare_dcs`] gives the [`PreparedDcs`] that estimates).
#[derive(Clone)]
pub struct Dcs {
    name: String,
    sampler: LightSampler,
    detection: Silhouettes,
    covered: CoveredSamples,
    output: PerSampleOutput,
    forced_bits: Option<u32>,
    /// Whether pixels of one shared sample set share its set-up ([`crate::accel::shared_sets`]);
    /// off only in tests, which check the shared set-up against each pixel's own.
    share_sets: bool,
    /// Frames where rays are predicted to cost less go to these shadow rays on the same samples
    /// ([`rays`]); `None`: DCS everywhere.
    rays: Option<(RayChoice, Arc<dyn ShadowRays>)>,
}

/// DCS prepared for one scene and light: its edges, silhouettes, wedges and tables.
pub struct PreparedDcs {
    config: Dcs,
    /// Shared between configurations that differ only in their samples
    /// ([`Dcs::prepare_sharing`]).
    p: Arc<Prepared>,
    stats: Stats,
}

impl std::fmt::Debug for PreparedDcs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PreparedDcs")
            .field("config", &self.config)
            .finish_non_exhaustive()
    }
}

impl std::fmt::Debug for Dcs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Dcs")
            .field("name", &self.name)
            .field("samples", &self.sampler.count())
            .field("detection", &self.detection)
            .field("covered", &self.covered)
            .finish()
    }
}

/// Per-frame data shared by every pixel.
struct Frame<'a> {
    origins: Vec<Vec3>,
    /// `origins` relative to the light centre ([`crate::accel::centred`]).
    centred: Vec<Vec3>,
    horizon: Vec<Horizon>,
    active: Vec<bool>,
    constants: Vec<i64>,
    /// The pixels that take the light-plane form of the covered-sample test (planar lights,
    /// exact covered samples, a receiver clear of the light's plane); empty without.
    planar_ok: Vec<bool>,
    bits: u32,
    view: &'a ViewSamples,
}

/// Candidates up to which an edge's samples are tested one by one rather than a whole word
/// at a time.
const FEW_CANDIDATES: u32 = 12;

/// Fewest wedge pairs for which a pixel builds its angular index: below, the exact test on
/// every sample costs less than the index.
const INDEX_MIN_PAIRS: usize = 6;

/// Receivers closer to the light's plane than this share of their distance to the light centre
/// take the 3D form of the covered-sample test instead of the light-plane form (whose sector
/// normals shrink with that height).
const NEAR_PLANE: f32 = 1e-2;

/// Relative error bound of the per-sample horizon test in `f32`, against
/// `|n| (|c| + r + |p|)` (normal, light centre and radius, receiver): a light whose every point
/// lies above both tangent planes by more than this has every sample above them.
const HORIZON_BOUND: f64 = 1e-5;

/// Where the light lies relative to a receiver's tangent plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Horizon {
    /// The whole light above both planes, by more than the per-sample test's rounding.
    Above,
    /// The whole light above both planes, but within rounding of one: every sample above the
    /// planes in exact arithmetic, tested one by one as the reference does.
    Grazing,
    Below,
    Mixed,
}

/// The class of a pixel from its samples' visibilities, taken one by one, with the visible
/// samples marked on the way.
struct ClassTally {
    lit: bool,
    dark: bool,
}

impl ClassTally {
    fn new() -> Self {
        Self {
            lit: true,
            dark: true,
        }
    }

    /// Sample `k` has visibility `v`; a visible one (1) is set in `visible`.
    #[inline]
    fn add(&mut self, k: usize, v: f32, visible: &mut [u64]) {
        self.lit &= v == 1.0;
        self.dark &= v == 0.0;
        if v == 1.0 {
            visible[k / 64] |= 1 << (k % 64);
        }
    }

    fn class(&self) -> PixelClass {
        if self.lit {
            PixelClass::Lit
        } else if self.dark {
            PixelClass::Umbra
        } else {
            PixelClass::Penumbra
        }
    }
}

/// What a pixel's pass keeps from its start to its end.
struct PixelStart {
    /// The integration constant (0 where it came out negative).
    d0: u64,
    /// Whether its samples get the angular index.
    indexed: bool,
    /// Whether it takes the light-plane test.
    planar: bool,
    /// Whether its samples are set up (it needs per-sample work).
    ready: bool,
}

/// What the batched covered-sample step needs of the refined tables of section 7.3 for one
/// pixel.
struct Refined<'a> {
    tables: &'a DiscreteTables,
    edges: &'a [CentredEdge],
    /// The view sample relative to the light centre.
    p: DVec3,
    pixel: UVec2,
}

/// A pixel's per-sample updates of Algorithm 1, collected before the counters run (outer
/// wedges first, section 4.4): per pair that covers any sample, the covered samples (a mask of
/// the pixel's sample words) and the pair's weight `k_e(p)`. Every covered-sample test (exact,
/// table, light-plane, with or without the angular index) ends in [`Updates::push`], the one
/// place an update is recorded.
#[derive(Debug, Default)]
pub(super) struct Updates {
    /// The covered-sample masks, one after the other.
    pub(super) masks: Vec<u64>,
    /// The weight of each mask.
    pub(super) weights: Vec<i64>,
}

impl Updates {
    /// Records that the samples of `mask` gain `k` layers (counted in `covered_updates`).
    #[inline(always)]
    pub(super) fn push(&mut self, mask: &[u64], k: i64, covered_updates: &mut u64) {
        self.masks.extend_from_slice(mask);
        self.weights.push(k);
        *covered_updates += 1;
    }

    /// Forgets every update (a new pixel).
    pub(super) fn clear(&mut self) {
        self.masks.clear();
        self.weights.clear();
    }
}

/// Per-thread buffers.
#[derive(Default)]
struct Scratch {
    units: Vec<Vec2>,
    samples: Vec<LightSample>,
    /// The samples' radiances (textured lights: they weigh eq. 2).
    radiances: Vec<Vec3>,
    relative: RelativeSamples,
    /// The samples' positions, light-plane coordinates and angular index: the pixel's own, or
    /// a shared set's lent by `shared`.
    set: SampleSet,
    /// The shared sample sets met so far (correlated and interleaved sampling).
    shared: SharedSets,
    polygon: RelativePolygon,
    above: Vec<u64>,
    mask: Vec<u64>,
    /// Tests waiting for their candidates, and their weights.
    batch: Vec<EdgeTest>,
    batch_k: Vec<i64>,
    /// The silhouette index of each waiting test's edge (for the refined line table).
    batch_edge: Vec<u32>,
    batch_candidates: Vec<u64>,
    /// Per waiting test, the candidates in its sector's inner buckets (refined tables only).
    batch_inner: Vec<u64>,
    undecided: Vec<u64>,
    /// The pixel's per-sample updates, in pair order ([`Updates`]).
    updates: Updates,
    packed: Packed,
    sliced: BitSliced,
    plain: Vec<i64>,
    /// Whether the caller reads each sample's visibility and depth complexity (`vis`,
    /// `depth`); without, only `visible` is set.
    want_values: bool,
    /// The samples visible from the pixel (depth complexity 0, above the horizon), one bit
    /// each.
    visible: Vec<u64>,
    depth: Vec<u64>,
    vis: Vec<f32>,
    /// The shadow rays' buffers, for traced pixels (made on the first one).
    rays: Option<RayScratch>,
    /// The explicit triangles' buffers ([`Sides::explicit_list`]): the pixel's unit samples,
    /// light samples and one mask per triangle.
    explicit_units: Vec<Vec2>,
    explicit_samples: Vec<LightSample>,
    explicit_masks: Vec<u64>,
}

impl Scratch {
    /// Empties the per-pixel buffers for a pixel of `n` samples. A pixel facing away from the
    /// whole light (`below`) is counted and gets its values at once (every sample hidden, below
    /// the horizon): returns false for it.
    fn begin_pixel(&mut self, n: usize, below: bool, counts: &mut Counts) -> bool {
        self.vis.clear();
        self.depth.clear();
        self.samples.clear();
        self.radiances.clear();
        self.visible.clear();
        self.visible.resize(n.div_ceil(64), 0);
        self.updates.clear();
        if below {
            counts.facing_away += 1;
            if self.want_values {
                self.vis.resize(n, 0.0);
                self.depth.resize(n, u64::MAX);
            }
        }
        !below
    }
}

/// Per-thread buffers of a square: its pairs, the scan's buffers, and the pixels' scratch (kept
/// from square to square, so that they are allocated once per thread).
#[derive(Default)]
struct SquareBuffers {
    pairs: SquarePairs,
    scan: SquareScratch,
    scratch: Scratch,
}

/// Work counters of a row of pixels.
#[derive(Default, Clone, Copy)]
struct Counts {
    facing_away: u64,
    constant_only: u64,
    per_sample: u64,
    edge_tests: u64,
    covered_updates: u64,
    escalations: u64,
    plain_fallback: u64,
    negative: u64,
    ties: u64,
    scan: ScanCounts,
    pairs: u64,
    off_light: u64,
    /// Pixels whose samples came from a shared set, and the shared sets built.
    shared_set_pixels: u64,
    shared_sets_built: u64,
    sector_empty: u64,
    line_cells: u64,
    /// Squares and pixels traced with shadow rays, and the rays.
    traced_squares: u64,
    traced_pixels: u64,
    rays: u64,
}

impl Counts {
    fn add(&mut self, o: &Counts) {
        self.facing_away += o.facing_away;
        self.constant_only += o.constant_only;
        self.per_sample += o.per_sample;
        self.edge_tests += o.edge_tests;
        self.covered_updates += o.covered_updates;
        self.escalations += o.escalations;
        self.plain_fallback += o.plain_fallback;
        self.negative += o.negative;
        self.ties += o.ties;
        self.scan.add(&o.scan);
        self.pairs += o.pairs;
        self.off_light += o.off_light;
        self.shared_set_pixels += o.shared_set_pixels;
        self.shared_sets_built += o.shared_sets_built;
        self.sector_empty += o.sector_empty;
        self.line_cells += o.line_cells;
        self.traced_squares += o.traced_squares;
        self.traced_pixels += o.traced_pixels;
        self.rays += o.rays;
    }
}

impl Dcs {
    /// DCS with `samples` light samples per pixel drawn with `strategy` and `seed`, accurate
    /// silhouettes, exact covered samples and per-sample bits in the output.
    ///
    /// # Errors
    /// The sampler's error for a bad count or tile.
    pub fn new(
        samples: u32,
        strategy: SamplingStrategy,
        seed: u64,
    ) -> Result<Self, shadow_core::sampling::SamplingError> {
        Ok(Self::with_sampler(LightSampler::new(
            strategy, samples, seed,
        )?))
    }

    /// DCS on the samples of `sampler` (another technique's, so that both evaluate the same
    /// samples), with the defaults of [`Dcs::new`].
    pub fn with_sampler(sampler: LightSampler) -> Self {
        Self {
            name: format!("dcs-{}", sampler.count()),
            sampler,
            detection: Silhouettes::Accurate,
            covered: CoveredSamples::Exact,
            output: PerSampleOutput::Bits,
            forced_bits: None,
            share_sets: true,
            rays: None,
        }
    }

    /// Silhouette detection (section 4.1, Fig. 4).
    #[must_use]
    pub fn with_silhouettes(mut self, s: Silhouettes) -> Self {
        self.detection = s;
        self
    }

    /// How covered samples are found (section 7.3).
    ///
    /// # Errors
    /// [`TechniqueError::InvalidInput`] for the tables of section 7.3 with per-pixel sample sets
    /// (stratified or decorrelated sampling): the tables need a finite number of sets.
    pub fn with_covered_samples(mut self, c: CoveredSamples) -> Result<Self, TechniqueError> {
        let per_pixel = !matches!(
            self.sampler.strategy(),
            SamplingStrategy::Correlated | SamplingStrategy::Interleaved { .. }
        );
        if c != CoveredSamples::Exact && per_pixel {
            return Err(TechniqueError::InvalidInput(format!(
                "{}: the covered-sample tables of section 7.3 need a finite number of sample \
                 sets (correlated or interleaved sampling), not {:?}",
                self.name,
                self.sampler.strategy()
            )));
        }
        self.covered = c;
        Ok(self)
    }

    /// What per-sample visibility the estimate carries.
    #[must_use]
    pub fn with_per_sample(mut self, o: PerSampleOutput) -> Self {
        self.output = o;
        self
    }

    /// Forces the first counter width tried (8, 16 or 32 bits) instead of the one chosen from
    /// the largest integration constant; narrower than needed, every overflow is caught and the
    /// pixel redone wider (tests use this to exercise the escalation).
    #[must_use]
    pub fn with_counter_bits(mut self, bits: u32) -> Self {
        self.forced_bits = Some(bits);
        self
    }

    /// Traces with `tracer`'s shadow rays, on the same samples, the frames where `choice`
    /// predicts rays cost less than DCS ([`RayChoice`]): the same answers (up to numerical
    /// ties) for less work on dense meshes under large lights. Opaque scenes only (on
    /// semi-opaque ones the saturating opacity sum of section 3 is not what rays compute), and
    /// never when depth complexities are asked for. `shadow-ref`'s `BvhRays` is the tracer the
    /// `dcs-*-hybrid` presets hand in; this crate does not depend on it.
    #[must_use]
    pub fn with_rays(mut self, choice: RayChoice, tracer: Arc<dyn ShadowRays>) -> Self {
        self.rays = Some((choice, tracer));
        self
    }

    /// Renames the instance (presets).
    #[must_use]
    pub fn named(mut self, name: &str) -> Self {
        self.name = name.into();
        self
    }
}

/// The samples of `positions` above the tangent plane both from the surface point and from the
/// offset `origin` (the reference's rule), one bit each, into `above`.
fn horizon_mask_into(positions: &[Vec3], s: &ViewSample, origin: Vec3, above: &mut Vec<u64>) {
    above.clear();
    above.resize(positions.len().div_ceil(64), 0);
    let nrm = s.geometric_normal;
    for (k, y) in positions.iter().enumerate() {
        if (*y - s.position).dot(nrm) > 0.0 && (*y - origin).dot(nrm) > 0.0 {
            above[k / 64] |= 1 << (k % 64);
        }
    }
}

/// Sets the first `n` bits of `words` (the rest stay as they are).
fn fill_first(words: &mut [u64], n: usize) {
    for (k, w) in words.iter_mut().enumerate() {
        let left = n.saturating_sub(k * 64);
        *w = if left >= 64 {
            u64::MAX
        } else {
            (1 << left) - 1
        };
    }
}

impl ShadowTechnique for Dcs {
    fn name(&self) -> &str {
        &self.name
    }

    fn capabilities(&self) -> Capabilities {
        // The section 7.3 tables are defined on a planar light; the exact test also takes
        // sphere lights (their silhouette disk).
        let mut lights = vec![LightKind::Rectangle, LightKind::Disk, LightKind::Polygon];
        if self.covered == CoveredSamples::Exact {
            lights.push(LightKind::Sphere);
        }
        Capabilities {
            lights,
            semi_opaque: true,
            textured_lights: true,
            needs_closed_meshes: false,
            sample_based: true,
            processor: Processor::Cpu,
            // The integration constant is counted over shadow-volume quads from the eye
            // (section 4.1), or per receiver along its segment to the light centre.
            needs_camera: false,
        }
    }

    fn parameters(&self) -> serde_json::Value {
        json!({
            "samples": self.sampler.count(),
            "strategy": format!("{:?}", self.sampler.strategy()),
            "seed": self.sampler.seed(),
            "silhouettes": format!("{:?}", self.detection),
            "covered_samples": format!("{:?}", self.covered),
            // The hybrid's costs (in rays), so that a report says what the choice weighed.
            "rays": self.rays.as_ref().map(|(c, _)| json!({
                "rays_per_candidate": c.rays_per_candidate,
                "per_further_word": c.per_further_word,
                "rays_per_shadow_volume": c.rays_per_shadow_volume,
                "rays_per_bvh_triangle": c.rays_per_bvh_triangle,
            })),
        })
    }

    fn light_sampler(&self) -> Option<&LightSampler> {
        Some(&self.sampler)
    }

    fn prepare(
        &self,
        scene: SceneRef,
        light: Light,
    ) -> Result<Box<dyn PreparedShadows>, TechniqueError> {
        Ok(Box::new(self.prepare_dcs(scene, light)?))
    }
}

impl PreparedShadows for PreparedDcs {
    fn name(&self) -> &str {
        &self.config.name
    }

    fn preparation(&self) -> &Stats {
        &self.stats
    }

    fn light(&self) -> &dyn AreaLight {
        self.p.light.as_ref()
    }

    /// A caller's points are estimated in a spatial order, so that each square of the wedge
    /// scan holds receivers close in space ([`in_spatial_order`]); their direct light too, in
    /// the same order, when asked for.
    fn pass(&self, view: &ViewSamples, outputs: Outputs) -> Result<Estimate, TechniqueError> {
        let output = match self.config.output {
            PerSampleOutput::None if outputs.per_sample => PerSampleOutput::Bits,
            o => o,
        };
        in_spatial_order(view, |v| {
            let mut est = self.config.run(&self.p, v, output)?;
            if outputs.direct && view.raster_view().is_none() {
                let t0 = std::time::Instant::now();
                est.direct = Some(self.config.direct(&self.p, v)?);
                est.stats
                    .add_time(CorePhase::Direct, t0.elapsed().as_secs_f64());
            }
            Ok(est)
        })
    }

    fn direct_light(&self, view: &ViewSamples, _: &Estimate) -> Result<Vec<Vec3>, TechniqueError> {
        self.direct_illumination(view)
    }
}

impl PreparedDcs {
    /// The light samples this configuration evaluates.
    pub fn sampler(&self) -> &LightSampler {
        &self.config.sampler
    }

    /// Direct illumination of every view sample by DCS eq. 6: the light samples' contributions
    /// weighted by their binary visibility (saturated opacity sums with semi-opaque occluders).
    ///
    /// # Errors
    /// `Unsupported` for orthographic views.
    pub fn direct_illumination(&self, view: &ViewSamples) -> Result<Vec<Vec3>, TechniqueError> {
        self.config.direct(&self.p, view)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::statistics::DcsCounter;

    /// Every square's values land on their own pixels, for an image whose sides are not whole
    /// squares or blocks, one value and three values per pixel, and an empty output is left
    /// alone.
    #[test]
    fn squares_scatter_onto_their_pixels() {
        let (w, h) = (150u32, 37u32);
        let squares: Vec<Rect> = crate::accel::bins::blocks(w, h)
            .into_iter()
            .flat_map(|(_, s)| s)
            .collect();
        for per_pixel in [1usize, 3] {
            // Each square holds, for each of its pixels, the pixel's index and its slot.
            let values: Vec<(Rect, Vec<usize>)> = squares
                .iter()
                .map(|r| {
                    let v = r
                        .pixels(w)
                        .flat_map(|i| (0..per_pixel).map(move |k| i * per_pixel + k))
                        .collect();
                    (*r, v)
                })
                .collect();
            let mut out = vec![usize::MAX; (w * h) as usize * per_pixel];
            output::scatter_squares(&mut out, per_pixel, w as usize, &values, |v| v);
            assert!(out.iter().enumerate().all(|(i, v)| *v == i));
        }
        let mut none: Vec<u64> = Vec::new();
        output::scatter_squares(&mut none, 1, w as usize, &[(squares[0], vec![7u64])], |v| v);
        assert!(none.is_empty());
    }

    /// Pixels of a shared sample set (correlated and interleaved sampling) that take its
    /// set-up from the set built once get exactly the depth complexities of pixels that set
    /// their samples up themselves, in every form of the set-up: the light-plane test on a
    /// rectangle light (`bunny`, `contact`) and on a disk (`spot-self-shadow`), the 3D test
    /// of the refined tables, and pixels whose horizon cuts the light (`large-light-close`).
    /// Each thread builds each set it meets once per form.
    #[test]
    fn shared_sample_sets_give_each_pixels_own_depth_complexities() {
        let depth = |e: &Estimate| match e.visibility.per_sample() {
            Some(PerSampleVisibility::Counters { counts, .. }) => counts.clone(),
            _ => panic!("counters requested"),
        };
        let mut lent = 0;
        for name in ["bunny", "contact", "spot-self-shadow", "large-light-close"] {
            let setup = shadow_scenes::builtin(name).unwrap();
            let view =
                ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 64, 48)
                    .unwrap();
            for (strategy, covered) in [
                (
                    SamplingStrategy::Interleaved { tile: 4 },
                    CoveredSamples::Exact,
                ),
                (
                    SamplingStrategy::Interleaved { tile: 4 },
                    CoveredSamples::Refined,
                ),
                (SamplingStrategy::Correlated, CoveredSamples::Exact),
            ] {
                let run = |share: bool| {
                    let mut d = Dcs::new(64, strategy, 7)
                        .unwrap()
                        .with_covered_samples(covered)
                        .unwrap()
                        .with_per_sample(PerSampleOutput::Counters);
                    d.share_sets = share;
                    let d_prepared = d
                        .prepare(setup.scene.clone(), setup.lights[0].clone())
                        .unwrap();
                    d_prepared.estimate(&view, Outputs::VISIBILITY).unwrap()
                };
                let (shared, own) = (run(true), run(false));
                let case = format!("{name} {strategy:?} {covered:?}");
                assert_eq!(depth(&shared), depth(&own), "{case}");
                let (pixels, built) = (
                    shared
                        .stats
                        .counter(DcsCounter::PixelsSharedSampleSets)
                        .unwrap(),
                    shared
                        .stats
                        .counter(DcsCounter::SharedSampleSetsBuilt)
                        .unwrap(),
                );
                assert_eq!(
                    own.stats
                        .counter(DcsCounter::PixelsSharedSampleSets)
                        .unwrap(),
                    0,
                    "{case}"
                );
                assert_eq!(
                    pixels,
                    shared.stats.counter(DcsCounter::PixelsPerSample).unwrap(),
                    "{case}"
                );
                let sets = match strategy {
                    SamplingStrategy::Interleaved { tile } => u64::from(tile * tile),
                    _ => 1,
                };
                let threads = rayon::current_num_threads() as u64;
                assert!(built <= sets * 3 * threads, "{case}: {built} sets built");
                assert!(pixels == 0 || built > 0, "{case}");
                lent += pixels;
            }
        }
        assert!(lent > 1000, "{lent} pixels took a shared set");
    }
}
