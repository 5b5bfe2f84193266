//! Every light of a scene (issue 67 item 3): one technique prepared for each light, V per
//! light, direct light summed over the lights.
//!
//! The DCS paper's headline scene has four lights and a real interior has several; a renderer
//! hands in all of them. [`PreparedLights`] prepares the technique once per light through
//! [`ShadowTechnique::prepare_each`], which lets a technique build what the lights share once
//! (the reference's BVH); the receivers are the caller's one [`ViewSamples`], shared by every
//! light. Per view, a light that cannot reach any receiver (every valid receiver lies behind the
//! plane it emits from, DCS eq. 1 with the one-sided emitter rule of
//! [`crate::light::LightGeometry::behind`]) is skipped: its V is zero everywhere, exactly what
//! the technique would give, and it is counted in `lights-skipped`. A light whose kind the
//! technique refuses is traced by the fallback technique when the caller names one (and counted
//! in `lights-fallback`), otherwise the refusal names the light ([`TechniqueError::Light`]).
//!
//! Direct illumination (DCS eq. 6) is linear in the lights, so the sum of each light's direct
//! light is the scene's.

use glam::Vec3;

use crate::light::Light;
use crate::stats::CoreCounter;
use crate::technique::{
    Estimate, Outputs, PreparedShadows, SceneRef, ShadowTechnique, Stats, TechniqueError,
    UnsupportedReason,
};
use crate::view_samples::ViewSamples;
use crate::visibility::{PerSampleVisibility, VisibilityImage};

/// One light prepared: by the technique, or by the fallback with the reason the technique gave.
#[derive(Debug)]
struct PreparedLight {
    light: Light,
    prepared: Box<dyn PreparedShadows>,
    /// The light samples per pixel of whichever technique prepared it (for a skipped light's
    /// per-sample visibility).
    samples: Option<u32>,
    fallback: Option<UnsupportedReason>,
}

/// A technique prepared for every light of a scene.
#[derive(Debug)]
pub struct PreparedLights {
    lights: Vec<PreparedLight>,
    preparation: Stats,
}

/// One light's answer within a [`LightsEstimate`].
#[derive(Debug, Clone)]
pub struct LightEstimate {
    /// The light's index in the caller's list.
    pub index: usize,
    /// The technique that shadowed it (the fallback's name where the technique refused it).
    pub technique: String,
    /// Why the technique refused this light, when the fallback traced it.
    pub fallback: Option<UnsupportedReason>,
    /// True when the light reaches no receiver and was skipped (V zero, no work done).
    pub skipped: bool,
    /// V of this light for every receiver, with what the outputs asked for.
    pub estimate: Estimate,
}

/// V per light and direct light summed over the lights.
#[derive(Debug, Clone)]
pub struct LightsEstimate {
    /// One entry per light, in the caller's order.
    pub lights: Vec<LightEstimate>,
    /// The sum over the lights of their direct illumination, when [`Outputs::direct`].
    pub direct: Option<Vec<Vec3>>,
    /// Every light's estimate statistics merged, with `lights-shadowed`, `lights-skipped` and
    /// `lights-fallback`.
    pub stats: Stats,
}

impl PreparedLights {
    /// Prepares `technique` for every light of `lights` in `scene`; a light the technique
    /// refuses as [`TechniqueError::Unsupported`] is prepared by `fallback` when given.
    ///
    /// # Errors
    /// [`TechniqueError::InvalidInput`] for an empty list; otherwise the first light's error,
    /// wrapped in [`TechniqueError::Light`] with its index.
    pub fn prepare(
        technique: &dyn ShadowTechnique,
        fallback: Option<&dyn ShadowTechnique>,
        scene: SceneRef,
        lights: &[Light],
    ) -> Result<Self, TechniqueError> {
        if lights.is_empty() {
            return Err(TechniqueError::InvalidInput(
                "no lights to shadow: the list is empty".into(),
            ));
        }
        let mut preparation = Stats::default();
        let answers = technique.prepare_each(scene.clone(), lights);
        let mut out = Vec::with_capacity(lights.len());
        for (index, (light, answer)) in lights.iter().zip(answers).enumerate() {
            let entry = match (answer, fallback) {
                (Ok(prepared), _) => PreparedLight {
                    light: light.clone(),
                    prepared,
                    samples: technique.light_sampler().map(|s| s.count()),
                    fallback: None,
                },
                (Err(TechniqueError::Unsupported { reason, .. }), Some(f)) => {
                    let prepared = f
                        .prepare(scene.clone(), light.clone())
                        .map_err(|e| TechniqueError::for_light(index, e))?;
                    preparation.add(CoreCounter::LightsFallback, 1);
                    PreparedLight {
                        light: light.clone(),
                        prepared,
                        samples: f.light_sampler().map(|s| s.count()),
                        fallback: Some(reason),
                    }
                }
                (Err(e), _) => return Err(TechniqueError::for_light(index, e)),
            };
            preparation.merge(entry.prepared.preparation());
            out.push(entry);
        }
        Ok(Self {
            lights: out,
            preparation,
        })
    }

    /// How many lights were prepared.
    pub fn len(&self) -> usize {
        self.lights.len()
    }

    /// Never true: preparing an empty list of lights is an error.
    pub fn is_empty(&self) -> bool {
        self.lights.is_empty()
    }

    /// Every light's preparation statistics merged, with `lights-fallback`.
    pub fn preparation(&self) -> &Stats {
        &self.preparation
    }

    /// V of every receiver of `view` for each light, and the summed direct light when
    /// `outputs.direct`.
    ///
    /// # Errors
    /// The first light's error, wrapped in [`TechniqueError::Light`] with its index.
    pub fn estimate(
        &self,
        view: &ViewSamples,
        outputs: Outputs,
    ) -> Result<LightsEstimate, TechniqueError> {
        self.estimate_with_progress(view, outputs, &mut |_, _| Ok(()))
    }

    /// [`PreparedLights::estimate`], calling `progress(lights_done, lights)` after each light;
    /// an error from `progress` stops the estimate there and is returned (a caller's
    /// cancellation: a Python `KeyboardInterrupt`, a closed window).
    ///
    /// # Errors
    /// As [`PreparedLights::estimate`], and `progress`'s error unchanged.
    pub fn estimate_with_progress(
        &self,
        view: &ViewSamples,
        outputs: Outputs,
        progress: &mut dyn FnMut(usize, usize) -> Result<(), TechniqueError>,
    ) -> Result<LightsEstimate, TechniqueError> {
        let mut stats = Stats::default();
        let mut direct = outputs.direct.then(|| vec![Vec3::ZERO; view.len()]);
        let mut lights = Vec::with_capacity(self.lights.len());
        for (index, p) in self.lights.iter().enumerate() {
            let skipped = !reaches_any_receiver(&p.light, view);
            let estimate = if skipped {
                stats.add(CoreCounter::LightsSkipped, 1);
                p.prepared
                    .check_outputs(outputs)
                    .map_err(|e| TechniqueError::for_light(index, e))?;
                dark_estimate(view, &p.light, outputs, p.samples)
                    .map_err(|e| TechniqueError::for_light(index, e))?
            } else {
                stats.add(CoreCounter::LightsShadowed, 1);
                p.prepared
                    .estimate(view, outputs)
                    .map_err(|e| TechniqueError::for_light(index, e))?
            };
            if let (Some(sum), Some(d)) = (&mut direct, &estimate.direct) {
                for (s, v) in sum.iter_mut().zip(d) {
                    *s += *v;
                }
            }
            stats.merge(&estimate.stats);
            lights.push(LightEstimate {
                index,
                technique: p.prepared.name().to_string(),
                fallback: p.fallback.clone(),
                skipped,
                estimate,
            });
            progress(lights.len(), self.lights.len())?;
        }
        Ok(LightsEstimate {
            lights,
            direct,
            stats,
        })
    }
}

/// Whether any valid receiver of `view` lies in front of the plane `light` emits from (always,
/// for lights that emit all around).
pub fn reaches_any_receiver(light: &Light, view: &ViewSamples) -> bool {
    let geometry = light.geometry();
    if geometry.emitting_plane().is_none() {
        return view.valid_count() > 0;
    }
    (0..view.len()).any(|i| view.get(i).is_some_and(|s| !geometry.behind(s.position)))
}

/// The estimate of a light that reaches no receiver: V zero at every valid receiver (RGB for a
/// textured light), every one of `samples` light samples occluded when per-sample visibility
/// is asked for, no direct light.
///
/// # Errors
/// [`TechniqueError::Output`] if the per-sample buffer does not fit the view (a bug).
fn dark_estimate(
    view: &ViewSamples,
    light: &Light,
    outputs: Outputs,
    samples: Option<u32>,
) -> Result<Estimate, TechniqueError> {
    let mut visibility = if light.is_textured() {
        VisibilityImage::rgb_buffer(view)
    } else {
        VisibilityImage::scalar(view)
    };
    if let (true, Some(n)) = (outputs.per_sample, samples) {
        visibility.set_per_sample(PerSampleVisibility::bits(view.len(), n))?;
    }
    let mut stats = Stats::default();
    stats.add(CoreCounter::PixelsBehindLight, view.valid_count() as u64);
    let mut estimate = Estimate::new(visibility, stats);
    estimate.direct = outputs.direct.then(|| vec![Vec3::ZERO; view.len()]);
    Ok(estimate)
}
