//! The adaptive reference against an independent high-sample reference: its achieved RMSE
//! follows its target, it spends fewer samples than the uniform reference of the same error,
//! it is deterministic whatever the thread count, and bad configurations are errors.

use shadow_core::prelude::*;
use shadow_io::SceneSetup;
use shadow_metrics::compare;
use shadow_ref::adaptive::{DEFAULT_BATCH, DEFAULT_CAP};
use shadow_ref::statistics::RefCounter;
use shadow_ref::{AdaptiveReference, Reference};
use shadow_scenes::builtin;

fn estimate(t: &dyn ShadowTechnique, setup: &SceneSetup, view: &ViewSamples) -> Estimate {
    let p = t
        .prepare(setup.scene.clone(), setup.lights[0].clone())
        .unwrap();
    p.estimate(view, Outputs::VISIBILITY).unwrap()
}

#[test]
fn achieved_rmse_follows_the_target() {
    for scene in ["quad-over-plane", "bunny", "sphere-light"] {
        let setup = builtin(scene).unwrap();
        let view =
            ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 96, 72).unwrap();
        let truth = estimate(&Reference::stratified(4096, 0xfeed).unwrap(), &setup, &view);
        for target in [0.01f32, 0.004] {
            let a = AdaptiveReference::new(target, DEFAULT_BATCH, DEFAULT_CAP, 1).unwrap();
            let e = estimate(&a, &setup, &view);
            let m = compare(&e.visibility, &truth.visibility).unwrap();
            // The truth's own error (about 0.001 at 4096 samples) adds to the achieved one.
            assert!(
                m.rmse <= 1.3 * f64::from(target) + 0.001 && m.rmse >= 0.4 * f64::from(target),
                "{scene} target {target}: rmse {}",
                m.rmse
            );
            // Fewer samples than the uniform reference that reaches the same error.
            let mean = e.stats.counter(RefCounter::AdaptiveSamples).unwrap() as f64
                / view.valid_count() as f64;
            let uniform = [16u32, 32, 64, 128, 256, 512, 1024, 2048, 4096]
                .into_iter()
                .find(|&n| {
                    let u = estimate(&Reference::stratified(n, 1).unwrap(), &setup, &view);
                    compare(&u.visibility, &truth.visibility).unwrap().rmse <= m.rmse
                })
                .unwrap_or(4096);
            assert!(
                mean < f64::from(uniform),
                "{scene} target {target}: {mean} samples a pixel against {uniform}"
            );
        }
    }
}

#[test]
fn adaptive_output_is_identical_whatever_the_thread_count() {
    let setup = builtin("overlapping-occluders").unwrap();
    let view =
        ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 64, 48).unwrap();
    let a = AdaptiveReference::new(0.005, DEFAULT_BATCH, DEFAULT_CAP, 3).unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let v1 = one.install(|| estimate(&a, &setup, &view));
    let v2 = estimate(&a, &setup, &view);
    assert_eq!(v1.visibility.coefficients(), v2.visibility.coefficients());
    assert!(v1.stats.counter(RefCounter::PixelsWithoutSamples).unwrap() > 0);
}

#[test]
fn bad_configurations_are_errors() {
    assert!(AdaptiveReference::new(0.0, 16, 4096, 1).is_err());
    assert!(AdaptiveReference::new(f32::NAN, 16, 4096, 1).is_err());
    assert!(
        AdaptiveReference::new(0.01, 32, 4096, 1).is_err(),
        "32 is not a power of four"
    );
    assert!(AdaptiveReference::new(0.01, 16, 16, 1).is_err());
    assert!(AdaptiveReference::new(0.01, 16, 1 << 20, 1).is_err());
    let setup = builtin("quad-over-plane").unwrap();
    let view =
        ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 16, 12).unwrap();
    let a = AdaptiveReference::new(0.01, 16, 4096, 1).unwrap();
    let p = a
        .prepare(setup.scene.clone(), setup.lights[0].clone())
        .unwrap();
    assert!(matches!(
        p.estimate(&view, Outputs::PER_SAMPLE),
        Err(TechniqueError::Unsupported { .. })
    ));
}

/// Direct light from the adaptive samples agrees with the uniform reference's eq. 6.
#[test]
fn adaptive_direct_light_agrees_with_eq6() {
    let setup = builtin("bunny").unwrap();
    let view =
        ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 48, 36).unwrap();
    let out = Outputs {
        per_sample: false,
        direct: true,
    };
    let run = |t: &dyn ShadowTechnique| {
        let p = t
            .prepare(setup.scene.clone(), setup.lights[0].clone())
            .unwrap();
        p.estimate(&view, out).unwrap().direct.unwrap()
    };
    let a = run(&AdaptiveReference::new(0.003, DEFAULT_BATCH, DEFAULT_CAP, 1).unwrap());
    let r = run(&Reference::stratified(1024, 5).unwrap());
    let (mut sq, mut n, mut mean) = (0.0f64, 0, 0.0f64);
    for i in 0..view.len() {
        if view.get(i).is_some() {
            sq += f64::from((a[i] - r[i]).length_squared());
            mean += f64::from(r[i].x);
            n += 1;
        }
    }
    let (rmse, mean) = ((sq / n as f64).sqrt(), mean / n as f64);
    assert!(rmse < 0.05 * mean, "rmse {rmse} against a mean of {mean}");
}
