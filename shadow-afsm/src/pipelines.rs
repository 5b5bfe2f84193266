//! The compute passes' WGSL sources (each pass is its own file after the shared prefixes it
//! names) and their compiled pipelines, validated by naga and compiled once per context.

use std::sync::{Arc, OnceLock};

use shadow_core::gpu::{GpuContext, GpuError};

/// The shared WGSL prefix (structures, projection, light support function, tiles).
pub const COMMON: &str = include_str!("shaders/common.wgsl");
/// 64-bit tallies (`add64`), for the passes that declare `stats`.
pub const TALLY: &str = include_str!("shaders/tally.wgsl");
/// Tiles of influence regions (bindings 1 to 3 and their helpers).
pub const TILING: &str = include_str!("shaders/tiling.wgsl");
/// Penumbra volumes and their tests against boxes and frustum pieces.
pub const VOLUME: &str = include_str!("shaders/volume.wgsl");
/// The occupied tiles of a caster's box in its kept super-tiles.
pub const OCCUPIED: &str = include_str!("shaders/occupied.wgsl");

/// Every pass: name, source, and the prefixes it is compiled with, in order.
pub const MODULES: [(&str, &str, &[&str]); 12] = [
    ("count", include_str!("shaders/count.wgsl"), &[COMMON]),
    (
        "occupancy",
        include_str!("shaders/occupancy.wgsl"),
        &[COMMON],
    ),
    ("scan_block", include_str!("shaders/scan_block.wgsl"), &[]),
    ("scan_add", include_str!("shaders/scan_add.wgsl"), &[]),
    ("scatter", include_str!("shaders/scatter.wgsl"), &[COMMON]),
    (
        "influence",
        include_str!("shaders/influence.wgsl"),
        &[COMMON, TALLY, VOLUME],
    ),
    (
        "tiles",
        include_str!("shaders/tiles.wgsl"),
        &[COMMON, TALLY, VOLUME, OCCUPIED],
    ),
    (
        "tile_pairs",
        include_str!("shaders/tile_pairs.wgsl"),
        &[COMMON, TALLY, VOLUME, OCCUPIED, TILING],
    ),
    (
        "occlude",
        include_str!("shaders/occlude.wgsl"),
        &[COMMON, TALLY, OCCUPIED, TILING],
    ),
    (
        "stencil",
        include_str!("shaders/stencil.wgsl"),
        &[COMMON, OCCUPIED, TILING],
    ),
    ("resolve", include_str!("shaders/resolve.wgsl"), &[COMMON]),
    ("hidden", include_str!("shaders/hidden.wgsl"), &[COMMON]),
];

/// The full WGSL source of pass `name`.
///
/// # Panics
/// For a name not in [`MODULES`] (a programming error).
pub fn source(name: &str) -> String {
    let (_, src, prefixes) = MODULES
        .iter()
        .find(|(n, _, _)| *n == name)
        .expect("known module");
    let mut out = prefixes.join("\n");
    out.push('\n');
    out.push_str(src);
    out
}

/// The compiled pipelines.
#[derive(Debug)]
pub struct Pipelines {
    pub(crate) count: wgpu::ComputePipeline,
    pub(crate) occupancy: wgpu::ComputePipeline,
    pub(crate) scan_block: wgpu::ComputePipeline,
    pub(crate) scan_add: wgpu::ComputePipeline,
    pub(crate) scatter: wgpu::ComputePipeline,
    pub(crate) influence: wgpu::ComputePipeline,
    pub(crate) tiles: wgpu::ComputePipeline,
    pub(crate) tile_pairs: wgpu::ComputePipeline,
    pub(crate) occlude: wgpu::ComputePipeline,
    pub(crate) stencil: wgpu::ComputePipeline,
    pub(crate) resolve: wgpu::ComputePipeline,
    pub(crate) hidden: wgpu::ComputePipeline,
}

impl Pipelines {
    /// Validates (naga) and compiles every pass.
    ///
    /// # Errors
    /// [`GpuError::Shader`] or [`GpuError::Device`].
    pub fn new(gpu: &GpuContext) -> Result<Self, GpuError> {
        let p = |n: &str| gpu.pipeline(n, &source(n), "main");
        Ok(Self {
            count: p("count")?,
            occupancy: p("occupancy")?,
            scan_block: p("scan_block")?,
            scan_add: p("scan_add")?,
            scatter: p("scatter")?,
            influence: p("influence")?,
            tiles: p("tiles")?,
            tile_pairs: p("tile_pairs")?,
            occlude: p("occlude")?,
            stencil: p("stencil")?,
            resolve: p("resolve")?,
            hidden: p("hidden")?,
        })
    }

    /// The pipelines of the shared context, compiled once.
    ///
    /// # Errors
    /// As [`GpuContext::shared`] and [`Pipelines::new`].
    pub fn shared() -> Result<(Arc<GpuContext>, Arc<Pipelines>), GpuError> {
        static PIPES: OnceLock<Result<Arc<Pipelines>, GpuError>> = OnceLock::new();
        let gpu = GpuContext::shared()?;
        let pipes = PIPES
            .get_or_init(|| Pipelines::new(&gpu).map(Arc::new))
            .clone()?;
        Ok((gpu, pipes))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pass is valid WGSL for naga (no device needed).
    #[test]
    fn every_module_validates_with_naga() {
        for (name, _, _) in MODULES {
            if let Err(e) = shadow_core::gpu::validate_wgsl(&source(name)) {
                panic!("{name}: {e}");
            }
        }
    }
}
