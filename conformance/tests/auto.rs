//! The `auto` chooser on built-in scenes: it meets an RMSE budget (with a looser bound than
//! the budgets study's, at a small size), records its choice and prediction, is deterministic
//! under an error budget whatever the thread count, gives the outputs asked for, picks the
//! fastest prediction when nothing fits a time budget, and refuses bad budgets.

use shadow_auto::statistics::{AutoCounter, AutoPhase};
use shadow_auto::{Auto, AutoBudget, Decision};
use shadow_core::prelude::*;
use shadow_io::SceneSetup;
use shadow_metrics::compare;
use shadow_ref::Reference;
use shadow_scenes::builtin;

/// The decision `auto` made for `e`.
fn decision(e: &Estimate) -> &Decision {
    Decision::of(e).expect("auto records its decision")
}

fn view_of(setup: &SceneSetup, w: u32, h: u32) -> ViewSamples {
    ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), w, h).unwrap()
}

fn run(t: &dyn ShadowTechnique, setup: &SceneSetup, view: &ViewSamples, o: Outputs) -> Estimate {
    t.prepare(setup.scene.clone(), setup.lights[0].clone())
        .unwrap()
        .estimate(view, o)
        .unwrap()
}

#[test]
fn auto_meets_rmse_budgets_and_says_what_it_chose() {
    for scene in ["quad-over-plane", "bunny", "semi-opaque", "sphere-light"] {
        let setup = builtin(scene).unwrap();
        let view = view_of(&setup, 64, 48);
        let truth = run(
            &Reference::stratified(4096, 0xfeed).unwrap(),
            &setup,
            &view,
            Outputs::VISIBILITY,
        );
        for budget in [0.03, 0.01] {
            let auto = Auto::new(AutoBudget::Rmse(budget), 1, shadow_presets::build).unwrap();
            let e = run(&auto, &setup, &view, Outputs::VISIBILITY);
            let rmse = compare(&e.visibility, &truth.visibility).unwrap().rmse;
            let choice = decision(&e).choice.as_str();
            assert!(
                rmse <= 1.5 * budget + 0.002,
                "{scene} RMSE budget {budget}: {choice} gave {rmse}"
            );
            let predicted = decision(&e).predicted.rmse;
            assert!(predicted.is_finite() && predicted >= 0.0);
            assert!(e.stats.counter(AutoCounter::AutoCandidates).unwrap() > 0);
            assert!(e.stats.phase_seconds(AutoPhase::AutoProbe).is_some());
        }
    }
}

#[test]
fn auto_under_an_error_budget_is_deterministic_whatever_the_thread_count() {
    let setup = builtin("overlapping-occluders").unwrap();
    let view = view_of(&setup, 48, 36);
    let auto = Auto::new(AutoBudget::Rmse(0.01), 7, shadow_presets::build).unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let a = one.install(|| run(&auto, &setup, &view, Outputs::VISIBILITY));
    let b = run(&auto, &setup, &view, Outputs::VISIBILITY);
    assert_eq!(decision(&a).choice, decision(&b).choice);
    assert_eq!(a.visibility.coefficients(), b.visibility.coefficients());
}

#[test]
fn auto_gives_the_outputs_asked_for() {
    let setup = builtin("bunny").unwrap();
    let view = view_of(&setup, 32, 24);
    let auto = Auto::new(AutoBudget::Rmse(0.03), 1, shadow_presets::build).unwrap();
    let direct = Outputs {
        per_sample: false,
        direct: true,
    };
    assert!(run(&auto, &setup, &view, direct).direct.is_some());
    let e = run(&auto, &setup, &view, Outputs::PER_SAMPLE);
    assert!(e.visibility.per_sample().is_some());
}

#[test]
fn nothing_fits_a_tiny_time_budget_so_auto_takes_the_fastest_prediction() {
    let setup = builtin("contact").unwrap();
    let view = view_of(&setup, 48, 36);
    let auto = Auto::new(AutoBudget::Seconds(1e-9), 1, shadow_presets::build).unwrap();
    let e = run(&auto, &setup, &view, Outputs::VISIBILITY);
    let d = decision(&e);
    let fastest = d
        .candidates
        .iter()
        .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
        .unwrap();
    assert_eq!(d.choice, fastest.name);
    assert!(d.reason.contains("the fastest"));
}

#[test]
fn bad_budgets_are_errors() {
    for b in [
        AutoBudget::Rmse(0.0),
        AutoBudget::Rmse(1.0),
        AutoBudget::Rmse(f64::NAN),
        AutoBudget::Seconds(-1.0),
        AutoBudget::Seconds(f64::INFINITY),
    ] {
        assert!(
            matches!(
                Auto::new(b, 1, shadow_presets::build),
                Err(TechniqueError::InvalidInput(_))
            ),
            "{b:?}"
        );
    }
}

/// The DCS probe evaluates the reference probe's two sample sets, and DCS agrees with the
/// reference sample by sample on opaque occluders: both probes find the same shadowed and
/// penumbra shares and the same variance (up to a few numerical ties), the textured light's
/// radiance-weighted variance included. `auto` looks with DCS on meshes and with the
/// reference on semi-opaque occluders and on `grass` (a silhouette edge for every edge).
#[test]
fn the_dcs_probe_measures_what_the_reference_probe_measures() {
    use shadow_auto::{ProbeKind, measure_features, measure_features_by};
    for scene in [
        "bunny",
        "quad-over-plane",
        "textured-light",
        "sphere-light",
        "spot-self-shadow",
    ] {
        let setup = builtin(scene).unwrap();
        let view = view_of(&setup, 64, 48);
        let by = |k| {
            measure_features_by(
                Some(k),
                setup.scene.clone(),
                setup.lights[0].clone(),
                &view,
                768,
                3,
            )
            .unwrap()
        };
        let (d, r) = (by(ProbeKind::Dcs), by(ProbeKind::Reference));
        assert_eq!((d.probe, r.probe), (ProbeKind::Dcs, ProbeKind::Reference));
        assert_eq!(d.probe_pixels, r.probe_pixels, "{scene}");
        let ties = 2.0 / d.probe_pixels as f64;
        assert!(
            (d.sampled_share - r.sampled_share).abs() <= ties
                && (d.penumbra_share - r.penumbra_share).abs() <= ties,
            "{scene}: DCS {d:?}, reference {r:?}"
        );
        assert!(
            (d.v16 - r.v16).abs() <= 0.02 * r.v16 + 1e-6,
            "{scene}: v16 {} against {}",
            d.v16,
            r.v16
        );
        assert!(d.v16 > 0.0 && d.penumbra_share > 0.0, "{scene}");
        assert_eq!(d.silhouettes, r.silhouettes);
    }
    let chosen = |scene: &str| {
        let setup = builtin(scene).unwrap();
        let view = view_of(&setup, 32, 24);
        measure_features(setup.scene.clone(), setup.lights[0].clone(), &view, 768, 3)
            .unwrap()
            .probe
    };
    assert_eq!(chosen("bunny"), ProbeKind::Dcs);
    // DCS chosen after a DCS look runs on the look's preparation.
    let setup = builtin("bunny").unwrap();
    let view = view_of(&setup, 64, 48);
    let auto = Auto::new(AutoBudget::Rmse(0.01), 1, shadow_presets::build).unwrap();
    let prepared = auto
        .prepare(setup.scene.clone(), setup.lights[0].clone())
        .unwrap();
    assert_eq!(
        prepared.preparation().counter(AutoCounter::AutoProbeDcs),
        Some(1)
    );
    let e = prepared.estimate(&view, Outputs::VISIBILITY).unwrap();
    assert!(decision(&e).choice.as_str().starts_with("dcs-"));
    assert_eq!(
        e.stats.counter(AutoCounter::AutoProbePreparationReused),
        Some(1)
    );
    assert_eq!(chosen("semi-opaque"), ProbeKind::Reference);
    assert_eq!(chosen("grass"), ProbeKind::Reference);
    let setup = builtin("semi-opaque").unwrap();
    let view = view_of(&setup, 32, 24);
    assert!(matches!(
        measure_features_by(
            Some(ProbeKind::Dcs),
            setup.scene.clone(),
            setup.lights[0].clone(),
            &view,
            768,
            3
        ),
        Err(TechniqueError::InvalidInput(_))
    ));
}
