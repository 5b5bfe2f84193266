//! The ray-traced reference as a [`ShadowTechnique`] (`ref`): for every view sample, the light
//! samples of a [`LightSampler`] are tested for occlusion with the BVH and the visibility
//! coefficient `V(p)` (DCS eq. 1), its RGB form for textured lights (DCS eq. 2) and, on request,
//! the direct illumination (DCS eq. 6 estimator of eq. 4) are accumulated.
//!
//! Modes:
//! * stratified: `N` jittered stratified samples per pixel (default 1024);
//! * same samples: exactly the sampler another technique declares, with per-sample visibility;
//! * semi-opaque occluders: the product of the transmittances of every surface a segment crosses
//!   (the physically right answer DCS's saturating sum approximates);
//! * hard: one sample at the light centre (the point-light limit).
//!
//! A sample below the receiver's tangent plane (camera-facing geometric normal) is occluded
//! without a ray; the receiver's own triangle is never an occluder of its samples (it cannot be:
//! the sample is above its plane), which keeps the origin offset small. Pixels are independent
//! and their samples come from a counter-based hash, so the output is identical whatever the
//! thread count.
//!
//! Work a receiver does not need is skipped, with identical answers: for planar lights one
//! pyramid traversal of the BVH2 per receiver ([`crate::beam`]) proves most receivers fully
//! lit (their samples are then not even generated when the whole light is above their horizon)
//! or yields a short candidate list; only receivers whose beam holds many triangles query the
//! CWBVH segment by segment, last occluder first.

use shadow_core::spatial_order::in_spatial_order;
use std::sync::Arc;

use glam::{UVec2, Vec2, Vec3};
use rayon::prelude::*;
use serde_json::json;
use shadow_core::direct::pixel_direct;
use shadow_core::light::{LightSample, PointLight};
use shadow_core::prelude::*;
use shadow_core::sampling::SamplingError;

use crate::beam::Beam;
use crate::bvh::{BeamCandidates, BeamResult, OcclusionBvh};
use crate::offset::RayOffset;
use crate::statistics::{RefCounter, RefGauge, RefPhase};

/// Where the reference takes its light samples from.
#[derive(Debug, Clone, PartialEq)]
pub enum SampleSource {
    /// A stratified sampler of its own.
    Stratified,
    /// Exactly another technique's samples.
    Same,
    /// One sample at the light centre (hard shadow).
    Hard,
}

/// Receivers with fewer samples than this skip the beam (a single ray is cheaper).
const BEAM_MIN_SAMPLES: usize = 4;
/// Largest candidate list tested segment by segment; beyond it the BVH answers each segment.
const BEAM_CANDIDATES: usize = 16;

/// Per-thread buffers reused across receivers.
#[derive(Default)]
pub(crate) struct Scratch {
    pub(crate) vis: Vec<f32>,
    candidates: BeamCandidates,
}

/// Per-thread buffers of [`PreparedReference::pixel_visibility`], reused across its calls.
#[derive(Default)]
pub struct PixelScratch(Scratch);

/// What a receiver's beam found.
pub(crate) struct ReceiverBeam {
    origin: Vec3,
    pub(crate) mode: BeamResult,
    pub(crate) light_above: bool,
    pub(crate) counts: Counts,
}

/// Work counters of one receiver (or a row of them).
#[derive(Default, Clone, Copy)]
pub(crate) struct Counts {
    pub(crate) rays: u64,
    pub(crate) traversed: u64,
    pub(crate) beam_clear: u64,
    pub(crate) beam_candidates: u64,
    pub(crate) beam_fallback: u64,
    pub(crate) unsampled: u64,
}

impl Counts {
    pub(crate) fn add(&mut self, o: &Counts) {
        self.rays += o.rays;
        self.traversed += o.traversed;
        self.beam_clear += o.beam_clear;
        self.beam_candidates += o.beam_candidates;
        self.beam_fallback += o.beam_fallback;
        self.unsampled += o.unsampled;
    }
}

/// What [`Reference`] builds per scene and light.
pub(crate) struct Prepared {
    quad: Option<[Vec3; 4]>,
    pub(crate) scene: SceneRef,
    semi_opaque: bool,
    pub(crate) light: Light,
    /// Shared between preparations of the same scene ([`Reference::prepare_sharing`]).
    bvh: Arc<OcclusionBvh>,
    offset: RayOffset,
    /// Each light sample emits from the front of its own surface only (mesh lights, whose
    /// triangles face many ways): a sample facing away from the receiver contributes nothing.
    one_sided: bool,
}

impl Prepared {
    /// False when light sample `y` emits nothing toward view sample `s` (see `one_sided`).
    #[inline]
    fn faces(&self, s: &ViewSample, y: &LightSample) -> bool {
        !self.one_sided || (s.position - y.position).dot(y.normal) > 0.0
    }
}

/// The ray-traced reference: a configuration ([`ShadowTechnique::prepare`] or
/// [`Reference::prepare_reference`] gives the [`PreparedReference`] that estimates).
#[derive(Clone)]
pub struct Reference {
    name: String,
    source: SampleSource,
    sampler: LightSampler,
    per_sample: bool,
    beam: bool,
}

/// The reference prepared for one scene and light: its BVH, ray offsets and light.
pub struct PreparedReference {
    config: Reference,
    pub(crate) p: Prepared,
    pub(crate) stats: Stats,
}

impl std::fmt::Debug for PreparedReference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PreparedReference")
            .field("config", &self.config)
            .finish_non_exhaustive()
    }
}

impl std::fmt::Debug for Reference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Reference")
            .field("name", &self.name)
            .field("source", &self.source)
            .field("samples", &self.sampler.count())
            .finish()
    }
}

/// Outgoing radiance per pixel under diffuse shading (DCS eq. 6), background black.
pub type DirectImage = Vec<Vec3>;

impl Reference {
    /// `samples` stratified samples per pixel with `seed`.
    ///
    /// # Errors
    /// [`SamplingError`] for a sample count outside the sampler's range.
    pub fn stratified(samples: u32, seed: u64) -> Result<Self, SamplingError> {
        Ok(Self {
            name: if samples == 1024 {
                "ref".into()
            } else {
                format!("ref-{samples}")
            },
            source: SampleSource::Stratified,
            sampler: LightSampler::new(SamplingStrategy::Stratified, samples, seed)?,
            per_sample: false,
            beam: true,
        })
    }

    /// Exactly the samples of `sampler`, with per-sample visibility in the output.
    pub fn same_samples(sampler: LightSampler) -> Self {
        Self {
            name: "ref-same-samples".into(),
            source: SampleSource::Same,
            sampler,
            per_sample: true,
            beam: true,
        }
    }

    /// The hard shadow of the light's centre (point-light limit).
    pub fn hard() -> Self {
        Self {
            name: "ref-hard".into(),
            source: SampleSource::Hard,
            sampler: LightSampler::new(SamplingStrategy::Correlated, 1, 0)
                .expect("one sample is valid"),
            per_sample: true,
            beam: true,
        }
    }

    /// Also return per-sample visibility (bits: 1 = no surface crossed).
    #[must_use]
    pub fn with_per_sample(mut self, on: bool) -> Self {
        self.per_sample = on;
        self
    }

    /// Turns beam culling on (the default) or off. Off, every segment is a single-ray BVH query;
    /// the answers are identical either way (the tests check it), only the time differs.
    #[must_use]
    pub fn with_beam(mut self, on: bool) -> Self {
        self.beam = on;
        self
    }

    /// Renames the instance (presets).
    #[must_use]
    pub fn named(mut self, name: &str) -> Self {
        self.name = name.into();
        self
    }

    /// Builds the BVH and everything else per scene and light.
    ///
    /// # Errors
    /// [`TechniqueError::InvalidInput`] for a zero-area light whose point light is invalid.
    pub fn prepare_reference(
        &self,
        scene: SceneRef,
        light: Light,
    ) -> Result<PreparedReference, TechniqueError> {
        let mut stats = Stats::default();
        let bvh = stats.time(RefPhase::BvhBuild, || OcclusionBvh::build(scene.as_ref()));
        self.prepare_on(Arc::new(bvh), scene, light, stats)
    }

    /// Everything per light on a BVH already built for `scene`; `stats` holds the BVH's cost
    /// (or that it was shared).
    fn prepare_on(
        &self,
        bvh: Arc<OcclusionBvh>,
        scene: SceneRef,
        light: Light,
        mut stats: Stats,
    ) -> Result<PreparedReference, TechniqueError> {
        stats.add(RefCounter::Triangles, scene.triangle_count() as u64);
        let light: Light = if light.area() == 0.0 {
            Arc::new(
                PointLight::new(light.center(), light.radiance().clone())
                    .map_err(|e| TechniqueError::InvalidInput(e.to_string()))?,
            )
        } else {
            light
        };
        let quad = if self.source == SampleSource::Hard {
            None
        } else {
            light.geometry().bounding_quad()
        };
        let offset = RayOffset::for_light(&*light);
        let p = Prepared {
            one_sided: light.kind() == LightKind::Mesh && self.source != SampleSource::Hard,
            quad,
            semi_opaque: scene.has_semi_opaque(),
            scene,
            light,
            bvh,
            offset,
        };
        Ok(PreparedReference {
            config: self.clone(),
            p,
            stats,
        })
    }

    /// This configuration prepared for the scene and light `other` was prepared for, sharing
    /// its BVH instead of building another (the `auto` chooser runs the reference after a
    /// probe that built one).
    pub fn prepare_sharing(&self, other: &PreparedReference) -> PreparedReference {
        let o = &other.p;
        let quad = if self.source == SampleSource::Hard {
            None
        } else {
            o.light.geometry().bounding_quad()
        };
        let mut stats = Stats::default();
        stats.add(RefCounter::BvhShared, 1);
        stats.add(RefCounter::Triangles, o.scene.triangle_count() as u64);
        PreparedReference {
            config: self.clone(),
            p: Prepared {
                quad,
                scene: o.scene.clone(),
                semi_opaque: o.semi_opaque,
                light: o.light.clone(),
                bvh: o.bvh.clone(),
                offset: o.offset,
                one_sided: o.one_sided && self.source != SampleSource::Hard,
            },
            stats,
        }
    }

    /// The light samples of a pixel (the centre alone in hard mode).
    fn pixel_samples(
        &self,
        light: &dyn AreaLight,
        pixel: UVec2,
        units: &mut Vec<Vec2>,
        out: &mut Vec<LightSample>,
    ) {
        out.clear();
        if self.source == SampleSource::Hard {
            let c = light.center();
            out.push(LightSample {
                position: c,
                normal: Vec3::ZERO,
                uv: Vec2::splat(0.5),
                radiance: light.radiance().mean(),
            });
            return;
        }
        self.sampler.unit_samples(pixel, units);
        light.sample_into(units, out);
    }

    /// The beam of one receiver (when the light is planar and there are enough samples to
    /// share it): its robust origin and what a traversal of the BVH2 with it found.
    pub(crate) fn receiver_beam(
        &self,
        p: &Prepared,
        s: &ViewSample,
        samples: usize,
        scratch: &mut Scratch,
    ) -> ReceiverBeam {
        let origin = p.offset.offset(s.position, s.geometric_normal);
        let mut counts = Counts::default();
        let beam = match p.quad {
            Some(q) if self.beam && samples >= BEAM_MIN_SAMPLES => {
                Beam::new(origin, q, Beam::rounding_slack(origin, &q))
            }
            _ => None,
        };
        let mode = match beam {
            Some(b) => {
                p.bvh
                    .beam_candidates(&b, s.triangle, BEAM_CANDIDATES, &mut scratch.candidates)
            }
            None => BeamResult::TooMany,
        };
        match (beam.is_some(), mode) {
            (false, _) => {}
            (true, BeamResult::Clear) => counts.beam_clear = 1,
            (true, BeamResult::Candidates(_)) => counts.beam_candidates = 1,
            (true, BeamResult::TooMany) => counts.beam_fallback = 1,
        }
        // The whole light (its quad, by convexity) above the tangent plane from both the
        // surface point and the offset origin: no sample is below the horizon.
        let n = s.geometric_normal;
        let light_above = p.quad.is_some_and(|q| {
            q.iter()
                .all(|c| (*c - s.position).dot(n) > 0.0 && (*c - origin).dot(n) > 0.0)
        });
        ReceiverBeam {
            origin,
            mode,
            light_above,
            counts,
        }
    }

    /// A receiver's beam known in advance to hold too many candidates: its robust origin and
    /// the per-segment BVH query, without traversing the beam again.
    pub(crate) fn receiver_without_beam(&self, p: &Prepared, s: &ViewSample) -> ReceiverBeam {
        ReceiverBeam {
            origin: p.offset.offset(s.position, s.geometric_normal),
            mode: BeamResult::TooMany,
            light_above: false,
            counts: Counts::default(),
        }
    }

    /// Visibility of each light sample from view sample `s` (transmittance in [0, 1]), and the
    /// work done.
    pub(crate) fn sample_visibility(
        &self,
        p: &Prepared,
        s: &ViewSample,
        rb: &ReceiverBeam,
        samples: &[LightSample],
        scratch: &mut Scratch,
    ) -> Counts {
        let vis = &mut scratch.vis;
        vis.clear();
        let mut counts = rb.counts;
        let (origin, mode) = (rb.origin, rb.mode);
        let cands = &scratch.candidates;
        let mut last = u32::MAX;
        for y in samples {
            if !p.faces(s, y) {
                vis.push(0.0);
                continue;
            }
            let Some((origin, dir, t_max)) = segment_from(origin, s, y.position) else {
                vis.push(0.0);
                continue;
            };
            counts.rays += 1;
            vis.push(match (mode, p.semi_opaque) {
                (BeamResult::Clear, _) => 1.0,
                (BeamResult::Candidates(_), true) => {
                    p.bvh.transmittance_by(cands, origin, dir, t_max).0
                }
                (BeamResult::Candidates(_), false) => {
                    if p.bvh.occluded_by(cands, origin, dir, t_max) {
                        0.0
                    } else {
                        1.0
                    }
                }
                (BeamResult::TooMany, true) => {
                    counts.traversed += 1;
                    p.bvh.transmittance(origin, dir, t_max, s.triangle).0
                }
                (BeamResult::TooMany, false) => {
                    // Shadow cache: the triangle that blocked the previous segment of this
                    // receiver is tried first; neighbouring samples usually share it.
                    counts.traversed += 1;
                    if p.bvh
                        .occluded_cached(origin, dir, t_max, s.triangle, &mut last)
                    {
                        0.0
                    } else {
                        1.0
                    }
                }
            });
        }
        counts
    }
}

fn segment(p: &Prepared, s: &ViewSample, y: Vec3) -> Option<(Vec3, Vec3, f32)> {
    segment_from(p.offset.offset(s.position, s.geometric_normal), s, y)
}

/// The segment from the offset `origin` of view sample `s` to `y` (see [`Reference::segment`]).
#[inline]
fn segment_from(origin: Vec3, s: &ViewSample, y: Vec3) -> Option<(Vec3, Vec3, f32)> {
    if (y - s.position).dot(s.geometric_normal) <= 0.0 {
        return None;
    }
    let d = y - origin;
    if d.dot(s.geometric_normal) <= 0.0 {
        return None;
    }
    let dist = d.length();
    Some((origin, d / dist, dist * (1.0 - 1e-6)))
}

/// The light's centre as a point light, for hard-mode direct illumination.
#[derive(Debug)]
struct HardLight(Vec3);

impl AreaLight for HardLight {
    fn geometry(&self) -> shadow_core::light::LightGeometry<'_> {
        shadow_core::light::LightGeometry::Point { position: self.0 }
    }
    fn area(&self) -> f32 {
        0.0
    }
    fn center(&self) -> Vec3 {
        self.0
    }
    fn bounds(&self) -> shadow_core::geometry::Aabb {
        shadow_core::geometry::Aabb::from_points(&[self.0])
    }
    fn point_at(&self, u: Vec2) -> (Vec3, Vec3, Vec2) {
        (self.0, Vec3::ZERO, u)
    }
    fn radiance(&self) -> &Radiance {
        static ONE: Radiance = Radiance::Constant(Vec3::ONE);
        &ONE
    }
}

use shadow_core::view_samples::ViewSample;

impl ShadowTechnique for Reference {
    fn name(&self) -> &str {
        &self.name
    }

    fn capabilities(&self) -> Capabilities {
        Capabilities::any_input(self.source != SampleSource::Stratified, Processor::Cpu)
    }

    fn parameters(&self) -> serde_json::Value {
        json!({
            "mode": format!("{:?}", self.source),
            "samples": if self.source == SampleSource::Hard { 1 } else { self.sampler.count() },
            "strategy": format!("{:?}", self.sampler.strategy()),
            "seed": self.sampler.seed(),
            "per_sample": self.per_sample,
            "beam_culling": self.beam,
        })
    }

    fn light_sampler(&self) -> Option<&LightSampler> {
        (self.source != SampleSource::Hard).then_some(&self.sampler)
    }

    fn prepare(
        &self,
        scene: SceneRef,
        light: Light,
    ) -> Result<Box<dyn PreparedShadows>, TechniqueError> {
        Ok(Box::new(self.prepare_reference(scene, light)?))
    }

    /// One BVH for every light: the first light's preparation builds it, the others share it
    /// (`bvh-shared`).
    fn prepare_each(
        &self,
        scene: SceneRef,
        lights: &[Light],
    ) -> Vec<Result<Box<dyn PreparedShadows>, TechniqueError>> {
        let mut shared: Option<Arc<OcclusionBvh>> = None;
        lights
            .iter()
            .map(|light| {
                let prepared = match &shared {
                    Some(bvh) => {
                        let mut stats = Stats::default();
                        stats.add(RefCounter::BvhShared, 1);
                        self.prepare_on(bvh.clone(), scene.clone(), light.clone(), stats)?
                    }
                    None => {
                        let p = self.prepare_reference(scene.clone(), light.clone())?;
                        shared = Some(p.p.bvh.clone());
                        p
                    }
                };
                Ok(Box::new(prepared) as Box<dyn PreparedShadows>)
            })
            .collect()
    }
}

impl PreparedShadows for PreparedReference {
    fn name(&self) -> &str {
        &self.config.name
    }

    fn preparation(&self) -> &Stats {
        &self.stats
    }

    fn light(&self) -> &dyn AreaLight {
        self.p.light.as_ref()
    }

    /// A caller's points are traced in a spatial order, so that beams hold receivers close in
    /// space ([`in_spatial_order`]).
    fn pass(&self, view: &ViewSamples, outputs: Outputs) -> Result<Estimate, TechniqueError> {
        let per_sample = self.config.per_sample || outputs.per_sample;
        in_spatial_order(view, |v| self.config.run(&self.p, v, per_sample))
    }

    fn direct_light(&self, view: &ViewSamples, _: &Estimate) -> Result<Vec<Vec3>, TechniqueError> {
        Ok(self.direct_illumination(view))
    }
}

impl PreparedReference {
    /// The BVH.
    pub fn bvh(&self) -> &OcclusionBvh {
        &self.p.bvh
    }

    /// The visibility of each of `samples` (any sampler's light samples, in order) from view
    /// sample `s`, found exactly as [`PreparedShadows::estimate`] finds it for the same samples
    /// (the receiver's beam, its candidate list or the BVH segment by segment): per sample 1 or
    /// 0 (the transmittance in `[0, 1]` on semi-opaque scenes), 0 below the receiver's horizon.
    /// Returns the visibilities (in `scratch`) and the segments traced. Other techniques use it
    /// to hand the pixels where rays cost less than their own work to the reference, with the
    /// same answers.
    pub fn pixel_visibility<'a>(
        &self,
        s: &ViewSample,
        samples: &[LightSample],
        scratch: &'a mut PixelScratch,
    ) -> (&'a [f32], u64) {
        let c = &self.config;
        let rb = c.receiver_beam(&self.p, s, samples.len(), &mut scratch.0);
        let counts = c.sample_visibility(&self.p, s, &rb, samples, &mut scratch.0);
        (&scratch.0.vis, counts.rays)
    }

    /// The occlusion segment from view sample `s` to light sample `y`: robust origin, unit
    /// direction and length, or `None` when `y` is below the receiver's tangent plane, when
    /// the receiver lies behind a planar light (which emits from its front side only: the
    /// estimate darkens such pixels), or, on a light whose samples emit from one side (a mesh
    /// light), when `y` faces away from the receiver.
    pub fn segment(&self, s: &ViewSample, y: &LightSample) -> Option<(Vec3, Vec3, f32)> {
        if !self.p.faces(s, y) || self.p.light.geometry().behind(s.position) {
            return None;
        }
        segment(&self.p, s, y.position)
    }

    /// Every occlusion segment the reference casts for `view`, in pixel and sample order:
    /// (origin, unit direction, length, receiver triangle). For benchmarks and peer
    /// comparisons on identical rays.
    pub fn segments(&self, view: &ViewSamples) -> Vec<(Vec3, Vec3, f32, u32)> {
        let p = &self.p;
        let (mut units, mut samples) = (Vec::new(), Vec::new());
        let mut out = Vec::new();
        for i in 0..view.len() {
            let Some(s) = view.get(i) else { continue };
            self.config
                .pixel_samples(p.light.as_ref(), s.pixel, &mut units, &mut samples);
            let origin = p.offset.offset(s.position, s.geometric_normal);
            for y in samples.iter().filter(|y| p.faces(&s, y)) {
                if let Some((o, d, t)) = segment_from(origin, &s, y.position) {
                    out.push((o, d, t, s.triangle));
                }
            }
        }
        out
    }

    /// Direct illumination of every view sample (DCS eq. 6 with the exact transmittance).
    ///
    pub fn direct_illumination(&self, view: &ViewSamples) -> DirectImage {
        let (c, p) = (&self.config, &self.p);
        let w = view.width() as usize;
        let mut out = vec![Vec3::ZERO; view.len()];
        out.par_chunks_mut(w).enumerate().for_each(|(row, line)| {
            let (mut units, mut samples, mut scratch) =
                (Vec::new(), Vec::new(), Scratch::default());
            for (x, px) in line.iter_mut().enumerate() {
                let Some(s) = view.get_at(x as u32, row as u32) else {
                    continue;
                };
                c.pixel_samples(p.light.as_ref(), s.pixel, &mut units, &mut samples);
                let rb = c.receiver_beam(p, &s, samples.len(), &mut scratch);
                c.sample_visibility(p, &s, &rb, &samples, &mut scratch);
                let vis = &scratch.vis;
                let albedo = s.albedo_in(p.scene.as_ref());
                let light: &dyn AreaLight = if c.source == SampleSource::Hard {
                    &HardLight(p.light.center())
                } else {
                    p.light.as_ref()
                };
                *px = pixel_direct(&s, albedo, light, &samples, |k| vis[k]);
            }
        });
        out
    }
}

impl Reference {
    /// The estimate of `view` on prepared data `p`, with per-sample bits when `per_sample`.
    fn run(
        &self,
        p: &Prepared,
        view: &ViewSamples,
        per_sample: bool,
    ) -> Result<Estimate, TechniqueError> {
        let mut stats = Stats::default();
        let textured = p.light.is_textured();
        let n = if self.source == SampleSource::Hard {
            1
        } else {
            self.sampler.count()
        };
        let w = view.width() as usize;
        let words = n.div_ceil(64) as usize;
        struct Row {
            v: Vec<f32>,
            rgb: Vec<Vec3>,
            class: Vec<PixelClass>,
            bits: Vec<u64>,
            rays: u64,
            below: u64,
            counts: Counts,
        }
        let rows: Vec<Row> = stats.time(RefPhase::Trace, || {
            (0..view.height() as usize)
                .into_par_iter()
                .map(|row| {
                    let mut r = Row {
                        v: vec![0.0; w],
                        rgb: vec![Vec3::ZERO; if textured { w } else { 0 }],
                        class: vec![PixelClass::Background; w],
                        bits: vec![0; if per_sample { w * words } else { 0 }],
                        rays: 0,
                        below: 0,
                        counts: Counts::default(),
                    };
                    let (mut units, mut samples, mut scratch) =
                        (Vec::new(), Vec::new(), Scratch::default());
                    for x in 0..w {
                        let Some(s) = view.get_at(x as u32, row as u32) else {
                            continue;
                        };
                        let rb = self.receiver_beam(p, &s, n as usize, &mut scratch);
                        let c = if rb.mode == BeamResult::Clear && rb.light_above && !textured {
                            // Fully lit with the whole light above the horizon: every sample
                            // is visible, so none needs to be generated.
                            scratch.vis.clear();
                            scratch.vis.resize(n as usize, 1.0);
                            Counts {
                                rays: n as u64,
                                unsampled: 1,
                                ..rb.counts
                            }
                        } else {
                            self.pixel_samples(p.light.as_ref(), s.pixel, &mut units, &mut samples);
                            self.sample_visibility(p, &s, &rb, &samples, &mut scratch)
                        };
                        let vis = &scratch.vis;
                        r.rays += c.rays;
                        r.below += n as u64 - c.rays;
                        r.counts.add(&c);
                        let sum: f64 = vis.iter().map(|&v| v as f64).sum();
                        r.v[x] = (sum / n as f64) as f32;
                        if textured {
                            let acc = samples
                                .iter()
                                .zip(vis)
                                .fold(Vec3::ZERO, |a, (s, v)| a + s.radiance * *v);
                            r.rgb[x] = acc / n as f32;
                        }
                        let lit = vis.iter().filter(|&&v| v == 1.0).count();
                        r.class[x] = if lit == vis.len() {
                            PixelClass::Lit
                        } else if vis.iter().all(|&v| v == 0.0) {
                            PixelClass::Umbra
                        } else {
                            PixelClass::Penumbra
                        };
                        if per_sample {
                            for (k, &v) in vis.iter().enumerate() {
                                if v == 1.0 {
                                    r.bits[x * words + k / 64] |= 1 << (k % 64);
                                }
                            }
                        }
                    }
                    r
                })
                .collect()
        });
        let mut vis = if textured {
            VisibilityImage::rgb_buffer(view)
        } else {
            VisibilityImage::scalar(view)
        };
        let mut classes = Vec::with_capacity(view.len());
        let mut bits = Vec::with_capacity(if per_sample { view.len() * words } else { 0 });
        for (row, r) in rows.iter().enumerate() {
            if textured {
                vis.rgbs_mut()[row * w..(row + 1) * w].copy_from_slice(&r.rgb);
            } else {
                vis.scalars_mut()[row * w..(row + 1) * w].copy_from_slice(&r.v);
            }
            classes.extend_from_slice(&r.class);
            bits.extend_from_slice(&r.bits);
            stats.add(RefCounter::OcclusionRays, r.rays);
            stats.add(RefCounter::SamplesBelowHorizon, r.below);
            stats.add(RefCounter::RaysSingle, r.counts.traversed);
            stats.add(RefCounter::PixelsBeamClear, r.counts.beam_clear);
            stats.add(RefCounter::PixelsBeamCandidates, r.counts.beam_candidates);
            stats.add(RefCounter::PixelsBeamFallback, r.counts.beam_fallback);
            stats.add(RefCounter::PixelsLitWithoutSamples, r.counts.unsampled);
        }
        stats.add(RefCounter::Pixels, view.valid_count() as u64);
        stats.gauge_max(RefGauge::Threads, rayon::current_num_threads() as u64);
        vis.set_classes(classes)?;
        if per_sample {
            vis.set_per_sample(PerSampleVisibility::Bits {
                samples: n,
                words: bits,
            })?;
        }
        vis.validate()?;
        Ok(Estimate::new(vis, stats))
    }
}
