//! The adaptive reference (`ref-adaptive-*`): per-pixel sampling toward an image error
//! target, so samples go where a pixel's visibility is uncertain and nowhere else (DESIGN
//! section 3, "choosing the work"; the survey's section 4.1 notes that none of the real-time
//! methods it reviews chooses its own quality).
//!
//! Two passes over the pixels, both deterministic for a seed and independent of the thread
//! count (every decision depends on the first pass's results, not on scheduling):
//! 1. **Probe.** A receiver whose beam ([`crate::beam`]) proves the whole light visible and
//!    above its horizon stops with no sample, as in the uniform reference. Every other pixel
//!    draws two independent stratified sets of `B` samples (8 x 8 for `B` = 64): the first
//!    starts its progressive set (below), the second is a replicate. `(m0 - m1)^2 / 2`, with
//!    `m` the two sets' means, is an unbiased estimate of the variance of one set's mean
//!    (the random-group method, valid for stratified sampling where the sample variance of
//!    all samples is not), pooled over the sampled pixels of its 3 x 3 neighbourhood to steady
//!    a one-degree-of-freedom estimate; a pixel whose samples agreed by chance beside a
//!    penumbra inherits its neighbours' variance, so no pixel stops on luck alone.
//! 2. **Allocation.** With `c_i` that variance, pixel `i`'s error at `n` samples is modelled as
//!    `c_i (n / B)^-3/2` (stratified sampling of a light with an edge across it). The counts
//!    that minimise the image's mean squared error for a total number of samples are
//!    `n_i = K c_i^(2/5)` (Lagrange); `K` is solved by bisection so that the predicted RMSE over
//!    the valid pixels equals the target, with every `n_i` within `[B, cap]`, and each `n_i`
//!    is rounded to the nearest count of the progressive schedule (in log scale).
//!
//! The progressive set is progressive jittered sampling (Christensen, Kensler and Kilpatrick,
//! "Progressive Multi-Jittered Sample Sequences", EGSR 2018): from a jittered set with one
//! sample per cell of a `g x g` grid, each cell gets one sample in the sub-cell diagonal to its
//! sample's (`2 g^2` samples, stratified in 2:1 rectangles), then one in each of the two
//! others (`4 g^2`, one per cell of the `2g x 2g` grid). Every count of the schedule
//! `B, 2B, 4B, ...` is thus one stratified set, so stopping early or late never loses the
//! stratification (independent batches would: their union is no stratified set).
//! `V(p)` is the count-weighted mean of the progressive set and the replicate. Textured lights
//! plan on the largest channel's variance. Direct light (DCS eq. 6) is estimated from the same
//! samples, a pixel the beam proves lit drawing its probe for it.

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use serde::Serialize;
use serde_json::json;
use shadow_core::direct::sample_term;
use shadow_core::light::LightSample;
use shadow_core::prelude::*;
use shadow_core::sampling::{MAX_SAMPLES, SamplingError, hash_words, mix64, unit_float};
use shadow_core::view_samples::ViewSample;

use crate::bvh::BeamResult;
use crate::reference::{Counts, PreparedReference, Reference, Scratch};
use crate::statistics::{RefCounter, RefGauge, RefPhase};

/// Samples of each probe set by default (4 x 4 strata).
pub const DEFAULT_BATCH: u32 = 16;
/// The most samples a pixel draws by default: a 4096-sample progressive set (64 x 64) and
/// the replicate.
pub const DEFAULT_CAP: u32 = 4096 + DEFAULT_BATCH;

/// The adaptive reference: a configuration (target, probe size, cap, seed).
#[derive(Debug, Clone)]
pub struct AdaptiveReference {
    name: String,
    target: f32,
    batch: u32,
    cap: u32,
    seed: u64,
    /// The first set of the progressive sequence.
    first: LightSampler,
    /// The independent replicate of the probe.
    replicate: LightSampler,
    /// The schedule: progressive set sizes `B, 2B, 4B, ...` up to `cap - B`.
    schedule: Vec<u32>,
}

impl AdaptiveReference {
    /// Sampling toward image RMSE `target` with probe sets of `batch` samples and at most `cap`
    /// samples a pixel.
    ///
    /// # Errors
    /// [`TechniqueError::InvalidInput`] for a target that is not in (0, 1), a batch that is not
    /// a power of four of at least 4, or a cap below twice the batch or above [`MAX_SAMPLES`].
    pub fn new(target: f32, batch: u32, cap: u32, seed: u64) -> Result<Self, TechniqueError> {
        if !(target > 0.0 && target < 1.0) {
            return Err(TechniqueError::InvalidInput(format!(
                "adaptive target {target} is not in (0, 1)"
            )));
        }
        if batch < 4 || !batch.is_power_of_two() || !batch.trailing_zeros().is_multiple_of(2) {
            return Err(TechniqueError::InvalidInput(format!(
                "adaptive batch {batch} is not a power of four of at least 4"
            )));
        }
        if cap < 2 * batch || cap > MAX_SAMPLES {
            return Err(TechniqueError::InvalidInput(format!(
                "adaptive cap {cap} is outside {}..={MAX_SAMPLES}",
                2 * batch
            )));
        }
        let sampler = |salt: u64| {
            LightSampler::new(
                SamplingStrategy::Stratified,
                batch,
                hash_words(&[seed, 0xada, salt]),
            )
            .map_err(|e: SamplingError| TechniqueError::InvalidInput(e.to_string()))
        };
        let mut schedule = vec![batch];
        while schedule.last().is_some_and(|&n| 2 * n + batch <= cap) {
            schedule.push(2 * schedule[schedule.len() - 1]);
        }
        Ok(Self {
            name: format!("ref-adaptive-{target}"),
            target,
            batch,
            cap,
            seed,
            first: sampler(0)?,
            replicate: sampler(1)?,
            schedule,
        })
    }

    /// Renames the instance (presets).
    #[must_use]
    pub fn named(mut self, name: &str) -> Self {
        self.name = name.into();
        self
    }

    /// The image RMSE target.
    pub fn target(&self) -> f32 {
        self.target
    }
}

/// The adaptive reference prepared for one scene and light (the uniform reference's BVH,
/// offsets and beams).
pub struct PreparedAdaptive {
    config: AdaptiveReference,
    base: Reference,
    inner: PreparedReference,
}

impl std::fmt::Debug for PreparedAdaptive {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PreparedAdaptive")
            .field("config", &self.config)
            .finish_non_exhaustive()
    }
}

impl AdaptiveReference {
    /// The two independent `B`-sample stratified sets of the probe pass (the first and the
    /// replicate): another technique that evaluates the same samples per pixel (DCS, which
    /// agrees with the reference sample by sample) measures the same probe.
    pub fn probe_samplers(&self) -> [&LightSampler; 2] {
        [&self.first, &self.replicate]
    }

    /// [`ShadowTechnique::prepare`] with the concrete type, for callers that also want
    /// [`PreparedAdaptive::probe_view`] (the `auto` chooser).
    ///
    /// # Errors
    /// As [`Reference::prepare_reference`].
    pub fn prepare_adaptive(
        &self,
        scene: SceneRef,
        light: Light,
    ) -> Result<PreparedAdaptive, TechniqueError> {
        let base = Reference::stratified(self.batch, self.seed)?;
        let inner = base.prepare_reference(scene, light)?;
        Ok(PreparedAdaptive {
            config: self.clone(),
            base,
            inner,
        })
    }
}

impl AdaptiveReference {
    /// This configuration prepared for the scene and light `other` was prepared for, sharing
    /// its BVH ([`Reference::prepare_sharing`]).
    ///
    /// # Errors
    /// [`TechniqueError::InvalidInput`] never in practice: the probe size was checked by
    /// [`AdaptiveReference::new`].
    pub fn prepare_sharing(
        &self,
        other: &PreparedReference,
    ) -> Result<PreparedAdaptive, TechniqueError> {
        let base = Reference::stratified(self.batch, self.seed)?;
        let inner = base.prepare_sharing(other);
        Ok(PreparedAdaptive {
            config: self.clone(),
            base,
            inner,
        })
    }
}

impl PreparedAdaptive {
    /// The uniform reference's preparation underneath (its BVH can be shared).
    pub fn reference(&self) -> &PreparedReference {
        &self.inner
    }
}

/// What the probe pass (the beam and the two `B`-sample sets) finds over a view: the
/// quantities a chooser needs to predict the error of any stratified sample count, without
/// the allocation pass.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct ProbeSummary {
    /// Valid pixels of the view.
    pub pixels: usize,
    /// Pixels whose beam did not prove the whole light visible (they drew samples).
    pub sampled: usize,
    /// Pixels whose samples were neither all visible nor all occluded.
    pub penumbra: usize,
    /// Pixels where some sample of the two sets is occluded or below the horizon (umbra and
    /// penumbra): unlike `sampled`, a count any technique with the same samples finds.
    pub shadowed: usize,
    /// Samples in each probe set (`B`).
    pub batch: u32,
    /// Mean over the valid pixels of the variance of one set's mean, `(m0 - m1)^2 / 2`
    /// (0 where the beam settles the pixel): the image MSE of a `B`-sample stratified
    /// estimate, up to the random-group estimator's noise.
    pub mean_variance: f64,
    /// The most an allocation of counts among the sampled pixels could save over one count
    /// for all of them at equal image MSE, under the error model of the module docs
    /// (`c_i n^-3/2`): `mean(c)^(2/3) / mean(c^(2/5))^(5/3)` over the sampled pixels' unpooled
    /// variances (1 when they all agree). One-degree-of-freedom estimates spread more than the
    /// true variances, so this errs high: it bounds what `ref-adaptive` can gain.
    pub allocation_gain: f64,
    /// Wall-clock seconds of the probe.
    pub seconds: f64,
}

impl ShadowTechnique for AdaptiveReference {
    fn name(&self) -> &str {
        &self.name
    }

    fn capabilities(&self) -> Capabilities {
        Capabilities::any_input(false, Processor::Cpu)
    }

    fn parameters(&self) -> serde_json::Value {
        json!({
            "mode": "Adaptive",
            "target_rmse": self.target,
            "probe_set": self.batch,
            "cap": self.cap,
            "seed": self.seed,
            "variance_estimator": "random groups (two probe sets), pooled over 3 x 3 pixels",
            "sequence": "progressive jittered",
        })
    }

    fn prepare(
        &self,
        scene: SceneRef,
        light: Light,
    ) -> Result<Box<dyn PreparedShadows>, TechniqueError> {
        Ok(Box::new(self.prepare_adaptive(scene, light)?))
    }
}

/// One pixel's running sums.
#[derive(Default, Clone, Copy)]
struct Acc {
    /// `false` for background pixels.
    valid: bool,
    /// The beam proved the whole light visible and above the horizon: nothing to sample.
    clear: bool,
    sum: f64,
    rgb: [f64; 3],
    direct: Vec3,
    n: u32,
    lit: bool,
    dark: bool,
    /// `(m0 - m1)^2 / 2` of the two probe sets' means (largest channel).
    replicate_var: f64,
    /// Samples of the progressive set drawn.
    progressive: u32,
    /// The beam found too many candidates: the second pass queries the BVH per segment
    /// without traversing the beam again.
    beam_too_many: bool,
}

impl Acc {
    fn result(&self, light: &dyn AreaLight) -> (f32, Vec3, Vec3, PixelClass) {
        if self.clear {
            return (1.0, Vec3::ONE, Vec3::ZERO, PixelClass::Lit);
        }
        let nn = f64::from(self.n.max(1));
        let rgb = Vec3::new(
            (self.rgb[0] / nn) as f32,
            (self.rgb[1] / nn) as f32,
            (self.rgb[2] / nn) as f32,
        );
        let direct = if light.area() == 0.0 {
            self.direct / nn as f32
        } else {
            self.direct * (light.area() / nn as f32)
        };
        let class = if self.lit {
            PixelClass::Lit
        } else if self.dark {
            PixelClass::Umbra
        } else {
            PixelClass::Penumbra
        };
        ((self.sum / nn) as f32, rgb, direct, class)
    }
}

/// Per-thread buffers.
#[derive(Default)]
struct Buffers {
    scratch: Scratch,
    /// The pixel's progressive set, in the order drawn.
    progressive: Vec<Vec2>,
    units: Vec<Vec2>,
    samples: Vec<LightSample>,
}

/// What to accumulate besides `V(p)`.
#[derive(Clone, Copy)]
struct Wants {
    textured: bool,
    direct: bool,
}

/// Appends the next doubling of the progressive jittered set `set` of pixel `pixel`: from
/// one sample per cell of a `g x g` grid, one in each cell's sub-cell diagonal to it; from
/// there, one in each of the two other sub-cells (the set is then one sample per cell of the
/// `2g x 2g` grid).
fn extend_progressive(set: &mut Vec<Vec2>, seed: u64, pixel: glam::UVec2) {
    let t = set.len();
    let square = t.trailing_zeros().is_multiple_of(2);
    let originals = if square { t } else { t / 2 };
    let g = (originals as f64).sqrt().round() as f32;
    // One hash of the pixel and the step; each new sample mixes in its index.
    let base = hash_words(&[
        seed,
        0x9e0,
        u64::from(pixel.x),
        u64::from(pixel.y),
        t as u64,
    ]);
    for i in 0..originals {
        let p = set[i];
        // Positions are in [0, 1): truncation is the floor.
        let floor = |v: Vec2| Vec2::new(v.x as u32 as f32, v.y as u32 as f32);
        let cell = floor(p * g);
        let sub = floor(p * (2.0 * g)) - 2.0 * cell;
        let subs: &[Vec2] = if square {
            &[Vec2::new(1.0 - sub.x, 1.0 - sub.y)]
        } else {
            &[Vec2::new(1.0 - sub.x, sub.y), Vec2::new(sub.x, 1.0 - sub.y)]
        };
        for (k, sc) in subs.iter().enumerate() {
            let h = mix64(base ^ ((i as u64) << 1 | k as u64));
            let j = Vec2::new(unit_float(h), unit_float(mix64(h)));
            let u = (2.0 * cell + *sc + j) / (2.0 * g);
            set.push(u.min(Vec2::splat(1.0 - f32::EPSILON / 2.0)));
        }
    }
}

impl PreparedAdaptive {
    /// Pass 1 of a pixel: the beam, then the two probe sets, unless the beam settles it.
    fn probe(&self, s: &ViewSample, wants: Wants, buf: &mut Buffers, counts: &mut Counts) -> Acc {
        let (c, p) = (&self.config, &self.inner.p);
        let rb = self
            .base
            .receiver_beam(p, s, c.batch as usize, &mut buf.scratch);
        counts.add(&rb.counts);
        let mut acc = Acc {
            valid: true,
            lit: true,
            dark: true,
            ..Acc::default()
        };
        acc.beam_too_many = rb.mode == BeamResult::TooMany;
        if rb.mode == BeamResult::Clear && rb.light_above && !wants.textured && !wants.direct {
            counts.unsampled += 1;
            acc.clear = true;
            return acc;
        }
        let mut means = [[0.0f64; 3]; 2];
        for (j, m) in means.iter_mut().enumerate() {
            let sampler = if j == 0 { &c.first } else { &c.replicate };
            sampler.unit_samples(s.pixel, &mut buf.units);
            let units = std::mem::take(&mut buf.units);
            let (sum, rgb) = self.trace(s, &rb, &units, wants, buf, counts, &mut acc);
            buf.units = units;
            let len = f64::from(c.batch);
            *m = if wants.textured {
                rgb.map(|x| x / len)
            } else {
                [sum / len; 3]
            };
        }
        acc.progressive = c.batch;
        acc.replicate_var = (0..3)
            .map(|ch| 0.5 * (means[0][ch] - means[1][ch]).powi(2))
            .fold(0.0, f64::max);
        acc
    }

    /// Traces the light samples at unit positions `units` from `s` into `acc`; returns their
    /// sum and RGB sums.
    #[expect(
        clippy::too_many_arguments,
        reason = "one pixel's samples: the receiver, its beam, the positions, what to accumulate \
                  and the thread's buffers and counters"
    )]
    fn trace(
        &self,
        s: &ViewSample,
        rb: &crate::reference::ReceiverBeam,
        units: &[Vec2],
        wants: Wants,
        buf: &mut Buffers,
        counts: &mut Counts,
        acc: &mut Acc,
    ) -> (f64, [f64; 3]) {
        let p = &self.inner.p;
        let light = p.light.as_ref();
        buf.samples.clear();
        light.sample_into(units, &mut buf.samples);
        let mut k = self
            .base
            .sample_visibility(p, s, rb, &buf.samples, &mut buf.scratch);
        // The receiver's beam was counted once, in the probe.
        k.beam_clear = 0;
        k.beam_candidates = 0;
        k.beam_fallback = 0;
        counts.add(&k);
        let vis = &buf.scratch.vis;
        let sum: f64 = vis.iter().map(|&v| f64::from(v)).sum();
        let mut rgb = [0.0f64; 3];
        if wants.textured {
            for (y, &v) in buf.samples.iter().zip(vis) {
                for (ch, r) in rgb.iter_mut().enumerate() {
                    *r += f64::from(y.radiance[ch] * v);
                }
            }
        }
        if wants.direct {
            let albedo = s.albedo_in(p.scene.as_ref());
            let point = light.area() == 0.0;
            for (y, &v) in buf.samples.iter().zip(vis) {
                if v > 0.0 {
                    acc.direct += v * sample_term(s, albedo, y, point);
                }
            }
        }
        acc.n += vis.len() as u32;
        acc.sum += sum;
        for ch in 0..3 {
            acc.rgb[ch] += rgb[ch];
        }
        acc.lit &= vis.iter().all(|&v| v == 1.0);
        acc.dark &= vis.iter().all(|&v| v == 0.0);
        (sum, rgb)
    }

    /// Pass 2 of a pixel: its progressive set grown to `count` samples.
    fn grow(
        &self,
        s: &ViewSample,
        mut acc: Acc,
        count: u32,
        wants: Wants,
        buf: &mut Buffers,
        counts: &mut Counts,
    ) -> Acc {
        let c = &self.config;
        if count <= acc.progressive {
            return acc;
        }
        let p = &self.inner.p;
        let rb = if acc.beam_too_many {
            self.base.receiver_without_beam(p, s)
        } else {
            self.base
                .receiver_beam(p, s, c.batch as usize, &mut buf.scratch)
        };
        c.first.unit_samples(s.pixel, &mut buf.progressive);
        while (buf.progressive.len() as u32) < count {
            let from = buf.progressive.len();
            extend_progressive(&mut buf.progressive, c.seed, s.pixel);
            let set = std::mem::take(&mut buf.progressive);
            self.trace(s, &rb, &set[from..], wants, buf, counts, &mut acc);
            buf.progressive = set;
        }
        acc.progressive = buf.progressive.len() as u32;
        acc
    }
}

impl PreparedAdaptive {
    /// The probe pass alone over `view` (pass 1 of the module docs), summarised: what the
    /// `auto` chooser predicts the error of a stratified count from. Deterministic for a seed
    /// and independent of the thread count, but for `seconds`.
    pub fn probe_view(&self, view: &ViewSamples) -> ProbeSummary {
        let wants = Wants {
            textured: self.inner.p.light.is_textured(),
            direct: false,
        };
        let t0 = std::time::Instant::now();
        let (w, h) = (view.width(), view.height());
        let rows: Vec<ProbeSummary> = (0..h)
            .into_par_iter()
            .map(|y| {
                let (mut buf, mut counts) = (Buffers::default(), Counts::default());
                let mut sum = ProbeSummary::default();
                // Sum of c^(2/5) over sampled pixels, kept in `allocation_gain` until the end.
                for x in 0..w {
                    if let Some(s) = view.get_at(x, y) {
                        let acc = self.probe(&s, wants, &mut buf, &mut counts);
                        sum.pixels += 1;
                        if !acc.clear {
                            sum.sampled += 1;
                            sum.penumbra += usize::from(!acc.lit && !acc.dark);
                            sum.shadowed += usize::from(!acc.lit);
                            sum.mean_variance += acc.replicate_var;
                            sum.allocation_gain += acc.replicate_var.powf(0.4);
                        }
                    }
                }
                sum
            })
            .collect();
        let mut total = ProbeSummary {
            batch: self.config.batch,
            ..ProbeSummary::default()
        };
        let mut powers = 0.0;
        for r in rows {
            total.pixels += r.pixels;
            total.sampled += r.sampled;
            total.penumbra += r.penumbra;
            total.shadowed += r.shadowed;
            total.mean_variance += r.mean_variance;
            powers += r.allocation_gain;
        }
        let sampled = total.sampled.max(1) as f64;
        let (mean_c, mean_p) = (total.mean_variance / sampled, powers / sampled);
        total.allocation_gain = if mean_p > 0.0 {
            mean_c.powf(2.0 / 3.0) / mean_p.powf(5.0 / 3.0)
        } else {
            1.0
        };
        total.mean_variance /= total.pixels.max(1) as f64;
        total.seconds = t0.elapsed().as_secs_f64();
        total
    }
}

/// The variance pixel `(x, y)` plans with: the mean of the probe's replicate variances over
/// the sampled pixels of its 3 x 3 neighbourhood.
fn neighbourhood_variance(probe: &[Acc], w: usize, h: usize, x: usize, y: usize) -> f64 {
    let (mut sum, mut n) = (0.0, 0u32);
    for yy in y.saturating_sub(1)..(y + 2).min(h) {
        for xx in x.saturating_sub(1)..(x + 2).min(w) {
            let a = &probe[yy * w + xx];
            if a.valid && !a.clear {
                sum += a.replicate_var;
                n += 1;
            }
        }
    }
    if n == 0 { 0.0 } else { sum / f64::from(n) }
}

/// The variance pixel `i` plans with where the receivers are no image: the mean of the probe's
/// replicate variances over `i` and the sampled pixels of `list` (its nearest receivers).
fn listed_variance(probe: &[Acc], i: usize, list: &[u32]) -> f64 {
    let (mut sum, mut n) = (0.0, 0u32);
    for j in std::iter::once(i).chain(list.iter().map(|&j| j as usize)) {
        let a = &probe[j];
        if a.valid && !a.clear {
            sum += a.replicate_var;
            n += 1;
        }
    }
    if n == 0 { 0.0 } else { sum / f64::from(n) }
}

impl PreparedShadows for PreparedAdaptive {
    fn name(&self) -> &str {
        &self.config.name
    }

    fn preparation(&self) -> &Stats {
        &self.inner.stats
    }

    fn light(&self) -> &dyn AreaLight {
        self.inner.p.light.as_ref()
    }

    fn check_outputs(&self, outputs: Outputs) -> Result<(), TechniqueError> {
        if outputs.per_sample {
            return Err(TechniqueError::unsupported(
                &self.config.name,
                UnsupportedReason::Configuration(
                    "the adaptive reference draws a different number of samples per pixel, so \
                     it has no per-sample visibility"
                        .into(),
                ),
            ));
        }
        Ok(())
    }

    /// The adaptive pass computes direct light beside the visibility, from the same samples.
    /// Receivers without a camera are laid out along a space-filling curve first
    /// ([`shadow_core::spatial_order::SpatialOrder`]), since the variance is pooled over image
    /// neighbours, and answered in the caller's order.
    fn pass(&self, view: &ViewSamples, outputs: Outputs) -> Result<Estimate, TechniqueError> {
        if view.raster_view().is_some() {
            return self.image_pass(view, outputs, None);
        }
        let order = view.spatially_ordered();
        // The 3 x 3 neighbourhood's eight, found in space.
        let neighbours = order.neighbours::<8>(POINT_NEIGHBOUR_WINDOW);
        let est = self.image_pass(&order.view, outputs, Some(&neighbours))?;
        order.restore(view, est)
    }
}

/// How far along the space-filling curve the neighbours of a receiver without a camera are
/// looked for, each way.
const POINT_NEIGHBOUR_WINDOW: usize = 24;

impl PreparedAdaptive {
    /// The pass on receivers laid out as an image: each pixel's variance is pooled over its
    /// 3 x 3 neighbourhood, or over `neighbours` (pixel lists) where the layout is not an image.
    fn image_pass(
        &self,
        view: &ViewSamples,
        outputs: Outputs,
        neighbours: Option<&[Vec<u32>]>,
    ) -> Result<Estimate, TechniqueError> {
        let textured = self.inner.p.light.is_textured();
        let wants = Wants {
            textured,
            direct: outputs.direct,
        };
        let light = self.inner.p.light.as_ref();
        let (w, h) = (view.width() as usize, view.height() as usize);
        let schedule = &self.config.schedule;
        let mut stats = Stats::default();
        let rows: Vec<(Vec<Acc>, Counts)> = stats.time(RefPhase::Trace, || {
            let probe: Vec<(Vec<Acc>, Counts)> = (0..h)
                .into_par_iter()
                .map(|row| {
                    let (mut buf, mut counts) = (Buffers::default(), Counts::default());
                    let line = (0..w)
                        .map(|x| match view.get_at(x as u32, row as u32) {
                            Some(s) => self.probe(&s, wants, &mut buf, &mut counts),
                            None => Acc::default(),
                        })
                        .collect();
                    (line, counts)
                })
                .collect();
            let mut probe_counts = Counts::default();
            let mut flat = Vec::with_capacity(w * h);
            for (line, c) in probe {
                probe_counts.add(&c);
                flat.extend(line);
            }
            let vars: Vec<f64> = (0..w * h)
                .map(|i| {
                    let a = &flat[i];
                    if !a.valid || a.clear {
                        0.0
                    } else if let Some(lists) = neighbours {
                        listed_variance(&flat, i, &lists[i])
                    } else {
                        neighbourhood_variance(&flat, w, h, i % w, i / w)
                    }
                })
                .collect();
            let target = f64::from(self.config.target);
            let plan = crate::allocation::allocate(&vars, view.valid_count(), target, schedule);
            let mut rows: Vec<(Vec<Acc>, Counts)> = (0..h)
                .into_par_iter()
                .map(|row| {
                    let (mut buf, mut counts) = (Buffers::default(), Counts::default());
                    let line = (0..w)
                        .map(|x| {
                            let (i, acc) = (row * w + x, flat[row * w + x]);
                            match view.get_at(x as u32, row as u32) {
                                Some(s) if acc.valid && !acc.clear => {
                                    self.grow(&s, acc, plan[i], wants, &mut buf, &mut counts)
                                }
                                _ => acc,
                            }
                        })
                        .collect();
                    (line, counts)
                })
                .collect();
            rows.push((Vec::new(), probe_counts));
            rows
        });
        let mut vis = if textured {
            VisibilityImage::rgb_buffer(view)
        } else {
            VisibilityImage::scalar(view)
        };
        let mut classes = Vec::with_capacity(view.len());
        let mut direct_out = outputs.direct.then(|| Vec::with_capacity(view.len()));
        let mut stopped = vec![0u64; schedule.len() + 1];
        let (mut total, mut most) = (0u64, 0u32);
        let mut counts = Counts::default();
        let mut i = 0;
        for (line, c) in &rows {
            counts.add(c);
            for acc in line {
                if acc.valid {
                    let (v, rgb, d, class) = acc.result(light);
                    if textured {
                        vis.rgbs_mut()[i] = rgb;
                    } else {
                        vis.scalars_mut()[i] = v;
                    }
                    classes.push(class);
                    if let Some(o) = direct_out.as_mut() {
                        o.push(d);
                    }
                    let level = if acc.clear {
                        0
                    } else {
                        1 + schedule
                            .iter()
                            .position(|&n| n == acc.progressive)
                            .unwrap_or(0)
                    };
                    stopped[level] += 1;
                    total += u64::from(acc.n);
                    most = most.max(acc.n);
                } else {
                    classes.push(PixelClass::Background);
                    if let Some(o) = direct_out.as_mut() {
                        o.push(Vec3::ZERO);
                    }
                }
                i += 1;
            }
        }
        let capped = stopped.last().copied().unwrap_or(0);
        stats.add(RefCounter::OcclusionRays, counts.rays);
        stats.add(RefCounter::RaysSingle, counts.traversed);
        stats.add(RefCounter::PixelsBeamClear, counts.beam_clear);
        stats.add(RefCounter::PixelsBeamCandidates, counts.beam_candidates);
        stats.add(RefCounter::PixelsBeamFallback, counts.beam_fallback);
        stats.add(RefCounter::PixelsLitWithoutSamples, counts.unsampled);
        stats.add(RefCounter::AdaptiveSamples, total);
        stats.add(RefCounter::Pixels, view.valid_count() as u64);
        stats.add(RefCounter::PixelsAtCap, capped);
        stats.add(RefCounter::PixelsWithoutSamples, stopped[0]);
        for (j, n) in stopped.iter().enumerate().skip(1) {
            stats.add_to_bucket(
                RefCounter::PixelsByProgressiveSamples,
                u64::from(schedule[j - 1]),
                *n,
            );
        }
        stats.gauge_max(RefGauge::AdaptiveMaxSamplesPerPixel, u64::from(most));
        stats.gauge_max(RefGauge::Threads, rayon::current_num_threads() as u64);
        vis.set_classes(classes)?;
        vis.validate()?;
        let mut est = Estimate::new(vis, stats);
        est.direct = direct_out;
        Ok(est)
    }
}
