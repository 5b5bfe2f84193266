//! The adaptive reference (`ref-adaptive-*`): per-pixel sampling toward an error target, so
//! samples go where a pixel's visibility is uncertain and nowhere else (DESIGN section 3,
//! "choosing the work"; the survey's section 4.1 notes that none of the real-time methods it
//! reviews chooses its own quality).
//!
//! Each pixel draws stratified batches of light samples until the estimated standard error of
//! its `V(p)` is at most the target, or its cap is reached:
//! * a receiver whose beam ([`crate::beam`]) proves the whole light visible and above its
//!   horizon stops before any sample (exactly as the uniform reference skips it);
//! * batch `j` (from 0) holds `B` samples for `j` = 0 and 1 and `B * 2^(j-1)` after, so the
//!   total after batch `j` is `B * 2^j` for `j >= 1`; each batch is one jittered stratified set of
//!   its own seed, so batches are independent and every batch is stratified;
//! * the variance of a batch's sum is estimated by collapsed strata (Cochran, "Sampling
//!   Techniques", section 5A.12; the paired-strata estimator): strata are paired with their
//!   horizontal neighbour and `sum (y1 - y2)^2` over the pairs estimates the variance of the
//!   batch's sum from inside the batch. Its expectation is the true variance plus the squared
//!   differences of the paired strata's means, so it never underestimates on average; it is
//!   valid for stratified sampling, where the sample variance of all samples is not (it
//!   ignores the stratification and overstates the error of a sharp edge by far);
//! * `V(p)` is the sample mean over every batch drawn, and its standard error
//!   `sqrt(sum of the batches' variance estimates) / n`.
//!
//! A batch whose samples all agree has a variance estimate of zero and stops the pixel: a pixel
//! fully lit or in umbra pays one batch. Near a penumbra's border a first batch can miss a
//! small occluded (or lit) part of the light; the conformance budgets and the bench measure
//! what that costs against an independent reference, and the first batch's size `B` bounds it.
//!
//! The target bounds every pixel's estimated standard error, so it bounds the image's RMSE as
//! well (pixels that stop on agreement or the beam have no estimated error). The output is
//! deterministic for a seed and independent of the thread count: every decision depends on the
//! pixel's own samples only. Textured lights stop on the largest channel's error. Direct light
//! (DCS eq. 6) is estimated from the same samples, a pixel the beam proves lit drawing its first
//! batch for it.

use glam::{Vec2, Vec3};
use rayon::prelude::*;
use serde_json::json;
use shadow_core::direct::sample_term;
use shadow_core::light::{LightKind, LightSample};
use shadow_core::prelude::*;
use shadow_core::sampling::{MAX_SAMPLES, SamplingError, hash_words};
use shadow_core::view_samples::ViewSample;

use crate::bvh::BeamResult;
use crate::reference::{Counts, PreparedReference, RAYS_COUNTER, Reference, Scratch, TRACE_PHASE};

/// Samples of the first batch by default (an 8 x 8 stratified set).
pub const DEFAULT_BATCH: u32 = 64;
/// The most samples a pixel draws by default.
pub const DEFAULT_CAP: u32 = 4096;
/// The counter of samples the estimate drew (its mean per pixel is this over `pixels`).
pub const SAMPLES_COUNTER: &str = "adaptive-samples";
/// The gauge of the most samples one pixel drew.
pub const MAX_SAMPLES_GAUGE: &str = "adaptive-max-samples-per-pixel";

/// The adaptive reference: a configuration (target, first batch, cap, seed).
#[derive(Debug, Clone)]
pub struct AdaptiveReference {
    name: String,
    target: f32,
    batch: u32,
    cap: u32,
    seed: u64,
    /// One stratified sampler per batch size (`batch`, `batch`, `2 batch`, ... up to `cap`).
    samplers: Vec<LightSampler>,
}

impl AdaptiveReference {
    /// Sampling toward standard error `target` per pixel with first batches of `batch`
    /// samples and at most `cap` samples a pixel.
    ///
    /// # Errors
    /// [`TechniqueError::InvalidInput`] for a target that is not a positive finite number
    /// below 1, a batch that is not a power of two of at least 4, or a cap below the batch or
    /// above [`MAX_SAMPLES`].
    pub fn new(target: f32, batch: u32, cap: u32, seed: u64) -> Result<Self, TechniqueError> {
        if !(target > 0.0 && target < 1.0) {
            return Err(TechniqueError::InvalidInput(format!(
                "adaptive target {target} is not in (0, 1)"
            )));
        }
        if batch < 4 || !batch.is_power_of_two() {
            return Err(TechniqueError::InvalidInput(format!(
                "adaptive batch {batch} is not a power of two of at least 4"
            )));
        }
        if cap < batch || cap > MAX_SAMPLES {
            return Err(TechniqueError::InvalidInput(format!(
                "adaptive cap {cap} is outside {batch}..={MAX_SAMPLES}"
            )));
        }
        let mut samplers = Vec::new();
        let (mut total, mut j) = (0u32, 0u64);
        while total < cap {
            let size = if j == 0 { batch } else { total }.min(cap - total);
            let s = LightSampler::new(
                SamplingStrategy::Stratified,
                size,
                hash_words(&[seed, 0xada, j]),
            )
            .map_err(|e: SamplingError| TechniqueError::InvalidInput(e.to_string()))?;
            samplers.push(s);
            total += size;
            j += 1;
        }
        Ok(Self {
            name: format!("ref-adaptive-{target}"),
            target,
            batch,
            cap,
            seed,
            samplers,
        })
    }

    /// Renames the instance (presets).
    #[must_use]
    pub fn named(mut self, name: &str) -> Self {
        self.name = name.into();
        self
    }

    /// The per-pixel standard-error target.
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

impl ShadowTechnique for AdaptiveReference {
    fn name(&self) -> &str {
        &self.name
    }

    fn capabilities(&self) -> Capabilities {
        Capabilities {
            lights: LightKind::ALL.to_vec(),
            semi_opaque: true,
            textured_lights: true,
            needs_closed_meshes: false,
            sample_based: false,
            processor: Processor::Cpu,
        }
    }

    fn parameters(&self) -> serde_json::Value {
        json!({
            "mode": "Adaptive",
            "target_standard_error": self.target,
            "first_batch": self.batch,
            "cap": self.cap,
            "seed": self.seed,
            "variance_estimator": "collapsed strata (horizontal pairs)",
        })
    }

    fn prepare(
        &self,
        scene: SceneRef,
        light: Light,
    ) -> Result<Box<dyn PreparedShadows>, TechniqueError> {
        let base = Reference::stratified(self.batch, self.seed)?;
        let inner = base.prepare_reference(scene, light)?;
        Ok(Box::new(PreparedAdaptive {
            config: self.clone(),
            base,
            inner,
        }))
    }
}

/// What one pixel's sampling gave.
#[derive(Default, Clone, Copy)]
struct PixelResult {
    v: f32,
    rgb: Vec3,
    direct: Vec3,
    class: Option<PixelClass>,
    samples: u32,
    /// Batches drawn (0: the beam settled it).
    batches: usize,
    capped: bool,
}

/// Per-thread buffers.
#[derive(Default)]
struct Buffers {
    scratch: Scratch,
    units: Vec<Vec2>,
    samples: Vec<LightSample>,
}

impl PreparedAdaptive {
    /// Samples one pixel until its standard error meets the target or the cap is reached.
    fn pixel(
        &self,
        s: &ViewSample,
        textured: bool,
        direct: bool,
        buf: &mut Buffers,
        counts: &mut Counts,
    ) -> PixelResult {
        let (c, p) = (&self.config, &self.inner.p);
        let light = p.light.as_ref();
        let rb = self
            .base
            .receiver_beam(p, s, c.batch as usize, &mut buf.scratch);
        if rb.mode == BeamResult::Clear && rb.light_above && !textured && !direct {
            counts.add(&Counts {
                unsampled: 1,
                ..rb_counts(&rb)
            });
            return PixelResult {
                v: 1.0,
                rgb: Vec3::ONE,
                class: Some(PixelClass::Lit),
                ..PixelResult::default()
            };
        }
        counts.add(&rb_counts(&rb));
        let target = f64::from(c.target);
        let albedo = direct.then(|| p.scene.albedo(s.triangle as usize));
        let point = light.area() == 0.0;
        let (mut sum, mut sum_rgb, mut dir) = (0.0f64, [0.0f64; 3], Vec3::ZERO);
        let (mut var, mut var_rgb) = (0.0f64, [0.0f64; 3]);
        let (mut n, mut lit, mut dark) = (0u32, true, true);
        let mut out = PixelResult::default();
        for (j, sampler) in c.samplers.iter().enumerate() {
            sampler.unit_samples(s.pixel, &mut buf.units);
            light.sample_into(&buf.units, &mut buf.samples);
            let mut k = self
                .base
                .sample_visibility(p, s, &rb, &buf.samples, &mut buf.scratch);
            // The beam counts of the receiver were added once above.
            k.beam_clear = 0;
            k.beam_candidates = 0;
            k.beam_fallback = 0;
            counts.add(&k);
            let vis = &buf.scratch.vis;
            n += vis.len() as u32;
            sum += vis.iter().map(|&v| f64::from(v)).sum::<f64>();
            var += paired_variance(vis.len(), |i| f64::from(vis[i]));
            lit &= vis.iter().all(|&v| v == 1.0);
            dark &= vis.iter().all(|&v| v == 0.0);
            if textured {
                for ch in 0..3 {
                    let y = |i: usize| f64::from(buf.samples[i].radiance[ch] * vis[i]);
                    sum_rgb[ch] += (0..vis.len()).map(y).sum::<f64>();
                    var_rgb[ch] += paired_variance(vis.len(), y);
                }
            }
            if let Some(albedo) = albedo {
                for (y, &v) in buf.samples.iter().zip(vis) {
                    if v > 0.0 {
                        dir += v * sample_term(s, albedo, y, point);
                    }
                }
            }
            out.batches = j + 1;
            let nn = f64::from(n);
            let worst = if textured {
                var_rgb.iter().copied().fold(0.0, f64::max)
            } else {
                var
            };
            if worst.sqrt() / nn <= target {
                break;
            }
            out.capped = j + 1 == c.samplers.len();
        }
        let nn = f64::from(n.max(1));
        out.samples = n;
        out.v = (sum / nn) as f32;
        out.rgb = Vec3::new(
            (sum_rgb[0] / nn) as f32,
            (sum_rgb[1] / nn) as f32,
            (sum_rgb[2] / nn) as f32,
        );
        out.direct = if point {
            dir / nn as f32
        } else {
            dir * (light.area() / nn as f32)
        };
        out.class = Some(if lit {
            PixelClass::Lit
        } else if dark {
            PixelClass::Umbra
        } else {
            PixelClass::Penumbra
        });
        out
    }
}

/// The beam part of a receiver's counts.
fn rb_counts(rb: &crate::reference::ReceiverBeam) -> Counts {
    rb.counts
}

/// The collapsed-strata estimate of the variance of a stratified batch's sum: samples `2i` and
/// `2i + 1` lie in horizontally neighbouring strata (the sampler's cells are in row-major order
/// on a grid whose width is even for every power-of-two count), and `sum (y_2i - y_2i+1)^2`
/// over the pairs estimates the variance of the sum, conservatively.
fn paired_variance(len: usize, y: impl Fn(usize) -> f64) -> f64 {
    (0..len / 2)
        .map(|i| {
            let d = y(2 * i) - y(2 * i + 1);
            d * d
        })
        .sum()
}

impl PreparedShadows for PreparedAdaptive {
    fn name(&self) -> &str {
        &self.config.name
    }

    fn preparation(&self) -> &Stats {
        &self.inner.stats
    }

    fn estimate(&self, view: &ViewSamples, outputs: Outputs) -> Result<Estimate, TechniqueError> {
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
        let textured = self.inner.p.light.is_textured();
        let w = view.width() as usize;
        let mut stats = Stats::default();
        let rows: Vec<(Vec<PixelResult>, Counts)> = stats.time(TRACE_PHASE, || {
            (0..view.height() as usize)
                .into_par_iter()
                .map(|row| {
                    let mut buf = Buffers::default();
                    let mut counts = Counts::default();
                    let line = (0..w)
                        .map(|x| match view.get_at(x as u32, row as u32) {
                            Some(s) => {
                                self.pixel(&s, textured, outputs.direct, &mut buf, &mut counts)
                            }
                            None => PixelResult::default(),
                        })
                        .collect();
                    (line, counts)
                })
                .collect()
        });
        let mut vis = if textured {
            VisibilityImage::rgb_buffer(view)
        } else {
            VisibilityImage::scalar(view)
        };
        let mut classes = Vec::with_capacity(view.len());
        let mut direct = outputs.direct.then(|| Vec::with_capacity(view.len()));
        let mut stopped = vec![0u64; self.config.samplers.len() + 1];
        let (mut total, mut most, mut capped) = (0u64, 0u32, 0u64);
        let mut counts = Counts::default();
        for (row, (line, c)) in rows.iter().enumerate() {
            counts.add(c);
            for (x, r) in line.iter().enumerate() {
                let i = row * w + x;
                if textured {
                    vis.rgbs_mut()[i] = r.rgb;
                } else {
                    vis.scalars_mut()[i] = r.v;
                }
                classes.push(r.class.unwrap_or(PixelClass::Background));
                if let Some(d) = direct.as_mut() {
                    d.push(r.direct);
                }
                if r.class.is_some() {
                    stopped[r.batches] += 1;
                    total += u64::from(r.samples);
                    most = most.max(r.samples);
                    capped += u64::from(r.capped);
                }
            }
        }
        stats.add(RAYS_COUNTER, counts.rays);
        stats.add("rays-single", counts.traversed);
        stats.add("pixels-beam-clear", counts.beam_clear);
        stats.add("pixels-beam-candidates", counts.beam_candidates);
        stats.add("pixels-beam-fallback", counts.beam_fallback);
        stats.add("pixels-lit-without-samples", counts.unsampled);
        stats.add(SAMPLES_COUNTER, total);
        stats.add("pixels", view.valid_count() as u64);
        stats.add("pixels-at-cap", capped);
        for (j, n) in stopped.iter().enumerate() {
            stats.add(&format!("pixels-stopped-at-batch-{j}"), *n);
        }
        stats.gauge_max(MAX_SAMPLES_GAUGE, u64::from(most));
        stats.gauge_max(
            crate::reference::THREADS_GAUGE,
            rayon::current_num_threads() as u64,
        );
        vis.set_classes(classes)?;
        vis.validate()?;
        let mut est = Estimate::new(vis, stats);
        est.direct = direct;
        Ok(est)
    }
}
