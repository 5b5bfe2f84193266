//! Configurations that differ only in their samples share one preparation
//! (`Dcs::prepare_sharing`) and one frame (`PreparedDcs::estimate_replicates`): the `auto`
//! chooser looks with DCS on two 16-sample sets and then runs another sample count on the
//! same edges, silhouettes and wedges. Sharing changes the cost, never the answer: each
//! estimate is bit for bit the one its configuration gives alone.

use shadow_core::prelude::*;
use shadow_core::sampling::SamplingStrategy;
use shadow_dcs::statistics::DcsCounter;
use shadow_dcs::{CoveredSamples, Dcs};
use shadow_io::SceneSetup;
use shadow_scenes::builtin;

fn view_of(setup: &SceneSetup, w: u32, h: u32) -> ViewSamples {
    ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), w, h).unwrap()
}

fn alone(d: &Dcs, setup: &SceneSetup, view: &ViewSamples) -> Estimate {
    d.prepare(setup.scene.clone(), setup.lights[0].clone())
        .unwrap()
        .estimate(view, Outputs::PER_SAMPLE)
        .unwrap()
}

fn same(a: &Estimate, b: &Estimate, what: &str) {
    assert_eq!(
        a.visibility.coefficients(),
        b.visibility.coefficients(),
        "{what}"
    );
    assert_eq!(
        a.visibility.per_sample(),
        b.visibility.per_sample(),
        "{what}"
    );
}

#[test]
fn shared_preparations_and_frames_give_each_configuration_its_own_answer() {
    for scene in [
        "bunny",
        "textured-light",
        "sphere-light",
        "spot-self-shadow",
    ] {
        let setup = builtin(scene).unwrap();
        let view = view_of(&setup, 48, 36);
        let a = Dcs::new(16, SamplingStrategy::Stratified, 1).unwrap();
        let b = Dcs::new(16, SamplingStrategy::Stratified, 2).unwrap();
        let c = Dcs::new(64, SamplingStrategy::Stratified, 3).unwrap();
        let pa = a
            .prepare_dcs(setup.scene.clone(), setup.lights[0].clone())
            .unwrap();
        let pb = b.prepare_sharing(&pa).unwrap();
        let pc = c.prepare_sharing(&pa).unwrap();
        for p in [&pb, &pc] {
            assert_eq!(
                p.preparation().counter(DcsCounter::PreparationShared),
                Some(1)
            );
        }
        let shared = pc.estimate(&view, Outputs::PER_SAMPLE).unwrap();
        same(
            &shared,
            &alone(&c, &setup, &view),
            &format!("{scene}: dcs-64"),
        );
        let reps = pa.estimate_replicates(&[&pb, &pc], &view).unwrap();
        assert_eq!(reps.len(), 3);
        assert_eq!(reps[1].stats.counter(DcsCounter::FrameShared), Some(1));
        for (r, d) in reps.iter().zip([&a, &b, &c]) {
            same(r, &alone(d, &setup, &view), &format!("{scene}: replicate"));
        }
        // Different samples, different answers: the replicates are not one estimate thrice.
        assert_ne!(
            reps[0].visibility.per_sample(),
            reps[1].visibility.per_sample()
        );
    }
}

/// What depends on the samples is never shared: the tables of section 7.3 are built for an
/// interleaved configuration of its own, and its estimate is its own.
#[test]
fn a_configuration_whose_preparation_depends_on_its_samples_prepares_afresh() {
    let setup = builtin("bunny").unwrap();
    let view = view_of(&setup, 48, 36);
    let a = Dcs::new(16, SamplingStrategy::Stratified, 1).unwrap();
    let tables = Dcs::new(64, SamplingStrategy::Interleaved { tile: 4 }, 5)
        .unwrap()
        .with_covered_samples(CoveredSamples::Refined)
        .unwrap();
    let pa = a
        .prepare_dcs(setup.scene.clone(), setup.lights[0].clone())
        .unwrap();
    let pt = tables.prepare_sharing(&pa).unwrap();
    assert_eq!(
        pt.preparation().counter(DcsCounter::PreparationShared),
        Some(0)
    );
    let e = pt.estimate(&view, Outputs::PER_SAMPLE).unwrap();
    same(&e, &alone(&tables, &setup, &view), "tables");
    // A replicate that cannot share the frame is estimated on its own, with its own answer.
    let reps = pa.estimate_replicates(&[&pt], &view).unwrap();
    assert_eq!(reps[1].stats.counter(DcsCounter::FrameShared), None);
    same(&reps[1], &e, "tables as a replicate");
}
