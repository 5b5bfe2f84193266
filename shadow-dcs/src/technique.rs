//! The [`Dcs`] technique: depth complexity sampling (Forest, Barthe and Paulin 2008) on the CPU.
//!
//! Per frame (Algorithm 2 for one light):
//! 1. silhouette edges of the scene for the light (prepared once per scene and light,
//!    [`crate::edges`], section 4.1);
//! 2. the integration constant `D(p, c)` of every view sample by the shadow-volume step
//!    ([`crate::constant`], section 4.1), and the counter width from its maximum (section 5.3);
//! 3. square by square (16 x 16 pixels), the wedges' view samples and each one's weight
//!    ([`crate::wedges`] and the box hierarchy of `bins`, section 4.2), with each pair's
//!    light-plane test set up on the way (planar lights, `planar`);
//! 4. per view sample: its light samples (the shared [`LightSampler`], section 5), the samples
//!    each wedge edge covers (the light-plane test or [`crate::coverage`]'s 3D one, exact; or
//!    the discrete tables of section 7.3), the packed counters updated outer wedges first
//!    ([`crate::counters`], sections 4.3-4.4),
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

use std::sync::Mutex;

use glam::{DVec3, UVec2, Vec2, Vec3};
use rayon::prelude::*;
use serde_json::json;
use shadow_core::direct::pixel_direct;
use shadow_core::light::{LightGeometry, LightKind, LightSample};
use shadow_core::offset::RayOffset;
use shadow_core::prelude::*;
use shadow_core::technique::{Capabilities, Processor, SceneRef};
use shadow_core::view_samples::ViewSample;
use shadow_core::visibility::{PerSampleVisibility, PixelClass};

use crate::angular::{BATCH, QuadRanges};
use crate::bins::{
    BlockWedges, Rect, SQUARE, ScanCounts, ScanInput, ScanWedge, SquarePairs, SquareScratch,
    WedgeLanes, square_pairs,
};
use crate::centred::CentredEdge;
use crate::constant::{eye_constant, integration_constants};
use crate::counters::{self, BitSliced, Packed, WIDTHS, width_for};
use crate::coverage::{EdgeTest, RelativePolygon, RelativeSamples};
use crate::discrete::{CoveredSamples, DiscreteTables, LineMasks};
use crate::edges::{SceneEdge, Silhouettes, scene_edges, silhouettes};
use crate::light_shape::LightShape;
use crate::planar::{PlanarEdge, PlanarTest, RectMap};
use crate::shared_sets::{SampleSet, SetForm, SharedSets};
use crate::wedges::{FOLD_SLACK, Pair, wedges};

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
}

/// A planar light's frame, for the light-plane test ([`crate::planar`]).
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
    /// Whether pixels of one shared sample set share its set-up ([`crate::shared_sets`]);
    /// off only in tests, which check the shared set-up against each pixel's own.
    share_sets: bool,
}

/// DCS prepared for one scene and light: its edges, silhouettes, wedges and tables.
pub struct PreparedDcs {
    config: Dcs,
    p: Prepared,
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
    /// `origins` relative to the light centre ([`crate::centred`]).
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
    masks: Vec<u64>,
    weights: Vec<i64>,
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
        Ok(Self {
            name: format!("dcs-{samples}"),
            sampler: LightSampler::new(strategy, samples, seed)?,
            detection: Silhouettes::Accurate,
            covered: CoveredSamples::Exact,
            output: PerSampleOutput::Bits,
            forced_bits: None,
            share_sets: true,
        })
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

    /// Renames the instance (presets).
    #[must_use]
    pub fn named(mut self, name: &str) -> Self {
        self.name = name.into();
        self
    }

    /// Everything per frame before the per-pixel pass.
    fn frame<'a>(
        &self,
        p: &Prepared,
        view: &'a ViewSamples,
        stats: &mut Stats,
    ) -> Result<Frame<'a>, TechniqueError> {
        let eye = view.eye().ok_or_else(|| {
            TechniqueError::unsupported(
                &self.name,
                UnsupportedReason::View(
                    "orthographic views: the shadow-volume step counts quads from an eye point"
                        .into(),
                ),
            )
        })?;
        let n = view.len();
        let (origins, horizon): (Vec<Vec3>, Vec<Horizon>) = (0..n)
            .into_par_iter()
            .map(|i| match view.get(i) {
                Some(s) => {
                    let o = p.offset.offset(s.position, s.geometric_normal);
                    (o, Self::horizon(&p.shape, &s, o))
                }
                None => (Vec3::ZERO, Horizon::Below),
            })
            .unzip();
        let active: Vec<bool> = horizon.par_iter().map(|h| *h != Horizon::Below).collect();
        let c = p.shape.center;
        let cd = c.as_dvec3();
        let centred: Vec<Vec3> = origins
            .par_iter()
            .map(|o| (o.as_dvec3() - cd).as_vec3())
            .collect();
        let (constants, quads) = stats.time("shadow-volumes", || {
            let eye_c = eye_constant(p.scene.as_ref(), p.units, eye, c);
            integration_constants(
                &p.edges,
                &p.silhouettes,
                c,
                eye,
                eye_c,
                view.raster_view(),
                &origins,
                &centred,
                &active,
            )
        });
        stats.add("shadow-volume-quads", quads);
        let max_constant = constants.par_iter().copied().max().unwrap_or(0).max(0) as u64;
        let bits = self.forced_bits.unwrap_or_else(|| width_for(max_constant));
        stats.gauge_max("max-integration-constant", max_constant);
        stats.gauge_max("counter-bits", bits as u64);
        stats.add("wedges", p.scan.len() as u64);
        let planar_ok = match (&p.planar, self.covered) {
            (Some(pl), CoveredSamples::Exact) => centred
                .par_iter()
                .zip(&active)
                .map(|(x, a)| *a && x.dot(pl.normal).abs() > NEAR_PLANE * x.length())
                .collect(),
            _ => Vec::new(),
        };
        Ok(Frame {
            origins,
            centred,
            horizon,
            active,
            constants,
            planar_ok,
            bits,
            view,
        })
    }

    /// Runs the per-pixel pass over the square `rect`: its wedge pairs (from the wedges its box
    /// keeps, `wedges`), then every view sample, handed to `visit` with its class and the
    /// scratch holding its visible samples and, with `values`, its samples' visibilities and
    /// depth complexities.
    #[allow(clippy::too_many_arguments)]
    fn run_square(
        &self,
        p: &Prepared,
        f: &Frame,
        wedges: &[u32],
        rect: Rect,
        values: bool,
        counts: &mut Counts,
        buffers: &mut SquareBuffers,
        mut visit: impl FnMut(usize, &ViewSample, PixelClass, &Scratch),
    ) {
        let view = f.view;
        let SquareBuffers {
            pairs,
            scan,
            scratch,
        } = buffers;
        scratch.want_values = values;
        square_pairs(&Self::scan_input(p, f), wedges, rect, pairs, scan);
        counts.scan.add(&pairs.counts);
        counts.pairs += pairs.len() as u64;
        let w = view.width() as usize;
        for (j, x, y) in pairs.pixels() {
            let i = y as usize * w + x as usize;
            let Some(s) = view.get_at(x, y) else { continue };
            let (entries, tests) = pairs.of(j);
            let class = self.pixel(p, f, i, &s, entries, tests, scratch, counts);
            visit(i, &s, class, scratch);
        }
    }

    /// What the wedge scan reads of a frame.
    fn scan_input<'a>(p: &'a Prepared, f: &'a Frame) -> ScanInput<'a> {
        ScanInput {
            edges: &p.edges,
            wedges: &p.scan,
            lanes: &p.scan_lanes,
            c: p.shape.center.as_dvec3(),
            width: f.view.width(),
            origins: &f.origins,
            centred: &f.centred,
            active: &f.active,
            slack: (FOLD_SLACK * p.extent) as f32,
            planar: (!f.planar_ok.is_empty()).then_some((&p.centred_edges[..], &f.planar_ok[..])),
        }
    }

    /// Runs `work` on every square of the view in parallel, with the wedges its box keeps (the
    /// box hierarchy of [`crate::bins`]: blocks, then their squares). Returns each square's
    /// result and the number of (block, wedge) pairs kept.
    fn squares<T: Send>(
        &self,
        p: &Prepared,
        f: &Frame,
        work: impl Fn(Rect, &[u32], &mut SquareBuffers) -> T + Sync + Send,
    ) -> (Vec<(Rect, T)>, u64) {
        let view = f.view;
        let input = Self::scan_input(p, f);
        let blocks = crate::bins::blocks(view.width(), view.height());
        let levels = BlockWedges::new(&input, &blocks);
        // Every block's square lists first, then all squares of the view as one parallel
        // loop: a block boundary is no barrier, so a thread that runs out of work steals any
        // square left, not only those of the block it is in.
        let lists: Vec<(Vec<Vec<u32>>, usize)> = blocks
            .par_iter()
            .enumerate()
            .map(|(bi, (_, squares))| levels.square_lists(&input, bi, squares))
            .collect();
        let kept = lists.iter().map(|(_, k)| *k as u64).sum();
        let jobs: Vec<(Rect, &[u32])> = blocks
            .iter()
            .zip(&lists)
            .flat_map(|((_, squares), (l, _))| {
                squares.iter().copied().zip(l.iter().map(Vec::as_slice))
            })
            .collect();
        // One square per job: a square's cost ranges from nothing to milliseconds (the
        // penumbra gathers in a few of them), and rayon's own split of the list left one
        // thread on a run of 128 costly squares while the other idled (on `bunny`, a thread
        // busy 90 ms of the pass's 164 ms). The buffers go back to a pool after each square,
        // since a job per square would otherwise start from empty buffers every time.
        let pool = Mutex::new(Vec::<SquareBuffers>::new());
        let out = jobs
            .par_iter()
            .with_max_len(1)
            .map(|&(r, list)| {
                let mut buffers = pool
                    .lock()
                    .ok()
                    .and_then(|mut p| p.pop())
                    .unwrap_or_default();
                let done = work(r, list, &mut buffers);
                if let Ok(mut p) = pool.lock() {
                    p.push(buffers);
                }
                (r, done)
            })
            .collect();
        (out, kept)
    }

    /// The horizon class of a receiver: the reference's rule, a sample counts when it lies
    /// above the tangent plane both from the surface point and from the offset origin.
    fn horizon(shape: &LightShape, s: &ViewSample, origin: Vec3) -> Horizon {
        let n = s.geometric_normal.as_dvec3();
        let [(lo1, hi1), (lo2, hi2)] =
            shape.ranges(n, -n.dot(s.position.as_dvec3()), -n.dot(origin.as_dvec3()));
        let reach = shape.center.as_dvec3().length() + f64::from(shape.radius);
        let bound = HORIZON_BOUND
            * n.length()
            * (reach
                + s.position
                    .as_dvec3()
                    .length()
                    .max(origin.as_dvec3().length()));
        if lo1 > bound && lo2 > bound {
            Horizon::Above
        } else if lo1 > 0.0 && lo2 > 0.0 {
            Horizon::Grazing
        } else if !(hi1 > 0.0 && hi2 > 0.0) {
            Horizon::Below
        } else {
            Horizon::Mixed
        }
    }

    /// Per-sample visibility of pixel `i` into `scratch.visible` (with `scratch.want_values`,
    /// also `scratch.vis` and depth complexities into `scratch.depth`), and its samples'
    /// radiances into `scratch.radiances` when the light is textured (they weigh eq. 2; none for
    /// a pixel whose integration constant alone puts it in the umbra; the whole light samples
    /// into `scratch.samples` only where the samples were set up), from its
    /// wedge pairs `entries` (and, for the light-plane test, their `tests`). Returns the class.
    #[allow(clippy::too_many_arguments)]
    fn pixel(
        &self,
        p: &Prepared,
        f: &Frame,
        i: usize,
        s: &ViewSample,
        entries: &[Pair],
        tests: &[PlanarTest],
        scratch: &mut Scratch,
        counts: &mut Counts,
    ) -> PixelClass {
        // The refined tables of section 7.3 settle what they can of the index's candidates.
        let pc = f.origins[i].as_dvec3() - p.shape.center.as_dvec3();
        let refined = match (self.covered, &p.tables) {
            (CoveredSamples::Refined, Some(t)) => Some(Refined {
                tables: t,
                edges: &p.centred_edges,
                p: pc,
                pixel: s.pixel,
            }),
            _ => None,
        };
        let pairs = entries.len() + tests.len();
        let indexed = p.shape.plane.is_some()
            && (self.covered == CoveredSamples::Exact || refined.is_some())
            && pairs >= INDEX_MIN_PAIRS;
        let Some(mut start) = self.pixel_start(p, f, i, s, indexed, scratch, counts) else {
            return PixelClass::Skipped;
        };
        if let (Some(poly), false) = (&p.polygon, pairs == 0) {
            scratch.polygon.set(poly, f.centred[i]);
        }
        // Each pair's covered-sample test. The light-overlap test decides whether the pixel
        // needs per-sample work at all: its samples are set up at the first pair that may cover
        // the light (at once when the horizon cuts the light). With the angular index the later
        // pairs go straight to their candidates, which drop off-light pairs more cheaply.
        // The scan gives the light-plane tests to exactly the pixels marked for them.
        debug_assert!(start.planar || tests.is_empty());
        debug_assert!(!start.planar || entries.is_empty());
        if !tests.is_empty() {
            self.ensure_ready(p, f, i, s, &mut start, scratch, counts);
            Self::planar_pairs(tests, indexed, scratch, counts);
        }
        for pair in entries {
            let Some(test) = p.centred_edges[pair.edge as usize].test(pc) else {
                counts.ties += 1;
                continue;
            };
            if (!start.ready || !indexed)
                && p.polygon.is_some()
                && !test.may_cover(&scratch.polygon)
            {
                counts.off_light += 1;
                continue;
            }
            self.ensure_ready(p, f, i, s, &mut start, scratch, counts);
            if indexed {
                // Candidates a batch at a time (their sector arithmetic vectorises).
                scratch.batch.push(test);
                scratch.batch_k.push(pair.k as i64);
                if refined.is_some() {
                    scratch.batch_edge.push(pair.edge);
                }
                if scratch.batch.len() == BATCH {
                    Self::indexed_updates(scratch, counts, refined.as_ref());
                }
            } else {
                self.covered_update(
                    p,
                    s,
                    pc + p.shape.center.as_dvec3(),
                    pair,
                    &test,
                    scratch,
                    counts,
                );
            }
        }
        if !scratch.batch.is_empty() {
            Self::indexed_updates(scratch, counts, refined.as_ref());
        }
        self.pixel_finish(p, f, s, &start, scratch, counts)
    }

    /// The start of pixel `i`'s pass: its scratch emptied, its class when it faces away from the
    /// whole light (`None`, its values set), else its integration constant and whether it takes
    /// the light-plane test, with its samples set up at once when the horizon cuts the light
    /// (`indexed`: with the angular index).
    #[allow(clippy::too_many_arguments)]
    fn pixel_start(
        &self,
        p: &Prepared,
        f: &Frame,
        i: usize,
        s: &ViewSample,
        indexed: bool,
        scratch: &mut Scratch,
        counts: &mut Counts,
    ) -> Option<PixelStart> {
        let n = self.sampler.count() as usize;
        let horizon = f.horizon[i];
        scratch.vis.clear();
        scratch.depth.clear();
        scratch.samples.clear();
        scratch.radiances.clear();
        scratch.visible.clear();
        scratch.visible.resize(n.div_ceil(64), 0);
        scratch.masks.clear();
        scratch.weights.clear();
        if horizon == Horizon::Below {
            counts.facing_away += 1;
            if scratch.want_values {
                scratch.vis.resize(n, 0.0);
                scratch.depth.resize(n, u64::MAX);
            }
            return None;
        }
        let mut d0 = f.constants[i];
        if d0 < 0 {
            counts.negative += 1;
            d0 = 0;
        }
        let mut start = PixelStart {
            d0: d0 as u64,
            indexed,
            // The light-plane form of the test (planar lights, exact covered samples, a
            // receiver clear of the light's plane).
            planar: f.planar_ok.get(i).copied().unwrap_or(false),
            ready: false,
        };
        if horizon == Horizon::Mixed {
            self.ensure_ready(p, f, i, s, &mut start, scratch, counts);
        }
        Some(start)
    }

    /// Sets the pixel's samples up unless they are.
    fn ensure_ready(
        &self,
        p: &Prepared,
        f: &Frame,
        i: usize,
        s: &ViewSample,
        start: &mut PixelStart,
        scratch: &mut Scratch,
        counts: &mut Counts,
    ) {
        if !start.ready {
            let all_above = f.horizon[i] == Horizon::Above;
            self.sample_setup(
                p,
                s,
                f.origins[i],
                start.indexed,
                all_above,
                start.planar,
                scratch,
                counts,
            );
            start.ready = true;
        }
    }

    /// The end of a pixel's pass: its integration constant for every sample when it set no
    /// sample up, else its counters from the updates in `scratch`; returns its class.
    fn pixel_finish(
        &self,
        p: &Prepared,
        f: &Frame,
        s: &ViewSample,
        start: &PixelStart,
        scratch: &mut Scratch,
        counts: &mut Counts,
    ) -> PixelClass {
        let n = self.sampler.count() as usize;
        let words = n.div_ceil(64);
        let d0 = start.d0;
        let units = p.units as f32;
        let textured = p.light.is_textured();
        let values = scratch.want_values;
        if !start.ready {
            // No wedge: every sample has the integration constant.
            counts.constant_only += 1;
            let v = 1.0 - (d0 as f32 / units).min(1.0);
            if d0 == 0 {
                fill_first(&mut scratch.visible, n);
            }
            if values {
                scratch.vis.resize(n, v);
                scratch.depth.resize(n, d0);
            }
            // In the umbra every sample's weight is zero: eq. 2 needs no radiance. Elsewhere
            // only the radiances, not the positions.
            if textured && v > 0.0 {
                self.sampler.unit_samples(s.pixel, &mut scratch.units);
                let light = p.light.as_ref();
                light.radiances_into(&scratch.units, &mut scratch.radiances);
            }
            return if d0 == 0 {
                PixelClass::Lit
            } else if v == 0.0 {
                PixelClass::Umbra
            } else {
                PixelClass::Penumbra
            };
        }
        counts.per_sample += 1;
        // Packed counters, outer wedges (k > 0) before inner ones (section 4.4); wider ones on
        // overflow, plain signed counters as the last resort. Bit-sliced when only the zero
        // counters are read, the paper's lanes when every depth complexity is.
        let mut done = false;
        for bits in WIDTHS.into_iter().filter(|&b| b >= f.bits) {
            let (masks, weights) = (&scratch.masks, &scratch.weights);
            let fits = if values {
                counters::run(&mut scratch.packed, bits, n, d0, masks, weights)
            } else {
                counters::run(&mut scratch.sliced, bits, n, d0, masks, weights)
            };
            if fits.is_ok() {
                if !values {
                    // Only which samples are visible: the zero counters above the horizon.
                    scratch.sliced.zero_mask_into(&mut scratch.visible);
                    let mut any = 0u64;
                    let mut all = true;
                    for (k, (v, a)) in scratch.visible.iter_mut().zip(&scratch.above).enumerate() {
                        *v &= *a;
                        any |= *v;
                        let left = n - k * 64;
                        all &= *v
                            == if left >= 64 {
                                u64::MAX
                            } else {
                                (1 << left) - 1
                            };
                    }
                    return if all {
                        PixelClass::Lit
                    } else if any == 0 {
                        PixelClass::Umbra
                    } else {
                        PixelClass::Penumbra
                    };
                }
                scratch.packed.unpack_into(&mut scratch.depth);
                done = true;
                break;
            }
            counts.escalations += 1;
        }
        if !done {
            counts.plain_fallback += 1;
            scratch.plain.clear();
            scratch.plain.resize(n, d0 as i64);
            for (m, &k) in scratch.masks.chunks(words).zip(&scratch.weights) {
                for j in 0..n {
                    if m[j / 64] >> (j % 64) & 1 == 1 {
                        scratch.plain[j] = scratch.plain[j].saturating_add(k);
                    }
                }
            }
            if scratch.plain.iter().any(|&d| d < 0) {
                counts.negative += 1;
            }
            scratch
                .depth
                .extend(scratch.plain.iter().map(|&d| d.max(0) as u64));
        }
        let (mut lit, mut dark) = (true, true);
        // One unit per occluder (no semi-opaque scene): the visibility is whether the depth
        // complexity is 0, as the general expression gives it.
        let whole = units == 1.0;
        for k in 0..n {
            let v = if scratch.above[k / 64] >> (k % 64) & 1 == 1 {
                let d = scratch.depth[k];
                if whole {
                    if d == 0 { 1.0 } else { 0.0 }
                } else {
                    1.0 - (d as f32 / units).min(1.0)
                }
            } else {
                scratch.depth[k] = u64::MAX;
                0.0
            };
            lit &= v == 1.0;
            dark &= v == 0.0;
            if v == 1.0 {
                scratch.visible[k / 64] |= 1 << (k % 64);
            }
            scratch.vis.push(v);
        }
        if lit {
            PixelClass::Lit
        } else if dark {
            PixelClass::Umbra
        } else {
            PixelClass::Penumbra
        }
    }

    /// A per-sample pixel's samples: positions, the horizon mask, the samples relative to the
    /// view sample (in the light plane with `planar`), the angular index (`indexed`), and empty
    /// update lists. What depends on the samples alone comes from the pixel's shared set when
    /// it has one (correlated and interleaved sampling, [`crate::shared_sets`]), built once.
    #[allow(clippy::too_many_arguments)]
    fn sample_setup(
        &self,
        p: &Prepared,
        s: &ViewSample,
        origin: Vec3,
        indexed: bool,
        all_above: bool,
        planar: bool,
        scratch: &mut Scratch,
        counts: &mut Counts,
    ) {
        let n = self.sampler.count() as usize;
        let words = n.div_ceil(64);
        self.sampler.unit_samples(s.pixel, &mut scratch.units);
        let light = p.light.as_ref();
        scratch.samples.clear();
        scratch.radiances.clear();
        // A constant rectangle light wholly above the receiver needs no world positions: the
        // light-plane coordinates are an affine map of the unit samples (positions are still
        // made under debug assertions, to check the horizon).
        let rect = p.rect.as_ref().filter(|_| planar && all_above);
        let form = match (&p.planar, planar, rect) {
            (Some(_), true, Some(_)) => SetForm::PlanarRect,
            (Some(_), true, None) => SetForm::Planar,
            _ => SetForm::Spatial,
        };
        // The radiances of a textured light weigh the visibilities (eq. 2): its pixels set
        // their samples up themselves.
        let textured = light.is_textured();
        let shared = (self.share_sets && !textured)
            .then(|| self.sampler.shared_set(s.pixel))
            .flatten();
        let units = &scratch.units;
        match shared {
            Some(k) => {
                // Built with its index, which the pixels of the set that take one then share.
                let built = scratch.shared.lend(k, form, &mut scratch.set, |set| {
                    self.set_up_samples(p, form, units, true, set);
                });
                counts.shared_sets_built += u64::from(built);
                counts.shared_set_pixels += 1;
            }
            None => {
                scratch.shared.restore(&mut scratch.set);
                scratch.set.positions.clear();
                if textured {
                    light.sample_into(units, &mut scratch.samples);
                    scratch
                        .set
                        .positions
                        .extend(scratch.samples.iter().map(|l| l.position));
                    scratch
                        .radiances
                        .extend(scratch.samples.iter().map(|l| l.radiance));
                }
                self.set_up_samples(p, form, units, indexed, &mut scratch.set);
            }
        }
        // Samples above the horizon (the reference's rule), every one when the whole light is
        // surely above.
        if all_above {
            scratch.above.clear();
            scratch.above.resize(words, u64::MAX);
            if !n.is_multiple_of(64) {
                scratch.above[words - 1] = (1 << (n % 64)) - 1;
            }
            if cfg!(debug_assertions) {
                let mut check = Vec::new();
                horizon_mask_into(&scratch.set.positions, s, origin, &mut check);
                assert_eq!(
                    scratch.above, check,
                    "a light surely above the horizon has a sample below it"
                );
            }
        } else {
            horizon_mask_into(&scratch.set.positions, s, origin, &mut scratch.above);
        }
        scratch.masks.clear();
        scratch.weights.clear();
        if form == SetForm::Spatial {
            scratch.relative.set(origin, &scratch.set.positions);
        }
        scratch.mask.clear();
        scratch.mask.resize(words, 0);
    }

    /// What a pixel's samples need of their unit samples `units` alone, in `form`, into `set`:
    /// the world positions (unless already there, as a textured light's samples put them;
    /// none for the rectangle form outside debug builds), the light-plane coordinates (the
    /// light-plane forms) and, with `indexed`, the angular index.
    fn set_up_samples(
        &self,
        p: &Prepared,
        form: SetForm,
        units: &[Vec2],
        indexed: bool,
        set: &mut SampleSet,
    ) {
        let n = units.len();
        let light = p.light.as_ref();
        let positions_needed = form != SetForm::PlanarRect || cfg!(debug_assertions);
        if set.positions.is_empty() && positions_needed {
            light.positions_into(units, &mut set.positions);
        }
        match (form, &p.planar, p.rect.as_ref()) {
            (SetForm::PlanarRect, Some(_), Some(r)) => set.planar.set_rect(units, r),
            (SetForm::Planar | SetForm::PlanarRect, Some(pl), _) => {
                set.planar.set(&set.positions, p.shape.center, pl.u, pl.v);
            }
            _ => {
                if let (Some(plane), true) = (&p.shape.plane, indexed) {
                    set.angular.build(plane, p.shape.center, &set.positions);
                }
                return;
            }
        }
        if indexed {
            set.angular.build_planar(&set.planar, n);
        }
    }

    /// The samples one pair's edge covers (section 7.3 tables, or the exact test on every
    /// sample above the horizon), appended to the pixel's updates when there is any.
    #[allow(clippy::too_many_arguments)]
    fn covered_update(
        &self,
        p: &Prepared,
        s: &ViewSample,
        o: DVec3,
        pair: &Pair,
        test: &EdgeTest,
        scratch: &mut Scratch,
        counts: &mut Counts,
    ) {
        counts.edge_tests += 1;
        let mask = &mut scratch.mask;
        let any = match (&self.covered, &p.tables) {
            (CoveredSamples::Discrete | CoveredSamples::Refined, Some(t)) => t.mask(
                s.pixel,
                test,
                o,
                &p.edges[p.silhouettes[pair.edge as usize] as usize],
                &scratch.relative,
                &scratch.above,
                mask,
            ),
            _ => test.mask(&scratch.relative, &scratch.above, mask),
        };
        if any {
            counts.covered_updates += 1;
            scratch.masks.extend_from_slice(mask);
            scratch.weights.push(pair.k as i64);
        }
    }

    /// The covered samples of the batched tests (`scratch.batch`, emptied): their angular
    /// candidates, then the exact test on those (with `refined`, on those the line table leaves
    /// undecided), appended to the pixel's updates when any.
    fn indexed_updates(scratch: &mut Scratch, counts: &mut Counts, refined: Option<&Refined>) {
        let words = scratch.above.len();
        let n = scratch.batch.len();
        scratch.batch_candidates.resize(BATCH * words, 0);
        scratch.batch_inner.resize(BATCH * words, 0);
        let any = scratch.set.angular.candidates_batch(
            &scratch.batch,
            &scratch.above,
            &mut scratch.batch_candidates,
            refined.map(|_| &mut scratch.batch_inner[..]),
        );
        counts.edge_tests += n as u64;
        for (i, (test, k)) in scratch.batch.iter().zip(&scratch.batch_k).enumerate() {
            if any >> i & 1 == 0 {
                counts.sector_empty += 1;
                continue;
            }
            let cand = &scratch.batch_candidates[i * words..(i + 1) * words];
            let mask = &mut scratch.mask;
            let few = cand.iter().map(|w| w.count_ones()).sum::<u32>() <= FEW_CANDIDATES;
            // With the refined tables, a pair with many candidates asks the line table first:
            // candidates in the sector's inner buckets and surely beyond the line are covered,
            // the exact test takes those the line leaves undecided.
            let decided = match (refined, few) {
                (Some(r), false) => {
                    let (a, b) = r.edges[scratch.batch_edge[i] as usize].ends();
                    match r.tables.refined_line(r.pixel, r.p, a, b) {
                        LineMasks::Unknown => None,
                        LineMasks::NoneBeyond => Some(false),
                        LineMasks::Cell { beyond, maybe } => {
                            counts.line_cells += 1;
                            let inner = &scratch.batch_inner[i * words..(i + 1) * words];
                            let undecided = &mut scratch.undecided;
                            undecided.clear();
                            let mut open = 0;
                            for j in 0..words {
                                mask[j] = inner[j] & beyond[j];
                                undecided.push(cand[j] & maybe[j] & !mask[j]);
                                open |= undecided[j];
                            }
                            if open != 0 {
                                test.add_covered(&scratch.relative, undecided, mask);
                            }
                            Some(mask.iter().any(|w| *w != 0))
                        }
                    }
                }
                _ => None,
            };
            let covered = match decided {
                Some(covered) => covered,
                None if few => {
                    mask.fill(0);
                    test.add_covered(&scratch.relative, cand, mask);
                    mask.iter().any(|w| *w != 0)
                }
                None => test.mask(&scratch.relative, cand, mask),
            };
            if covered {
                counts.covered_updates += 1;
                scratch.masks.extend_from_slice(mask);
                scratch.weights.push(*k);
            }
        }
        scratch.batch.clear();
        scratch.batch_k.clear();
        scratch.batch_edge.clear();
    }

    /// The covered samples of every pair of a pixel by its light-plane test (`tests`, set up
    /// by the wedge scan; samples set up), four pairs at a time: their sectors' bucket ranges
    /// (with `indexed`; otherwise every sample is a candidate), then the exact test on the
    /// candidates, appended to the pixel's updates when any.
    #[inline(never)]
    fn planar_pairs(
        tests: &[PlanarTest],
        indexed: bool,
        scratch: &mut Scratch,
        counts: &mut Counts,
    ) {
        let words = scratch.above.len();
        scratch.mask.resize(words, 0);
        scratch.batch_candidates.resize(words, 0);
        counts.edge_tests += tests.len() as u64;
        if indexed {
            // Up to four words of samples (`dcs-256`): candidates, samples and covered samples
            // as fixed arrays.
            let done = match words {
                1 => Self::indexed_pairs::<1>(tests, scratch, counts),
                2 => Self::indexed_pairs::<2>(tests, scratch, counts),
                3 => Self::indexed_pairs::<3>(tests, scratch, counts),
                4 => Self::indexed_pairs::<4>(tests, scratch, counts),
                _ => false,
            };
            if done {
                return;
            }
        }
        for quad in tests.chunks(4) {
            let ranges = indexed.then(|| {
                let mut four = [PlanarTest::NONE; 4];
                four[..quad.len()].copy_from_slice(quad);
                QuadRanges::of_tests(&four)
            });
            for (j, test) in quad.iter().enumerate() {
                let mut hit = 0u64;
                if let Some(r) = &ranges {
                    let cand = &mut scratch.batch_candidates;
                    if !scratch
                        .set
                        .angular
                        .quad_candidates(r, j, &scratch.above, cand)
                    {
                        counts.sector_empty += 1;
                        continue;
                    }
                    for (w, &c) in cand.iter().enumerate() {
                        let m = test.covered_in(&scratch.set.planar, w, c);
                        scratch.mask[w] = m;
                        hit |= m;
                    }
                } else {
                    for (w, &a) in scratch.above.iter().enumerate() {
                        let m = test.covered_word(&scratch.set.planar, w) & a;
                        scratch.mask[w] = m;
                        hit |= m;
                    }
                }
                if hit != 0 {
                    counts.covered_updates += 1;
                    scratch.masks.extend_from_slice(&scratch.mask);
                    scratch.weights.push(i64::from(test.k));
                }
            }
        }
    }

    /// [`Dcs::planar_pairs`] with the angular index on `W` words of samples (`scratch.above`
    /// has `W` words; `false`, nothing done, when it has not): four pairs' sectors at a time,
    /// each pair's candidates word by word, then the exact test on them. At 256 samples on
    /// `bunny` (`scripts/dcs_instructions.sh bunny stratified-256`) this took the pass from
    /// 1156 M instructions (words as slices of any length, a word's candidates tested sample
    /// by sample through the slices) to 731 M.
    #[inline(always)]
    fn indexed_pairs<const W: usize>(
        tests: &[PlanarTest],
        scratch: &mut Scratch,
        counts: &mut Counts,
    ) -> bool {
        let Ok(above) = <[u64; W]>::try_from(&scratch.above[..]) else {
            return false;
        };
        let samples = &scratch.set.planar;
        let (xs, ys) = (samples.words_x::<W>(), samples.words_y::<W>());
        let Some(rows) = scratch.set.angular.rows::<W>() else {
            return false;
        };
        let (masks, weights) = (&mut scratch.masks, &mut scratch.weights);
        let (mut empty, mut covered) = (0, 0);
        let mut quad_of = |four: &[PlanarTest; 4], n: usize| {
            let r = QuadRanges::of_tests(four);
            for (j, test) in four[..n].iter().enumerate() {
                let mut cand = r.words(rows, j);
                let mut any = 0;
                for (c, a) in cand.iter_mut().zip(&above) {
                    *c &= a;
                    any |= *c;
                }
                if any == 0 {
                    empty += 1;
                    continue;
                }
                let hit: [u64; W] =
                    std::array::from_fn(|w| test.covered_of(&xs[w], &ys[w], cand[w]));
                if hit.iter().any(|h| *h != 0) {
                    covered += 1;
                    masks.extend_from_slice(&hit);
                    weights.push(i64::from(test.k));
                }
            }
        };
        let (whole, rest) = tests.as_chunks::<4>();
        for four in whole {
            quad_of(four, 4);
        }
        if !rest.is_empty() {
            let mut four = [PlanarTest::NONE; 4];
            four[..rest.len()].copy_from_slice(rest);
            quad_of(&four, rest.len());
        }
        counts.sector_empty += empty;
        counts.covered_updates += covered;
        true
    }

    /// Direct illumination of every view sample by DCS eq. 6: the light samples' contributions
    /// weighted by their binary visibility (saturated opacity sums with semi-opaque occluders).
    ///
    /// # Errors
    /// `Unsupported` for orthographic views.
    fn direct(&self, p: &Prepared, view: &ViewSamples) -> Result<Vec<Vec3>, TechniqueError> {
        let mut stats = Stats::default();
        let f = self.frame(p, view, &mut stats)?;
        let (parts, _) = self.squares(p, &f, |rect, block, buffers| {
            let mut out = Vec::with_capacity(rect.len());
            let mut counts = Counts::default();
            let mut units = Vec::new();
            let mut samples = Vec::new();
            // Eq. 6 weighs every sample by its visibility.
            self.run_square(
                p,
                &f,
                block,
                rect,
                true,
                &mut counts,
                buffers,
                |i, s, _, scratch| {
                    let light = p.light.as_ref();
                    let samples: &[LightSample] = if scratch.samples.is_empty() {
                        self.sampler.unit_samples(s.pixel, &mut units);
                        samples.clear();
                        light.sample_into(&units, &mut samples);
                        &samples
                    } else {
                        &scratch.samples
                    };
                    let albedo = p.scene.albedo(s.triangle as usize);
                    let vis = &scratch.vis;
                    out.push((i, pixel_direct(s, albedo, light, samples, |k| vis[k])));
                },
            );
            out
        });
        let mut out = vec![Vec3::ZERO; view.len()];
        for (i, d) in parts.into_iter().flat_map(|(_, v)| v) {
            out[i] = d;
        }
        Ok(out)
    }
}

/// Copies each square's values (`values` of each of `squares`, `per_pixel` of them per pixel,
/// row by row within the square) into `out`, the image's values (`width` pixels a row), bands
/// of [`SQUARE`] rows in parallel. Nothing is copied when `out` is empty (an output not asked
/// for).
fn scatter_squares<T: Copy + Send + Sync, R: Sync>(
    out: &mut [T],
    per_pixel: usize,
    width: usize,
    squares: &[(Rect, R)],
    values: impl Fn(&R) -> &[T] + Sync,
) {
    let row = width * per_pixel;
    if out.is_empty() || row == 0 {
        return;
    }
    let band = SQUARE as usize;
    let mut bands: Vec<Vec<(Rect, &[T])>> = vec![Vec::new(); (out.len() / row).div_ceil(band)];
    for (r, square) in squares {
        bands[r.rows.0 as usize / band].push((*r, values(square)));
    }
    out.par_chunks_mut(band * row)
        .zip(bands.par_iter())
        .for_each(|(chunk, band_squares)| {
            for (r, v) in band_squares {
                let (x0, rw) = (
                    r.cols.0 as usize * per_pixel,
                    r.width() as usize * per_pixel,
                );
                for (k, src) in v.chunks_exact(rw).enumerate() {
                    chunk[k * row + x0..k * row + x0 + rw].copy_from_slice(src);
                }
            }
        });
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
        }
    }

    fn parameters(&self) -> serde_json::Value {
        json!({
            "samples": self.sampler.count(),
            "strategy": format!("{:?}", self.sampler.strategy()),
            "seed": self.sampler.seed(),
            "silhouettes": format!("{:?}", self.detection),
            "covered_samples": format!("{:?}", self.covered),
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

    fn estimate(&self, view: &ViewSamples, outputs: Outputs) -> Result<Estimate, TechniqueError> {
        let output = match self.config.output {
            PerSampleOutput::None if outputs.per_sample => PerSampleOutput::Bits,
            o => o,
        };
        let mut est = self.config.run(&self.p, view, output)?;
        if outputs.direct {
            let t0 = std::time::Instant::now();
            est.direct = Some(self.direct_illumination(view)?);
            est.stats.add_time("direct", t0.elapsed().as_secs_f64());
        }
        Ok(est)
    }
}

impl PreparedDcs {
    /// Direct illumination of every view sample by DCS eq. 6: the light samples' contributions
    /// weighted by their binary visibility (saturated opacity sums with semi-opaque occluders).
    ///
    /// # Errors
    /// `Unsupported` for orthographic views.
    pub fn direct_illumination(&self, view: &ViewSamples) -> Result<Vec<Vec3>, TechniqueError> {
        self.config.direct(&self.p, view)
    }
}

impl Dcs {
    /// Builds the edges, silhouettes, wedges and (section 7.3) tables for `scene` and `light`.
    ///
    /// # Errors
    /// [`TechniqueError::Unsupported`] when the scene or light is outside the capabilities.
    pub fn prepare_dcs(
        &self,
        scene: SceneRef,
        light: Light,
    ) -> Result<PreparedDcs, TechniqueError> {
        self.capabilities()
            .require(&self.name, scene.as_ref(), light.as_ref())?;
        let mut stats = Stats::default();
        let shape = LightShape::new(light.as_ref(), &self.name)?;
        let (edges, units) = stats.time("edges", || scene_edges(scene.as_ref(), shape.center));
        let sil = stats.time("silhouettes", || {
            silhouettes(&edges, &shape, self.detection)
        });
        stats.add("edges", edges.len() as u64);
        stats.add("silhouette-edges", sil.len() as u64);
        let tables = match self.covered {
            CoveredSamples::Discrete | CoveredSamples::Refined => {
                Some(stats.time("discrete-tables", || {
                    DiscreteTables::build(
                        &self.sampler,
                        light.as_ref(),
                        &shape,
                        self.covered == CoveredSamples::Refined,
                        &self.name,
                    )
                })?)
            }
            CoveredSamples::Exact => None,
        };
        let extent = scene.bounds().union(light.bounds()).diagonal();
        let polygon = shape.plane.as_ref().map(|pl| {
            let c = shape.center.as_dvec3();
            pl.polygon
                .iter()
                .map(|v| (v.as_dvec3() - c).as_vec3())
                .collect()
        });
        let cd = shape.center.as_dvec3();
        let centred_edges = sil
            .iter()
            .map(|&i| CentredEdge::new(&edges[i as usize], cd))
            .collect();
        let wedges = stats.time("wedges", || wedges(&edges, &sil, &shape));
        let planar = shape.plane.as_ref().map(|pl| PlanarLight {
            u: pl.u,
            v: pl.v,
            normal: pl.u.cross(pl.v),
        });
        let rect = match (light.geometry(), &shape.plane, light.is_textured()) {
            (LightGeometry::Rectangle { half_u, half_v, .. }, Some(pl), false) => {
                Some(RectMap::new(half_u, half_v, pl.u, pl.v))
            }
            _ => None,
        };
        let (scan, scan_lanes) = wedges
            .par_iter()
            .map(|w| {
                let pe = shape.plane.as_ref().map(|pl| {
                    let (u, v) = (pl.u.as_dvec3(), pl.v.as_dvec3());
                    PlanarEdge::new(&edges[w.edge as usize], cd, u, v)
                });
                ScanWedge::new(w, pe)
            })
            .unzip();
        let p = Prepared {
            planar,
            rect,
            scan,
            scan_lanes,
            polygon,
            centred_edges,
            scene,
            light,
            shape,
            edges,
            silhouettes: sil,
            units,
            offset: RayOffset::for_extent(extent),
            extent: extent as f64,
            tables,
        };
        Ok(PreparedDcs {
            config: self.clone(),
            p,
            stats,
        })
    }

    /// The estimate of `view` on prepared data `p`, with `output` per sample.
    fn run(
        &self,
        p: &Prepared,
        view: &ViewSamples,
        output: PerSampleOutput,
    ) -> Result<Estimate, TechniqueError> {
        let mut stats = Stats::default();
        let f = self.frame(p, view, &mut stats)?;
        let n = self.sampler.count() as usize;
        let words = n.div_ceil(64);
        let w = view.width() as usize;
        let textured = p.light.is_textured();
        struct Row {
            v: Vec<f32>,
            rgb: Vec<Vec3>,
            class: Vec<PixelClass>,
            bits: Vec<u64>,
            depth: Vec<u32>,
            counts: Counts,
        }
        let (strips, block_wedges) = stats.time("depth-complexity", || {
            self.squares(p, &f, |rect, block, buffers| {
                let m = rect.len();
                let rw = rect.width() as usize;
                let mut r = Row {
                    v: vec![0.0; m],
                    rgb: vec![Vec3::ZERO; if textured { m } else { 0 }],
                    class: vec![PixelClass::Background; m],
                    bits: vec![
                        0;
                        if output == PerSampleOutput::Bits {
                            m * words
                        } else {
                            0
                        }
                    ],
                    depth: vec![
                        0;
                        if output == PerSampleOutput::Counters {
                            m * n
                        } else {
                            0
                        }
                    ],
                    counts: Counts::default(),
                };
                let mut counts = Counts::default();
                let values = textured || output == PerSampleOutput::Counters || p.units != 1;
                self.run_square(
                    p,
                    &f,
                    block,
                    rect,
                    values,
                    &mut counts,
                    buffers,
                    |i, _, class, scratch| {
                        let x =
                            (i / w - rect.rows.0 as usize) * rw + (i % w - rect.cols.0 as usize);
                        r.class[x] = class;
                        let vis = &scratch.vis;
                        // Lit and umbra pixels (most of an image): every sample alike.
                        let uniform = match class {
                            PixelClass::Lit => Some(true),
                            PixelClass::Umbra | PixelClass::Skipped => Some(false),
                            _ => None,
                        };
                        if let (Some(lit), false, false) =
                            (uniform, textured, output == PerSampleOutput::Counters)
                        {
                            r.v[x] = if lit { 1.0 } else { 0.0 };
                            if lit && output == PerSampleOutput::Bits {
                                for (k, word) in
                                    r.bits[x * words..(x + 1) * words].iter_mut().enumerate()
                                {
                                    let left = n - k * 64;
                                    *word = if left >= 64 {
                                        u64::MAX
                                    } else {
                                        (1 << left) - 1
                                    };
                                }
                            }
                            return;
                        }
                        if !scratch.want_values {
                            // Whole units, no texture, bits at most: the visible samples say all.
                            let seen: u32 = scratch.visible.iter().map(|w| w.count_ones()).sum();
                            r.v[x] = (f64::from(seen) / n as f64) as f32;
                            if output == PerSampleOutput::Bits {
                                r.bits[x * words..(x + 1) * words]
                                    .copy_from_slice(&scratch.visible);
                            }
                            return;
                        }
                        let sum: f64 = vis.iter().map(|&v| v as f64).sum();
                        r.v[x] = (sum / n as f64) as f32;
                        if textured {
                            let acc = scratch
                                .radiances
                                .iter()
                                .zip(vis)
                                .fold(Vec3::ZERO, |a, (l, v)| a + *l * *v);
                            r.rgb[x] = acc / n as f32;
                        }
                        match output {
                            PerSampleOutput::Bits => {
                                for (k, &v) in vis.iter().enumerate() {
                                    if v == 1.0 {
                                        r.bits[x * words + k / 64] |= 1 << (k % 64);
                                    }
                                }
                            }
                            PerSampleOutput::Counters => {
                                for (k, &d) in scratch.depth.iter().enumerate() {
                                    r.depth[x * n + k] = d.min(u32::MAX as u64) as u32;
                                }
                            }
                            PerSampleOutput::None => {}
                        }
                    },
                );
                r.counts = counts;
                r
            })
        });
        let mut vis = if textured {
            VisibilityImage::rgb_buffer(view)
        } else {
            VisibilityImage::scalar(view)
        };
        let mut classes = vec![PixelClass::Background; view.len()];
        let mut counts = Counts::default();
        let mut bits = vec![
            0u64;
            if output == PerSampleOutput::Bits {
                view.len() * words
            } else {
                0
            }
        ];
        let mut depth = vec![
            0u32;
            if output == PerSampleOutput::Counters {
                view.len() * n
            } else {
                0
            }
        ];
        // Each square's rows into the image, bands of squares in parallel (a serial copy
        // was 5 ms of a 160 ms frame on two threads).
        if textured {
            scatter_squares(vis.rgbs_mut(), 1, w, &strips, |r| &r.rgb);
        } else {
            scatter_squares(vis.scalars_mut(), 1, w, &strips, |r| &r.v);
        }
        scatter_squares(&mut classes, 1, w, &strips, |r| &r.class);
        scatter_squares(&mut bits, words, w, &strips, |r| &r.bits);
        scatter_squares(&mut depth, n, w, &strips, |r| &r.depth);
        for (_, r) in &strips {
            counts.add(&r.counts);
        }
        vis.set_classes(classes)?;
        match output {
            PerSampleOutput::Bits => vis.set_per_sample(PerSampleVisibility::Bits {
                samples: n as u32,
                words: bits,
            })?,
            PerSampleOutput::Counters => vis.set_per_sample(PerSampleVisibility::Counters {
                samples: n as u32,
                counts: depth,
            })?,
            PerSampleOutput::None => {}
        }
        stats.add("pixels-facing-away", counts.facing_away);
        stats.add("pixels-constant-only", counts.constant_only);
        stats.add("pixels-per-sample", counts.per_sample);
        stats.add("edge-tests", counts.edge_tests);
        stats.add("covered-updates", counts.covered_updates);
        stats.add("counter-escalations", counts.escalations);
        stats.add("plain-counter-fallbacks", counts.plain_fallback);
        stats.add("negative-depth-complexity", counts.negative);
        stats.add("edge-ties", counts.ties + counts.scan.ties);
        stats.add("wedge-pixels-scanned", counts.scan.scanned);
        stats.add("wedge-exact-weights", counts.scan.exact_weights);
        stats.add("bin-block-wedges", block_wedges);
        stats.add("bin-square-wedges", counts.scan.square_wedges);
        stats.add("bin-tile-wedges", counts.scan.tile_wedges);
        stats.add("wedge-pairs", counts.pairs);
        stats.add("wedge-pairs-off-light", counts.off_light);
        stats.add("wedge-pairs-empty-sector", counts.sector_empty);
        stats.add("refined-line-cells", counts.line_cells);
        stats.add("pixels-shared-sample-sets", counts.shared_set_pixels);
        stats.add("shared-sample-sets-built", counts.shared_sets_built);
        vis.validate()?;
        Ok(Estimate::new(vis, stats))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every square's values land on their own pixels, for an image whose sides are not whole
    /// squares or blocks, one value and three values per pixel, and an empty output is left
    /// alone.
    #[test]
    fn squares_scatter_onto_their_pixels() {
        let (w, h) = (150u32, 37u32);
        let squares: Vec<Rect> = crate::bins::blocks(w, h)
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
            scatter_squares(&mut out, per_pixel, w as usize, &values, |v| v);
            assert!(out.iter().enumerate().all(|(i, v)| *v == i));
        }
        let mut none: Vec<u64> = Vec::new();
        scatter_squares(&mut none, 1, w as usize, &[(squares[0], vec![7u64])], |v| v);
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
            let setup = shadow_core::scenes::builtin(name).unwrap();
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
                    shared.stats.counter("pixels-shared-sample-sets").unwrap(),
                    shared.stats.counter("shared-sample-sets-built").unwrap(),
                );
                assert_eq!(
                    own.stats.counter("pixels-shared-sample-sets").unwrap(),
                    0,
                    "{case}"
                );
                assert_eq!(
                    pixels,
                    shared.stats.counter("pixels-per-sample").unwrap(),
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
