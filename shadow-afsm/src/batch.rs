//! One batch of view samples through every pass (sections 3 and 4): the receivers uploaded
//! with the buffers the passes share, the light-space lists built, the silhouette stencil and
//! the occlusion of every caster batch ([`crate::passes`]), the resolve to `V(p)`, and the
//! results read back.

use glam::Vec3;
use shadow_core::gpu::{GpuContext, GpuError};
use shadow_core::prelude::*;

use crate::params::{Params, Receiver, Region};
use crate::passes::{
    Occlusion, Pipelines, SKIPPED_SLOTS, Shared, TALLIES, TALLY_WORDS, Work, scan, timed,
};
use crate::statistics::{AfsmCounter, AfsmPhase};

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
    params.dims[1] = receivers.len() as u32;
    params.options[0] = (!shared.silhouettes.is_empty()) as u32;
    params.options[1] = shared.semi_opaque as u32;
    params.options[3] = shared.culling as u32;
    let b = BatchBuffers::allocate(gpu, &params, receivers, shared, stats)?;
    let uni = gpu.uniform("params", &params);
    b.build_lists(gpu, pipes, &uni, stats)?;
    let occ = b.occlusion(gpu, pipes, shared);
    for batch in shared.silhouettes {
        occ.batch(params, batch, Work::Stencil, stats)?;
    }
    let mut last_regions = Vec::new();
    for batch in shared.casters {
        occ.batch(params, batch, Work::Occlude(batch), stats)?;
        if keep_regions {
            last_regions = gpu.read::<Region>(&b.regions, batch.len as usize)?;
        }
    }
    b.resolve(gpu, pipes, &uni, shared, stats)?;
    b.read_back(gpu, last_regions, stats)
}

/// The buffers of one batch of view samples: its receivers and lists, the per-texel and
/// per-tile bounds the culling reads, the occlusion masks and the tallies.
struct BatchBuffers {
    n: u32,
    words: u32,
    texels: u32,
    groups: u64,
    tiles_per_side: u64,
    receivers: wgpu::Buffer,
    counts: wgpu::Buffer,
    slots: wgpu::Buffer,
    lists: wgpu::Buffer,
    masks: wgpu::Buffer,
    result: wgpu::Buffer,
    tallies: wgpu::Buffer,
    texel_depth: wgpu::Buffer,
    tile_depth: wgpu::Buffer,
    tile_box: wgpu::Buffer,
    texel_near: wgpu::Buffer,
    tile_near: wgpu::Buffer,
    batch_box: wgpu::Buffer,
    texel_bits: wgpu::Buffer,
    super_bounds: wgpu::Buffer,
    occupancy: wgpu::Buffer,
    texel_hidden: wgpu::Buffer,
    tile_count: wgpu::Buffer,
    tile_hidden: wgpu::Buffer,
    regions: wgpu::Buffer,
    flags: wgpu::Buffer,
    depths: wgpu::Buffer,
}

impl BatchBuffers {
    /// Uploads the receivers and allocates every buffer the batch's passes use.
    fn allocate(
        gpu: &GpuContext,
        params: &Params,
        receivers: &[Receiver],
        shared: &Shared<'_>,
        stats: &mut Stats,
    ) -> Result<Self, GpuError> {
        let n = receivers.len() as u32;
        let side = params.dims[0];
        let words = params.dims[3];
        let texels = side * side;
        let tiles_per_side = side.div_ceil(8) as u64;
        let tiles = tiles_per_side.pow(2);
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
        // The box of the batch's ray origins, for the influence pass's root cull.
        let (lo, hi) = receivers.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), r| (lo.min(r.origin()), hi.max(r.origin())),
        );
        let supers = tiles_per_side.div_ceil(4);
        let largest = shared
            .casters
            .iter()
            .chain(shared.silhouettes)
            .map(|c| c.len)
            .max()
            .unwrap_or(0);
        let depth_slots = if shared.semi_opaque {
            n as u64 * params.dims[2] as u64
        } else {
            1
        };
        Ok(Self {
            n,
            words,
            texels,
            groups: (n as u64).div_ceil(64),
            tiles_per_side,
            receivers: rbuf,
            counts,
            slots,
            lists,
            masks,
            result,
            tallies,
            texel_depth: gpu.storage_zeroed("texel depths", texels as u64 * 4)?,
            tile_depth: gpu.storage_zeroed("tile depths", tiles * 4)?,
            tile_box: gpu.storage_zeroed("tile boxes", tiles * 24)?,
            texel_near: gpu.storage_zeroed("texel nearest depths", texels as u64 * 4)?,
            tile_near: gpu.storage_zeroed("tile nearest depths", tiles * 4)?,
            batch_box: gpu.storage(
                "batch box",
                &[[lo.x, lo.y, lo.z, 0.0], [hi.x, hi.y, hi.z, 0.0]],
            )?,
            texel_bits: gpu.storage_zeroed("occupied texels per tile", tiles * 8)?,
            super_bounds: gpu.storage_zeroed("super-tile bounds", supers * supers * 32)?,
            // Per row of tiles, running counts of occupied tiles and their columns.
            occupancy: gpu.storage_zeroed(
                "occupied tiles",
                (tiles_per_side * (tiles_per_side + 1) + tiles) * 4,
            )?,
            texel_hidden: gpu.storage_zeroed("hidden per texel", texels as u64 * 4)?,
            tile_count: gpu.storage_zeroed("view samples per tile", tiles * 4)?,
            tile_hidden: gpu.storage_zeroed("hidden per tile", tiles * 4)?,
            regions: gpu.storage_zeroed(
                "regions",
                largest as u64 * std::mem::size_of::<Region>() as u64,
            )?,
            flags: gpu.storage_zeroed("silhouette stencil", texels as u64 * 4)?,
            depths: gpu.storage_zeroed("optical depths", depth_slots * 4)?,
        })
    }

    /// The light-space lists (section 3): each receiver counted into its texel with the
    /// texel and tile bounds, the counts scanned into offsets, the receivers scattered.
    fn build_lists(
        &self,
        gpu: &GpuContext,
        pipes: &Pipelines,
        uni: &wgpu::Buffer,
        stats: &mut Stats,
    ) -> Result<(), GpuError> {
        let mut keep = Vec::new();
        timed(gpu, stats, AfsmPhase::GpuLists, || {
            let mut enc = gpu.encoder();
            let b = gpu.bind(
                &pipes.count,
                &[
                    uni,
                    &self.receivers,
                    &self.counts,
                    &self.slots,
                    &self.texel_depth,
                    &self.tile_depth,
                    &self.tile_box,
                    &self.tile_count,
                    &self.texel_near,
                    &self.tile_near,
                    &self.super_bounds,
                    &self.texel_bits,
                ],
            );
            gpu.dispatch(&mut enc, &pipes.count, &b, self.groups)?;
            let b = gpu.bind(&pipes.occupancy, &[uni, &self.tile_count, &self.occupancy]);
            gpu.dispatch(
                &mut enc,
                &pipes.occupancy,
                &b,
                self.tiles_per_side.div_ceil(64),
            )?;
            scan(
                gpu,
                pipes,
                &mut enc,
                &self.counts,
                self.texels + 1,
                &mut keep,
            )?;
            gpu.submit(enc)?;
            let mut enc = gpu.encoder();
            let b = gpu.bind(
                &pipes.scatter,
                &[uni, &self.slots, &self.counts, &self.lists],
            );
            gpu.dispatch(&mut enc, &pipes.scatter, &b, self.groups)?;
            gpu.submit(enc)
        })
    }

    /// The occlusion passes over these buffers.
    fn occlusion<'a>(
        &'a self,
        gpu: &'a GpuContext,
        pipes: &'a Pipelines,
        shared: &'a Shared<'a>,
    ) -> Occlusion<'a> {
        Occlusion {
            gpu,
            pipes,
            shared,
            regions: &self.regions,
            receivers: &self.receivers,
            offsets: &self.counts,
            lists: &self.lists,
            masks: &self.masks,
            tallies: &self.tallies,
            flags: &self.flags,
            depths: &self.depths,
            tile_depth: &self.tile_depth,
            texel_depth: &self.texel_depth,
            tile_box: &self.tile_box,
            texel_near: &self.texel_near,
            tile_near: &self.tile_near,
            occupancy: &self.occupancy,
            super_bounds: &self.super_bounds,
            texel_bits: &self.texel_bits,
            batch_box: &self.batch_box,
            slots: &self.slots,
            texel_hidden: &self.texel_hidden,
            tile_count: &self.tile_count,
            tile_hidden: &self.tile_hidden,
        }
    }

    /// Each receiver's visible samples summed into its value and radiance.
    fn resolve(
        &self,
        gpu: &GpuContext,
        pipes: &Pipelines,
        uni: &wgpu::Buffer,
        shared: &Shared<'_>,
        stats: &mut Stats,
    ) -> Result<(), GpuError> {
        timed(gpu, stats, AfsmPhase::GpuResolve, || {
            let mut enc = gpu.encoder();
            let b = gpu.bind(
                &pipes.resolve,
                &[
                    uni,
                    &self.receivers,
                    shared.samples,
                    shared.radiance,
                    &self.masks,
                    &self.result,
                    &self.depths,
                ],
            );
            gpu.dispatch(&mut enc, &pipes.resolve, &b, self.groups)?;
            gpu.submit(enc)
        })
    }

    /// The batch's results, lists and tallies read back.
    fn read_back(
        &self,
        gpu: &GpuContext,
        regions: Vec<Region>,
        stats: &mut Stats,
    ) -> Result<BatchOutput, GpuError> {
        timed(gpu, stats, AfsmPhase::GpuReadback, || {
            let t: Vec<u32> = gpu.read(&self.tallies, TALLY_WORDS)?;
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
                result: gpu.read(&self.result, self.n as usize)?,
                visible: gpu.read(&self.masks, (self.n * self.words) as usize)?,
                offsets: gpu.read(&self.counts, self.texels as usize + 1)?,
                regions,
                tallies,
                skipped,
            })
        })
    }
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
