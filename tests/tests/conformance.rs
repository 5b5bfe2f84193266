//! The conformance suite: every registered preset on every built-in scene, every check, one
//! named test per case (`conformance/PRESET/SCENE`, and `closed-form/PRESET` against the exact
//! answer of `quad-over-plane`), so a single case can be run and reported alone:
//!
//! ```sh
//! cargo test -p shadow-tests --test conformance -- dcs-64/bunny
//! cargo test -p shadow-tests --test conformance -- --list
//! ```
//!
//! After the built-in scenes come scenes of the corpus of real meshes
//! (`shadow_scenes::corpus`): a small share by default (`corpus_share`: every mesh once, the
//! lights in turn), all 44 with `SHADOW_TEST_CORPUS=all` (how the corpus rows of the budget
//! tables are measured). `cargo xtask conformance --corpus` runs them all with the report.
//!
//! A case the preset's capabilities exclude checks that preparing it is refused with a typed
//! reason; a preset that fails to run is a failure. Without a GPU adapter (and without
//! `SHADOW_REQUIRE_GPU`) a GPU case says so loudly and passes; with it, a missing adapter is a
//! failure.

use std::sync::{Arc, OnceLock};

use libtest_mimic::{Arguments, Failed, Trial};
use shadow_conformance::closed_form::{masked, quad_over_plane_buffer};
use shadow_conformance::conformance::{
    GPU_TEST_RESOLUTION, Outcome, ReceiverMode, SceneContext, SuiteConfig, run_case,
};
use shadow_core::technique::{Processor, UnsupportedReason};
use shadow_presets::Preset;
use shadow_presets::registry;
use shadow_scenes::corpus::{corpus_scene_names, corpus_share};
use shadow_scenes::{BUILTIN_SCENES, builtin};

/// The scenes every preset runs on with foreign receivers in `cargo test`.
const FOREIGN_RECEIVER_SCENES: [&str; 2] = ["bunny", "interior"];

/// A scene's context, built by the first case that needs it and shared by the others.
struct LazyContext {
    scene: String,
    config: SuiteConfig,
    cell: OnceLock<Result<SceneContext, String>>,
}

impl LazyContext {
    fn new(scene: &str, config: SuiteConfig) -> Arc<Self> {
        Arc::new(Self {
            scene: scene.to_string(),
            config,
            cell: OnceLock::new(),
        })
    }

    fn get(&self) -> Result<&SceneContext, Failed> {
        self.cell
            .get_or_init(|| {
                builtin(&self.scene)
                    .map_err(|e| e.to_string())
                    .and_then(|s| SceneContext::new(s, self.config))
            })
            .as_ref()
            .map_err(|e| Failed::from(format!("scene `{}`: {e}", self.scene)))
    }
}

fn on_gpu(p: &Preset, seed: u64) -> bool {
    (p.make)(seed).capabilities().processor == Processor::Gpu
}

/// A case whose technique did not run because no adapter exists: loud, and a pass only
/// where the environment does not require a GPU (the technique itself turns a missing
/// adapter into a failure when it does).
fn no_adapter(name: &str, reason: &UnsupportedReason) -> bool {
    if matches!(reason, UnsupportedReason::NoAdapter(_)) {
        eprintln!("SKIPPED {name}: {reason}");
        return true;
    }
    false
}

fn conformance_case(preset: Preset, ctx: &SceneContext) -> Result<(), Failed> {
    let scene = ctx.setup.name.clone();
    let caps = (preset.make)(1).capabilities();
    let declared = caps.check(ctx.setup.scene.as_ref(), ctx.light().as_ref());
    match run_case(&preset, ctx) {
        Outcome::Unsupported { reason } => {
            if no_adapter(preset.name, &reason) {
                return Ok(());
            }
            println!("{:<24} {:<22} unsupported: {reason}", preset.name, scene);
            // Every gap the capabilities declare must be refused; a refusal the capabilities
            // do not declare must come from the input (a light the kind allows but the
            // technique cannot sample, a view), never from a failure.
            if declared.is_ok() && matches!(reason, UnsupportedReason::Light { detail: None, .. }) {
                return Err(format!(
                    "{} on {scene}: refused as {reason}, but its capabilities accept the light",
                    preset.name
                )
                .into());
            }
            Ok(())
        }
        Outcome::Failed { error } => Err(format!("{} on {scene}: {error}", preset.name).into()),
        Outcome::Ran(r) => {
            if let Err(reason) = declared {
                return Err(format!(
                    "{} ran on {scene}, which its capabilities exclude ({reason})",
                    preset.name
                )
                .into());
            }
            println!(
                "{:<24} {:<22} rmse {:.4} pen {:.4} bias {:+.4} max {:.3} >0.1 {:.4} fs {:.4} det {:?} conv {:?}",
                preset.name,
                scene,
                r.metrics.rmse,
                r.metrics.penumbra_rmse.unwrap_or(0.0),
                r.metrics.bias,
                r.metrics.max_abs,
                r.metrics.share_over_0_1,
                r.false_shadow,
                r.deterministic,
                r.convergence
            );
            if r.violations.is_empty() {
                Ok(())
            } else {
                Err(format!("{} on {scene}: {}", preset.name, r.violations.join("; ")).into())
            }
        }
    }
}

/// `quad-over-plane`'s floor has an exact answer; each preset must meet its own budget against
/// it too (the reference at 1024 samples is itself within 4e-3 of it).
fn closed_form_case(preset: Preset, ctx: &SceneContext) -> Result<(), Failed> {
    let (exact, mask) = quad_over_plane_buffer(&ctx.view);
    let reference = masked(&ctx.reference()?.0, &mask);
    let m = shadow_metrics::compare(&reference, &exact).map_err(|e| e.to_string())?;
    if !(m.rmse < 4e-3 && m.max_abs < 0.03) {
        return Err(format!("reference vs closed form: {m:?}").into());
    }
    let r = match run_case(&preset, ctx) {
        Outcome::Ran(r) => r,
        Outcome::Unsupported { reason } if no_adapter(preset.name, &reason) => return Ok(()),
        Outcome::Unsupported { reason } => {
            return Err(format!("{} refuses quad-over-plane: {reason}", preset.name).into());
        }
        Outcome::Failed { error } => return Err(format!("{}: {error}", preset.name).into()),
    };
    let m =
        shadow_metrics::compare(&masked(&r.estimate, &mask), &exact).map_err(|e| e.to_string())?;
    let b = (preset.budget)("quad-over-plane").ok_or("no budget for quad-over-plane")?;
    println!(
        "{:<24} vs closed form: rmse {:.5} max {:.4}",
        preset.name, m.rmse, m.max_abs
    );
    // A sample-based technique's budget is against the reference on its own samples; against
    // the closed form it may add that reference's sampling error.
    let (noise_rmse, noise_max) = if r.same_samples {
        let n = shadow_metrics::compare(&masked(&r.reference, &mask), &exact)
            .map_err(|e| e.to_string())?;
        (n.rmse, n.max_abs)
    } else {
        (0.0, 0.0)
    };
    if m.rmse <= b.rmse + noise_rmse && m.max_abs <= b.max_abs + noise_max {
        Ok(())
    } else {
        Err(format!("{} against the closed form: {m:?}", preset.name).into())
    }
}

fn main() {
    let args = Arguments::from_args();
    let cfg = SuiteConfig::default();
    // GPU presets run smaller here (see `GPU_TEST_RESOLUTION`).
    let gpu_cfg = SuiteConfig {
        width: GPU_TEST_RESOLUTION.0,
        height: GPU_TEST_RESOLUTION.1,
        ..cfg
    };
    let closed_cfg = SuiteConfig {
        extra_checks: false,
        ..cfg
    };
    let presets = registry();
    assert!(!presets.is_empty(), "no preset is registered");
    let closed = LazyContext::new("quad-over-plane", closed_cfg);
    let mut trials = Vec::new();
    let corpus = match std::env::var("SHADOW_TEST_CORPUS").as_deref() {
        Ok("all") => corpus_scene_names(),
        Ok(other) if !other.is_empty() => {
            panic!("SHADOW_TEST_CORPUS takes `all` (or nothing for the share), not `{other}`")
        }
        _ => corpus_share(),
    };
    let scenes = BUILTIN_SCENES.iter().map(|s| s.to_string()).chain(corpus);
    for scene in scenes {
        let (cpu, gpu) = (
            LazyContext::new(&scene, cfg),
            LazyContext::new(&scene, gpu_cfg),
        );
        for &p in &presets {
            let ctx = if on_gpu(&p, cfg.seed) {
                Arc::clone(&gpu)
            } else {
                Arc::clone(&cpu)
            };
            trials.push(Trial::test(
                format!("conformance/{}/{scene}", p.name),
                move || conformance_case(p, ctx.get()?),
            ));
        }
    }
    // Receivers handed in as another renderer would: every preset on scenes of both kinds
    // (a mesh under a large light, a room around the light), as a foreign G-buffer with the
    // camera and as shuffled points without one; `cargo xtask conformance --receivers` runs
    // every scene.
    for mode in [ReceiverMode::Gbuffer, ReceiverMode::Points] {
        for scene in FOREIGN_RECEIVER_SCENES {
            let (cpu, gpu) = (
                LazyContext::new(
                    scene,
                    SuiteConfig {
                        receivers: mode,
                        ..cfg
                    },
                ),
                LazyContext::new(
                    scene,
                    SuiteConfig {
                        receivers: mode,
                        ..gpu_cfg
                    },
                ),
            );
            let label = mode.label();
            for &p in &presets {
                let ctx = Arc::clone(if on_gpu(&p, cfg.seed) { &gpu } else { &cpu });
                trials.push(Trial::test(
                    format!("{label}/{}/{scene}", p.name),
                    move || conformance_case(p, ctx.get()?),
                ));
            }
        }
    }
    for &p in &presets {
        let ctx = Arc::clone(&closed);
        trials.push(Trial::test(format!("closed-form/{}", p.name), move || {
            closed_form_case(p, ctx.get()?)
        }));
    }
    libtest_mimic::run(&args, trials).exit();
}
