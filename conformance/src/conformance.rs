//! The conformance runner: one preset on one scene, against the reference on the same view
//! samples, with every check of DESIGN section 6.

use std::sync::OnceLock;
use std::time::Instant;

use glam::Vec3;
use serde::Serialize;
use shadow_core::prelude::*;
use shadow_io::SceneSetup;
use shadow_metrics::{Metrics, compare};
use shadow_presets::{Budget, Preset};
use shadow_ref::Reference;

/// Mixed into the seed of the stratified reference so its samples differ from a technique's.
pub const REFERENCE_SEED_SALT: u64 = 0x005e_ed0f_7e5e;

/// Image size, reference sample count and seed of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct SuiteConfig {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Samples per pixel of the stratified reference.
    pub ref_samples: u32,
    /// Seed of every technique.
    pub seed: u64,
    /// Check determinism and convergence (two and three extra runs per case).
    pub extra_checks: bool,
    /// Where the receivers come from.
    pub receivers: ReceiverMode,
}

/// Where a run's receivers come from: the built-in rasterizer, or the same surfaces handed in
/// as another renderer would (`shadow_core::receivers`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ReceiverMode {
    /// The camera's view samples.
    #[default]
    Camera,
    /// The view samples as a foreign float G-buffer with the camera: positions moved along
    /// their normals by up to `1e-6` of the scene's size (a renderer's depth precision), no
    /// triangle ids, snapped back onto the scene.
    Gbuffer,
    /// The valid view samples as points with normals in a shuffled order, without a camera.
    Points,
}

impl ReceiverMode {
    /// The mode's name (`camera`, `gbuffer`, `points`).
    pub fn label(self) -> &'static str {
        match self {
            Self::Camera => "camera",
            Self::Gbuffer => "gbuffer",
            Self::Points => "points",
        }
    }

    /// Parses `camera`, `gbuffer` or `points`.
    ///
    /// # Errors
    /// A message naming the valid modes.
    pub fn parse(s: &str) -> Result<Self, String> {
        match s {
            "camera" => Ok(Self::Camera),
            "gbuffer" => Ok(Self::Gbuffer),
            "points" => Ok(Self::Points),
            other => Err(format!(
                "unknown receivers `{other}`; valid: camera, gbuffer, points"
            )),
        }
    }

    /// The receivers of `view` (rendered from `scene`'s camera) in this mode.
    ///
    /// # Errors
    /// The receivers' error as text (none for a rendered view).
    pub fn receivers(self, scene: &dyn Scene, view: ViewSamples) -> Result<ViewSamples, String> {
        let snapping = shadow_core::receivers::Snapping::for_scene(scene);
        let valid: Vec<usize> = (0..view.len()).filter(|&i| view.is_valid(i)).collect();
        match self {
            Self::Camera => Ok(view),
            Self::Gbuffer => {
                let scale = 1e-6 * scene.bounds().diagonal();
                let positions: Vec<Vec3> = (0..view.len())
                    .map(|i| {
                        view.positions()[i] + view.geometric_normals()[i] * (scale * jitter(i))
                    })
                    .collect();
                let mask = view.valid_mask();
                let g = shadow_core::receivers::GBuffer {
                    width: view.width(),
                    height: view.height(),
                    positions: &positions,
                    geometric_normals: view.geometric_normals(),
                    shading_normals: Some(view.shading_normals()),
                    albedo: None,
                    valid: Some(&mask),
                    camera: view.raster_view().copied(),
                };
                ViewSamples::from_gbuffer(scene, &g, snapping).map_err(|e| e.to_string())
            }
            Self::Points => {
                let mut order = valid;
                order.sort_by_key(|&i| (i as u64).wrapping_mul(0x2545_F491_4F6C_DD1D));
                let positions: Vec<Vec3> = order.iter().map(|&i| view.positions()[i]).collect();
                let normals: Vec<Vec3> =
                    order.iter().map(|&i| view.geometric_normals()[i]).collect();
                ViewSamples::from_points(scene, &positions, &normals, snapping)
                    .map_err(|e| e.to_string())
            }
        }
    }
}

/// A reproducible value in `[-1, 1)` per index.
fn jitter(i: usize) -> f32 {
    let h = (i as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    (h >> 40) as f32 / (1u64 << 23) as f32 - 1.0
}

/// The image size every budget was measured at. Max error is a tail statistic that grows with
/// the pixel count and changes with the light sample sets drawn per pixel, so it is enforced
/// only on an image of this size (not on points, whose layout draws other sets); RMSE, bias
/// and shares hold at any size and in any layout.
pub const BUDGET_RESOLUTION: (u32, u32) = (128, 96);

/// The image size at which `cargo test` runs presets that execute on the GPU. CI's adapter is
/// a software rasteriser (lavapipe), on which AFSM's 1024-sample presets take minutes per scene
/// at [`BUDGET_RESOLUTION`]; `cargo xtask conformance` runs them at the budget resolution.
/// Their budgets hold at both sizes (tie budgets do not depend on size; measured tables take
/// the larger error of the two sizes).
pub const GPU_TEST_RESOLUTION: (u32, u32) = (48, 36);

impl Default for SuiteConfig {
    fn default() -> Self {
        Self {
            width: BUDGET_RESOLUTION.0,
            height: BUDGET_RESOLUTION.1,
            ref_samples: 1024,
            seed: 1,
            extra_checks: true,
            receivers: ReceiverMode::Camera,
        }
    }
}

/// A scene prepared once for every preset: the setup, its view samples and (lazily) the
/// stratified reference.
pub struct SceneContext {
    /// The scene.
    pub setup: SceneSetup,
    /// Shared view samples.
    pub view: ViewSamples,
    config: SuiteConfig,
    reference: OnceLock<Result<(VisibilityImage, f64), String>>,
    /// The same scene at [`GPU_TEST_RESOLUTION`], for the extra checks of GPU presets.
    small: OnceLock<Result<Box<SceneContext>, String>>,
}

impl SceneContext {
    /// Renders the view samples of `setup`.
    ///
    /// # Errors
    /// A message when the scene has no light or the view cannot be rendered.
    pub fn new(setup: SceneSetup, config: SuiteConfig) -> Result<Self, String> {
        if setup.lights.is_empty() {
            return Err(format!("scene `{}` has no light", setup.name));
        }
        let camera = setup.camera_or_default();
        let view = ViewSamples::render(setup.scene.as_ref(), &camera, config.width, config.height)
            .map_err(|e| e.to_string())?;
        let view = config.receivers.receivers(setup.scene.as_ref(), view)?;
        Ok(Self {
            setup,
            view,
            config,
            reference: OnceLock::new(),
            small: OnceLock::new(),
        })
    }

    /// Where the determinism and convergence re-runs of a preset take place: this context, or
    /// for a GPU preset run above [`GPU_TEST_RESOLUTION`] the same scene at that size. Those
    /// checks compare a technique with itself and with the reference at two sample counts, so
    /// they do not depend on the image size, and on a software adapter the three re-runs at full
    /// size would be most of the main job's time.
    ///
    /// # Errors
    /// A message when the smaller view cannot be rendered.
    pub fn for_extra_checks(&self, processor: Processor) -> Result<&SceneContext, String> {
        let (w, h) = GPU_TEST_RESOLUTION;
        if processor != Processor::Gpu || self.config.width * self.config.height <= w * h {
            return Ok(self);
        }
        self.small
            .get_or_init(|| {
                let config = SuiteConfig {
                    width: w,
                    height: h,
                    ..self.config
                };
                SceneContext::new(self.setup.clone(), config).map(Box::new)
            })
            .as_deref()
            .map_err(Clone::clone)
    }

    /// The light every case's main checks use (the scene's first; a scene with several has
    /// every light checked too, [`crate::lights`]).
    pub fn light(&self) -> Light {
        self.setup.lights[0].clone()
    }

    /// The stratified reference and its time in seconds.
    ///
    /// # Errors
    /// The reference's error as text.
    pub fn reference(&self) -> Result<&(VisibilityImage, f64), String> {
        self.reference
            .get_or_init(|| {
                let seed = self.config.seed ^ REFERENCE_SEED_SALT;
                let r = Reference::stratified(self.config.ref_samples, seed)
                    .map_err(|e| e.to_string())?;
                run_technique(&r, &self.setup, self.light(), &self.view)
                    .map(|(e, _, secs)| (e.visibility, secs))
                    .map_err(|e| e.to_string())
            })
            .as_ref()
            .map_err(Clone::clone)
    }
}

/// Prepares and runs a technique (with per-sample visibility when it is sample-based); returns
/// the estimate, the prepare stats and the wall time of prepare plus estimate.
///
/// # Errors
/// The technique's error.
pub fn run_technique(
    tech: &dyn ShadowTechnique,
    setup: &SceneSetup,
    light: Light,
    view: &ViewSamples,
) -> Result<(Estimate, Stats, f64), TechniqueError> {
    let outputs = if tech.capabilities().sample_based {
        Outputs::PER_SAMPLE
    } else {
        Outputs::VISIBILITY
    };
    let t0 = Instant::now();
    let prepared = tech.prepare(setup.scene.clone(), light)?;
    let est = prepared.estimate(view, outputs)?;
    Ok((
        est,
        prepared.preparation().clone(),
        t0.elapsed().as_secs_f64(),
    ))
}

/// What happened to one (preset, scene) case.
#[derive(Debug)]
pub enum Outcome {
    /// The preset does not support the scene; the reason says why.
    Unsupported {
        /// Why.
        reason: UnsupportedReason,
    },
    /// The technique failed with an error (a conformance failure).
    Failed {
        /// The error.
        error: String,
    },
    /// It ran; the report holds the measurements and any violations.
    Ran(Box<CaseReport>),
}

/// Measurements and verdicts of one case.
#[derive(Debug, Serialize)]
pub struct CaseReport {
    /// Preset name.
    pub technique: String,
    /// Scene name.
    pub scene: String,
    /// Errors against the reference.
    pub metrics: Metrics,
    /// Share of reference-lit pixels the technique darkened by more than 0.1.
    pub false_shadow: f64,
    /// The declared budget, if any.
    pub budget: Option<Budget>,
    /// Every check that failed, in words.
    pub violations: Vec<String>,
    /// Observations that are not failures (e.g. max error at another image size).
    pub notes: Vec<String>,
    /// Same seed, same output (`None` when not checked).
    pub deterministic: Option<bool>,
    /// RMSE at 16 and at 256 samples (sample-count presets).
    pub convergence: Option<(f64, f64)>,
    /// Technique parameters.
    pub parameters: serde_json::Value,
    /// Prepare statistics.
    pub prepare_stats: Stats,
    /// Estimate statistics.
    pub estimate_stats: Stats,
    /// Prepare + estimate wall time, seconds.
    pub seconds: f64,
    /// Wall time of the reference it was compared with, seconds.
    pub reference_seconds: f64,
    /// On a scene with several lights, every light shadowed at once and compared
    /// ([`crate::lights`]).
    pub every_light: Option<crate::lights::EveryLight>,
    /// True when compared with the same-samples reference.
    pub same_samples: bool,
    /// The technique's output.
    #[serde(skip)]
    pub estimate: VisibilityImage,
    /// The reference it was compared with.
    #[serde(skip)]
    pub reference: VisibilityImage,
}

impl CaseReport {
    /// True when every check held.
    pub fn passed(&self) -> bool {
        self.violations.is_empty()
    }
}

/// Share of pixels the reference calls fully lit where `estimate` is darker by more than 0.1.
pub fn false_shadow_share(
    estimate: &dyn VisibilityBuffer,
    reference: &dyn VisibilityBuffer,
) -> f64 {
    let (mut n, mut bad) = (0u64, 0u64);
    for i in 0..reference.len() {
        if !reference.is_valid(i) {
            continue;
        }
        n += 1;
        let lit = match reference.class(i) {
            Some(c) => c == PixelClass::Lit,
            None => reference.value(i) >= 1.0,
        };
        if lit && estimate.value(i) < reference.value(i) - 0.1 {
            bad += 1;
        }
    }
    if n == 0 { 0.0 } else { bad as f64 / n as f64 }
}

fn check_budget(
    m: &Metrics,
    false_shadow: f64,
    b: &Budget,
    enforce_max: bool,
    v: &mut Vec<String>,
    notes: &mut Vec<String>,
) {
    if m.max_abs > b.max_abs && !enforce_max {
        notes.push(format!(
            "max error {:.5} above the budget {:.5} measured at {}x{} (not enforced at this size or layout)",
            m.max_abs, b.max_abs, BUDGET_RESOLUTION.0, BUDGET_RESOLUTION.1
        ));
    }
    let max_limit = if enforce_max {
        b.max_abs
    } else {
        f64::INFINITY
    };
    let mut over = |what: &str, got: f64, limit: f64| {
        if got > limit || got.is_nan() {
            v.push(format!("{what} {got:.5} exceeds budget {limit:.5}"));
        }
    };
    over("rmse", m.rmse, b.rmse);
    if let Some(p) = m.penumbra_rmse {
        over("penumbra rmse", p, b.penumbra_rmse);
    }
    over("|bias|", m.bias.abs(), b.bias);
    over("max error", m.max_abs, max_limit);
    over("share > 0.1", m.share_over_0_1, b.share_over_0_1);
    over("false shadow", false_shadow, b.false_shadow);
    if let Some(min) = b.min_sample_agreement {
        match m.sample_agreement {
            Some(a) if a >= min => {}
            Some(a) => v.push(format!("per-sample agreement {a:.6} below {min:.6}")),
            None => v.push("no per-sample visibility to compare".into()),
        }
    }
}

/// Runs every check for `preset` on the scene of `ctx`.
pub fn run_case(preset: &Preset, ctx: &SceneContext) -> Outcome {
    let cfg = ctx.config;
    let tech = (preset.make)(cfg.seed);
    let caps = tech.capabilities();
    if let Err(reason) = caps.check(ctx.setup.scene.as_ref(), ctx.light().as_ref()) {
        return Outcome::Unsupported { reason };
    }
    let (est, prep, seconds) =
        match run_technique(tech.as_ref(), &ctx.setup, ctx.light(), &ctx.view) {
            Ok(r) => r,
            Err(TechniqueError::Unsupported { reason, .. }) => {
                return Outcome::Unsupported { reason };
            }
            Err(e) => {
                return Outcome::Failed {
                    error: e.to_string(),
                };
            }
        };
    let mut violations = Vec::new();
    if let Err(e) = est.visibility.validate() {
        violations.push(format!("invalid output: {e}"));
    }
    let same = caps.sample_based && tech.light_sampler().is_some();
    let (reference, reference_seconds) = match case_reference(tech.as_ref(), same, ctx) {
        Ok(r) => r,
        Err(error) => return Outcome::Failed { error },
    };
    let metrics = match compare(&est.visibility, &reference) {
        Ok(m) => m,
        Err(e) => {
            return Outcome::Failed {
                error: format!("metrics: {e}"),
            };
        }
    };
    let false_shadow = false_shadow_share(&est.visibility, &reference);
    // A preset may declare a budget of its own for a receiver mode (`bunny@points`): `auto`
    // chooses among fewer candidates where there is no camera.
    let budget = match ctx.config.receivers {
        ReceiverMode::Camera => None,
        mode => (preset.budget)(&format!("{}@{}", ctx.setup.name, mode.label())),
    }
    .or_else(|| (preset.budget)(&ctx.setup.name));
    let mut notes: Vec<String> = decision_note(&est, metrics.rmse, seconds)
        .into_iter()
        .collect();
    // The budget's image: not another size, nor the same receivers as points in another
    // layout, whose light sample sets (drawn per pixel) are another draw of the tail.
    let enforce_max = (ctx.view.width(), ctx.view.height()) == BUDGET_RESOLUTION;
    match &budget {
        Some(b) => check_budget(
            &metrics,
            false_shadow,
            b,
            enforce_max,
            &mut violations,
            &mut notes,
        ),
        None => violations.push("the preset declares no budget for this scene".into()),
    }
    // Every light of a multi-light scene, on the camera's receivers (the foreign modes check
    // the receivers on the first light).
    let every_light = (cfg.receivers == ReceiverMode::Camera)
        .then(|| {
            let case = crate::lights::LightsCase {
                setup: &ctx.setup,
                view: &ctx.view,
                seed: cfg.seed,
                ref_samples: cfg.ref_samples,
                reference_seed: cfg.seed ^ REFERENCE_SEED_SALT,
            };
            crate::lights::check_every_light(preset, &case, budget.as_ref(), &mut violations)
        })
        .flatten();
    let (deterministic, convergence) = if cfg.extra_checks {
        extra_checks(
            preset,
            ctx,
            caps.processor,
            &est,
            &mut violations,
            &mut notes,
        )
    } else {
        (None, None)
    };
    Outcome::Ran(Box::new(CaseReport {
        technique: preset.name.to_string(),
        scene: ctx.setup.name.clone(),
        metrics,
        false_shadow,
        budget,
        violations,
        notes,
        deterministic,
        convergence,
        parameters: tech.parameters(),
        prepare_stats: prep,
        estimate_stats: est.stats,
        seconds,
        reference_seconds,
        every_light,
        same_samples: same,
        estimate: est.visibility,
        reference,
    }))
}

/// The reference a case is measured against: for a sample-based technique the reference on
/// its own light samples (its error is then its own approximation alone), else the scene's
/// independent reference; its seconds.
fn case_reference(
    tech: &dyn ShadowTechnique,
    same_samples: bool,
    ctx: &SceneContext,
) -> Result<(VisibilityImage, f64), String> {
    if same_samples && let Some(sampler) = tech.light_sampler() {
        let r = Reference::same_samples(sampler.clone());
        return run_technique(&r, &ctx.setup, ctx.light(), &ctx.view)
            .map(|(e, _, s)| (e.visibility, s))
            .map_err(|e| format!("reference: {e}"));
    }
    match ctx.reference() {
        Ok((r, s)) => Ok((r.clone(), *s)),
        Err(e) => Err(format!("reference: {e}")),
    }
}

/// What a technique that decides per view chose, against what it achieved.
fn decision_note(est: &Estimate, rmse: f64, seconds: f64) -> Option<String> {
    if let Some(d) = shadow_auto::Decision::of(est) {
        return Some(format!(
            "chose {} ({}): predicted RMSE {:.4} in {:.4} s, achieved {:.4} in {:.4} s",
            d.choice, d.reason, d.predicted.rmse, d.predicted.seconds, rmse, seconds,
        ));
    }
    est.decision
        .as_ref()
        .map(|d| format!("chose {} ({})", d.choice(), d.reason()))
}

/// Determinism (a second run with the same seed gives the same buffer) and convergence (the
/// error falls from 16 to 256 samples), on the view `ctx` gives a `processor`'s extra checks.
fn extra_checks(
    preset: &Preset,
    main: &SceneContext,
    processor: Processor,
    est: &Estimate,
    violations: &mut Vec<String>,
    notes: &mut Vec<String>,
) -> (Option<bool>, Option<(f64, f64)>) {
    let cfg = main.config;
    let ctx = match main.for_extra_checks(processor) {
        Ok(c) => c,
        Err(e) => {
            violations.push(format!("extra checks: {e}"));
            return (None, None);
        }
    };
    if ctx.config != cfg {
        notes.push(format!(
            "determinism and convergence checked at {}x{} (GPU preset)",
            ctx.config.width, ctx.config.height
        ));
    }
    // The first run at this size: the main run, or a run on the smaller view.
    let first = if ctx.config == cfg {
        Ok(est.visibility.coefficients().clone())
    } else {
        let t = (preset.make)(cfg.seed);
        run_technique(t.as_ref(), &ctx.setup, ctx.light(), &ctx.view)
            .map(|(e, _, _)| e.visibility.coefficients().clone())
    };
    let again = (preset.make)(cfg.seed);
    let deterministic = match first.and_then(|first| {
        run_technique(again.as_ref(), &ctx.setup, ctx.light(), &ctx.view).map(|r| (first, r))
    }) {
        Ok((first, (e2, _, _))) => {
            let same_output = *e2.visibility.coefficients() == first;
            if !same_output {
                violations
                    .push("not deterministic: a second run with the same seed differs".into());
            }
            Some(same_output)
        }
        Err(e) => {
            violations.push(format!("second run failed: {e}"));
            None
        }
    };
    let convergence = preset.with_samples.and_then(|with| {
        match (
            convergence_rmse(with, ctx, 16),
            convergence_rmse(with, ctx, 256),
        ) {
            (Ok(a), Ok(b)) => {
                if !(b < a) && a > 1e-6 {
                    violations.push(format!(
                        "error does not fall with samples: rmse {a:.5} at 16, {b:.5} at 256"
                    ));
                }
                Some((a, b))
            }
            (Err(e), _) | (_, Err(e)) => {
                violations.push(format!("convergence run failed: {e}"));
                None
            }
        }
    });
    (deterministic, convergence)
}

/// The RMSE of the preset at `n` samples against the independent reference.
fn convergence_rmse(
    with: fn(u32, u64) -> Result<Box<dyn ShadowTechnique>, TechniqueError>,
    ctx: &SceneContext,
    n: u32,
) -> Result<f64, String> {
    let cfg = ctx.config;
    let t = with(n, cfg.seed).map_err(|e| e.to_string())?;
    let (e, _, _) =
        run_technique(t.as_ref(), &ctx.setup, ctx.light(), &ctx.view).map_err(|e| e.to_string())?;
    let r = if t.capabilities().sample_based {
        let r = Reference::stratified(cfg.ref_samples, cfg.seed ^ REFERENCE_SEED_SALT)
            .map_err(|e| e.to_string())?;
        run_technique(&r, &ctx.setup, ctx.light(), &ctx.view)
            .map_err(|e| e.to_string())?
            .0
            .visibility
    } else {
        ctx.reference()?.0.clone()
    };
    compare(&e.visibility, &r)
        .map(|m| m.rmse)
        .map_err(|e| e.to_string())
}

/// One point of the reference's time-error curve.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct CurvePoint {
    /// Samples per pixel.
    pub samples: u32,
    /// RMSE against the high-count reference.
    pub rmse: f64,
    /// Seconds (prepare + estimate).
    pub seconds: f64,
}

/// The reference at each of `counts` samples against the context's reference: the baseline
/// time-error curve.
///
/// # Errors
/// A message when a run fails.
pub fn reference_curve(ctx: &SceneContext, counts: &[u32]) -> Result<Vec<CurvePoint>, String> {
    let (high, _) = ctx.reference()?;
    counts
        .iter()
        .map(|&n| {
            let r =
                Reference::stratified(n, ctx.config.seed ^ 0xc0ffee).map_err(|e| e.to_string())?;
            let (e, _, secs) =
                run_technique(&r, &ctx.setup, ctx.light(), &ctx.view).map_err(|e| e.to_string())?;
            let m = compare(&e.visibility, high).map_err(|e| e.to_string())?;
            Ok(CurvePoint {
                samples: n,
                rmse: m.rmse,
                seconds: secs,
            })
        })
        .collect()
}

/// The reference's time at error `rmse`, interpolated log-log on `curve` (sorted by samples).
/// `None` when `rmse` is below the curve's best error (the technique beats every reference run).
pub fn reference_time_at(curve: &[CurvePoint], rmse: f64) -> Option<f64> {
    let first = curve.first()?;
    if rmse >= first.rmse {
        return Some(first.seconds);
    }
    for w in curve.windows(2) {
        let (a, b) = (w[0], w[1]);
        if rmse <= a.rmse && rmse >= b.rmse && a.rmse > 0.0 && b.rmse > 0.0 {
            let t = (rmse.ln() - a.rmse.ln()) / (b.rmse.ln() - a.rmse.ln());
            return Some((a.seconds.ln() + t * (b.seconds.ln() - a.seconds.ln())).exp());
        }
    }
    None
}
