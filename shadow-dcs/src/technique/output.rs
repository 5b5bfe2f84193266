//! What the per-pixel pass of DCS (Algorithm 2's step 4) writes: each square's values,
//! radiances, classes and per-sample bits or counters, scattered into the image once every
//! square is done, and the pass's counts as statistics.

use glam::Vec3;
use rayon::prelude::*;
use shadow_core::prelude::*;
use shadow_core::visibility::{PerSampleVisibility, PixelClass};

use super::{Counts, PerSampleOutput, SQUARE, Scratch};
use crate::accel::bins::Rect;
use crate::statistics::DcsCounter;

/// One square's pixels as the per-pixel pass leaves them, row-major in the square.
pub(super) struct SquareOut {
    v: Vec<f32>,
    rgb: Vec<Vec3>,
    class: Vec<PixelClass>,
    bits: Vec<u64>,
    depth: Vec<u32>,
    /// The square's counts.
    pub counts: Counts,
}

/// What the pass writes per pixel: `n` samples (`words` of bits), radiance for a textured
/// light, and the per-sample output asked for.
#[derive(Clone, Copy)]
pub(super) struct PixelOutput {
    pub n: usize,
    pub words: usize,
    pub textured: bool,
    pub output: PerSampleOutput,
}

impl PixelOutput {
    /// Empty buffers for a square of `m` pixels.
    pub fn square(&self, m: usize) -> SquareOut {
        let per_sample = |kind: PerSampleOutput, len: usize| {
            if self.output == kind { len } else { 0 }
        };
        SquareOut {
            v: vec![0.0; m],
            rgb: vec![Vec3::ZERO; if self.textured { m } else { 0 }],
            class: vec![PixelClass::Background; m],
            bits: vec![0; per_sample(PerSampleOutput::Bits, m * self.words)],
            depth: vec![0; per_sample(PerSampleOutput::Counters, m * self.n)],
            counts: Counts::default(),
        }
    }

    /// Writes pixel `x` of square `r` from the pass's scratch: its class, `V(p)` (eq. 2), its
    /// radiance and its per-sample output.
    pub fn write(&self, r: &mut SquareOut, x: usize, class: PixelClass, scratch: &Scratch) {
        let (n, words) = (self.n, self.words);
        r.class[x] = class;
        // Lit and umbra pixels (most of an image): every sample alike.
        let uniform = match class {
            PixelClass::Lit => Some(true),
            PixelClass::Umbra | PixelClass::Skipped => Some(false),
            _ => None,
        };
        if let (Some(lit), false, false) = (
            uniform,
            self.textured,
            self.output == PerSampleOutput::Counters,
        ) {
            r.v[x] = if lit { 1.0 } else { 0.0 };
            if lit && self.output == PerSampleOutput::Bits {
                for (k, word) in r.bits[x * words..(x + 1) * words].iter_mut().enumerate() {
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
            if self.output == PerSampleOutput::Bits {
                r.bits[x * words..(x + 1) * words].copy_from_slice(&scratch.visible);
            }
            return;
        }
        let vis = &scratch.vis;
        let sum: f64 = vis.iter().map(|&v| v as f64).sum();
        r.v[x] = (sum / n as f64) as f32;
        if self.textured {
            let acc = scratch
                .radiances
                .iter()
                .zip(vis)
                .fold(Vec3::ZERO, |a, (l, v)| a + *l * *v);
            r.rgb[x] = acc / n as f32;
        }
        match self.output {
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
    }

    /// The visibility buffer of `view` from every square, and their counts summed.
    pub fn image(
        &self,
        view: &ViewSamples,
        strips: &[(Rect, SquareOut)],
    ) -> Result<(VisibilityImage, Counts), TechniqueError> {
        let (n, words, w) = (self.n, self.words, view.width() as usize);
        let mut vis = if self.textured {
            VisibilityImage::rgb_buffer(view)
        } else {
            VisibilityImage::scalar(view)
        };
        let mut classes = vec![PixelClass::Background; view.len()];
        let per_sample = |kind: PerSampleOutput, len: usize| {
            if self.output == kind { len } else { 0 }
        };
        let mut bits = vec![0u64; per_sample(PerSampleOutput::Bits, view.len() * words)];
        let mut depth = vec![0u32; per_sample(PerSampleOutput::Counters, view.len() * n)];
        // Each square's rows into the image, bands of squares in parallel (a serial copy
        // was 5 ms of a 160 ms frame on two threads).
        if self.textured {
            scatter_squares(vis.rgbs_mut(), 1, w, strips, |r| &r.rgb);
        } else {
            scatter_squares(vis.scalars_mut(), 1, w, strips, |r| &r.v);
        }
        scatter_squares(&mut classes, 1, w, strips, |r| &r.class);
        scatter_squares(&mut bits, words, w, strips, |r| &r.bits);
        scatter_squares(&mut depth, n, w, strips, |r| &r.depth);
        let mut counts = Counts::default();
        for (_, r) in strips {
            counts.add(&r.counts);
        }
        vis.set_classes(classes)?;
        match self.output {
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
        Ok((vis, counts))
    }
}

/// The per-pixel pass's counts as statistics, with the square plan's binned wedges and, when
/// it weighed tracing, its predicted work (`[dcs, shadow volumes, traced rays, bvh]`).
pub(super) fn record_counts(
    stats: &mut Stats,
    counts: &Counts,
    block_wedges: u64,
    predicted: Option<[f64; 4]>,
) {
    stats.add(DcsCounter::PixelsFacingAway, counts.facing_away);
    stats.add(DcsCounter::PixelsConstantOnly, counts.constant_only);
    stats.add(DcsCounter::PixelsPerSample, counts.per_sample);
    stats.add(DcsCounter::EdgeTests, counts.edge_tests);
    stats.add(DcsCounter::CoveredUpdates, counts.covered_updates);
    stats.add(DcsCounter::CounterEscalations, counts.escalations);
    stats.add(DcsCounter::PlainCounterFallbacks, counts.plain_fallback);
    stats.add(DcsCounter::NegativeDepthComplexity, counts.negative);
    stats.add(DcsCounter::EdgeTies, counts.ties + counts.scan.ties);
    stats.add(DcsCounter::WedgePixelsScanned, counts.scan.scanned);
    stats.add(DcsCounter::WedgeExactWeights, counts.scan.exact_weights);
    stats.add(DcsCounter::BinBlockWedges, block_wedges);
    stats.add(DcsCounter::SquaresTraced, counts.traced_squares);
    if let Some([dcs, volumes, rays, bvh]) = predicted {
        // Whole rays: the predictions are far below u64's range.
        stats.add(DcsCounter::PredictedDcsRays, dcs as u64);
        stats.add(DcsCounter::PredictedShadowVolumeRays, volumes as u64);
        stats.add(DcsCounter::PredictedTracedRays, rays as u64);
        stats.add(DcsCounter::PredictedBvhRays, bvh as u64);
    }
    stats.add(DcsCounter::PixelsTraced, counts.traced_pixels);
    stats.add(DcsCounter::OcclusionRays, counts.rays);
    stats.add(DcsCounter::BinSquareWedges, counts.scan.square_wedges);
    stats.add(DcsCounter::BinTileWedges, counts.scan.tile_wedges);
    stats.add(DcsCounter::WedgePairs, counts.pairs);
    stats.add(DcsCounter::WedgePairsOffLight, counts.off_light);
    stats.add(DcsCounter::WedgePairsEmptySector, counts.sector_empty);
    stats.add(DcsCounter::RefinedLineCells, counts.line_cells);
    stats.add(DcsCounter::PixelsSharedSampleSets, counts.shared_set_pixels);
    stats.add(DcsCounter::SharedSampleSetsBuilt, counts.shared_sets_built);
}

/// Copies each square's values (`values` of each of `squares`, `per_pixel` of them per pixel,
/// row by row within the square) into `out`, the image's values (`width` pixels a row), bands
/// of [`SQUARE`] rows in parallel. Nothing is copied when `out` is empty (an output not asked
/// for).
pub(super) fn scatter_squares<T: Copy + Send + Sync, R: Sync>(
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
