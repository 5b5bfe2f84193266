//! The object-safe [`ShadowTechnique`] trait every technique implements, its capabilities, its
//! statistics and its error type (DESIGN section 3).

use std::sync::Arc;

use glam::Vec3;
use serde::Serialize;
use thiserror::Error;

use crate::light::{AreaLight, Light, LightKind, LightSample};
use crate::raster::RasterError;
use crate::sampling::LightSampler;
use crate::scene::Scene;
use crate::stats::{CoreCounter, CorePhase};
pub use crate::stats::{Phase, Stats};
use crate::view_samples::{ViewSample, ViewSamples};
use crate::visibility::{VisibilityError, VisibilityImage};

/// A scene shared between the caller and the techniques that keep it.
pub type SceneRef = Arc<dyn Scene>;

/// Why a technique cannot handle an input, by kind: callers branch on the kind (a missing GPU
/// adapter is a skip outside CI, a light kind is a gap in the capability table), the message
/// says the rest.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub enum UnsupportedReason {
    /// The light's shape is outside the technique's capabilities (or, with a message, a light
    /// the shape allows but the technique cannot sample, such as a point light for DCS).
    Light {
        /// The light's kind.
        kind: LightKind,
        /// What is missing, beyond the kind.
        detail: Option<String>,
    },
    /// The scene has semi-opaque occluders.
    SemiOpaque,
    /// The light is textured.
    TexturedLight,
    /// The scene has open meshes and the technique needs closed ones.
    OpenMeshes,
    /// The view cannot be handled (for example an orthographic camera).
    View(String),
    /// No GPU adapter was found.
    NoAdapter(String),
    /// The input exceeds a limit of the device.
    DeviceLimit(String),
    /// The technique's configuration cannot handle this input (for example tables that need a
    /// finite number of sample sets).
    Configuration(String),
}

impl std::fmt::Display for UnsupportedReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Light { kind, detail: None } => write!(
                f,
                "{} lights are not supported",
                format!("{kind:?}").to_lowercase()
            ),
            Self::Light {
                detail: Some(d), ..
            } => f.write_str(d),
            Self::SemiOpaque => f.write_str("semi-opaque occluders are not supported"),
            Self::TexturedLight => f.write_str("textured lights are not supported"),
            Self::OpenMeshes => {
                f.write_str("the scene has open meshes and the technique needs closed ones")
            }
            Self::View(m) | Self::DeviceLimit(m) | Self::Configuration(m) => f.write_str(m),
            Self::NoAdapter(m) => write!(f, "no GPU adapter: {m}"),
        }
    }
}

/// Why a technique produced no buffer.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TechniqueError {
    /// The technique cannot handle this input; nothing is wrong with the input itself.
    #[error("{technique} does not support this input: {reason}")]
    Unsupported {
        /// Technique name.
        technique: String,
        /// Why, by kind.
        reason: UnsupportedReason,
    },
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
    /// One light of several failed or was refused ([`crate::lights::PreparedLights`]).
    #[error("light {index}: {error}")]
    Light {
        /// The light's index in the caller's list.
        index: usize,
        /// What went wrong with it.
        error: Box<TechniqueError>,
    },
}

impl From<crate::sampling::SamplingError> for TechniqueError {
    fn from(e: crate::sampling::SamplingError) -> Self {
        Self::InvalidInput(e.to_string())
    }
}

impl TechniqueError {
    /// [`TechniqueError::Unsupported`] for `technique`.
    pub fn unsupported(technique: &str, reason: UnsupportedReason) -> Self {
        Self::Unsupported {
            technique: technique.to_string(),
            reason,
        }
    }

    /// [`TechniqueError::Unsupported`] for direct light asked of a technique without light
    /// samples; `what` names what it has instead (`hard shadows`, `shadow-map filters`).
    pub fn no_direct_light(technique: &str, what: &str) -> Self {
        Self::unsupported(
            technique,
            UnsupportedReason::Configuration(format!(
                "{what} have no light samples to shade direct light from"
            )),
        )
    }

    /// `error` as the error of light `index` of several.
    pub fn for_light(index: usize, error: TechniqueError) -> Self {
        Self::Light {
            index,
            error: Box::new(error),
        }
    }

    /// The reason, when the technique does not support the input (for one light of several,
    /// that light's reason).
    pub fn unsupported_reason(&self) -> Option<&UnsupportedReason> {
        match self {
            Self::Unsupported { reason, .. } => Some(reason),
            Self::Light { error, .. } => error.unsupported_reason(),
            _ => None,
        }
    }
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
    /// Works in the camera's image (DCS's shadow volumes counted from the eye, GBP07's
    /// screen-space selection): receivers without a perspective camera are refused.
    pub needs_camera: bool,
}

impl Capabilities {
    /// Every light kind, semi-opaque occluders, textured lights and open meshes: the
    /// capabilities of a technique that handles any input (ray tracing, AFSM, the `auto`
    /// chooser).
    pub fn any_input(sample_based: bool, processor: Processor) -> Self {
        Self {
            lights: LightKind::ALL.to_vec(),
            semi_opaque: true,
            textured_lights: true,
            needs_closed_meshes: false,
            sample_based,
            processor,
            needs_camera: false,
        }
    }

    /// `Ok` when the technique takes `view`'s receivers, else the reason (receivers without a
    /// perspective camera for a technique that [`Capabilities::needs_camera`]).
    ///
    /// # Errors
    /// [`UnsupportedReason::View`].
    pub fn check_view(&self, view: &ViewSamples) -> Result<(), UnsupportedReason> {
        if self.needs_camera && view.eye().is_none() {
            return Err(UnsupportedReason::View(
                "the technique works in a perspective camera's image; these receivers have none"
                    .into(),
            ));
        }
        Ok(())
    }

    /// `Ok` when the technique can handle `scene` lit by `light`, else the reason.
    ///
    /// # Errors
    /// The first unsupported feature.
    pub fn check(&self, scene: &dyn Scene, light: &dyn AreaLight) -> Result<(), UnsupportedReason> {
        let kind = light.kind();
        if !self.lights.contains(&kind) {
            return Err(UnsupportedReason::Light { kind, detail: None });
        }
        if light.is_textured() && !self.textured_lights {
            return Err(UnsupportedReason::TexturedLight);
        }
        if scene.has_semi_opaque() && !self.semi_opaque {
            return Err(UnsupportedReason::SemiOpaque);
        }
        if self.needs_closed_meshes && !scene.topology().all_closed() {
            return Err(UnsupportedReason::OpenMeshes);
        }
        Ok(())
    }

    /// [`Capabilities::check`] as a [`TechniqueError`] naming `technique`.
    ///
    /// # Errors
    /// [`TechniqueError::Unsupported`] with the first unsupported feature.
    pub fn require(
        &self,
        technique: &str,
        scene: &dyn Scene,
        light: &dyn AreaLight,
    ) -> Result<(), TechniqueError> {
        self.check(scene, light)
            .map_err(|reason| TechniqueError::unsupported(technique, reason))
    }
}

/// What a caller wants from an estimate beyond `V(p)`.
///
/// Asking only for what is read saves memory and time: per-sample visibility is
/// `ceil(N / 64)` words per pixel, and direct illumination one more pass over the samples.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Outputs {
    /// Per-sample visibility in the buffer (sample-based techniques; a technique whose
    /// configuration already returns it, or returns counters, keeps doing so), read with
    /// [`crate::visibility::VisibilityBuffer::per_sample`].
    pub per_sample: bool,
    /// Direct illumination (DCS eq. 6) in [`Estimate::direct`], from the technique's own
    /// per-sample visibility (sample-based techniques; the others answer
    /// [`UnsupportedReason::Configuration`]).
    pub direct: bool,
}

impl Outputs {
    /// `V(p)` alone.
    pub const VISIBILITY: Self = Self {
        per_sample: false,
        direct: false,
    };
    /// `V(p)` and per-sample visibility.
    pub const PER_SAMPLE: Self = Self {
        per_sample: true,
        direct: false,
    };
}

/// A technique's answer: the visibility buffer and what it cost.
#[derive(Debug, Clone)]
pub struct Estimate {
    /// Visibility per pixel.
    pub visibility: VisibilityImage,
    /// Outgoing radiance per pixel under diffuse shading (DCS eq. 6), background black, when
    /// [`Outputs::direct`] asked for it.
    pub direct: Option<Vec<Vec3>>,
    /// Times and counters of this estimate.
    pub stats: Stats,
    /// What the technique decided at estimate time (the `auto` chooser's choice, its reason
    /// and its prediction); `None` for techniques that decide nothing per view. Read the
    /// concrete type with [`EstimateDecision::as_any`].
    pub decision: Option<Arc<dyn EstimateDecision>>,
}

impl Estimate {
    /// An estimate of `visibility` alone.
    pub fn new(visibility: VisibilityImage, stats: Stats) -> Self {
        Self {
            visibility,
            direct: None,
            stats,
            decision: None,
        }
    }
}

impl Estimate {
    /// Applies the light-side rule every technique shares: a receiver behind the plane a
    /// planar light emits from (or in it) gets no light, so its visibility, per-sample
    /// visibility and direct light are zero ([`crate::light::LightGeometry::behind`]). Counts
    /// the pixels in `pixels-behind-light`. [`finish_estimate`] applies it after every
    /// technique's pass; techniques skip those pixels' work where they can.
    pub fn darken_behind_light(&mut self, view: &ViewSamples, light: &dyn AreaLight) {
        let geometry = light.geometry();
        if geometry.emitting_plane().is_none() {
            return;
        }
        let mut count = 0u64;
        for i in 0..view.len() {
            if view.get(i).is_some_and(|s| geometry.behind(s.position)) {
                self.visibility.darken(i);
                if let Some(d) = &mut self.direct {
                    d[i] = Vec3::ZERO;
                }
                count += 1;
            }
        }
        self.stats.add(CoreCounter::PixelsBehindLight, count);
    }
}

/// What a technique decided at estimate time: a configuration chosen for this view, and why.
///
/// The technique's own type holds the rest (`shadow_auto::Decision` holds the predictions);
/// a caller that knows it reads it with [`EstimateDecision::as_any`], a report reads the
/// choice, the reason and [`EstimateDecision::to_json`].
pub trait EstimateDecision: std::fmt::Debug + Send + Sync + std::any::Any {
    /// The configuration chosen, by preset name.
    fn choice(&self) -> &str;
    /// Why it was chosen.
    fn reason(&self) -> &str;
    /// The whole decision for `stats.json`.
    fn to_json(&self) -> serde_json::Value;
    /// The decision as [`std::any::Any`], to downcast to the technique's type.
    fn as_any(&self) -> &dyn std::any::Any;
}

/// A soft-shadow technique: a configuration that prepares a scene and light.
///
/// Object-safe so that suites and tools hold `Vec<Box<dyn ShadowTechnique>>`; construction
/// (presets, parameters) lives on the concrete types, and a configuration that cannot work
/// is refused there.
///
/// Contract:
/// * `prepare` builds everything per scene and light and returns it as a [`PreparedShadows`],
///   whose `estimate` may be called any number of times; there is no "not prepared" state.
/// * `estimate` returns a buffer of the view's size whose background pixels are invalid and
///   whose valid pixels hold `V(p)` in [0, 1] (RGB non-negative for textured lights), never NaN.
/// * For a fixed seed the output is identical whatever the thread count.
/// * Input the technique cannot handle gives [`TechniqueError::Unsupported`] with a typed
///   reason, never a silently wrong image.
pub trait ShadowTechnique: Send + Sync {
    /// Preset name, e.g. `ref` or `dcs-64`.
    fn name(&self) -> &str;
    /// What the technique handles, from its configuration.
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
    fn prepare(
        &self,
        scene: SceneRef,
        light: Light,
    ) -> Result<Box<dyn PreparedShadows>, TechniqueError>;
    /// [`ShadowTechnique::prepare`] for each of `lights` in `scene`, in order
    /// ([`crate::lights::PreparedLights`]). A technique overrides it to build what the lights
    /// share once (the reference builds one BVH for all of them).
    fn prepare_each(
        &self,
        scene: SceneRef,
        lights: &[Light],
    ) -> Vec<Result<Box<dyn PreparedShadows>, TechniqueError>> {
        lights
            .iter()
            .map(|l| self.prepare(scene.clone(), l.clone()))
            .collect()
    }
}

/// A technique prepared for one scene and light.
///
/// A technique implements its own pass ([`PreparedShadows::pass`]) and, when it can shade,
/// [`PreparedShadows::direct_light`]; the steps every technique shares are
/// [`PreparedShadows::estimate`]'s, written once here ([`finish_estimate`]): outputs refused
/// before any work, direct light timed as the `direct` phase, the behind-the-light rule,
/// validation.
pub trait PreparedShadows: Send + Sync + std::fmt::Debug {
    /// The technique's name.
    fn name(&self) -> &str;
    /// Times and counters of the preparation.
    fn preparation(&self) -> &Stats;
    /// The light it was prepared for.
    fn light(&self) -> &dyn AreaLight;
    /// Refuses, before any work, `outputs` the technique cannot give (for example direct
    /// light from a technique without light samples).
    ///
    /// # Errors
    /// [`TechniqueError::Unsupported`] naming what cannot be given.
    fn check_outputs(&self, outputs: Outputs) -> Result<(), TechniqueError> {
        let _ = outputs;
        Ok(())
    }
    /// The technique's own pass: the visibility of every view sample (with per-sample
    /// visibility when `outputs.per_sample`), and direct light only where the pass computes it
    /// itself; [`PreparedShadows::estimate`] does the rest.
    ///
    /// # Errors
    /// As the technique documents (unsupported views, device failures).
    fn pass(&self, view: &ViewSamples, outputs: Outputs) -> Result<Estimate, TechniqueError>;
    /// Direct illumination (DCS eq. 6) of every view sample, from the pass's estimate; asked
    /// for when `outputs.direct` and the pass left [`Estimate::direct`] empty.
    ///
    /// # Errors
    /// [`TechniqueError::Unsupported`] by default: the technique has no light samples to shade
    /// from.
    fn direct_light(
        &self,
        view: &ViewSamples,
        estimate: &Estimate,
    ) -> Result<Vec<Vec3>, TechniqueError> {
        let _ = (view, estimate);
        Err(TechniqueError::unsupported(
            self.name(),
            UnsupportedReason::Configuration("the technique gives no direct light".into()),
        ))
    }
    /// Computes the visibility of every view sample, and what `outputs` asks for besides: the
    /// technique's pass, then the shared steps ([`finish_estimate`]).
    ///
    /// # Errors
    /// As [`PreparedShadows::check_outputs`], [`PreparedShadows::pass`] and
    /// [`PreparedShadows::direct_light`]; a buffer that fails validation.
    fn estimate(&self, view: &ViewSamples, outputs: Outputs) -> Result<Estimate, TechniqueError> {
        self.check_outputs(outputs)?;
        let est = self.pass(view, outputs)?;
        finish_estimate(self, view, outputs, est)
    }
}

/// The steps every technique's estimate shares, after its pass: direct light when asked for
/// and not given by the pass (timed as the `direct` phase), the light-side rule
/// ([`Estimate::darken_behind_light`]), and validation of the buffer.
///
/// # Errors
/// As [`PreparedShadows::direct_light`]; a buffer that fails validation.
pub fn finish_estimate<P: PreparedShadows + ?Sized>(
    prepared: &P,
    view: &ViewSamples,
    outputs: Outputs,
    mut est: Estimate,
) -> Result<Estimate, TechniqueError> {
    if outputs.direct && est.direct.is_none() {
        let t0 = std::time::Instant::now();
        let direct = prepared.direct_light(view, &est)?;
        est.direct = Some(direct);
        est.stats
            .add_time(CorePhase::Direct, t0.elapsed().as_secs_f64());
    }
    est.darken_behind_light(view, prepared.light());
    est.visibility.validate()?;
    Ok(est)
}

/// Direct illumination of every view sample (DCS eq. 6) from a sample-based technique's
/// per-sample visibility: the light samples of `sampler` at each pixel, weighted by their
/// binary visibility. This is how every sample-based technique answers [`Outputs::direct`],
/// so that shading differs between techniques only where their visibility does.
///
/// # Errors
/// [`TechniqueError::InvalidInput`] when `visibility` has no per-sample data of the sampler's
/// count for the view's pixels.
pub fn direct_from_per_sample(
    scene: &dyn Scene,
    light: &dyn AreaLight,
    sampler: &LightSampler,
    view: &ViewSamples,
    visibility: &VisibilityImage,
) -> Result<Vec<Vec3>, TechniqueError> {
    shade_from_per_sample(
        scene,
        light,
        sampler,
        view,
        visibility,
        |s, albedo, samples, v| crate::direct::pixel_direct(s, albedo, light, samples, v),
    )
}

/// Shadowed direct light by the ratio estimator ([`crate::irradiance`]): the closed-form
/// unshadowed radiance of a planar constant light times the visible share of the eq. 6 terms
/// of the same per-sample visibility as [`direct_from_per_sample`]. `Ok(None)` for lights
/// without a closed form here (textured, sphere, point).
///
/// # Errors
/// As [`direct_from_per_sample`].
pub fn ratio_direct_from_per_sample(
    scene: &dyn Scene,
    light: &dyn AreaLight,
    sampler: &LightSampler,
    view: &ViewSamples,
    visibility: &VisibilityImage,
) -> Result<Option<Vec<Vec3>>, TechniqueError> {
    if light.is_textured() || light.geometry().plane_normal().is_none() {
        return Ok(None);
    }
    shade_from_per_sample(
        scene,
        light,
        sampler,
        view,
        visibility,
        |s, albedo, samples, v| {
            crate::irradiance::pixel_ratio_direct(s, albedo, light, samples, v)
                .unwrap_or(Vec3::ZERO)
        },
    )
    .map(Some)
}

/// Runs `shade(view sample, albedo, its light samples, visibility of sample k)` on every valid
/// pixel, from the per-sample visibility in `visibility` (background black).
fn shade_from_per_sample(
    scene: &dyn Scene,
    light: &dyn AreaLight,
    sampler: &LightSampler,
    view: &ViewSamples,
    visibility: &VisibilityImage,
    shade: impl Fn(&ViewSample, Vec3, &[LightSample], &dyn Fn(usize) -> f32) -> Vec3 + Sync,
) -> Result<Vec<Vec3>, TechniqueError> {
    use crate::visibility::VisibilityBuffer;
    use rayon::prelude::*;
    let per = visibility.per_sample().ok_or_else(|| {
        TechniqueError::InvalidInput("direct illumination needs per-sample visibility".into())
    })?;
    if per.samples() != sampler.count() || per.pixels() != view.len() {
        return Err(TechniqueError::InvalidInput(format!(
            "per-sample visibility holds {} samples for {} pixels; the sampler draws {} for {}",
            per.samples(),
            per.pixels(),
            sampler.count(),
            view.len()
        )));
    }
    let w = view.width() as usize;
    let mut out = vec![Vec3::ZERO; view.len()];
    out.par_chunks_mut(w.max(1))
        .enumerate()
        .for_each(|(row, line)| {
            let (mut units, mut samples) = (Vec::new(), Vec::new());
            for (x, px) in line.iter_mut().enumerate() {
                let i = row * w + x;
                let Some(s) = view.get(i) else { continue };
                sampler.unit_samples(s.pixel, &mut units);
                samples.clear();
                light.sample_into(&units, &mut samples);
                let albedo = s.albedo_in(scene);
                let v = |k: usize| if per.visible(i, k as u32) { 1.0 } else { 0.0 };
                *px = shade(&s, albedo, &samples, &v);
            }
        });
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unsupported_reasons_read_as_before() {
        let e = TechniqueError::unsupported(
            "x",
            UnsupportedReason::Light {
                kind: LightKind::Sphere,
                detail: None,
            },
        );
        assert_eq!(
            e.to_string(),
            "x does not support this input: sphere lights are not supported"
        );
        assert!(matches!(
            e.unsupported_reason(),
            Some(UnsupportedReason::Light { .. })
        ));
    }
}
