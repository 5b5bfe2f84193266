//! The conformance suite: every registered preset on every built-in scene, every check.
//! Unsupported combinations are listed with their reason, never dropped.

use shadow_core::preset::Preset;
use shadow_core::scenes::{BUILTIN_SCENES, builtin};
use shadow_core::technique::Processor;
use shadow_tests::closed_form::{masked, quad_over_plane_buffer};
use shadow_tests::conformance::{
    GPU_TEST_RESOLUTION, Outcome, SceneContext, SuiteConfig, run_case,
};
use shadow_tests::registry;

#[test]
fn every_preset_on_every_builtin_scene() {
    let cfg = SuiteConfig::default();
    // GPU presets run smaller here (see `GPU_TEST_RESOLUTION`).
    let gpu_cfg = SuiteConfig {
        width: GPU_TEST_RESOLUTION.0,
        height: GPU_TEST_RESOLUTION.1,
        ..cfg
    };
    let presets = registry();
    assert!(!presets.is_empty());
    let on_gpu = |p: &Preset| (p.make)(cfg.seed).capabilities().processor == Processor::Gpu;
    let mut failures = Vec::new();
    let mut ran = 0;
    for scene in BUILTIN_SCENES {
        let ctx = SceneContext::new(builtin(scene).unwrap(), cfg).unwrap();
        let gpu_ctx = SceneContext::new(builtin(scene).unwrap(), gpu_cfg).unwrap();
        for p in &presets {
            let ctx = if on_gpu(p) { &gpu_ctx } else { &ctx };
            match run_case(p, ctx) {
                Outcome::Unsupported { reason } => {
                    println!("{:<12} {:<22} unsupported: {reason}", p.name, scene)
                }
                Outcome::Failed { error } => {
                    failures.push(format!("{} on {scene}: {error}", p.name))
                }
                Outcome::Ran(r) => {
                    ran += 1;
                    println!(
                        "{:<12} {:<22} rmse {:.4} pen {:.4} bias {:+.4} max {:.3} >0.1 {:.4} fs {:.4} det {:?} conv {:?}",
                        p.name,
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
                    for v in &r.violations {
                        failures.push(format!("{} on {scene}: {v}", p.name));
                    }
                }
            }
        }
    }
    assert!(ran >= BUILTIN_SCENES.len(), "only {ran} cases ran");
    assert!(
        failures.is_empty(),
        "conformance failures:\n{}",
        failures.join("\n")
    );
}

#[test]
fn every_preset_against_the_closed_form() {
    // quad-over-plane's floor has an exact answer; each preset must meet its own budget against
    // it too (the reference at 1024 samples is itself within 4e-3 of it).
    let cfg = SuiteConfig {
        extra_checks: false,
        ..SuiteConfig::default()
    };
    let ctx = SceneContext::new(builtin("quad-over-plane").unwrap(), cfg).unwrap();
    let (exact, mask) = quad_over_plane_buffer(&ctx.view);
    let reference = masked(&ctx.reference().unwrap().0, &mask);
    let m = shadow_core::metrics::compare(&reference, &exact).unwrap();
    assert!(
        m.rmse < 4e-3 && m.max_abs < 0.03,
        "reference vs closed form: {m:?}"
    );
    for p in registry() {
        if let Outcome::Ran(r) = run_case(&p, &ctx) {
            let m = shadow_core::metrics::compare(&masked(&r.estimate, &mask), &exact).unwrap();
            let b = (p.budget)("quad-over-plane").unwrap();
            println!(
                "{:<12} vs closed form: rmse {:.5} max {:.4}",
                p.name, m.rmse, m.max_abs
            );
            // A sample-based technique's budget is against the reference on its own samples;
            // against the closed form it may add that reference's sampling error.
            let (noise_rmse, noise_max) = if r.same_samples {
                let n =
                    shadow_core::metrics::compare(&masked(&r.reference, &mask), &exact).unwrap();
                (n.rmse, n.max_abs)
            } else {
                (0.0, 0.0)
            };
            assert!(
                m.rmse <= b.rmse + noise_rmse && m.max_abs <= b.max_abs + noise_max,
                "{} against the closed form: {m:?}",
                p.name
            );
        }
    }
}
