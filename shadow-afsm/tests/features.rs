//! Temporal jittering, splitting under a memory limit, the plane table and textured lights,
//! each against the reference.

use std::sync::Arc;

use shadow_afsm::{Afsm, accumulate};
use shadow_core::gpu::context_for_test;
use shadow_core::metrics::compare;
use shadow_core::prelude::*;
use shadow_core::scenes::builtin;
use shadow_ref::Reference;

fn setup_view(name: &str, w: u32, h: u32) -> (SceneSetup, ViewSamples) {
    let setup = builtin(name).unwrap();
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), w, h).unwrap();
    (setup, view)
}

fn stratified_reference(setup: &SceneSetup, view: &ViewSamples) -> VisibilityImage {
    let mut r = Reference::stratified(1024, 99).unwrap();
    r.prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
        .unwrap();
    r.estimate(view).unwrap().visibility
}

/// Fig. 7: accumulating frames of rotated sample sets converges toward the true visibility.
#[test]
fn temporal_jittering_converges() {
    if context_for_test("temporal_jittering_converges").is_none() {
        return;
    }
    let (setup, view) = setup_view("quad-over-plane", 48, 36);
    let truth = stratified_reference(&setup, &view);
    let mut afsm = Afsm::new(16, SamplingStrategy::Correlated, 4).unwrap();
    afsm.prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
        .unwrap();
    let one = accumulate(&mut afsm, &view, 1).unwrap();
    let eight = accumulate(&mut afsm, &view, 8).unwrap();
    let (e1, e8) = (
        compare(&one, &truth).unwrap().rmse,
        compare(&eight, &truth).unwrap().rmse,
    );
    println!("rmse after 1 frame {e1:.4}, after 8 frames {e8:.4}");
    assert!(e8 < 0.6 * e1, "{e1} {e8}");
    assert_eq!(afsm.frame(), 0);
}

/// A tiny memory limit forces many receiver batches (each with its own frustum) and many
/// caster batches; the bits are the same as in one batch.
#[test]
fn splitting_under_a_memory_limit_changes_nothing() {
    if context_for_test("splitting_under_a_memory_limit_changes_nothing").is_none() {
        return;
    }
    let (setup, view) = setup_view("contact", 40, 30);
    let run = |limit: Option<u64>| {
        let mut a = Afsm::new(64, SamplingStrategy::Interleaved { tile: 2 }, 8).unwrap();
        if let Some(l) = limit {
            a = a.with_memory_limit(l);
        }
        a.prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
            .unwrap();
        a.estimate(&view).unwrap()
    };
    let whole = run(None);
    let split = run(Some(16 * 1024));
    assert!(split.stats.counter("receiver-batches") > 1);
    assert!(split.stats.counter("caster-batches") > 1);
    let m = compare(&split.visibility, &whole.visibility).unwrap();
    assert!(m.sample_agreement.unwrap() >= 0.9999, "{m:?}");
}

/// The plane table (section 4.2) against the exact test on the same samples: close, not equal.
#[test]
fn lookup_table_is_close_to_the_exact_test() {
    if context_for_test("lookup_table_is_close_to_the_exact_test").is_none() {
        return;
    }
    let (setup, view) = setup_view("bunny", 48, 36);
    let run = |lut: bool| {
        let mut a = Afsm::new(128, SamplingStrategy::Correlated, 2).unwrap();
        if lut {
            a = a.with_lut().unwrap();
        }
        a.prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
            .unwrap();
        a.estimate(&view).unwrap().visibility
    };
    let m = compare(&run(true), &run(false)).unwrap();
    println!("LUT vs exact: {m:?}");
    assert!(m.sample_agreement.unwrap() > 0.97 && m.rmse < 0.05, "{m:?}");
}

/// Textured lights: the visible samples weighted by their radiance (DCS eq. 2), per channel
/// equal to the same-samples reference.
#[test]
fn textured_light_matches_the_reference_per_channel() {
    if context_for_test("textured_light_matches_the_reference_per_channel").is_none() {
        return;
    }
    let (setup, view) = setup_view("textured-light", 48, 36);
    let mut a = Afsm::new(64, SamplingStrategy::Interleaved { tile: 4 }, 6).unwrap();
    a.prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
        .unwrap();
    let e = a.estimate(&view).unwrap();
    assert!(e.visibility.is_rgb());
    let mut r = Reference::same_samples(a.light_sampler().unwrap().clone());
    r.prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
        .unwrap();
    let m = compare(&e.visibility, &r.estimate(&view).unwrap().visibility).unwrap();
    assert!(
        m.rmse < 1e-4 && m.sample_agreement.unwrap() >= 0.999,
        "{m:?}"
    );
}

/// Bad input gets a clear error: per-pixel sample strategies and sample counts out of range.
#[test]
fn bad_parameters_are_refused() {
    assert!(Afsm::new(0, SamplingStrategy::Correlated, 1).is_err());
    assert!(Afsm::new(2048, SamplingStrategy::Correlated, 1).is_err());
    assert!(Afsm::new(64, SamplingStrategy::Stratified, 1).is_err());
    assert!(
        Afsm::new(64, SamplingStrategy::Interleaved { tile: 4 }, 1)
            .unwrap()
            .with_lut()
            .is_err()
    );
}
