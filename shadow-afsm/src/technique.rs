//! The [`Afsm`] technique: alias-free shadow maps and sample-based soft shadows (Sintorn,
//! Eisemann and Assarsson 2008) in wgpu compute shaders.
//!
//! Per estimate:
//! * CPU: the view samples whose tangent plane leaves part of the light above (light
//!   front-facing, section 3) become receivers, with the reference's offset ray origin
//!   ([`shadow_core::offset`]); the others are 0 with no work. Receivers go to the GPU in
//!   batches whose buffers respect the device's binding limit, each with its own fitted light
//!   frustum ([`crate::frame`], section 4.3).
//! * GPU: lists, influence regions, occlusion and resolve ([`crate::passes`]).
//! * CPU: visibility `V = visible / N` (DCS eq. 1), or the radiance-weighted sum for textured
//!   lights (DCS eq. 2), per-sample bits and classes.
//!
//! Light samples are shared sets (one set, or `k x k` interleaved sets), as the lookup table of
//! section 4.2 needs a fixed set; [`Afsm::set_frame`] rotates them for temporal jittering
//! (section 4.2, Fig. 7), see [`crate::temporal`].
//!
//! Semi-opaque occluders: the paper's section 6 approximates transparency by multiplying
//! casters' transparencies weighted by their coverage, since its bits cannot hold more. Here
//! each (view sample, light sample) pair of a scene with semi-opaque casters also gets a
//! fixed-point optical-depth sum that semi-opaque casters add to, so the transmittance product
//! is exact per sample (to a relative 5e-7 per crossing). Opaque casters keep the bitmask.
//! Scenes without semi-opaque casters allocate nothing for it.

use std::sync::Arc;

use glam::{UVec2, Vec3};
use serde_json::json;
use shadow_core::gpu::{GpuContext, GpuError, check_finite, gpu_required};
use shadow_core::offset::RayOffset;
use shadow_core::prelude::*;
use shadow_core::sampling::hash_words;
use shadow_core::technique::{Capabilities, Processor, SceneRef};

pub use crate::inputs::silhouette_edges;
use crate::inputs::{casters_of, upload_casters};
use crate::lut::PlaneLut;
use crate::params::{Caster, LightBounds, OPAQUE, Region};
use crate::passes::{CasterBatch, Pipelines, device_error};
use crate::sample_grid::SampleGrid;
use crate::statistics::AfsmPhase;

mod estimate;

pub use estimate::Run;

/// How the occlusion pass finds the samples behind a plane (section 4.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlaneTest {
    /// Every sample tested against every plane that cuts the light.
    Exact,
    /// The 3D lookup table of section 4.2 (one shared sample set).
    Lut,
}

/// Largest sample count per view sample.
pub const MAX_SAMPLES: u32 = 1024;

struct Prepared {
    scene: SceneRef,
    light: Light,
    gpu: Arc<GpuContext>,
    pipes: Arc<Pipelines>,
    bounds: LightBounds,
    offset: RayOffset,
    batches: Vec<CasterBatch>,
    /// Per topology component: closed and consistently oriented, so that only its light
    /// back-facing triangles cast (section 3.3) for an eye outside it.
    closed: Vec<bool>,
    /// Per component: whether it holds the light's centre.
    around_light: Vec<bool>,
    /// Every caster with no component taken as closed, uploaded the first time an eye lies
    /// inside a closed mesh that the light is outside of, or outside one that holds the light
    /// (its receivers' segments then cross that mesh an odd number of times, through a front
    /// face alone).
    open_batches: std::sync::OnceLock<Result<Vec<CasterBatch>, TechniqueError>>,
    /// Casters per batch within the binding limit.
    per_batch: usize,
    semi_opaque: bool,
    silhouettes: Vec<CasterBatch>,
    silhouette_count: usize,
    samples: wgpu::Buffer,
    radiance: wgpu::Buffer,
    lut: wgpu::Buffer,
    grid: Option<(u32, [f32; 4])>,
    sample_positions: Vec<Vec3>,
}

/// Alias-free shadow maps (hard) and sample-based visibility (soft) on wgpu: a configuration
/// ([`ShadowTechnique::prepare`] or [`Afsm::prepare_afsm`] gives the [`PreparedAfsm`] that
/// estimates).
#[derive(Clone)]
pub struct Afsm {
    name: String,
    samples: u32,
    strategy: SamplingStrategy,
    seed: u64,
    frame: u64,
    sampler: LightSampler,
    hard: bool,
    plane_test: PlaneTest,
    stencil: bool,
    culling: bool,
    memory_limit: Option<u64>,
}

/// AFSM prepared for one scene and light: its device, pipelines, casters and light samples.
pub struct PreparedAfsm {
    config: Afsm,
    p: Prepared,
    stats: Stats,
}

impl std::fmt::Debug for PreparedAfsm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PreparedAfsm")
            .field("config", &self.config)
            .finish_non_exhaustive()
    }
}

impl std::fmt::Debug for Afsm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Afsm")
            .field("name", &self.name)
            .field("samples", &self.samples)
            .field("plane_test", &self.plane_test)
            .finish_non_exhaustive()
    }
}

impl Afsm {
    /// Soft shadows with `samples` light samples per view sample (1 to 1024) drawn by
    /// `strategy`, which must share sets between view samples (correlated or interleaved).
    ///
    /// # Errors
    /// [`TechniqueError::InvalidInput`] for a count outside 1..=1024 or a per-pixel strategy.
    pub fn new(
        samples: u32,
        strategy: SamplingStrategy,
        seed: u64,
    ) -> Result<Self, TechniqueError> {
        if samples == 0 || samples > MAX_SAMPLES {
            return Err(TechniqueError::InvalidInput(format!(
                "AFSM takes 1 to {MAX_SAMPLES} samples per view sample, got {samples}"
            )));
        }
        if !matches!(
            strategy,
            SamplingStrategy::Correlated | SamplingStrategy::Interleaved { .. }
        ) {
            return Err(TechniqueError::InvalidInput(format!(
                "AFSM shares light sample sets between view samples (section 4.2); {strategy:?} \
                 draws a set per pixel: use Correlated or Interleaved"
            )));
        }
        let sampler = LightSampler::new(strategy, samples, seed)
            .map_err(|e| TechniqueError::InvalidInput(e.to_string()))?;
        Ok(Self {
            name: format!("afsm-{samples}"),
            samples,
            strategy,
            seed,
            frame: 0,
            sampler,
            hard: false,
            plane_test: PlaneTest::Exact,
            stencil: false,
            culling: true,
            memory_limit: None,
        })
    }

    /// Hard shadows from the light's centre (section 3): one bit per view sample.
    pub fn hard() -> Self {
        let mut a = Self::new(1, SamplingStrategy::Correlated, 0).expect("one sample is valid");
        a.hard = true;
        a.name = "afsm-hard".into();
        a
    }

    /// Uses the plane lookup table (needs a single shared set: correlated sampling).
    ///
    /// # Errors
    /// [`TechniqueError::InvalidInput`] with interleaved sets.
    pub fn with_lut(mut self) -> Result<Self, TechniqueError> {
        if self.strategy != SamplingStrategy::Correlated || self.hard {
            return Err(TechniqueError::InvalidInput(
                "the plane lookup table holds one sample set: use correlated sampling".into(),
            ));
        }
        self.plane_test = PlaneTest::Lut;
        Ok(self)
    }

    /// Turns on the silhouette stencil of section 4.3: the influence regions of the edges that
    /// can be a silhouette for some light point mark the texels whose view samples can be in
    /// penumbra; elsewhere one sample per pair stands for all. It pays when occluders are large
    /// against the light (umbrae far from any silhouette's region); under the built-in scenes'
    /// large lights every busy texel is marked, so it only adds its passes, and it is off by
    /// default.
    pub fn with_silhouette_stencil(mut self) -> Self {
        self.stencil = true;
        self
    }

    /// Turns cluster culling off (`tile_pairs.wgsl`), and the skipping of texels and tiles
    /// whose view samples are all hidden already: every view sample listed in a texel of a
    /// caster's influence region is tested against it, as in the paper. The output is the
    /// same sample for sample; only the work differs (tests compare the two).
    pub fn without_cluster_culling(mut self) -> Self {
        self.culling = false;
        self
    }

    /// Caps every GPU buffer at `bytes` (below the device's own limit), forcing the receiver
    /// and caster splitting a smaller device would need.
    pub fn with_memory_limit(mut self, bytes: u64) -> Self {
        self.memory_limit = Some(bytes);
        self
    }

    /// Renames the technique.
    pub fn named(mut self, name: &str) -> Self {
        self.name = name.into();
        self
    }

    /// The current frame of temporal jittering.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Moves to frame `k` of temporal jittering: frame 0 uses the seed's sets, every other
    /// frame a fresh set from a hash of the seed and `k` (section 4.2, Fig. 7). A prepared
    /// technique moves with [`PreparedAfsm::set_frame`].
    ///
    /// # Errors
    /// [`TechniqueError::InvalidInput`] when the sampler cannot be rebuilt.
    pub fn set_frame(&mut self, k: u64) -> Result<(), TechniqueError> {
        let seed = if k == 0 {
            self.seed
        } else {
            hash_words(&[self.seed, 0x7e3f, k])
        };
        self.frame = k;
        self.sampler = LightSampler::new(self.strategy, self.samples, seed)
            .map_err(|e| TechniqueError::InvalidInput(e.to_string()))?;
        Ok(())
    }

    /// A GPU failure as a technique error: a missing adapter is
    /// [`UnsupportedReason::NoAdapter`] (with a loud note) unless the environment requires a
    /// GPU, when it is a device failure like any other.
    fn gpu_error(&self, e: GpuError) -> TechniqueError {
        match e {
            GpuError::NoAdapter(m) if !gpu_required() => {
                eprintln!(
                    "{}: no GPU adapter: {m}; reported as unsupported (set {}=1 to make it a \
                     failure)",
                    self.name,
                    shadow_core::gpu::REQUIRE_GPU_ENV
                );
                TechniqueError::unsupported(&self.name, UnsupportedReason::NoAdapter(m))
            }
            e => device_error(e),
        }
    }

    /// Builds the device data (casters, light samples, tables) for `scene` and `light`.
    ///
    /// # Errors
    /// [`TechniqueError::Unsupported`] outside the capabilities or without an adapter (unless
    /// one is required); [`TechniqueError::Device`] on a device failure.
    pub fn prepare_afsm(
        &self,
        scene: SceneRef,
        light: Light,
    ) -> Result<PreparedAfsm, TechniqueError> {
        self.capabilities()
            .require(&self.name, scene.as_ref(), light.as_ref())?;
        let mut stats = Stats::default();
        let p = stats.time(AfsmPhase::Prepare, || self.build(scene, light))?;
        Ok(PreparedAfsm {
            config: self.clone(),
            p,
            stats,
        })
    }

    fn words(&self) -> u32 {
        self.samples.div_ceil(32)
    }

    fn binding_limit(&self, gpu: &GpuContext) -> u64 {
        let device = gpu.max_binding();
        self.memory_limit.map_or(device, |m| m.min(device))
    }

    /// The sets of light samples: one per interleaving cell (or one).
    fn sets(&self, light: &dyn AreaLight) -> Vec<Vec<LightSample>> {
        if self.hard {
            let c = light.center();
            return vec![vec![LightSample {
                position: c,
                normal: Vec3::ZERO,
                uv: glam::Vec2::splat(0.5),
                radiance: light.radiance().mean(),
            }]];
        }
        let tile = match self.strategy {
            SamplingStrategy::Interleaved { tile } => tile,
            _ => 1,
        };
        let mut out = Vec::new();
        for k in 0..tile * tile {
            let mut s = Vec::new();
            self.sampler
                .light_samples(light, UVec2::new(k % tile, k / tile), &mut s);
            out.push(s);
        }
        out
    }

    fn set_of(&self, pixel: UVec2) -> u32 {
        match self.strategy {
            SamplingStrategy::Interleaved { tile } if !self.hard => {
                (pixel.y % tile) * tile + pixel.x % tile
            }
            _ => 0,
        }
    }

    fn build(&self, scene: SceneRef, light: Light) -> Result<Prepared, TechniqueError> {
        let (gpu, pipes) = Pipelines::shared().map_err(|e| self.gpu_error(e))?;
        let bounds = LightBounds::new(light.as_ref(), self.hard);
        check_finite(&bounds.floats(), "light bounds").map_err(device_error)?;
        let topo = scene.topology();
        let closed: Vec<bool> = topo
            .components()
            .iter()
            .map(|c| c.closed && c.consistently_oriented)
            .collect();
        let casters = casters_of(scene.as_ref(), &closed);
        let around_light = shadow_core::scene::components_containing(
            scene.as_ref(),
            light.center().as_dvec3(),
            &closed,
        );
        let semi_opaque = casters.iter().any(|c| c.optical_depth != OPAQUE);
        let limit = self.binding_limit(&gpu);
        let per = (limit / std::mem::size_of::<Region>() as u64).max(1) as usize;
        let upload =
            |all: &[Caster], light, label: &str| upload_casters(&gpu, all, light, per, label);
        let batches = upload(&casters, Some(&bounds), "casters")?;
        // The stencil pays only when there are several samples to skip.
        let edges = if self.stencil && !self.hard && self.samples > 1 {
            silhouette_edges(scene.as_ref(), &bounds)
        } else {
            Vec::new()
        };
        let silhouettes = upload(&edges, None, "silhouette edges")?;
        let sets = self.sets(light.as_ref());
        let positions: Vec<[f32; 4]> = sets
            .iter()
            .flatten()
            .map(|s| [s.position.x, s.position.y, s.position.z, 1.0])
            .collect();
        let radiance: Vec<[f32; 4]> = sets
            .iter()
            .flatten()
            .map(|s| [s.radiance.x, s.radiance.y, s.radiance.z, 0.0])
            .collect();
        check_finite(positions.as_flattened(), "light samples").map_err(device_error)?;
        check_finite(radiance.as_flattened(), "light sample radiance").map_err(device_error)?;
        let sample_positions: Vec<Vec3> = sets.iter().flatten().map(|s| s.position).collect();
        // The plane table, or for the exact test the samples bucketed on a planar light.
        let mut grid = None;
        let lut_data = match self.plane_test {
            PlaneTest::Lut => PlaneLut::build(&bounds, &sample_positions).data,
            PlaneTest::Exact => {
                let per_set: Vec<Vec<Vec3>> = sets
                    .iter()
                    .map(|s| s.iter().map(|x| x.position).collect())
                    .collect();
                // Below 128 samples the plain loop is as fast (docs/benchmarks.md).
                let n = sets[0].len() as u32;
                match SampleGrid::build(&bounds, &per_set, n) {
                    Some(sg) if !self.hard && n >= SampleGrid::MIN_SAMPLES => {
                        let g = [sg.origin.x, sg.origin.y, sg.scale.x, sg.scale.y];
                        grid = Some((sg.g, g));
                        sg.data
                    }
                    _ => vec![0u32; 4],
                }
            }
        };
        let up = || -> Result<_, GpuError> {
            Ok((
                gpu.storage("light samples", &positions)?,
                gpu.storage("light radiance", &radiance)?,
                gpu.storage("plane table", &lut_data)?,
            ))
        };
        let (samples, radiance, lut) = up().map_err(device_error)?;
        let offset = RayOffset::for_light(&*light);
        Ok(Prepared {
            scene,
            light,
            gpu,
            pipes,
            bounds,
            offset,
            batches,
            around_light,
            closed,
            open_batches: std::sync::OnceLock::new(),
            per_batch: per,
            semi_opaque,
            silhouettes,
            silhouette_count: edges.len(),
            samples,
            radiance,
            lut,
            grid,
            sample_positions,
        })
    }
}

impl PreparedAfsm {
    /// The adapter the technique runs on.
    pub fn adapter(&self) -> String {
        self.p.gpu.describe()
    }

    /// The sample positions of the current frame (all sets, in set order).
    pub fn sample_positions(&self) -> &[Vec3] {
        &self.p.sample_positions
    }

    /// The current frame of temporal jittering.
    pub fn frame(&self) -> u64 {
        self.config.frame
    }

    /// The configuration, at its current frame.
    pub fn config(&self) -> &Afsm {
        &self.config
    }

    /// Moves to frame `k` of temporal jittering ([`Afsm::set_frame`]) and uploads the new
    /// samples (and table).
    ///
    /// # Errors
    /// [`TechniqueError::Device`] when the new samples cannot be uploaded.
    pub fn set_frame(&mut self, k: u64) -> Result<(), TechniqueError> {
        self.config.set_frame(k)?;
        self.p = self
            .config
            .build(self.p.scene.clone(), self.p.light.clone())?;
        Ok(())
    }

    /// Runs the passes on `view`, keeping the last caster batch's influence regions when
    /// `keep_regions` (for stage tests). Returns the estimate, the receivers, their map frames
    /// and regions per batch.
    ///
    /// # Errors
    /// [`TechniqueError::Device`] on a device failure.
    pub fn run(&self, view: &ViewSamples, keep_regions: bool) -> Result<Run, TechniqueError> {
        self.config.run(&self.p, view, keep_regions)
    }
}

impl ShadowTechnique for Afsm {
    fn name(&self) -> &str {
        &self.name
    }

    fn capabilities(&self) -> Capabilities {
        // Every light but meshes for soft shadows: the sample masks and the plane
        // classification take one emitting plane or a sphere (section 3.1), not triangles
        // facing many ways. Hard shadows use the light's centre only, so any light will do.
        let mut c = Capabilities::any_input(!self.hard, Processor::Gpu);
        if !self.hard {
            c.lights.retain(|k| *k != LightKind::Mesh);
        }
        c
    }

    fn parameters(&self) -> serde_json::Value {
        json!({
            "samples": self.samples,
            "strategy": format!("{:?}", self.strategy),
            "seed": self.seed,
            "frame": self.frame,
            "hard": self.hard,
            "plane_test": format!("{:?}", self.plane_test),
            "silhouette_stencil": self.stencil && !self.hard && self.samples > 1,
            "cluster_culling": self.culling,
            "lut_bins": (self.plane_test == PlaneTest::Lut).then(|| crate::lut::bins_for(self.samples)),
        })
    }

    fn light_sampler(&self) -> Option<&LightSampler> {
        (!self.hard).then_some(&self.sampler)
    }

    fn prepare(
        &self,
        scene: SceneRef,
        light: Light,
    ) -> Result<Box<dyn PreparedShadows>, TechniqueError> {
        Ok(Box::new(self.prepare_afsm(scene, light)?))
    }
}

impl PreparedShadows for PreparedAfsm {
    fn name(&self) -> &str {
        &self.config.name
    }

    fn preparation(&self) -> &Stats {
        &self.stats
    }

    fn light(&self) -> &dyn AreaLight {
        self.p.light.as_ref()
    }

    fn check_outputs(&self, outputs: Outputs) -> Result<(), TechniqueError> {
        if outputs.direct && self.config.light_sampler().is_none() {
            return Err(TechniqueError::no_direct_light(
                &self.config.name,
                "hard shadows",
            ));
        }
        Ok(())
    }

    fn pass(&self, view: &ViewSamples, _outputs: Outputs) -> Result<Estimate, TechniqueError> {
        self.run(view, false).map(|(est, _, _)| est)
    }

    fn direct_light(
        &self,
        view: &ViewSamples,
        est: &Estimate,
    ) -> Result<Vec<Vec3>, TechniqueError> {
        let no_samples = || TechniqueError::no_direct_light(&self.config.name, "hard shadows");
        let sampler = self.config.light_sampler().ok_or_else(no_samples)?;
        let (scene, light) = (self.p.scene.as_ref(), self.p.light.as_ref());
        shadow_core::technique::direct_from_per_sample(scene, light, sampler, view, &est.visibility)
    }
}
