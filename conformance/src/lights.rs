//! Every light of a multi-light scene (issue 67): a case's main checks take the scene's first
//! light; on a scene with several, the technique also shadows all of them at once
//! ([`PreparedLights`]) and each light's V is held to the preset's budget against the
//! reference's V for that light, and the summed direct light (DCS eq. 6) to the reference's
//! summed direct light from the same samples.
//!
//! A light the technique refuses (its kind) is traced by the reference as the fallback and
//! listed with the reason; it is compared like the others. A preset may declare a budget for
//! one light (`interior#1`, the scene's light 1); the others are held to the scene's.

use glam::Vec3;
use serde::Serialize;
use shadow_core::lights::{LightsEstimate, PreparedLights};
use shadow_core::prelude::*;
use shadow_metrics::{Metrics, compare};
use shadow_presets::{Budget, Preset};
use shadow_ref::Reference;

use shadow_io::SceneSetup;

/// Samples of the fallback that traces the lights a technique without light samples refuses.
const FALLBACK_SAMPLES: u32 = 256;

/// The least relative RMSE of the summed direct light allowed. A technique may do worse by as
/// much as its budget lets its V (three times its RMSE budget) or its light samples disagree
/// with the reference's (four times the share its budget allows): the disagreeing samples
/// carry that share of the light.
const DIRECT_TOLERANCE_FLOOR: f64 = 0.02;

/// One light of the scene, as the technique shadowed it among all of them.
#[derive(Debug, Clone, Serialize)]
pub struct LightCheck {
    /// The light's index in the scene.
    pub index: usize,
    /// Its shape.
    pub kind: LightKind,
    /// Who shadowed it: the preset, or the fallback.
    pub technique: String,
    /// Why the preset refused it, when the fallback traced it.
    pub fallback_because: Option<String>,
    /// True when it reaches no receiver (V zero, no work done).
    pub skipped: bool,
    /// Its V against the reference's V for this light.
    pub metrics: Metrics,
    /// The budget its RMSE is held to: the preset's for this light, else for the scene.
    pub budget_rmse: Option<f64>,
}

/// Every light of a multi-light scene, shadowed together.
#[derive(Debug, Clone, Serialize)]
pub struct EveryLight {
    /// Each light in the scene's order.
    pub lights: Vec<LightCheck>,
    /// RMSE of the summed direct light over the mean of the reference's, both from the same
    /// light samples (`None` for techniques without light samples).
    pub direct_relative_rmse: Option<f64>,
    /// The bound [`EveryLight::direct_relative_rmse`] is held to.
    pub direct_tolerance: Option<f64>,
}

/// A case's scene, receivers and reference settings.
#[derive(Clone, Copy)]
pub struct LightsCase<'a> {
    /// The scene with its lights.
    pub setup: &'a SceneSetup,
    /// The receivers.
    pub view: &'a ViewSamples,
    /// Seed of the technique.
    pub seed: u64,
    /// Samples per pixel of the stratified reference.
    pub ref_samples: u32,
    /// Seed of the stratified reference (another than the technique's).
    pub reference_seed: u64,
}

/// Shadows every light of the case's scene with `preset` and holds each light and the summed
/// direct light to the reference (`budget` is the preset's for the scene); pushes what fails to
/// `violations`. `None` on a one-light scene.
pub fn check_every_light(
    preset: &Preset,
    ctx: &LightsCase,
    budget: Option<&Budget>,
    violations: &mut Vec<String>,
) -> Option<EveryLight> {
    if ctx.setup.lights.len() < 2 {
        return None;
    }
    match every_light(preset, ctx, budget) {
        Ok(report) => {
            hold_to_budget(&report, violations);
            Some(report)
        }
        Err(e) => {
            violations.push(format!("every light: {e}"));
            None
        }
    }
}

/// The preset's and the reference's answers for every light, compared.
fn every_light(
    preset: &Preset,
    ctx: &LightsCase,
    budget: Option<&Budget>,
) -> Result<EveryLight, String> {
    let tech = (preset.make)(ctx.seed);
    let sampler = tech.light_sampler().cloned();
    let (reference, fallback, outputs) = match &sampler {
        Some(s) if tech.capabilities().sample_based => (
            Reference::same_samples(s.clone()),
            Reference::same_samples(s.clone()),
            Outputs {
                per_sample: true,
                direct: true,
            },
        ),
        _ => (
            Reference::stratified(ctx.ref_samples, ctx.reference_seed)
                .map_err(|e| e.to_string())?,
            Reference::stratified(FALLBACK_SAMPLES, ctx.seed).map_err(|e| e.to_string())?,
            Outputs::VISIBILITY,
        ),
    };
    let run = |t: &dyn ShadowTechnique, fallback: Option<&dyn ShadowTechnique>| {
        PreparedLights::prepare(t, fallback, ctx.setup.scene.clone(), &ctx.setup.lights)
            .and_then(|all| all.estimate(ctx.view, outputs))
            .map_err(|e| e.to_string())
    };
    let got = run(tech.as_ref(), Some(&fallback))?;
    let truth = run(&reference, None).map_err(|e| format!("reference: {e}"))?;
    let mut lights = Vec::with_capacity(got.lights.len());
    for ((each, want), light) in got.lights.iter().zip(&truth.lights).zip(&ctx.setup.lights) {
        let metrics = compare(&each.estimate.visibility, &want.estimate.visibility)
            .map_err(|e| format!("light {}: {e}", each.index))?;
        let own = (preset.budget)(&format!("{}#{}", ctx.setup.name, each.index));
        lights.push(LightCheck {
            index: each.index,
            kind: light.kind(),
            technique: each.technique.clone(),
            fallback_because: each.fallback.as_ref().map(ToString::to_string),
            skipped: each.skipped,
            metrics,
            budget_rmse: own.as_ref().or(budget).map(|b| b.rmse),
        });
    }
    let direct_relative_rmse = relative_rmse(&got, &truth, ctx.view);
    let direct_tolerance = direct_relative_rmse.map(|_| {
        let agreement = budget.and_then(|b| b.min_sample_agreement).unwrap_or(1.0);
        let rmse = budget.map_or(0.0, |b| b.rmse);
        DIRECT_TOLERANCE_FLOOR
            .max(4.0 * (1.0 - agreement))
            .max(3.0 * rmse)
    });
    Ok(EveryLight {
        lights,
        direct_relative_rmse,
        direct_tolerance,
    })
}

/// RMSE of `got`'s summed direct light against `truth`'s over the valid receivers (channels
/// counted apart), over the mean of `truth`'s; `None` without direct light or light.
fn relative_rmse(got: &LightsEstimate, truth: &LightsEstimate, view: &ViewSamples) -> Option<f64> {
    let (a, b) = (got.direct.as_ref()?, truth.direct.as_ref()?);
    let (mut sq, mut sum, mut n) = (0.0f64, 0.0f64, 0u64);
    for i in (0..view.len()).filter(|&i| view.is_valid(i)) {
        let d: Vec3 = a[i] - b[i];
        sq += f64::from(d.length_squared());
        sum += f64::from(b[i].x + b[i].y + b[i].z);
        n += 3;
    }
    let mean = sum / n.max(1) as f64;
    (mean > 0.0).then(|| (sq / n.max(1) as f64).sqrt() / mean)
}

/// Each light's RMSE against its budget, the summed direct light against its tolerance.
fn hold_to_budget(report: &EveryLight, violations: &mut Vec<String>) {
    for l in &report.lights {
        let rmse = l.metrics.rmse;
        if let Some(b) = l.budget_rmse
            && !(rmse <= b)
        {
            violations.push(format!(
                "light {} ({:?}, {}): rmse {rmse:.5} exceeds budget {b:.5}",
                l.index, l.kind, l.technique
            ));
        }
    }
    if let (Some(r), Some(t)) = (report.direct_relative_rmse, report.direct_tolerance)
        && !(r <= t)
    {
        violations.push(format!(
            "summed direct light over every light: relative rmse {r:.5} exceeds {t:.5}"
        ));
    }
}
