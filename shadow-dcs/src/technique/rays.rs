//! DCS or shadow rays, chosen per frame before any per-pixel work (issue 49, the
//! `dcs-*-hybrid` presets, [`Dcs::with_rays`]).
//!
//! DCS's cost follows the wedge pairs of a pixel (section 4.2: every silhouette wedge that
//! holds the view sample), which dense meshes under large lights make many times the light
//! samples: on `grass` 7,800 pairs per per-sample pixel for 64 samples. A shadow ray's cost
//! follows the logarithm of the triangles instead. Both answer the same question on the same
//! light samples (the rays are handed in through [`shadow_core::rays::ShadowRays`]; the
//! reference's agree with DCS sample by sample), so the choice changes the cost, never the
//! answer.
//!
//! The prediction reads what the box hierarchy knows before the scan: the (tile, wedge)
//! candidates whose boxes meet, which the scan would evaluate on the tiles' view samples,
//! counted on an evenly spaced sample of the squares (and of each one's wedges) and scaled to
//! the frame; against them, one ray per light sample of every active pixel, the reference's
//! BVH unless already built, and the shadow-volume pass (section 4.1) that a traced frame
//! skips. Costs are in rays ([`RayChoice`]), measured.
//!
//! A choice per square was built and measured first (`docs/history/dcs-hybrid-2026-12-07.md`):
//! the per-square predictions err by several times either way, so mixed frames traced
//! squares of `bunny` and the corpus that DCS does faster, and left grass squares to DCS; the
//! frame-level choice is right on every scene measured. Counters: `squares-traced`,
//! `pixels-traced`, `occlusion-rays`, `shadow-volumes-skipped`, and the predictions
//! (`predicted-dcs-rays`, `predicted-shadow-volume-rays`, `predicted-traced-rays`,
//! `predicted-bvh-rays`).

use std::sync::OnceLock;

use super::*;
use crate::accel::bins::{SquareScratch, square_tile_wedges};

/// When a frame is traced rather than estimated by DCS: the predicted costs of each side, in
/// units of one shadow ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RayChoice {
    /// DCS's work per (tile, wedge) candidate of a square (of the wedge scan's box hierarchy:
    /// the pairs whose boxes meet, which the scan then evaluates on the tile's view samples).
    pub rays_per_candidate: f32,
    /// How much DCS's work per candidate grows with each 64-sample word past the first (its
    /// covered-sample masks and counters are word by word), as a share of the first word's.
    pub per_further_word: f32,
    /// The shadow-volume pass (section 4.1) per silhouette edge: a frame traced throughout
    /// skips it.
    pub rays_per_shadow_volume: f32,
    /// The reference's BVH build per triangle: nothing is traced in a frame whose predicted
    /// saving is less, unless the BVH is already built.
    pub rays_per_bvh_triangle: f32,
}

impl RayChoice {
    /// Every frame traced, whatever it costs (tests: the ray path alone).
    pub const EVERYWHERE: Self = Self {
        rays_per_candidate: f32::INFINITY,
        per_further_word: 0.0,
        rays_per_shadow_volume: 0.0,
        rays_per_bvh_triangle: 0.0,
    };
}

impl Default for RayChoice {
    /// Measured on 12 built-in and corpus scenes at 64x48 to 512x384, in the time of one of
    /// the scene's own rays (`docs/history/dcs-hybrid-2026-12-07.md`): DCS took 1 to 45 rays
    /// per candidate (1 to 5 on the dense meshes where the choice matters), the shadow-volume
    /// pass 3 to 70 per silhouette edge on dense meshes (more on small scenes, where it is
    /// negligible), the BVH 17 to 110 per triangle; on `grass` at 128x96 DCS's time grew by
    /// 0.42 to 0.45 of its 64-sample figure per further word (1.9 s, 3.9 s and 12.5 s at 64,
    /// 256 and 1024 samples). With these constants every scene measured goes the faster way
    /// (`docs/benchmarks.md`, "DCS or rays").
    fn default() -> Self {
        Self {
            rays_per_candidate: 1.5,
            per_further_word: 0.4,
            rays_per_shadow_volume: 10.0,
            rays_per_bvh_triangle: 30.0,
        }
    }
}

/// Most wedges of a square's list whose box tests predict its DCS work (an evenly spaced
/// sample of longer lists).
const PROBE_WEDGES: usize = 256;

/// Most squares of a frame whose candidates predict its DCS work (an evenly spaced sample).
const PROBE_SQUARES: usize = 128;

/// The shadow-ray side of a hybrid: the caller's tracer prepared on DCS's scene and light,
/// built when first needed.
#[derive(Default)]
pub(super) struct RayPath {
    reference: OnceLock<Option<Box<dyn PreparedRays>>>,
}

impl RayPath {
    /// `tracer` prepared for `p`'s scene and light on `dcs`'s samples, built on the first call
    /// (`None` when it cannot take them, which never happens for the reference on the scenes
    /// DCS takes).
    fn get_or_build(
        &self,
        dcs: &Dcs,
        tracer: &dyn ShadowRays,
        p: &Prepared,
    ) -> Option<&dyn PreparedRays> {
        self.reference
            .get_or_init(|| {
                tracer
                    .prepare_rays(p.scene.clone(), p.light.clone(), &dcs.sampler)
                    .ok()
            })
            .as_deref()
    }
}

/// A square of the wedge scan: its pixels and the wedges its box keeps.
pub(super) struct Job {
    pub(super) rect: Rect,
    pub(super) wedges: Vec<u32>,
}

/// The squares of a frame and where their visibility comes from.
pub(super) struct Plan<'p> {
    pub(super) jobs: Vec<Job>,
    /// The (block, wedge) pairs the box hierarchy kept.
    pub(super) block_wedges: u64,
    /// The reference, when the frame is traced (every square: then no pixel needs an
    /// integration constant).
    pub(super) reference: Option<&'p dyn PreparedRays>,
    /// The predicted work, in rays: DCS's squares, its shadow-volume pass, the rays of every
    /// active pixel, the BVH build (0 once built).
    pub(super) predicted: Option<[f64; 4]>,
}

impl Dcs {
    /// The squares of frame `f` with their wedges, and whether the hybrid traces the frame
    /// (never when not `traceable`: the caller reads depth complexities).
    pub(super) fn plan<'p>(&self, p: &'p Prepared, f: &Frame, traceable: bool) -> Plan<'p> {
        let (lists, block_wedges) = self.square_lists(p, f);
        let jobs: Vec<Job> = lists
            .into_iter()
            .map(|(rect, wedges)| Job { rect, wedges })
            .collect();
        let mut plan = Plan {
            jobs,
            block_wedges,
            reference: None,
            predicted: None,
        };
        let (Some(path), Some((choice, tracer)), true, 1) =
            (&p.rays, self.rays.as_ref(), traceable, p.units)
        else {
            return plan;
        };
        let choice = *choice;
        let words = f64::from(self.sampler.count().div_ceil(64));
        let per_candidate = f64::from(choice.rays_per_candidate)
            * (1.0 + f64::from(choice.per_further_word) * (words - 1.0));
        let n = f64::from(self.sampler.count());
        let rays = f.active.iter().filter(|a| **a).count() as f64 * n;
        let bvh = if path.reference.get().is_some() {
            0.0
        } else {
            f64::from(choice.rays_per_bvh_triangle) * p.scene.triangle_count() as f64
        };
        let volumes = f64::from(choice.rays_per_shadow_volume) * p.silhouettes.len() as f64;
        let input = Self::scan_input(p, f);
        // DCS's work from the (tile, wedge) candidates of an evenly spaced sample of the
        // squares, scaled to all of them: the choice is per frame, so only the total counts.
        let step = plan.jobs.len().div_ceil(PROBE_SQUARES).max(1);
        let probed: Vec<f64> = plan
            .jobs
            .par_iter()
            .step_by(step)
            .map_init(SquareScratch::default, |scratch, job| {
                square_tile_wedges(&input, &job.wedges, job.rect, PROBE_WEDGES, scratch)
            })
            .collect();
        let dcs = probed.iter().sum::<f64>() * per_candidate * plan.jobs.len() as f64
            / probed.len().max(1) as f64;
        plan.predicted = Some([dcs, volumes, rays, bvh]);
        if choice == RayChoice::EVERYWHERE || rays + bvh < dcs + volumes {
            plan.reference = path.get_or_build(self, tracer.as_ref(), p);
        }
        plan
    }

    /// Pixel `i` (view sample `s`) by shadow rays on its DCS samples: what the per-pixel pass
    /// leaves in the scratch (visible samples, with `want_values` their visibilities; no depth
    /// complexities, which rays do not count), and its class.
    #[expect(
        clippy::too_many_arguments,
        reason = "the traced pixel fills the same scratch and counters as the per-pixel pass"
    )]
    pub(super) fn ray_pixel(
        &self,
        p: &Prepared,
        reference: &dyn PreparedRays,
        f: &Frame,
        i: usize,
        s: &ViewSample,
        scratch: &mut Scratch,
        counts: &mut Counts,
    ) -> PixelClass {
        let n = self.sampler.count() as usize;
        if !scratch.begin_pixel(n, f.horizon[i] == Horizon::Below, counts) {
            return PixelClass::Skipped;
        }
        counts.traced_pixels += 1;
        let light = p.light.as_ref();
        self.sampler.unit_samples(s.pixel, &mut scratch.units);
        light.sample_into(&scratch.units, &mut scratch.samples);
        if light.is_textured() {
            light.radiances_into(&scratch.units, &mut scratch.radiances);
        }
        let buffers = scratch.rays.get_or_insert_with(|| reference.scratch());
        let (vis, rays) = reference.pixel_visibility(s, &scratch.samples, buffers);
        counts.rays += rays;
        let mut tally = ClassTally::new();
        for (k, &v) in vis.iter().enumerate() {
            tally.add(k, v, &mut scratch.visible);
        }
        if scratch.want_values {
            scratch.vis.extend_from_slice(vis);
        }
        tally.class()
    }
}
