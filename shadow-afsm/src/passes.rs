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

use crate::params::{Params, Receiver, Region};
pub use crate::pipelines::{COMMON, MODULES, OCCUPIED, Pipelines, TALLY, TILING, VOLUME, source};
use crate::statistics::{AfsmCounter, AfsmPhase};
use glam::Vec3;

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
fn timed<T>(
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
enum Work<'a> {
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
const SKIPPED_SLOTS: [(usize, AfsmCounter); 10] = [
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
const TALLY_WORDS: usize = 38;

/// The buffers one batch of view samples shares between its caster ranges.
struct Occlusion<'a> {
    gpu: &'a GpuContext,
    pipes: &'a Pipelines,
    shared: &'a Shared<'a>,
    regions: &'a wgpu::Buffer,
    receivers: &'a wgpu::Buffer,
    offsets: &'a wgpu::Buffer,
    lists: &'a wgpu::Buffer,
    masks: &'a wgpu::Buffer,
    tallies: &'a wgpu::Buffer,
    flags: &'a wgpu::Buffer,
    depths: &'a wgpu::Buffer,
    tile_depth: &'a wgpu::Buffer,
    texel_depth: &'a wgpu::Buffer,
    tile_box: &'a wgpu::Buffer,
    texel_near: &'a wgpu::Buffer,
    tile_near: &'a wgpu::Buffer,
    occupancy: &'a wgpu::Buffer,
    super_bounds: &'a wgpu::Buffer,
    texel_bits: &'a wgpu::Buffer,
    batch_box: &'a wgpu::Buffer,
    slots: &'a wgpu::Buffer,
    texel_hidden: &'a wgpu::Buffer,
    tile_count: &'a wgpu::Buffer,
    tile_hidden: &'a wgpu::Buffer,
}

impl Occlusion<'_> {
    /// Reads the 64-bit tally `slot`.
    fn tally(&self, slot: usize) -> Result<u64, GpuError> {
        let t: Vec<u32> = self.gpu.read(self.tallies, TALLY_WORDS)?;
        Ok(t[2 * slot] as u64 | (t[2 * slot + 1] as u64) << 32)
    }

    /// Influence regions of `batch`, then its tiled work.
    fn batch(
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
        let pipes = self.pipes;
        let mut p = params;
        p.work = [base, count, 0, 0];
        let mut keep = Vec::new();
        let tile_counts = gpu.storage_zeroed("tile counts", (count as u64 + 1) * 4)?;
        let caster_masks = gpu.storage_zeroed("kept super-tiles", count as u64 * 12)?;
        let tiles = timed(gpu, stats, AfsmPhase::GpuTiles, || {
            let uni = gpu.uniform("params", &p);
            let mut enc = gpu.encoder();
            enc.clear_buffer(self.tallies, 4 * 2 * TILE_SLOT as u64, Some(16));
            let b = gpu.bind(
                &pipes.tiles,
                &[
                    &uni,
                    self.regions,
                    &tile_counts,
                    self.tallies,
                    self.occupancy,
                    &caster_masks,
                    volumes,
                    self.super_bounds,
                ],
            );
            gpu.dispatch(&mut enc, &pipes.tiles, &b, (count as u64).div_ceil(64))?;
            scan(gpu, pipes, &mut enc, &tile_counts, count + 1, &mut keep)?;
            gpu.submit(enc)?;
            self.tally(TILE_SLOT)
        })?;
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
            Work::Stencil => {
                return timed(gpu, stats, AfsmPhase::GpuStencil, || {
                    let uni = gpu.uniform("params", &p);
                    let mut enc = gpu.encoder();
                    let b = gpu.bind(
                        &pipes.stencil,
                        &[
                            &uni,
                            self.regions,
                            &tile_counts,
                            self.offsets,
                            self.flags,
                            self.occupancy,
                            &caster_masks,
                        ],
                    );
                    gpu.dispatch(&mut enc, &pipes.stencil, &b, tiles.div_ceil(64))?;
                    gpu.submit(enc)
                });
            }
        };
        // Pair counts (scanned in place), then two words of overlap mask per tile. The tallies
        // are kept aside in case the range must be split and its tiles counted again.
        let pair_counts = gpu.storage_zeroed("pair counts", (3 * tiles + 1) * 4)?;
        let saved = gpu.storage_zeroed("saved tallies", TALLY_WORDS as u64 * 4)?;
        let pairs = timed(gpu, stats, AfsmPhase::GpuTiles, || {
            let uni = gpu.uniform("params", &p);
            let mut enc = gpu.encoder();
            enc.copy_buffer_to_buffer(self.tallies, 0, &saved, 0, TALLY_WORDS as u64 * 4);
            let b = gpu.bind(
                &pipes.tile_pairs,
                &[
                    &uni,
                    self.regions,
                    &tile_counts,
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
                    &caster_masks,
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
                &mut keep,
            )?;
            gpu.submit(enc)?;
            self.tally(PAIR_SLOT)
        })?;
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
        let groups = pairs.div_ceil(64 * pairs_per_invocation(params.dims[3]) as u64);
        timed(gpu, stats, AfsmPhase::GpuOcclude, || {
            let uni = gpu.uniform("params", &p);
            let mut enc = gpu.encoder();
            let b = gpu.bind(
                &pipes.occlude,
                &[
                    &uni,
                    self.regions,
                    &tile_counts,
                    self.offsets,
                    &pair_counts,
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
                    &caster_masks,
                ],
            );
            gpu.dispatch(&mut enc, &pipes.occlude, &b, groups)?;
            gpu.submit(enc)
        })
    }
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

/// What a batch of view samples gives back.
#[derive(Debug, Clone, PartialEq)]
pub struct BatchOutput {
    /// Per receiver: radiance sum of visible samples (xyz), visible count (w).
    pub result: Vec<[f32; 4]>,
    /// Per receiver: `W` words of visible bits.
    pub visible: Vec<u32>,
    /// List offsets (`side^2 + 1`, the last one the total).
    pub offsets: Vec<u32>,
    /// The influence regions of the last caster batch (kept for tests).
    pub regions: Vec<Region>,
    /// The occlusion tallies ([`TALLIES`]).
    pub tallies: [u64; TALLIES.len()],
    /// The tallies of work skipped, named.
    pub skipped: Vec<(AfsmCounter, u64)>,
}

/// Runs every pass for one batch of receivers; `params` holds the frame, light and sizes
/// (`dims[1]` is set here).
///
/// # Errors
/// [`GpuError`] from any pass.
pub fn run_batch(
    gpu: &GpuContext,
    pipes: &Pipelines,
    mut params: Params,
    receivers: &[Receiver],
    shared: &Shared<'_>,
    keep_regions: bool,
    stats: &mut Stats,
) -> Result<BatchOutput, GpuError> {
    let n = receivers.len() as u32;
    params.dims[1] = n;
    params.options[0] = (!shared.silhouettes.is_empty()) as u32;
    params.options[1] = shared.semi_opaque as u32;
    params.options[3] = shared.culling as u32;
    let side = params.dims[0];
    let words = params.dims[3];
    let texels = side * side;
    let mut keep = Vec::new();
    let tiles_per_side = side.div_ceil(8) as u64;
    let (rbuf, counts, slots, lists, masks, result, tallies) =
        timed(gpu, stats, AfsmPhase::GpuUpload, || {
            Ok::<_, GpuError>((
                gpu.storage("receivers", receivers)?,
                gpu.storage_zeroed("list counts", (texels as u64 + 1) * 4)?,
                gpu.storage_zeroed("slots", n as u64 * 8)?,
                gpu.storage_zeroed("lists", n as u64 * 4)?,
                gpu.storage_zeroed("masks", n as u64 * words as u64 * 4)?,
                gpu.storage_zeroed("result", n as u64 * 16)?,
                gpu.storage_zeroed("tallies", TALLY_WORDS as u64 * 4)?,
            ))
        })?;
    let texel_depth = gpu.storage_zeroed("texel depths", texels as u64 * 4)?;
    let tile_depth = gpu.storage_zeroed("tile depths", tiles_per_side * tiles_per_side * 4)?;
    let tile_box = gpu.storage_zeroed("tile boxes", tiles_per_side * tiles_per_side * 24)?;
    let texel_near = gpu.storage_zeroed("texel nearest depths", texels as u64 * 4)?;
    let tile_near = gpu.storage_zeroed("tile nearest depths", tiles_per_side.pow(2) * 4)?;
    // The box of the batch's ray origins, for the influence pass's root cull.
    let (lo, hi) = receivers.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), r| (lo.min(r.origin()), hi.max(r.origin())),
    );
    let batch_box = gpu.storage(
        "batch box",
        &[[lo.x, lo.y, lo.z, 0.0], [hi.x, hi.y, hi.z, 0.0]],
    )?;
    let texel_bits = gpu.storage_zeroed("occupied texels per tile", tiles_per_side.pow(2) * 8)?;
    let supers = tiles_per_side.div_ceil(4);
    let super_bounds = gpu.storage_zeroed("super-tile bounds", supers * supers * 32)?;
    // Per row of tiles, running counts of occupied tiles and their columns.
    let occupancy = gpu.storage_zeroed(
        "occupied tiles",
        (tiles_per_side * (tiles_per_side + 1) + tiles_per_side.pow(2)) * 4,
    )?;
    let texel_hidden = gpu.storage_zeroed("hidden per texel", texels as u64 * 4)?;
    let tile_count = gpu.storage_zeroed("view samples per tile", tiles_per_side.pow(2) * 4)?;
    let tile_hidden = gpu.storage_zeroed("hidden per tile", tiles_per_side.pow(2) * 4)?;
    let uni = gpu.uniform("params", &params);
    let groups = (n as u64).div_ceil(64);
    timed(gpu, stats, AfsmPhase::GpuLists, || {
        let mut enc = gpu.encoder();
        let b = gpu.bind(
            &pipes.count,
            &[
                &uni,
                &rbuf,
                &counts,
                &slots,
                &texel_depth,
                &tile_depth,
                &tile_box,
                &tile_count,
                &texel_near,
                &tile_near,
                &super_bounds,
                &texel_bits,
            ],
        );
        gpu.dispatch(&mut enc, &pipes.count, &b, groups)?;
        let b = gpu.bind(&pipes.occupancy, &[&uni, &tile_count, &occupancy]);
        gpu.dispatch(&mut enc, &pipes.occupancy, &b, tiles_per_side.div_ceil(64))?;
        scan(gpu, pipes, &mut enc, &counts, texels + 1, &mut keep)?;
        gpu.submit(enc)?;
        let mut enc = gpu.encoder();
        let b = gpu.bind(&pipes.scatter, &[&uni, &slots, &counts, &lists]);
        gpu.dispatch(&mut enc, &pipes.scatter, &b, groups)?;
        gpu.submit(enc)
    })?;
    let largest = shared
        .casters
        .iter()
        .chain(shared.silhouettes)
        .map(|c| c.len)
        .max()
        .unwrap_or(0);
    let regions = gpu.storage_zeroed(
        "regions",
        largest as u64 * std::mem::size_of::<Region>() as u64,
    )?;
    let flags = gpu.storage_zeroed("silhouette stencil", texels as u64 * 4)?;
    let depth_slots = if shared.semi_opaque {
        n as u64 * params.dims[2] as u64
    } else {
        1
    };
    let depths = gpu.storage_zeroed("optical depths", depth_slots * 4)?;
    let occ = Occlusion {
        gpu,
        pipes,
        shared,
        regions: &regions,
        receivers: &rbuf,
        offsets: &counts,
        lists: &lists,
        masks: &masks,
        tallies: &tallies,
        flags: &flags,
        depths: &depths,
        tile_depth: &tile_depth,
        texel_depth: &texel_depth,
        tile_box: &tile_box,
        texel_near: &texel_near,
        tile_near: &tile_near,
        occupancy: &occupancy,
        super_bounds: &super_bounds,
        texel_bits: &texel_bits,
        batch_box: &batch_box,
        slots: &slots,
        texel_hidden: &texel_hidden,
        tile_count: &tile_count,
        tile_hidden: &tile_hidden,
    };
    for batch in shared.silhouettes {
        occ.batch(params, batch, Work::Stencil, stats)?;
    }
    let mut last_regions = Vec::new();
    for batch in shared.casters {
        occ.batch(params, batch, Work::Occlude(batch), stats)?;
        if keep_regions {
            last_regions = gpu.read::<Region>(&regions, batch.len as usize)?;
        }
    }
    timed(gpu, stats, AfsmPhase::GpuResolve, || {
        let mut enc = gpu.encoder();
        let b = gpu.bind(
            &pipes.resolve,
            &[
                &uni,
                &rbuf,
                shared.samples,
                shared.radiance,
                &masks,
                &result,
                &depths,
            ],
        );
        gpu.dispatch(&mut enc, &pipes.resolve, &b, groups)?;
        gpu.submit(enc)
    })?;
    timed(gpu, stats, AfsmPhase::GpuReadback, || {
        let t: Vec<u32> = gpu.read(&tallies, TALLY_WORDS)?;
        let word = |k: usize| t[2 * k] as u64 | (t[2 * k + 1] as u64) << 32;
        let mut tallies = [0u64; TALLIES.len()];
        for (k, v) in tallies.iter_mut().enumerate() {
            *v = word(k);
        }
        let skipped = SKIPPED_SLOTS
            .iter()
            .map(|&(k, name)| (name, word(k)))
            .collect();
        Ok(BatchOutput {
            result: gpu.read(&result, n as usize)?,
            visible: gpu.read(&masks, (n * words) as usize)?,
            offsets: gpu.read(&counts, texels as usize + 1)?,
            regions: last_regions,
            tallies,
            skipped,
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The GPU scan against a CPU running sum, over sizes around the block boundaries and one
    /// needing two levels of block totals.
    #[test]
    fn gpu_scan_equals_the_cpu_running_sum() {
        let Some(gpu) = shadow_core::gpu::context_for_test("gpu_scan_equals_the_cpu_running_sum")
        else {
            return;
        };
        let pipes = Pipelines::new(&gpu).unwrap();
        for n in [1u32, 511, 512, 513, 4097, 300_001] {
            let data: Vec<u32> = (0..n)
                .map(|i| i.wrapping_mul(2_654_435_761u32) >> 28)
                .collect();
            let buf = gpu.storage("data", &data).unwrap();
            let mut keep = Vec::new();
            let mut enc = gpu.encoder();
            scan(&gpu, &pipes, &mut enc, &buf, n, &mut keep).unwrap();
            gpu.submit(enc).unwrap();
            let got: Vec<u32> = gpu.read(&buf, n as usize).unwrap();
            let mut acc = 0u32;
            for (i, v) in data.iter().enumerate() {
                assert_eq!(got[i], acc, "n {n} at {i}");
                acc += v;
            }
        }
    }
}
