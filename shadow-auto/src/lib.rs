//! `auto`: a technique chooser behind the same trait. Given an error budget (image RMSE
//! against an independent many-sample reference) or a time budget (seconds), it looks at the
//! scene and view cheaply, predicts every registered CPU configuration's error and time from
//! models that `cargo xtask budgets --write-model` fits and commits (`auto-model.json`, see
//! [`model`]), runs the one it picks, and reports what it chose, why, and its prediction in
//! [`Estimate::decision`].
//!
//! The look is the adaptive reference's probe pass ([`shadow_ref::adaptive`]) on a copy of
//! the view at most [`AutoModel::probe_pixels`] pixels large: two independent 16-sample
//! stratified sets per pixel, evaluated by DCS on opaque scenes (its preparation is then the
//! DCS configurations' own) and by the reference elsewhere ([`probe`]). The sets'
//! disagreement measures the image's sampling variance, which carries the light's solid
//! angle, the penumbra's extent and the occluders' detail at once; the shares of pixels in
//! shadow and in penumbra, and the triangle count, carry the cost. Capabilities (light kind,
//! semi-opacity, textured lights) and the outputs asked for (per-sample visibility or direct
//! light need light samples) filter the candidates first.
//!
//! * Under an error budget the pick is the candidate of least predicted time whose predicted
//!   RMSE meets the budget; when none does, the one of least predicted RMSE. The choice
//!   depends only on deterministic features, so the output is identical for a seed whatever
//!   the thread count or the machine.
//! * Under a time budget the probe's own time is spent first; the pick is the candidate of
//!   least predicted RMSE whose predicted time, times [`TIME_MARGIN`], fits what is left, else
//!   the fastest. Times are the fitted ones scaled by the probe's measured speed on this
//!   machine, so the choice may differ between machines (a time budget is a property of the
//!   machine).
//! * A chosen configuration is prepared once and kept for later estimates; the DCS
//!   configurations share a DCS probe's preparation, the reference family a reference probe's
//!   BVH (built on first use after a DCS probe, and then shared).
//!
//! The survey (Hasenfratz et al. 2003, section 4.1) notes that none of the algorithms it
//! reviews picks its own quality from a budget; this is that choice, made on measured models
//! rather than rules of thumb. GPU techniques are not candidates: their cost depends on the
//! device more than on the scene, and a CPU probe cannot predict it.

pub mod model;
pub mod probe;
pub mod statistics;

use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

use serde::Serialize;
use serde_json::json;
use shadow_core::prelude::*;
use shadow_core::sampling::SamplingStrategy;
use shadow_dcs::Dcs;
use shadow_ref::adaptive::{DEFAULT_BATCH, DEFAULT_CAP, PreparedAdaptive};
use shadow_ref::{AdaptiveReference, Reference};

pub use model::{
    AutoModel, Candidate, Catalogue, Config, ErrorModel, Features, Observation, Prediction,
};
pub use probe::ProbeKind;
use probe::{Probe, probe_features, probe_reference};
pub use statistics::{AutoCounter, AutoPhase};

/// Under a time budget a pick must fit `TIME_MARGIN` times its predicted time: the 0.9
/// quantile of achieved over predicted time of `auto`'s picks under time budgets on scenes the
/// models were not fitted on (`cargo xtask budgets`, leave-one-out over the built-in scenes;
/// `docs/benchmarks.md` holds the figures), so that nine budgets in ten are met where the
/// prediction is the only guide.
pub const TIME_MARGIN: f64 = 2.0;

/// What `auto` must meet.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum AutoBudget {
    /// Image RMSE against an independent many-sample reference.
    Rmse(f64),
    /// Seconds of preparation and estimate together, the probe included.
    Seconds(f64),
}

/// The chooser: a budget, a seed, the models and the catalogue its candidates are built from.
#[derive(Debug, Clone)]
pub struct Auto {
    name: String,
    budget: AutoBudget,
    seed: u64,
    model: Arc<AutoModel>,
    catalogue: Catalogue,
}

impl Auto {
    /// The chooser with the committed model, its candidates built by `catalogue`
    /// (`shadow_presets::build` names every configuration the committed model holds).
    ///
    /// # Errors
    /// [`TechniqueError::InvalidInput`] for a budget that is not a positive finite number, or
    /// an RMSE budget of 1 or more; a broken committed model.
    pub fn new(
        budget: AutoBudget,
        seed: u64,
        catalogue: Catalogue,
    ) -> Result<Self, TechniqueError> {
        let model = AutoModel::committed().map_err(TechniqueError::InvalidInput)?;
        Self::with_model(budget, seed, Arc::new(model), catalogue)
    }

    /// The chooser with another model (fitting studies leave a scene out).
    ///
    /// # Errors
    /// As [`Auto::new`], and a model without candidates.
    pub fn with_model(
        budget: AutoBudget,
        seed: u64,
        model: Arc<AutoModel>,
        catalogue: Catalogue,
    ) -> Result<Self, TechniqueError> {
        let (name, ok) = match budget {
            AutoBudget::Rmse(r) => (format!("auto-rmse-{r}"), r > 0.0 && r < 1.0),
            AutoBudget::Seconds(s) => (format!("auto-seconds-{s}"), s > 0.0 && s.is_finite()),
        };
        if !ok {
            return Err(TechniqueError::InvalidInput(format!(
                "auto budget {budget:?} is not a positive finite number (an RMSE below 1)"
            )));
        }
        if model.candidates.is_empty() {
            return Err(TechniqueError::InvalidInput(
                "the auto model has no candidates".into(),
            ));
        }
        Ok(Self {
            name,
            budget,
            seed,
            model,
            catalogue,
        })
    }

    /// Renames the instance (presets).
    #[must_use]
    pub fn named(mut self, name: &str) -> Self {
        self.name = name.into();
        self
    }
}

impl ShadowTechnique for Auto {
    fn name(&self) -> &str {
        &self.name
    }

    fn capabilities(&self) -> Capabilities {
        // The reference is always a candidate and handles every input.
        Capabilities::any_input(false, Processor::Cpu)
    }

    fn parameters(&self) -> serde_json::Value {
        json!({
            "budget": self.budget,
            "seed": self.seed,
            "model": self.model.fitted,
            "candidates": self.model.candidates.iter().map(|c| c.config.name()).collect::<Vec<_>>(),
        })
    }

    fn prepare(
        &self,
        scene: SceneRef,
        light: Light,
    ) -> Result<Box<dyn PreparedShadows>, TechniqueError> {
        let t0 = Instant::now();
        let probe = Probe::prepare(scene.clone(), light.clone(), self.seed)?;
        let probe_prepare = t0.elapsed().as_secs_f64();
        // Candidates that can handle this scene and light, built once.
        let mut usable = Vec::new();
        for c in &self.model.candidates {
            let t = c.config.build(self.seed, self.catalogue)?;
            let caps = t.capabilities();
            if caps.processor == Processor::Cpu
                && caps.check(scene.as_ref(), light.as_ref()).is_ok()
            {
                usable.push((c.clone(), t));
            }
        }
        let mut stats = Stats::default();
        stats.add_time(AutoPhase::AutoProbePrepare, probe_prepare);
        stats.add(
            AutoCounter::AutoProbeDcs,
            u64::from(probe.kind() == ProbeKind::Dcs),
        );
        Ok(Box::new(PreparedAuto {
            config: self.clone(),
            scene,
            light,
            probe,
            reference: OnceLock::new(),
            probe_prepare,
            usable,
            chosen: Mutex::new(Vec::new()),
            stats,
        }))
    }
}

/// `auto` prepared for a scene and light: the probe and the usable candidates.
pub struct PreparedAuto {
    config: Auto,
    scene: SceneRef,
    light: Light,
    probe: Probe,
    /// The reference family's BVH after a DCS probe, built when a reference configuration is
    /// first chosen.
    reference: OnceLock<PreparedAdaptive>,
    probe_prepare: f64,
    usable: Vec<(Candidate, Box<dyn ShadowTechnique>)>,
    /// Configurations already prepared by an earlier estimate, by name: a renderer that calls
    /// `estimate` every frame prepares each choice once.
    chosen: Mutex<Vec<(String, Arc<dyn PreparedShadows>)>>,
    stats: Stats,
}

impl std::fmt::Debug for PreparedAuto {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PreparedAuto")
            .field("config", &self.config)
            .field("usable", &self.usable.len())
            .finish_non_exhaustive()
    }
}

/// The choice, its reason and the predictions it was made from.
#[derive(Debug, Clone, Serialize)]
pub struct Decision {
    /// The budget.
    pub budget: AutoBudget,
    /// The configuration run.
    pub choice: String,
    /// Why.
    pub reason: String,
    /// Its predicted RMSE and seconds (the probe's time included under a time budget).
    pub predicted: Prediction,
    /// The features the models read.
    pub features: Features,
    /// This machine's speed against the fitting machine's (probe time over modelled).
    pub speed_ratio: f64,
    /// Every candidate considered, with its prediction.
    pub candidates: Vec<Prediction>,
}

impl Decision {
    /// The decision `auto` made for `estimate`, `None` for another technique's estimate.
    pub fn of(estimate: &Estimate) -> Option<&Decision> {
        estimate.decision.as_ref()?.as_any().downcast_ref()
    }
}

impl EstimateDecision for Decision {
    fn choice(&self) -> &str {
        &self.choice
    }
    fn reason(&self) -> &str {
        &self.reason
    }
    fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or(serde_json::Value::Null)
    }
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

impl PreparedAuto {
    /// Candidate `i` prepared: from the cache, else prepared now (DCS on a DCS probe's
    /// preparation, the reference family on the shared BVH) and cached.
    fn prepared_choice(&self, i: usize) -> Result<Arc<dyn PreparedShadows>, TechniqueError> {
        let (c, technique) = &self.usable[i];
        let name = c.config.name();
        let cached = self.chosen.lock().ok().and_then(|list| {
            list.iter()
                .find(|(n, _)| *n == name)
                .map(|(_, p)| p.clone())
        });
        if let Some(p) = cached {
            return Ok(p);
        }
        let seed = self.config.seed;
        let prepared: Arc<dyn PreparedShadows> = match (&c.config, self.probe.dcs()) {
            (Config::Ref { samples }, _) => Arc::new(
                Reference::stratified(*samples, seed)?
                    .named(&name)
                    .prepare_sharing(self.bvh()?.reference()),
            ),
            (Config::RefAdaptive { target }, _) => Arc::new(
                AdaptiveReference::new(*target, DEFAULT_BATCH, DEFAULT_CAP, seed)?
                    .named(&name)
                    .prepare_sharing(self.bvh()?.reference())?,
            ),
            // The configuration the registry builds (`dcs-16`'s `with_samples`), on the probe's
            // edges, silhouettes and wedges.
            (Config::Dcs { samples }, Some(probe)) => Arc::new(
                Dcs::new(*samples, SamplingStrategy::Stratified, seed)
                    .map_err(|e| TechniqueError::InvalidInput(e.to_string()))?
                    .named(&name)
                    .prepare_sharing(probe)?,
            ),
            _ => Arc::from(technique.prepare(self.scene.clone(), self.light.clone())?),
        };
        if let Ok(mut list) = self.chosen.lock() {
            list.push((name, prepared.clone()));
        }
        Ok(prepared)
    }

    /// The prepared reference whose BVH the reference family shares: the probe's, else one
    /// built now (once).
    fn bvh(&self) -> Result<&PreparedAdaptive, TechniqueError> {
        if let Some(r) = self.probe.reference() {
            return Ok(r);
        }
        if let Some(r) = self.reference.get() {
            return Ok(r);
        }
        let r = probe_reference(self.config.seed)?
            .prepare_adaptive(self.scene.clone(), self.light.clone())?;
        Ok(self.reference.get_or_init(|| r))
    }

    /// Picks a usable candidate for `features` under the budget.
    fn decide(
        &self,
        f: &Features,
        outputs: Outputs,
        view: &ViewSamples,
    ) -> Result<(usize, Decision), TechniqueError> {
        let model = &self.config.model;
        let speed = model.speed_ratio(f);
        let preds: Vec<(usize, Prediction)> = self
            .usable
            .iter()
            .enumerate()
            .filter(|(_, (c, t))| {
                let samples = t.light_sampler().is_some();
                let adaptive = matches!(c.config, Config::RefAdaptive { .. });
                (!outputs.per_sample || samples)
                    && (!outputs.direct || samples || adaptive)
                    && (!f.semi_opaque || c.config.exact_with_semi_opacity())
                    && t.capabilities().check_view(view).is_ok()
            })
            .map(|(i, (c, _))| (i, model.predict(c, f, speed)))
            .collect();
        let by_time = |a: &&(usize, Prediction), b: &&(usize, Prediction)| {
            a.1.seconds
                .total_cmp(&b.1.seconds)
                .then(a.1.rmse.total_cmp(&b.1.rmse))
        };
        let by_error = |a: &&(usize, Prediction), b: &&(usize, Prediction)| {
            a.1.rmse
                .total_cmp(&b.1.rmse)
                .then(a.1.seconds.total_cmp(&b.1.seconds))
        };
        let (pick, reason) = match self.config.budget {
            AutoBudget::Rmse(r) => match preds.iter().filter(|p| p.1.rmse <= r).min_by(by_time) {
                Some(p) => (p, format!("the fastest predicted to meet RMSE {r}")),
                None => (
                    preds
                        .iter()
                        .min_by(by_error)
                        .ok_or_else(|| no_candidate(outputs))?,
                    format!("no candidate is predicted to meet RMSE {r}: the most accurate"),
                ),
            },
            AutoBudget::Seconds(s) => {
                let left = s - f.probe_seconds;
                match preds
                    .iter()
                    .filter(|p| p.1.seconds * TIME_MARGIN <= left)
                    .min_by(by_error)
                {
                    Some(p) => (
                        p,
                        format!("the most accurate predicted to fit the {left:.4} s left of {s} s"),
                    ),
                    None => (
                        preds
                            .iter()
                            .min_by(by_time)
                            .ok_or_else(|| no_candidate(outputs))?,
                        format!("no candidate is predicted to fit {s} s: the fastest"),
                    ),
                }
            }
        };
        let mut predicted = pick.1.clone();
        if let AutoBudget::Seconds(_) = self.config.budget {
            predicted.seconds += f.probe_seconds;
        }
        Ok((
            pick.0,
            Decision {
                budget: self.config.budget,
                choice: pick.1.name.clone(),
                reason,
                predicted,
                features: *f,
                speed_ratio: speed,
                candidates: preds.into_iter().map(|p| p.1).collect(),
            },
        ))
    }
}

/// The features of `scene` lit by `light` seen in `view` (see [`model::Features`]), measured
/// as `auto` measures them: the probe ([`probe`]) prepared and run on a copy of the view of at
/// most `probe_pixels` pixels, both timed.
///
/// # Errors
/// The probe's preparation or rasterization error.
pub fn measure_features(
    scene: SceneRef,
    light: Light,
    view: &ViewSamples,
    probe_pixels: u32,
    seed: u64,
) -> Result<Features, TechniqueError> {
    measure_features_by(None, scene, light, view, probe_pixels, seed)
}

/// [`measure_features`] with the probe `kind` (`None`: the one `auto` would choose).
///
/// # Errors
/// As [`measure_features`]; a DCS probe of a scene DCS does not take or of semi-opaque
/// occluders.
pub fn measure_features_by(
    kind: Option<ProbeKind>,
    scene: SceneRef,
    light: Light,
    view: &ViewSamples,
    probe_pixels: u32,
    seed: u64,
) -> Result<Features, TechniqueError> {
    let t0 = Instant::now();
    let probe = match kind {
        None => Probe::prepare(scene.clone(), light.clone(), seed)?,
        Some(k) => Probe::prepare_kind(k, scene.clone(), light.clone(), seed)?,
    };
    let prepare = t0.elapsed().as_secs_f64();
    probe_features(
        &probe,
        scene.as_ref(),
        light.as_ref(),
        prepare,
        view,
        probe_pixels,
    )
}

fn no_candidate(outputs: Outputs) -> TechniqueError {
    TechniqueError::unsupported(
        "auto",
        UnsupportedReason::Configuration(format!(
            "no candidate of the auto model gives the outputs asked for ({outputs:?})"
        )),
    )
}

impl PreparedShadows for PreparedAuto {
    fn name(&self) -> &str {
        &self.config.name
    }

    fn preparation(&self) -> &Stats {
        &self.stats
    }

    fn light(&self) -> &dyn AreaLight {
        self.light.as_ref()
    }

    /// The probe, the choice, and the chosen configuration's whole estimate: its shared steps
    /// (direct light, the behind-the-light rule, validation) are its own, so `auto` adds none
    /// ([`PreparedAuto::estimate`] is this pass).
    fn pass(&self, view: &ViewSamples, outputs: Outputs) -> Result<Estimate, TechniqueError> {
        let t0 = Instant::now();
        let (probe, probe_prepare) = (&self.probe, self.probe_prepare);
        let features = probe_features(
            probe,
            self.scene.as_ref(),
            self.light.as_ref(),
            probe_prepare,
            view,
            self.config.model.probe_pixels,
        )?;
        let probe_seconds = t0.elapsed().as_secs_f64();
        let (i, decision) = self.decide(&features, outputs, view)?;
        let t1 = Instant::now();
        let prepared = self.prepared_choice(i)?;
        let prepare_seconds = t1.elapsed().as_secs_f64();
        let mut est = prepared.estimate(view, outputs)?;
        let mut stats = Stats::default();
        stats.add_time(AutoPhase::AutoProbe, probe_seconds);
        stats.add_time(AutoPhase::AutoChosenPrepare, prepare_seconds);
        stats.merge(&est.stats);
        stats.add(AutoCounter::AutoProbePixels, features.probe_pixels as u64);
        // The chosen configuration on the probe's own preparation: DCS's edges, silhouettes
        // and wedges, or the reference's BVH.
        let reused = matches!(
            (&self.usable[i].0.config, self.probe.kind()),
            (Config::Dcs { .. }, ProbeKind::Dcs)
                | (
                    Config::Ref { .. } | Config::RefAdaptive { .. },
                    ProbeKind::Reference
                )
        );
        stats.add(AutoCounter::AutoProbePreparationReused, u64::from(reused));
        stats.add(
            AutoCounter::AutoCandidates,
            decision.candidates.len() as u64,
        );
        est.stats = stats;
        est.decision = Some(Arc::new(decision));
        Ok(est)
    }

    fn estimate(&self, view: &ViewSamples, outputs: Outputs) -> Result<Estimate, TechniqueError> {
        self.pass(view, outputs)
    }
}
