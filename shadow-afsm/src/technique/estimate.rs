//! One AFSM estimate, stage by stage (sections 3 and 4): the receivers (light front-facing
//! view samples), the batch size and map side that fit the device's binding limit, the casters
//! (every face when a closed mesh separates the eye from the light), the receivers grouped
//! into batches with a map frame each, the passes per batch ([`run_batch`]), and the buffer
//! assembled from the batches' results.

use glam::Vec3;
use shadow_core::gpu::check_finite;
use shadow_core::prelude::*;
use shadow_core::visibility::{PerSampleVisibility, PixelClass};

use super::{Afsm, PlaneTest, Prepared};
use crate::batch::{BatchOutput, run_batch};
use crate::frame::MapFrame;
use crate::inputs::{casters_of, group_receivers, upload_casters};
use crate::params::{Params, Receiver, Region};
use crate::passes::{CasterBatch, Shared, TALLIES, device_error};
use crate::statistics::{AfsmCounter, AfsmGauge, AfsmPhase};

/// The estimate, its receivers and each batch's frame, regions and list offsets (kept for
/// stage tests).
pub type Run = (
    Estimate,
    Vec<Receiver>,
    Vec<(MapFrame, Vec<Region>, Vec<u32>)>,
);

/// The receivers of one estimate and the pixels they came from.
struct Receivers {
    list: Vec<Receiver>,
    pixels: Vec<usize>,
    facing_away: u64,
}

/// Sizes within the device's binding limit.
struct Layout {
    limit: u64,
    per_batch: usize,
    side: u32,
}

/// The batches' results gathered per pixel, and the counts of the work.
struct Gathered {
    values: Vec<f32>,
    rgbs: Vec<Vec3>,
    bits: Vec<u64>,
    classes: Vec<PixelClass>,
    occupied: u64,
    longest: u64,
    batches: u64,
    tallies: [u64; TALLIES.len()],
    skipped: Vec<(AfsmCounter, u64)>,
    stages: Vec<(MapFrame, Vec<Region>, Vec<u32>)>,
}

impl Afsm {
    /// Runs the passes on `view`, keeping the last caster batch's influence regions when
    /// `keep_regions` (for stage tests).
    pub(super) fn run(
        &self,
        p: &Prepared,
        view: &ViewSamples,
        keep_regions: bool,
    ) -> Result<Run, TechniqueError> {
        let _gpu = p.gpu.exclusive();
        let mut stats = Stats::default();
        let textured = p.light.is_textured() && !self.hard;
        let receivers = stats.time(AfsmPhase::Receivers, || self.receivers(p, view));
        let floats: Vec<f32> = receivers.list.iter().flat_map(|r| r.floats()).collect();
        check_finite(&floats, "view samples").map_err(device_error)?;
        let layout = self.layout(p, view);
        let params = self.params(p, layout.side, textured);
        let casters = self.casters(p, view, &mut stats)?;
        let mut gathered = Gathered::new(view, self.samples, textured);
        let groups = stats.time(AfsmPhase::Frame, || {
            group_receivers(
                p.bounds.center,
                &receivers.list,
                &receivers.pixels,
                layout.per_batch,
                layout.side,
            )
        });
        for (chunk, chunk_px, frame) in groups {
            let mut prm = params;
            frame.write(&mut prm);
            check_finite(
                bytemuck::cast_slice::<Params, f32>(std::slice::from_ref(&prm))[..32].as_ref(),
                "light frame",
            )
            .map_err(device_error)?;
            let shared = Shared {
                casters,
                samples: &p.samples,
                radiance: &p.radiance,
                lut: &p.lut,
                semi_opaque: p.semi_opaque,
                silhouettes: &p.silhouettes,
                limit: layout.limit,
                culling: self.culling,
            };
            let out = run_batch(
                &p.gpu,
                &p.pipes,
                prm,
                &chunk,
                &shared,
                keep_regions,
                &mut stats,
            )
            .map_err(device_error)?;
            let (regions, offsets) =
                gathered.add(out, &chunk_px, self.samples, self.words(), textured);
            if keep_regions {
                gathered.stages.push((frame, regions, offsets));
            }
        }
        let vis = gathered.buffer(view, self.samples, textured)?;
        stats.add(AfsmCounter::ReceiversListed, receivers.list.len() as u64);
        stats.add(AfsmCounter::ReceiversFacingAway, receivers.facing_away);
        stats.add(AfsmCounter::ReceiverBatches, gathered.batches);
        stats.add(AfsmCounter::CasterBatches, casters.len() as u64);
        stats.add(AfsmCounter::SilhouetteEdges, p.silhouette_count as u64);
        stats.add(AfsmCounter::ListsOccupied, gathered.occupied);
        stats.gauge_max(AfsmGauge::ListLengthMax, gathered.longest);
        stats.gauge_max(AfsmGauge::MapSide, layout.side as u64);
        for (k, counter) in TALLIES.iter().enumerate() {
            stats.add(*counter, gathered.tallies[k]);
        }
        for (name, v) in gathered.skipped {
            stats.add(name, v);
        }
        Ok((Estimate::new(vis, stats), receivers.list, gathered.stages))
    }

    /// Receivers: the view samples in front of the light's bounds (section 3), their ray
    /// origins offset off their surfaces; the rest face away and are counted.
    fn receivers(&self, p: &Prepared, view: &ViewSamples) -> Receivers {
        let mut out = Receivers {
            list: Vec::new(),
            pixels: Vec::new(),
            facing_away: 0,
        };
        for i in 0..view.len() {
            let Some(s) = view.get(i) else { continue };
            let nrm = s.geometric_normal;
            let origin = p.offset.offset(s.position, nrm);
            let (_, hi_p) = p.bounds.range(nrm);
            let above_p = hi_p - nrm.dot(s.position) > 0.0;
            let above_o = hi_p - nrm.dot(origin) > 0.0;
            if !(above_p && above_o) {
                out.facing_away += 1;
                continue;
            }
            out.list.push(Receiver::new(
                origin,
                self.set_of(s.pixel),
                s.position,
                s.triangle,
                nrm,
            ));
            out.pixels.push(i);
        }
        out
    }

    /// Receivers per batch and the map's side, within the device's binding limit.
    fn layout(&self, p: &Prepared, view: &ViewSamples) -> Layout {
        let limit = self.binding_limit(&p.gpu);
        let depths = if p.semi_opaque {
            self.samples as u64 * 4
        } else {
            0
        };
        let per_receiver = (self.words() as u64 * 4)
            .max(depths)
            .max(std::mem::size_of::<Receiver>() as u64);
        let per_batch = (limit / per_receiver).max(1) as usize;
        let side = view.width().max(view.height()).clamp(8, 4096);
        let side = (1..=side)
            .rev()
            .find(|s| (*s as u64 * *s as u64 + 1) * 4 <= limit)
            .unwrap_or(1);
        Layout {
            limit,
            per_batch,
            side,
        }
    }

    /// The parameters every batch shares: sizes, the light's bounds, the sample grid and the
    /// plane table's bins.
    fn params(&self, p: &Prepared, side: u32, textured: bool) -> Params {
        let n = self.samples;
        let mut params = Params {
            dims: [side, 0, n, self.words()],
            lut: [0, 0, 0, textured as u32],
            ..bytemuck::Zeroable::zeroed()
        };
        p.bounds.write(&mut params);
        params.center = [p.bounds.center.x, p.bounds.center.y, p.bounds.center.z, 1.0];
        if let Some((g, grid)) = p.grid {
            params.options[2] = g;
            params.grid = grid;
        }
        if self.plane_test == PlaneTest::Lut {
            let b = crate::lut::bins_for(n);
            params.kind[3] = 1;
            params.lut[..3].copy_from_slice(&b);
        }
        params
    }

    /// The casters: light back-facing casters alone are exact when a receiver's segment
    /// crosses each closed mesh an even number of times, that is when receiver and light are
    /// on the same side of it. Every visible receiver is on the eye's side, so a closed mesh
    /// that separates the eye from the light makes every face cast.
    fn casters<'p>(
        &self,
        p: &'p Prepared,
        view: &ViewSamples,
        stats: &mut Stats,
    ) -> Result<&'p [CasterBatch], TechniqueError> {
        let separating = view.eye().map_or(0, |e| {
            crate::inputs::closed_meshes_between(p.scene.as_ref(), &p.closed, &p.around_light, e)
        });
        stats.add(
            AfsmCounter::ClosedMeshesBetweenEyeAndLight,
            separating as u64,
        );
        if separating == 0 {
            return Ok(&p.batches);
        }
        let open = p.open_batches.get_or_init(|| {
            let all_open = vec![false; p.closed.len()];
            let casters = casters_of(p.scene.as_ref(), &all_open);
            upload_casters(
                &p.gpu,
                &casters,
                Some(&p.bounds),
                p.per_batch,
                "casters, none closed",
            )
        });
        Ok(open.as_ref().map_err(Clone::clone)?)
    }
}

impl Gathered {
    fn new(view: &ViewSamples, n: u32, textured: bool) -> Self {
        let wpp = n.div_ceil(64) as usize;
        Self {
            values: vec![0.0f32; view.len()],
            rgbs: vec![Vec3::ZERO; if textured { view.len() } else { 0 }],
            bits: vec![0u64; view.len() * wpp],
            classes: (0..view.len())
                .map(|i| {
                    if view.is_valid(i) {
                        PixelClass::Skipped
                    } else {
                        PixelClass::Background
                    }
                })
                .collect(),
            occupied: 0,
            longest: 0,
            batches: 0,
            tallies: [0u64; TALLIES.len()],
            skipped: Vec::new(),
            stages: Vec::new(),
        }
    }

    /// One batch's results at its pixels `chunk_px`, its lists and tallies counted; gives back
    /// its regions and list offsets.
    fn add(
        &mut self,
        out: BatchOutput,
        chunk_px: &[usize],
        n: u32,
        words: u32,
        textured: bool,
    ) -> (Vec<Region>, Vec<u32>) {
        self.batches += 1;
        let wpp = n.div_ceil(64) as usize;
        for w in out.offsets.windows(2) {
            let len = (w[1] - w[0]) as u64;
            self.occupied += (len > 0) as u64;
            self.longest = self.longest.max(len);
        }
        for (k, t) in out.tallies.iter().enumerate() {
            self.tallies[k] = self.tallies[k].saturating_add(*t);
        }
        for &(name, v) in &out.skipped {
            match self.skipped.iter_mut().find(|(c, _)| *c == name) {
                Some((_, total)) => *total = total.saturating_add(v),
                None => self.skipped.push((name, v)),
            }
        }
        for (j, &i) in chunk_px.iter().enumerate() {
            let [r, g, b, count] = out.result[j];
            self.values[i] = count / n as f32;
            if textured {
                self.rgbs[i] = Vec3::new(r, g, b) / n as f32;
            }
            let vis = &out.visible[j * words as usize..(j + 1) * words as usize];
            for (w, v) in vis.iter().enumerate() {
                self.bits[i * wpp + w / 2] |= (*v as u64) << (32 * (w % 2));
            }
            self.classes[i] = if count as u32 == n {
                PixelClass::Lit
            } else if count == 0.0 {
                PixelClass::Umbra
            } else {
                PixelClass::Penumbra
            };
        }
        (out.regions, out.offsets)
    }

    /// The visibility buffer with its classes and per-sample bits.
    fn buffer(
        &mut self,
        view: &ViewSamples,
        n: u32,
        textured: bool,
    ) -> Result<VisibilityImage, TechniqueError> {
        let mut vis = if textured {
            let mut v = VisibilityImage::rgb_buffer(view);
            v.rgbs_mut().copy_from_slice(&self.rgbs);
            v
        } else {
            let mut v = VisibilityImage::scalar(view);
            v.scalars_mut().copy_from_slice(&self.values);
            v
        };
        vis.set_classes(std::mem::take(&mut self.classes))?;
        vis.set_per_sample(PerSampleVisibility::Bits {
            samples: n,
            words: std::mem::take(&mut self.bits),
        })?;
        vis.validate()?;
        Ok(vis)
    }
}
