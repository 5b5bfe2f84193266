//! `cargo xtask budgets`: the error-budget study of the adaptive reference and of the ratio
//! estimator of direct light, on every built-in scene, in one run on one machine:
//!
//! * **adaptive against uniform**: the uniform stratified reference at 4 to 2048 samples and
//!   `ref-adaptive` at targets 0.03 to 0.001, each against an independent 4096-sample
//!   reference; the speed-up at equal RMSE (the uniform curve's time at the adaptive run's
//!   RMSE, interpolated log-log, over the adaptive run's time), the speed-up at RMSE 0.003
//!   (both curves interpolated there), and the achieved RMSE against the target;
//! * **allocation bound**: what the probe says any per-pixel allocation could save over one
//!   count for every sampled pixel (`ProbeSummary::allocation_gain`), beside what
//!   `ref-adaptive` achieves;
//! * **direct light**: eq. 6 and the ratio estimator from the same per-sample visibility
//!   (the reference at 16 and 64 samples, and `dcs-64`), against eq. 6 from 4096 samples;
//! * **`auto`** (unless `--no-auto`): every configuration it may pick observed, its models
//!   fitted (written with `--write-model`), and `auto` under budgets with the models fitted
//!   on the other scenes ([`crate::auto_study`]).
//!
//! Writes `budgets.json` and `budgets.md` under `--out`; `docs/benchmarks.md` quotes the
//! Markdown.

use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Args;
use glam::Vec3;
use serde::Serialize;
use shadow_auto::{AutoModel, Config, Features, Observation};
use shadow_conformance::conformance::{CurvePoint, reference_time_at};
use shadow_core::prelude::*;
use shadow_core::technique::{direct_from_per_sample, ratio_direct_from_per_sample};
use shadow_io::SceneSetup;
use shadow_metrics::compare;
use shadow_ref::adaptive::{DEFAULT_BATCH, DEFAULT_CAP};
use shadow_ref::statistics::{RefCounter, RefGauge};
use shadow_ref::{AdaptiveReference, Reference};
use shadow_scenes::{BUILTIN_SCENES, builtin};

use crate::auto_study::{self, SceneRun, timed};
use crate::common::{Machine, machine, progress, write_json};
use crate::ensure_dir;

#[derive(Args)]
pub struct BudgetsArgs {
    /// Output directory.
    #[arg(long, default_value = "out/budgets")]
    out: PathBuf,
    /// Scenes (comma-separated; default every built-in scene).
    #[arg(long, value_delimiter = ',')]
    scenes: Vec<String>,
    /// Image width.
    #[arg(long, default_value_t = 128)]
    width: u32,
    /// Image height.
    #[arg(long, default_value_t = 96)]
    height: u32,
    /// Timed runs per point (median reported).
    #[arg(long, default_value_t = 3)]
    repeats: usize,
    /// Also write the fitted `auto` model here (the committed one is
    /// `shadow-auto/auto-model.json`).
    #[arg(long)]
    write_model: Option<PathBuf>,
    /// Skip the `auto` study (observations, fit and evaluation).
    #[arg(long)]
    no_auto: bool,
}

/// The adaptive targets of the study.
const TARGETS: [f32; 6] = [0.03, 0.01, 0.005, 0.003, 0.002, 0.001];
/// The uniform reference's sample counts.
const UNIFORM: [u32; 10] = [4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048];
/// The RMSE at which the issue compares the two.
const COMPARE_AT: f64 = 0.003;

#[derive(Debug, Clone, Serialize)]
struct AdaptivePoint {
    target: f32,
    rmse: f64,
    seconds: f64,
    mean_samples: f64,
    max_samples: Option<u64>,
    speedup: Option<f64>,
}

#[derive(Debug, Clone, Serialize)]
struct DirectRow {
    source: String,
    samples: u32,
    eq6_rmse: f64,
    ratio_rmse: f64,
}

#[derive(Debug, Clone, Serialize)]
struct SceneStudy {
    scene: String,
    uniform: Vec<CurvePoint>,
    adaptive: Vec<AdaptivePoint>,
    speedup_at_0_003: Option<f64>,
    worst_rmse_over_target: f64,
    /// The probe's bound on what any allocation among the sampled pixels can save.
    allocation_bound: f64,
    direct: Vec<DirectRow>,
}

/// Time at `rmse` on a curve of (rmse, seconds) points sorted by falling error.
fn time_at(curve: &[(f64, f64)], rmse: f64) -> Option<f64> {
    let pts: Vec<CurvePoint> = curve
        .iter()
        .map(|&(r, s)| CurvePoint {
            samples: 0,
            rmse: r,
            seconds: s,
        })
        .collect();
    let first = pts.first()?;
    (rmse < first.rmse).then(|| reference_time_at(&pts, rmse))?
}

/// RMSE between two RGB images over the view's valid pixels (channels as values).
fn rgb_rmse(view: &ViewSamples, a: &[Vec3], b: &[Vec3]) -> f64 {
    let (mut sq, mut n) = (0.0f64, 0u64);
    for i in 0..view.len() {
        if view.get(i).is_none() {
            continue;
        }
        let d = a[i] - b[i];
        sq += f64::from(d.x * d.x + d.y * d.y + d.z * d.z);
        n += 3;
    }
    if n == 0 { 0.0 } else { (sq / n as f64).sqrt() }
}

/// Per-pixel direct illumination by eq. 6 and by the ratio estimator, in that order.
type DirectPair = (Vec<Vec3>, Vec<Vec3>);

/// Eq. 6 and the ratio estimator of a sample-based technique's per-sample visibility.
fn direct_pair(
    t: &dyn ShadowTechnique,
    setup: &SceneSetup,
    view: &ViewSamples,
) -> Result<Option<DirectPair>, String> {
    let sampler = t.light_sampler().ok_or("no sampler")?.clone();
    let light = setup.lights[0].clone();
    let prepared = t
        .prepare(setup.scene.clone(), light.clone())
        .map_err(|e| e.to_string())?;
    let est = prepared
        .estimate(view, Outputs::PER_SAMPLE)
        .map_err(|e| e.to_string())?;
    let scene = setup.scene.as_ref();
    let eq6 = direct_from_per_sample(scene, light.as_ref(), &sampler, view, &est.visibility)
        .map_err(|e| e.to_string())?;
    let ratio =
        ratio_direct_from_per_sample(scene, light.as_ref(), &sampler, view, &est.visibility)
            .map_err(|e| e.to_string())?;
    Ok(ratio.map(|r| (eq6, r)))
}

pub fn run(a: BudgetsArgs) -> Result<(), String> {
    let scenes: Vec<String> = if a.scenes.is_empty() {
        BUILTIN_SCENES.iter().map(|s| s.to_string()).collect()
    } else {
        a.scenes.clone()
    };
    ensure_dir(&a.out)?;
    let m = machine();
    let pb = progress(scenes.len() as u64, "budgets");
    let mut studies = Vec::new();
    let mut contexts = Vec::new();
    let mut auto = AutoData::default();
    for name in &scenes {
        pb.set_message(format!("{name}: ground truth"));
        let setup = builtin(name).map_err(|e| e.to_string())?;
        let view = ViewSamples::render(
            setup.scene.as_ref(),
            &setup.camera_or_default(),
            a.width,
            a.height,
        )
        .map_err(|e| e.to_string())?;
        let truth = truth_of(&setup, &view)?;
        pb.set_message(format!("{name}: uniform and adaptive"));
        let study = study_scene(&a, name, &setup, &view, &truth)?;
        if !a.no_auto {
            pb.set_message(format!("{name}: auto observations"));
            let run = SceneRun {
                name,
                setup: &setup,
                view: &view,
                truth: &truth.visibility,
            };
            auto.observe(&run, &study, a.repeats)?;
        }
        studies.push(study);
        contexts.push((name.clone(), setup, view, truth.visibility));
        pb.inc(1);
    }
    pb.finish_and_clear();
    let mut md = markdown(&studies, &a, &m);
    let mut auto_runs = Vec::new();
    if !a.no_auto {
        auto_runs = auto.fit_and_evaluate(&a, &m, &scenes, &contexts)?;
        md.push_str(&auto_study::markdown(&auto_runs));
    }
    std::fs::write(a.out.join("budgets.md"), &md).map_err(|e| e.to_string())?;
    write_json(
        &a.out.join("budgets.json"),
        &serde_json::json!({
            "machine": m,
            "width": a.width,
            "height": a.height,
            "scenes": studies,
            "auto_observations": auto.observations,
            "auto_runs": auto_runs,
        }),
    )?;
    print!("{md}");
    Ok(())
}

/// The truth: another seed, 4096 samples, with eq. 6 from the same samples.
fn truth_of(setup: &SceneSetup, view: &ViewSamples) -> Result<Estimate, String> {
    let truth = Reference::stratified(4096, 0xfeed).map_err(|e| e.to_string())?;
    let prepared = truth
        .prepare(setup.scene.clone(), setup.lights[0].clone())
        .map_err(|e| e.to_string())?;
    let outputs = Outputs {
        per_sample: false,
        direct: true,
    };
    let est = prepared
        .estimate(view, outputs)
        .map_err(|e| e.to_string())?;
    if est.direct.is_none() {
        return Err("no direct light".into());
    }
    Ok(est)
}

/// One scene's study: the uniform and adaptive references against the truth, and direct
/// light by eq. 6 and by the ratio estimator.
fn study_scene(
    a: &BudgetsArgs,
    name: &str,
    setup: &SceneSetup,
    view: &ViewSamples,
    truth: &Estimate,
) -> Result<SceneStudy, String> {
    let mut uniform = Vec::new();
    for &n in &UNIFORM {
        let r = Reference::stratified(n, 1).map_err(|e| e.to_string())?;
        let (secs, e) = timed(&r, setup, view, a.repeats)?;
        let mt = compare(&e.visibility, &truth.visibility).map_err(|e| e.to_string())?;
        uniform.push(CurvePoint {
            samples: n,
            rmse: mt.rmse,
            seconds: secs,
        });
    }
    let mut adaptive = Vec::new();
    for &target in &TARGETS {
        let r = AdaptiveReference::new(target, DEFAULT_BATCH, DEFAULT_CAP, 1)
            .map_err(|e| e.to_string())?;
        let (secs, e) = timed(&r, setup, view, a.repeats)?;
        let mt = compare(&e.visibility, &truth.visibility).map_err(|e| e.to_string())?;
        let samples = e.stats.counter(RefCounter::AdaptiveSamples).unwrap_or(0);
        let pixels = e.stats.counter(RefCounter::Pixels).unwrap_or(1).max(1);
        adaptive.push(AdaptivePoint {
            target,
            rmse: mt.rmse,
            seconds: secs,
            mean_samples: samples as f64 / pixels as f64,
            max_samples: e.stats.gauge(RefGauge::AdaptiveMaxSamplesPerPixel),
            speedup: reference_time_at(&uniform, mt.rmse).map(|t| t / secs),
        });
    }
    let curve = |pts: Vec<(f64, f64)>| {
        let mut p = pts;
        p.sort_by(|x, y| y.0.total_cmp(&x.0));
        p
    };
    let u = curve(uniform.iter().map(|p| (p.rmse, p.seconds)).collect());
    let ad = curve(adaptive.iter().map(|p| (p.rmse, p.seconds)).collect());
    let speedup_at_0_003 = match (time_at(&u, COMPARE_AT), time_at(&ad, COMPARE_AT)) {
        (Some(tu), Some(ta)) => Some(tu / ta),
        _ => None,
    };
    let worst_rmse_over_target = adaptive
        .iter()
        .map(|p| p.rmse / f64::from(p.target))
        .fold(0.0, f64::max);
    let allocation_bound = AdaptiveReference::new(0.01, DEFAULT_BATCH, DEFAULT_CAP, 1)
        .and_then(|r| r.prepare_adaptive(setup.scene.clone(), setup.lights[0].clone()))
        .map_err(|e| e.to_string())?
        .probe_view(view)
        .allocation_gain;
    let truth_direct = truth.direct.as_ref().ok_or("no direct light")?;
    Ok(SceneStudy {
        scene: name.to_string(),
        uniform,
        adaptive,
        speedup_at_0_003,
        worst_rmse_over_target,
        allocation_bound,
        direct: direct_rows(setup, view, truth_direct)?,
    })
}

/// Direct light by eq. 6 and by the ratio estimator from the references' and DCS's
/// per-sample visibility, each against the truth's.
fn direct_rows(
    setup: &SceneSetup,
    view: &ViewSamples,
    truth_direct: &[Vec3],
) -> Result<Vec<DirectRow>, String> {
    let light = &setup.lights[0];
    let mut direct = Vec::new();
    let mut sources: Vec<(String, Box<dyn ShadowTechnique>)> = Vec::new();
    for n in [16, 64] {
        let r = Reference::stratified(n, 1)
            .map_err(|e| e.to_string())?
            .with_per_sample(true);
        sources.push((format!("ref-{n}"), Box::new(r)));
    }
    if let Ok(p) = shadow_presets::preset("dcs-64") {
        sources.push(("dcs-64".into(), (p.make)(1)));
    }
    for (label, t) in sources {
        let caps = t.capabilities();
        if caps.check(setup.scene.as_ref(), light.as_ref()).is_err() {
            continue;
        }
        let samples = t.light_sampler().map_or(0, |s| s.count());
        if let Some((eq6, ratio)) = direct_pair(t.as_ref(), setup, view)? {
            direct.push(DirectRow {
                source: label,
                samples,
                eq6_rmse: rgb_rmse(view, &eq6, truth_direct),
                ratio_rmse: rgb_rmse(view, &ratio, truth_direct),
            });
        }
    }
    Ok(direct)
}

/// What `auto`'s models are fitted on: every configuration's observed error and time per
/// scene, and each scene's probe features.
#[derive(Default)]
struct AutoData {
    observations: Vec<Observation>,
    probes: Vec<Features>,
}

impl AutoData {
    /// The scene's features, the study's uniform and adaptive points as observations, and
    /// the other candidates observed.
    fn observe(
        &mut self,
        run: &SceneRun,
        study: &SceneStudy,
        repeats: usize,
    ) -> Result<(), String> {
        let f = auto_study::features(run, repeats)?;
        for p in &study.uniform {
            self.observations.push(Observation {
                scene: run.name.to_string(),
                features: f,
                config: Config::Ref { samples: p.samples },
                rmse: p.rmse,
                seconds: p.seconds,
            });
        }
        // Target 0.001 is below the 4096-sample truth's own error: not a candidate.
        for p in study.adaptive.iter().filter(|p| p.target >= 0.002) {
            self.observations.push(Observation {
                scene: run.name.to_string(),
                features: f,
                config: Config::RefAdaptive { target: p.target },
                rmse: p.rmse,
                seconds: p.seconds,
            });
        }
        self.observations
            .extend(auto_study::observe_extra(run, &f, repeats)?);
        self.probes.push(f);
        Ok(())
    }

    /// Fits the models (written when `--write-model` asks) and evaluates `auto` on every
    /// scene against them.
    fn fit_and_evaluate(
        &self,
        a: &BudgetsArgs,
        m: &Machine,
        scenes: &[String],
        contexts: &[(String, SceneSetup, ViewSamples, VisibilityImage)],
    ) -> Result<Vec<auto_study::AutoRun>, String> {
        let model = AutoModel::fit(
            &self.observations,
            &self.probes,
            auto_study::PROBE_PIXELS,
            auto_study::ERROR_QUANTILE,
            serde_json::json!({
                "command": format!("cargo xtask budgets --width {} --height {} --repeats {} --write-model", a.width, a.height, a.repeats),
                "date": m.date,
                "machine": format!("{} ({} threads)", m.cpu, m.threads),
                "scenes": scenes,
            }),
        );
        if let Some(path) = &a.write_model {
            let text = serde_json::to_string_pretty(&model).map_err(|e| e.to_string())?;
            std::fs::write(path, text + "\n").map_err(|e| format!("{}: {e}", path.display()))?;
        }
        let runs: Vec<SceneRun<'_>> = contexts
            .iter()
            .map(|(name, setup, view, truth)| SceneRun {
                name,
                setup,
                view,
                truth,
            })
            .collect();
        auto_study::evaluate(&runs, &self.observations, &self.probes, a.repeats)
    }
}

fn fmt_opt(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |x| format!("{x:.digits$}"))
}

fn markdown(studies: &[SceneStudy], a: &BudgetsArgs, m: &crate::common::Machine) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "`cargo xtask budgets` ({}x{}, {} repeats, median), {} ({} threads), {}.\n",
        a.width, a.height, a.repeats, m.cpu, m.threads, m.date
    );
    let _ = writeln!(
        s,
        "### Adaptive reference against the uniform one (RMSE against 4096 samples, another seed)\n"
    );
    let _ = writeln!(
        s,
        "| scene | x uniform at RMSE 0.003 | allocation bound | RMSE / target, worst | target 0.01: RMSE, spp, x | target 0.003: RMSE, spp, x | target 0.001: RMSE, spp, x |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|");
    let at = |st: &SceneStudy, t: f32| {
        st.adaptive
            .iter()
            .find(|p| p.target == t)
            .map_or("-".into(), |p| {
                format!(
                    "{:.4}, {:.1}, {}",
                    p.rmse,
                    p.mean_samples,
                    fmt_opt(p.speedup, 2)
                )
            })
    };
    for st in studies {
        let _ = writeln!(
            s,
            "| {} | {} | {:.2} | {:.2} | {} | {} | {} |",
            st.scene,
            fmt_opt(st.speedup_at_0_003, 2),
            st.allocation_bound,
            st.worst_rmse_over_target,
            at(st, 0.01),
            at(st, 0.003),
            at(st, 0.001)
        );
    }
    let mut sp: Vec<f64> = studies.iter().filter_map(|s| s.speedup_at_0_003).collect();
    if !sp.is_empty() {
        sp.sort_by(f64::total_cmp);
        let _ = writeln!(
            s,
            "\nAt RMSE 0.003: median {:.2}x, worst {:.2}x over {} scenes.",
            sp[sp.len() / 2],
            sp[0],
            sp.len()
        );
    }
    let _ = writeln!(
        s,
        "\n### Direct light: eq. 6 against the ratio estimator on the same samples (RGB RMSE against eq. 6 at 4096 samples)\n"
    );
    let _ = writeln!(s, "| scene | source | N | eq. 6 | ratio | ratio / eq. 6 |");
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    for st in studies {
        for d in &st.direct {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.5} | {:.5} | {:.2} |",
                st.scene,
                d.source,
                d.samples,
                d.eq6_rmse,
                d.ratio_rmse,
                d.ratio_rmse / d.eq6_rmse.max(1e-12)
            );
        }
    }
    s
}
