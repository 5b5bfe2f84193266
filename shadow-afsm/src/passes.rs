//! The compute passes and how one batch of view samples runs through them:
//!
//! 1. `count` (section 3.1): project each view sample, atomically take a slot in its texel;
//!    `occupancy`: the map's tiles that hold a view sample, row by row;
//! 2. `scan_block` / `scan_add`: the running sum of list lengths gives list offsets;
//! 3. `scatter`: each view sample's index goes to its list's offset plus its slot;
//! 4. per batch of caster triangles, `influence` (section 4.1); then, per range of casters,
//!    `tiles` (the map's occupied 8 x 8 texel tiles each region touches, numbered by a
//!    running sum),
//!    `tile_pairs` (cluster culling of each (caster, tile), then the pairs of the overlapping
//!    texels' lists, numbered by a running sum) and `occlude` (sections 3.2, 3.3, 4.2, 4.3: a
//!    few consecutive pairs per invocation);
//! 5. `resolve`: horizon test, visible bits, counts and radiance sums.
//!
//! Every invocation does bounded work, however large an influence region or long a list: the
//! work is spread evenly over the GPU (the load balancing the paper's one-triangle-at-a-time
//! rasterisation lacks), and software rasterisers that end an invocation's loops after 65535
//! iterations in all (llvmpipe) still compute every pair.
//!
//! Each phase is submitted on its own and waited for, so [`Stats`] holds per-phase GPU times
//! (submission to completion); where the adapter has timestamp queries, each phase's
//! `device_seconds` holds the device time of its passes alone.

use shadow_core::gpu::{Encoder, GpuContext, GpuError};
use shadow_core::technique::Stats;

use crate::params::Params;
pub use crate::pipelines::{COMMON, MODULES, OCCUPIED, Pipelines, TALLY, TILING, VOLUME, source};
use crate::statistics::{AfsmCounter, AfsmPhase};

/// A device failure as a technique error.
pub(crate) fn device_error(e: GpuError) -> shadow_core::technique::TechniqueError {
    shadow_core::technique::TechniqueError::Device(e.to_string())
}

/// Consecutive pairs each occlusion invocation takes, for `words` words of sample bits per view
/// sample (`pairs_per_invocation` in `occlude.wgsl`, which the dispatch size must match).
fn pairs_per_invocation(words: u32) -> u32 {
    (64 / words.max(1)).clamp(1, 8)
}

/// Runs `phase` of `stats` (wall-clock time from submission to completion, readbacks
/// included) and, where the device has timestamp queries, adds the device time of its passes
/// to the phase's device seconds.
pub(crate) fn timed<T>(
    gpu: &GpuContext,
    stats: &mut Stats,
    phase: AfsmPhase,
    f: impl FnOnce() -> Result<T, GpuError>,
) -> Result<T, GpuError> {
    gpu.take_device_seconds();
    let out = stats.time(phase, f)?;
    if let Some(s) = gpu.take_device_seconds().filter(|s| *s > 0.0) {
        stats.add_device_time(phase, s);
    }
    Ok(out)
}

/// Exclusive prefix sum of the first `n` values of `data`, in place (recursive over block
/// totals). Buffers that must outlive the submission go into `keep`.
///
/// # Errors
/// As [`GpuContext::dispatch`].
pub fn scan(
    gpu: &GpuContext,
    pipes: &Pipelines,
    enc: &mut Encoder,
    data: &wgpu::Buffer,
    n: u32,
    keep: &mut Vec<wgpu::Buffer>,
) -> Result<(), GpuError> {
    let blocks = n.div_ceil(512).max(1);
    let sums = gpu.storage_zeroed("scan sums", blocks as u64 * 4)?;
    let uni = gpu.uniform("scan n", &[n, 0u32, 0, 0]);
    let bind = gpu.bind(&pipes.scan_block, &[&uni, data, &sums]);
    gpu.dispatch(enc, &pipes.scan_block, &bind, blocks as u64)?;
    if blocks > 1 {
        scan(gpu, pipes, enc, &sums, blocks, keep)?;
        let bind = gpu.bind(&pipes.scan_add, &[&uni, data, &sums]);
        gpu.dispatch(enc, &pipes.scan_add, &bind, (n as u64).div_ceil(64))?;
    }
    keep.push(sums);
    keep.push(uni);
    Ok(())
}

/// Caster triangles uploaded in batches that respect the binding limits.
#[derive(Debug)]
pub struct CasterBatch {
    /// The triangles.
    pub buffer: wgpu::Buffer,
    /// Their penumbra volumes (`volume.rs`), one per triangle; one unbounded volume for the
    /// stencil's edges.
    pub volumes: wgpu::Buffer,
    /// How many.
    pub len: u32,
}

/// What one batch of view samples needs beyond its receivers.
#[derive(Debug)]
pub struct Shared<'a> {
    /// Caster batches.
    pub casters: &'a [CasterBatch],
    /// Light sample positions (`sets * N` vec4).
    pub samples: &'a wgpu::Buffer,
    /// Light sample radiance (same layout).
    pub radiance: &'a wgpu::Buffer,
    /// The plane table (a dummy in exact mode).
    pub lut: &'a wgpu::Buffer,
    /// True when some caster is semi-opaque: per-sample optical depths are kept.
    pub semi_opaque: bool,
    /// Potential silhouette edges as degenerate casters `(a, b, b)` (section 4.3), in batches;
    /// empty when the stencil is off.
    pub silhouettes: &'a [CasterBatch],
    /// The largest buffer the technique may bind (the device's limit or a smaller cap).
    pub limit: u64,
    /// Cluster culling (`tile_pairs.wgsl`) on.
    pub culling: bool,
}

/// What a range of tiled regions is for.
#[derive(Clone, Copy)]
pub(crate) enum Work<'a> {
    /// Occlusion by these casters.
    Occlude(&'a CasterBatch),
    /// The silhouette stencil from these edges' regions.
    Stencil,
}

/// Casters per occlusion range: between ranges, texels whose every view sample is hidden drop
/// out (on `grass`, most of them after the first range).
const RANGE_CASTERS: u32 = 4096;

/// 64-bit tally slots beyond [`TALLIES`]: tiles and pairs of the current caster range.
const TILE_SLOT: usize = 7;
const PAIR_SLOT: usize = 8;
/// The tallies of work skipped, kept over every range: cluster culling's (`tile_pairs.wgsl`)
/// and the pairs whose view sample was already hidden from every light sample (`occlude.wgsl`).
pub(crate) const SKIPPED_SLOTS: [(usize, AfsmCounter); 10] = [
    (9, AfsmCounter::TilesCulled),
    (10, AfsmCounter::TexelsCulledByDepth),
    (11, AfsmCounter::PairsAfterUmbra),
    (12, AfsmCounter::TilesEmpty),
    (13, AfsmCounter::TexelsHidden),
    (14, AfsmCounter::TilesHidden),
    (15, AfsmCounter::TexelsCulledByRegion),
    (16, AfsmCounter::TexelsCulledByVolume),
    (17, AfsmCounter::SuperTilesCulled),
    (18, AfsmCounter::CastersCulled),
];
/// Tallies buffer length in u32 words (nineteen 64-bit slots).
pub(crate) const TALLY_WORDS: usize = 38;

/// The buffers one batch of view samples shares between its caster ranges.
pub(crate) struct Occlusion<'a> {
    pub(crate) gpu: &'a GpuContext,
    pub(crate) pipes: &'a Pipelines,
    pub(crate) shared: &'a Shared<'a>,
    pub(crate) regions: &'a wgpu::Buffer,
    pub(crate) receivers: &'a wgpu::Buffer,
    pub(crate) offsets: &'a wgpu::Buffer,
    pub(crate) lists: &'a wgpu::Buffer,
    pub(crate) masks: &'a wgpu::Buffer,
    pub(crate) tallies: &'a wgpu::Buffer,
    pub(crate) flags: &'a wgpu::Buffer,
    pub(crate) depths: &'a wgpu::Buffer,
    pub(crate) tile_depth: &'a wgpu::Buffer,
    pub(crate) texel_depth: &'a wgpu::Buffer,
    pub(crate) tile_box: &'a wgpu::Buffer,
    pub(crate) texel_near: &'a wgpu::Buffer,
    pub(crate) tile_near: &'a wgpu::Buffer,
    pub(crate) occupancy: &'a wgpu::Buffer,
    pub(crate) super_bounds: &'a wgpu::Buffer,
    pub(crate) texel_bits: &'a wgpu::Buffer,
    pub(crate) batch_box: &'a wgpu::Buffer,
    pub(crate) slots: &'a wgpu::Buffer,
    pub(crate) texel_hidden: &'a wgpu::Buffer,
    pub(crate) tile_count: &'a wgpu::Buffer,
    pub(crate) tile_hidden: &'a wgpu::Buffer,
}

impl Occlusion<'_> {
    /// Reads the 64-bit tally `slot`.
    fn tally(&self, slot: usize) -> Result<u64, GpuError> {
        let t: Vec<u32> = self.gpu.read(self.tallies, TALLY_WORDS)?;
        Ok(t[2 * slot] as u64 | (t[2 * slot + 1] as u64) << 32)
    }

    /// Influence regions of `batch`, then its tiled work.
    pub(crate) fn batch(
        &self,
        params: Params,
        batch: &CasterBatch,
        work: Work<'_>,
        stats: &mut Stats,
    ) -> Result<(), GpuError> {
        let (gpu, pipes) = (self.gpu, self.pipes);
        let mut p = params;
        p.kind[0] = batch.len;
        if let Work::Stencil = work {
            // The stencil's edges have no penumbra volumes.
            p.options[3] = 0;
        }
        timed(gpu, stats, AfsmPhase::GpuInfluence, || {
            let uni = gpu.uniform("params", &p);
            let mut enc = gpu.encoder();
            let b = gpu.bind(
                &pipes.influence,
                &[
                    &uni,
                    &batch.buffer,
                    self.regions,
                    &batch.volumes,
                    self.batch_box,
                    self.tallies,
                ],
            );
            let groups = (batch.len as u64).div_ceil(64);
            gpu.dispatch(&mut enc, &pipes.influence, &b, groups)?;
            gpu.submit(enc)
        })?;
        // Occlusion runs over ranges of casters, and between them the texels whose every view
        // sample is already hidden drop out of the later ranges' pairs.
        let step = match work {
            Work::Occlude(_) => RANGE_CASTERS,
            Work::Stencil => batch.len.max(1),
        };
        let mut base = 0;
        while base < batch.len {
            let count = step.min(batch.len - base);
            self.range(p, work, &batch.volumes, base, count, stats)?;
            if let Work::Occlude(_) = work {
                self.refresh_hidden(&p, stats)?;
            }
            base += count;
        }
        Ok(())
    }

    /// Recounts each texel's view samples hidden from every light sample (`hidden.wgsl`).
    fn refresh_hidden(&self, params: &Params, stats: &mut Stats) -> Result<(), GpuError> {
        let (gpu, pipes) = (self.gpu, self.pipes);
        timed(gpu, stats, AfsmPhase::GpuHidden, || {
            let uni = gpu.uniform("params", params);
            let mut enc = gpu.encoder();
            enc.clear_buffer(self.texel_hidden, 0, None);
            enc.clear_buffer(self.tile_hidden, 0, None);
            let b = gpu.bind(
                &pipes.hidden,
                &[
                    &uni,
                    self.slots,
                    self.masks,
                    self.texel_hidden,
                    self.tile_hidden,
                ],
            );
            gpu.dispatch(
                &mut enc,
                &pipes.hidden,
                &b,
                (params.dims[1] as u64).div_ceil(64),
            )?;
            gpu.submit(enc)
        })
    }

    /// Tiles, then the stencil or the pairs and their occlusion, for casters
    /// `base..base + count` of the current batch. A range whose tile numbering would not fit a
    /// buffer is split in two.
    fn range(
        &self,
        params: Params,
        work: Work<'_>,
        volumes: &wgpu::Buffer,
        base: u32,
        count: u32,
        stats: &mut Stats,
    ) -> Result<(), GpuError> {
        let gpu = self.gpu;
        let mut p = params;
        p.work = [base, count, 0, 0];
        let mut r = RangeBuffers {
            tile_counts: gpu.storage_zeroed("tile counts", (count as u64 + 1) * 4)?,
            caster_masks: gpu.storage_zeroed("kept super-tiles", count as u64 * 12)?,
            keep: Vec::new(),
        };
        let tiles = self.number_tiles(&p, volumes, &mut r, count, stats)?;
        if let Work::Occlude(_) = work {
            stats.add(AfsmCounter::TilesNumbered, tiles);
        }
        if tiles == 0 {
            return Ok(());
        }
        // Three words per tile: its pair count and its 64-bit overlap mask.
        let max_tiles = (self.shared.limit / 12)
            .saturating_sub(1)
            .min(u32::MAX as u64 / 3 - 1);
        if tiles > max_tiles {
            // One caster covers at most (side / 8)^2 tiles, which the map's own buffer bounds.
            let half = count / 2;
            if half == 0 {
                return Err(GpuError::TooLarge {
                    what: "tile numbering of one caster".into(),
                    needed: (3 * tiles + 1) * 4,
                    limit: self.shared.limit,
                });
            }
            self.range(params, work, volumes, base, half, stats)?;
            return self.range(params, work, volumes, base + half, count - half, stats);
        }
        p.work[2] = tiles as u32;
        let batch = match work {
            Work::Occlude(batch) => batch,
            Work::Stencil => return self.stencil(&p, &r, tiles, stats),
        };
        // The tallies are kept aside in case the range must be split and its tiles counted
        // again.
        let saved = gpu.storage_zeroed("saved tallies", TALLY_WORDS as u64 * 4)?;
        let (pairs, pair_counts) = self.pair_tiles(&p, batch, &mut r, &saved, tiles, stats)?;
        if pairs >= u32::MAX as u64 {
            // The running sum of pair counts is 32-bit: count the halves apart.
            let half = count / 2;
            if half == 0 {
                return Err(GpuError::TooLarge {
                    what: format!("occlusion work of {pairs} pairs for one caster"),
                    needed: pairs,
                    limit: u32::MAX as u64 - 1,
                });
            }
            let mut enc = gpu.encoder();
            enc.copy_buffer_to_buffer(&saved, 0, self.tallies, 0, TALLY_WORDS as u64 * 4);
            gpu.submit(enc)?;
            self.range(params, work, volumes, base, half, stats)?;
            return self.range(params, work, volumes, base + half, count - half, stats);
        }
        if pairs == 0 {
            return Ok(());
        }
        p.work[3] = pairs as u32;
        self.occlude(&p, batch, &r, &pair_counts, pairs, stats)
    }

    /// Numbers the tiles each caster of the range overlaps (`tiles.wgsl`, scanned); their
    /// count.
    fn number_tiles(
        &self,
        p: &Params,
        volumes: &wgpu::Buffer,
        r: &mut RangeBuffers,
        count: u32,
        stats: &mut Stats,
    ) -> Result<u64, GpuError> {
        let (gpu, pipes) = (self.gpu, self.pipes);
        timed(gpu, stats, AfsmPhase::GpuTiles, || {
            let uni = gpu.uniform("params", p);
            let mut enc = gpu.encoder();
            enc.clear_buffer(self.tallies, 4 * 2 * TILE_SLOT as u64, Some(16));
            let b = gpu.bind(
                &pipes.tiles,
                &[
                    &uni,
                    self.regions,
                    &r.tile_counts,
                    self.tallies,
                    self.occupancy,
                    &r.caster_masks,
                    volumes,
                    self.super_bounds,
                ],
            );
            gpu.dispatch(&mut enc, &pipes.tiles, &b, (count as u64).div_ceil(64))?;
            scan(gpu, pipes, &mut enc, &r.tile_counts, count + 1, &mut r.keep)?;
            gpu.submit(enc)?;
            self.tally(TILE_SLOT)
        })
    }

    /// The silhouette stencil (section 4.3) over the range's tiles.
    fn stencil(
        &self,
        p: &Params,
        r: &RangeBuffers,
        tiles: u64,
        stats: &mut Stats,
    ) -> Result<(), GpuError> {
        let (gpu, pipes) = (self.gpu, self.pipes);
        timed(gpu, stats, AfsmPhase::GpuStencil, || {
            let uni = gpu.uniform("params", p);
            let mut enc = gpu.encoder();
            let b = gpu.bind(
                &pipes.stencil,
                &[
                    &uni,
                    self.regions,
                    &r.tile_counts,
                    self.offsets,
                    self.flags,
                    self.occupancy,
                    &r.caster_masks,
                ],
            );
            gpu.dispatch(&mut enc, &pipes.stencil, &b, tiles.div_ceil(64))?;
            gpu.submit(enc)
        })
    }

    /// Pair counts per tile (`tile_pairs.wgsl`, with cluster culling; scanned in place), then
    /// two words of overlap mask per tile; the tallies are first copied to `saved`. The
    /// range's pair count and the scanned pair counts.
    fn pair_tiles(
        &self,
        p: &Params,
        batch: &CasterBatch,
        r: &mut RangeBuffers,
        saved: &wgpu::Buffer,
        tiles: u64,
        stats: &mut Stats,
    ) -> Result<(u64, wgpu::Buffer), GpuError> {
        let (gpu, pipes) = (self.gpu, self.pipes);
        let pair_counts = gpu.storage_zeroed("pair counts", (3 * tiles + 1) * 4)?;
        let pairs = timed(gpu, stats, AfsmPhase::GpuTiles, || {
            let uni = gpu.uniform("params", p);
            let mut enc = gpu.encoder();
            enc.copy_buffer_to_buffer(self.tallies, 0, saved, 0, TALLY_WORDS as u64 * 4);
            let b = gpu.bind(
                &pipes.tile_pairs,
                &[
                    &uni,
                    self.regions,
                    &r.tile_counts,
                    self.offsets,
                    &pair_counts,
                    self.tallies,
                    &batch.buffer,
                    self.tile_depth,
                    self.texel_depth,
                    self.tile_box,
                    self.texel_hidden,
                    self.tile_count,
                    self.tile_hidden,
                    &batch.volumes,
                    self.texel_near,
                    self.tile_near,
                    self.occupancy,
                    &r.caster_masks,
                    self.texel_bits,
                ],
            );
            gpu.dispatch(&mut enc, &pipes.tile_pairs, &b, tiles.div_ceil(64))?;
            scan(
                gpu,
                pipes,
                &mut enc,
                &pair_counts,
                tiles as u32 + 1,
                &mut r.keep,
            )?;
            gpu.submit(enc)?;
            self.tally(PAIR_SLOT)
        })?;
        Ok((pairs, pair_counts))
    }

    /// The occlusion pass (`occlude.wgsl`, section 4.2) over the range's `pairs`.
    fn occlude(
        &self,
        p: &Params,
        batch: &CasterBatch,
        r: &RangeBuffers,
        pair_counts: &wgpu::Buffer,
        pairs: u64,
        stats: &mut Stats,
    ) -> Result<(), GpuError> {
        let (gpu, pipes) = (self.gpu, self.pipes);
        let groups = pairs.div_ceil(64 * pairs_per_invocation(p.dims[3]) as u64);
        timed(gpu, stats, AfsmPhase::GpuOcclude, || {
            let uni = gpu.uniform("params", p);
            let mut enc = gpu.encoder();
            let b = gpu.bind(
                &pipes.occlude,
                &[
                    &uni,
                    self.regions,
                    &r.tile_counts,
                    self.offsets,
                    pair_counts,
                    &batch.buffer,
                    self.receivers,
                    self.lists,
                    self.shared.samples,
                    self.masks,
                    self.tallies,
                    self.shared.lut,
                    self.flags,
                    self.depths,
                    self.occupancy,
                    &r.caster_masks,
                ],
            );
            gpu.dispatch(&mut enc, &pipes.occlude, &b, groups)?;
            gpu.submit(enc)
        })
    }
}

/// The buffers one caster range's passes share.
struct RangeBuffers {
    /// Tiles per caster, scanned into offsets.
    tile_counts: wgpu::Buffer,
    /// The super-tiles each caster keeps after culling.
    caster_masks: wgpu::Buffer,
    /// Scan buffers that must outlive the submission.
    keep: Vec<wgpu::Buffer>,
}

/// Occlusion-pass tallies, in the order the shader keeps them.
pub const TALLIES: [AfsmCounter; 7] = [
    AfsmCounter::TexelsVisited,
    AfsmCounter::PairsTested,
    AfsmCounter::PairsEmpty,
    AfsmCounter::PairsFull,
    AfsmCounter::PairsPerSample,
    AfsmCounter::PairsOwnTriangle,
    AfsmCounter::PairsOneSample,
];
