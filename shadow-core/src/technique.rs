//! The object-safe [`ShadowTechnique`] trait every technique implements, its capabilities, its
//! statistics and its error type (DESIGN section 3).

use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;
use thiserror::Error;

use crate::light::{AreaLight, Light, LightKind};
use crate::raster::RasterError;
use crate::sampling::LightSampler;
use crate::scene::Scene;
use crate::view_samples::ViewSamples;
use crate::visibility::{VisibilityError, VisibilityImage};

/// A scene shared between the caller and the techniques that keep it.
pub type SceneRef = Arc<dyn Scene>;

/// Why a technique produced no buffer.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TechniqueError {
    /// The technique cannot handle this input; nothing is wrong with the input itself.
    #[error("{technique} does not support this input: {reason}")]
    Unsupported {
        /// Technique name.
        technique: String,
        /// Why.
        reason: String,
    },
    /// `estimate` was called before `prepare`.
    #[error("{0}: estimate called before prepare")]
    NotPrepared(String),
    /// The input is invalid (the caller's fault).
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// A rasterization failed.
    #[error(transparent)]
    Raster(#[from] RasterError),
    /// The technique's own output failed validation (a bug, reported instead of a wrong image).
    #[error("output failed validation: {0}")]
    Output(#[from] VisibilityError),
    /// A GPU device or resource problem.
    #[error("device: {0}")]
    Device(String),
}

/// Where a technique runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Processor {
    /// CPU (rayon).
    Cpu,
    /// GPU (wgpu).
    Gpu,
}

/// What a technique can handle.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Capabilities {
    /// Light shapes supported.
    pub lights: Vec<LightKind>,
    /// Handles semi-opaque occluders (opacity < 1).
    pub semi_opaque: bool,
    /// Handles textured lights (RGB output).
    pub textured_lights: bool,
    /// Needs every mesh closed.
    pub needs_closed_meshes: bool,
    /// Evaluates a declared set of light samples (see [`ShadowTechnique::light_sampler`]).
    pub sample_based: bool,
    /// CPU or GPU.
    pub processor: Processor,
}

impl Capabilities {
    /// `Ok` when the technique can handle `scene` lit by `light`, else the reason.
    ///
    /// # Errors
    /// The reason, as text, for the first unsupported feature.
    pub fn check(&self, scene: &dyn Scene, light: &dyn AreaLight) -> Result<(), String> {
        let kind = light.kind();
        if !self.lights.contains(&kind) {
            return Err(format!("{kind:?} lights are not supported"));
        }
        if light.is_textured() && !self.textured_lights {
            return Err("textured lights are not supported".into());
        }
        if scene.has_semi_opaque() && !self.semi_opaque {
            return Err("semi-opaque occluders are not supported".into());
        }
        if self.needs_closed_meshes && !scene.topology().all_closed() {
            return Err("the scene has open meshes and the technique needs closed ones".into());
        }
        Ok(())
    }
}

/// Time of one phase.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Phase {
    /// Phase name.
    pub name: String,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Per-phase times and counters of work done and skipped.
///
/// Counters saturate at `u64::MAX` and record the saturation in `saturated`, so they never wrap
/// silently.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Stats {
    /// Phases in the order they ran.
    pub phases: Vec<Phase>,
    /// Named counters.
    pub counters: BTreeMap<String, u64>,
    /// Counters that saturated.
    pub saturated: Vec<String>,
}

impl Stats {
    /// Runs `f`, adding its wall-clock time to phase `name`.
    pub fn time<T>(&mut self, name: &str, f: impl FnOnce() -> T) -> T {
        let t0 = Instant::now();
        let r = f();
        let s = t0.elapsed().as_secs_f64();
        match self.phases.iter_mut().find(|p| p.name == name) {
            Some(p) => p.seconds += s,
            None => self.phases.push(Phase {
                name: name.to_string(),
                seconds: s,
            }),
        }
        r
    }

    /// Adds `n` to counter `name`, saturating (and recording it) on overflow.
    pub fn add(&mut self, name: &str, n: u64) {
        let c = self.counters.entry(name.to_string()).or_insert(0);
        match c.checked_add(n) {
            Some(v) => *c = v,
            None => {
                *c = u64::MAX;
                if !self.saturated.iter().any(|s| s == name) {
                    self.saturated.push(name.to_string());
                }
            }
        }
    }

    /// Total time over all phases.
    pub fn total_seconds(&self) -> f64 {
        self.phases.iter().map(|p| p.seconds).sum()
    }

    /// Merges another set of stats (times and counters add up).
    pub fn merge(&mut self, other: &Stats) {
        for p in &other.phases {
            match self.phases.iter_mut().find(|q| q.name == p.name) {
                Some(q) => q.seconds += p.seconds,
                None => self.phases.push(p.clone()),
            }
        }
        for (k, v) in &other.counters {
            self.add(k, *v);
        }
        for s in &other.saturated {
            if !self.saturated.contains(s) {
                self.saturated.push(s.clone());
            }
        }
    }

    /// Counter value (0 when absent).
    pub fn counter(&self, name: &str) -> u64 {
        self.counters.get(name).copied().unwrap_or(0)
    }
}

/// A technique's answer: the visibility buffer and what it cost.
#[derive(Debug, Clone)]
pub struct Estimate {
    /// Visibility per pixel.
    pub visibility: VisibilityImage,
    /// Times and counters of this estimate.
    pub stats: Stats,
}

/// A soft-shadow technique.
///
/// Object-safe so that suites and tools hold `Vec<Box<dyn ShadowTechnique>>`; construction
/// (presets, parameters) lives on the concrete types.
///
/// Contract:
/// * `prepare` is called once per scene and light, `estimate` any number of times after it.
/// * `estimate` returns a buffer of the view's size whose background pixels are invalid and
///   whose valid pixels hold `V(p)` in [0, 1] (RGB non-negative for textured lights), never NaN.
/// * For a fixed seed the output is identical whatever the thread count.
/// * Input the technique cannot handle gives [`TechniqueError::Unsupported`] with the reason,
///   never a silently wrong image.
pub trait ShadowTechnique: Send + Sync {
    /// Preset name, e.g. `ref` or `dcs-64`.
    fn name(&self) -> &str;
    /// What the technique handles.
    fn capabilities(&self) -> Capabilities;
    /// Parameters for reports (`stats.json`).
    fn parameters(&self) -> serde_json::Value {
        serde_json::Value::Null
    }
    /// The light samples a sample-based technique evaluates, so the reference can use the same.
    fn light_sampler(&self) -> Option<&LightSampler> {
        None
    }
    /// Builds per-scene and per-light data.
    ///
    /// # Errors
    /// [`TechniqueError::Unsupported`] when the scene or light is outside the capabilities.
    fn prepare(&mut self, scene: SceneRef, light: Light) -> Result<Stats, TechniqueError>;
    /// Computes the visibility of every view sample.
    ///
    /// # Errors
    /// [`TechniqueError::NotPrepared`] before `prepare`; others as the technique documents.
    fn estimate(&mut self, view: &ViewSamples) -> Result<Estimate, TechniqueError>;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counters_saturate_and_report() {
        let mut s = Stats::default();
        s.add("rays", u64::MAX - 1);
        s.add("rays", 5);
        assert_eq!(s.counter("rays"), u64::MAX);
        assert_eq!(s.saturated, vec!["rays".to_string()]);
        let v = s.time("phase", || 3);
        assert_eq!(v, 3);
        assert_eq!(s.phases.len(), 1);
    }
}
