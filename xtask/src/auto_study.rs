//! The `auto` chooser's fit and its evaluation, part of `cargo xtask budgets`:
//!
//! * **observations**: every CPU configuration `auto` may pick (the uniform reference at 4 to
//!   2048 samples and the adaptive one at its targets, measured by the budgets sweep; DCS at
//!   16, 64 and 256 samples; PCF, PCSS and the SSM presets) on every scene, RMSE against the
//!   independent 4096-sample reference and median time, beside the scene's probe features;
//! * **fit**: the cost and error models of [`shadow_auto::model`], written to
//!   `shadow-auto/auto-model.json` with `--write-model`;
//! * **evaluation**, each scene with the model fitted on the other scenes (leave one out, so
//!   no scene grades a model it trained): `auto` under RMSE budgets 0.03, 0.01 and 0.003 (met
//!   or not; time against the fastest configuration of the sweep that met the budget) and
//!   under time budgets 0.02, 0.1 and 0.5 s (met or not; error).

use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;
use shadow_auto::{
    Auto, AutoBudget, AutoModel, Config, Decision, Features, Observation, measure_features,
};
use shadow_core::prelude::*;
use shadow_io::SceneSetup;
use shadow_metrics::compare;

/// The probe's pixel budget written into the model.
pub const PROBE_PIXELS: u32 = 768;
/// The quantile of the error ratios each error factor is.
pub const ERROR_QUANTILE: f64 = 0.8;
/// The RMSE budgets of the evaluation.
pub const RMSE_BUDGETS: [f64; 3] = [0.03, 0.01, 0.003];
/// The time budgets of the evaluation (seconds).
pub const TIME_BUDGETS: [f64; 3] = [0.02, 0.1, 0.5];
/// Configurations measured here (the reference's are measured by the budgets sweep).
fn extra_configs() -> Vec<Config> {
    let mut v: Vec<Config> = [16, 64, 256]
        .into_iter()
        .map(|samples| Config::Dcs { samples })
        .collect();
    for name in [
        "pcf",
        "pcss",
        "ssm-backprojection",
        "ssm-peeling",
        "ssm-contours",
        "ssm-adaptive",
    ] {
        v.push(Config::Preset { name: name.into() });
    }
    v
}

/// What one scene brings to the study.
pub struct SceneRun<'a> {
    /// The scene's name.
    pub name: &'a str,
    /// The scene.
    pub setup: &'a SceneSetup,
    /// The view.
    pub view: &'a ViewSamples,
    /// The independent 4096-sample reference.
    pub truth: &'a VisibilityImage,
}

/// Median seconds (prepare and estimate, `V(p)` alone) of `repeats` runs, and the last
/// estimate.
pub fn timed(
    t: &dyn ShadowTechnique,
    setup: &SceneSetup,
    view: &ViewSamples,
    repeats: usize,
) -> Result<(f64, Estimate), String> {
    let mut runs = Vec::new();
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let t0 = Instant::now();
        let prepared = t
            .prepare(setup.scene.clone(), setup.lights[0].clone())
            .map_err(|e| e.to_string())?;
        let e = prepared
            .estimate(view, Outputs::VISIBILITY)
            .map_err(|e| e.to_string())?;
        runs.push(t0.elapsed().as_secs_f64());
        last = Some(e);
    }
    runs.sort_by(f64::total_cmp);
    Ok((runs[runs.len() / 2], last.expect("one run at least")))
}

/// The scene's probe features, the probe's time the median of `repeats`.
pub fn features(run: &SceneRun<'_>, repeats: usize) -> Result<Features, String> {
    let mut all = Vec::new();
    for _ in 0..repeats.max(1) {
        all.push(
            measure_features(
                run.setup.scene.clone(),
                run.setup.lights[0].clone(),
                run.view,
                PROBE_PIXELS,
                1,
            )
            .map_err(|e| e.to_string())?,
        );
    }
    all.sort_by(|a, b| a.probe_seconds.total_cmp(&b.probe_seconds));
    Ok(all[all.len() / 2])
}

/// Observations of the configurations measured here, on one scene.
pub fn observe_extra(
    run: &SceneRun<'_>,
    features: &Features,
    repeats: usize,
) -> Result<Vec<Observation>, String> {
    let mut out = Vec::new();
    for config in extra_configs() {
        let t = config
            .build(1, shadow_presets::build)
            .map_err(|e| e.to_string())?;
        let caps = t.capabilities();
        if caps
            .check(run.setup.scene.as_ref(), run.setup.lights[0].as_ref())
            .is_err()
        {
            continue;
        }
        let (seconds, e) = timed(t.as_ref(), run.setup, run.view, repeats)?;
        let rmse = compare(&e.visibility, run.truth)
            .map_err(|e| e.to_string())?
            .rmse;
        out.push(Observation {
            scene: run.name.into(),
            features: *features,
            config,
            rmse,
            seconds,
        });
    }
    Ok(out)
}

/// One `auto` run of the evaluation.
#[derive(Debug, Clone, Serialize)]
pub struct AutoRun {
    /// The scene.
    pub scene: String,
    /// The budget.
    pub budget: AutoBudget,
    /// What it chose.
    pub choice: String,
    /// Predicted RMSE and seconds.
    pub predicted_rmse: f64,
    /// Predicted seconds (probe included).
    pub predicted_seconds: f64,
    /// Achieved RMSE against the independent reference.
    pub rmse: f64,
    /// Achieved seconds (median).
    pub seconds: f64,
    /// Whether the budget was met.
    pub met: bool,
    /// Whether some swept configuration met it (a budget nothing meets is reported apart).
    pub feasible: bool,
    /// Under an RMSE budget: the fastest swept configuration that met it, and its seconds.
    pub fastest: Option<(String, f64)>,
}

/// Every scene's `auto` runs with the model fitted on the other scenes.
pub fn evaluate(
    runs: &[SceneRun<'_>],
    observations: &[Observation],
    probes: &[Features],
    repeats: usize,
) -> Result<Vec<AutoRun>, String> {
    let mut out = Vec::new();
    for (i, run) in runs.iter().enumerate() {
        let others: Vec<Observation> = observations
            .iter()
            .filter(|o| o.scene != run.name)
            .cloned()
            .collect();
        let other_probes: Vec<Features> = probes
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, f)| *f)
            .collect();
        let model = Arc::new(AutoModel::fit(
            &others,
            &other_probes,
            PROBE_PIXELS,
            ERROR_QUANTILE,
            serde_json::json!({ "leave_out": run.name }),
        ));
        let mine: Vec<&Observation> = observations
            .iter()
            .filter(|o| o.scene == run.name)
            .collect();
        let budgets = RMSE_BUDGETS
            .iter()
            .map(|&r| AutoBudget::Rmse(r))
            .chain(TIME_BUDGETS.iter().map(|&s| AutoBudget::Seconds(s)));
        for budget in budgets {
            let auto = Auto::with_model(budget, 1, model.clone(), shadow_presets::build)
                .map_err(|e| e.to_string())?;
            let (seconds, e) = timed(&auto, run.setup, run.view, repeats)?;
            let rmse = compare(&e.visibility, run.truth)
                .map_err(|e| e.to_string())?
                .rmse;
            let d = Decision::of(&e).ok_or("auto gave no decision")?;
            let (met, fastest, feasible) = match budget {
                AutoBudget::Rmse(r) => {
                    let fastest = mine
                        .iter()
                        .filter(|o| o.rmse <= r)
                        .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
                        .map(|o| (o.config.name(), o.seconds));
                    (rmse <= r, fastest.clone(), fastest.is_some())
                }
                AutoBudget::Seconds(s) => (seconds <= s, None, mine.iter().any(|o| o.seconds <= s)),
            };
            out.push(AutoRun {
                scene: run.name.into(),
                budget,
                choice: d.choice.clone(),
                predicted_rmse: d.predicted.rmse,
                predicted_seconds: d.predicted.seconds,
                rmse,
                seconds,
                met,
                feasible,
                fastest,
            });
        }
    }
    Ok(out)
}

/// The evaluation as Markdown.
pub fn markdown(runs: &[AutoRun]) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "\n### `auto` under budgets (each scene with the model fitted on the other scenes)\n"
    );
    let _ = writeln!(
        s,
        "| scene | budget | choice | predicted RMSE, s | achieved RMSE, s | met | fastest swept config that met it | x its time |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    for r in runs {
        let budget = match r.budget {
            AutoBudget::Rmse(x) => format!("RMSE {x}"),
            AutoBudget::Seconds(x) => format!("{x} s"),
        };
        let (fastest, ratio) = match &r.fastest {
            Some((n, t)) => (format!("{n} ({t:.4} s)"), format!("{:.2}", r.seconds / t)),
            None => ("-".into(), "-".into()),
        };
        let _ = writeln!(
            s,
            "| {} | {budget} | {} | {:.4}, {:.4} | {:.4}, {:.4} | {} | {fastest} | {ratio} |",
            r.scene,
            r.choice,
            r.predicted_rmse,
            r.predicted_seconds,
            r.rmse,
            r.seconds,
            match (r.met, r.feasible) {
                (true, _) => "yes",
                (false, true) => "**no**",
                (false, false) => "no (nothing swept meets it)",
            },
        );
    }
    let rmse_runs: Vec<&AutoRun> = runs
        .iter()
        .filter(|r| r.feasible && matches!(r.budget, AutoBudget::Rmse(_)))
        .collect();
    let time_runs: Vec<&AutoRun> = runs
        .iter()
        .filter(|r| r.feasible && matches!(r.budget, AutoBudget::Seconds(_)))
        .collect();
    let infeasible = runs.iter().filter(|r| !r.feasible).count();
    let share = |v: &[&AutoRun]| {
        let met = v.iter().filter(|r| r.met).count();
        format!(
            "{met} of {} ({:.0}%)",
            v.len(),
            100.0 * met as f64 / v.len().max(1) as f64
        )
    };
    let mut ratios: Vec<f64> = rmse_runs
        .iter()
        .filter(|r| r.met)
        .filter_map(|r| r.fastest.as_ref().map(|(_, t)| r.seconds / t))
        .collect();
    ratios.sort_by(f64::total_cmp);
    let within = ratios.iter().filter(|&&x| x <= 1.5).count();
    let _ = writeln!(
        s,
        "\nOf the budgets some swept configuration meets ({infeasible} others left out): RMSE \
         budgets met {}, time budgets met {}. Where an RMSE budget was met, time against the \
         fastest swept configuration that met it: median {}, worst {}, within 1.5x in {} of {}.",
        share(&rmse_runs),
        share(&time_runs),
        ratios
            .get(ratios.len() / 2)
            .map_or("-".into(), |x| format!("{x:.2}x")),
        ratios.last().map_or("-".into(), |x| format!("{x:.2}x")),
        within,
        ratios.len()
    );
    s
}
