//! Contours and the adaptive scheme (GBP07 sections 4 and 5) against the reference: the claimed
//! gain over gap-filled back-projection, the adaptive scheme's saving, textured lights.

use shadow_core::prelude::*;
use shadow_core::visibility::Coefficients;
use shadow_io::SceneSetup;
use shadow_metrics::compare;
use shadow_ssm::backprojection::Backprojection;
use shadow_ssm::statistics::SsmCounter;
use shadow_ssm::{Contours, Filter, ScreenSpace, ShadowMapFilter};

struct Case {
    setup: SceneSetup,
    view: ViewSamples,
    truth: VisibilityImage,
}

fn case(scene: &str, w: u32, h: u32) -> Case {
    let setup = shadow_scenes::builtin(scene).unwrap();
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), w, h).unwrap();
    let r = shadow_ref::Reference::stratified(1024, 1).unwrap();
    let r_prepared = r
        .prepare(setup.scene.clone(), setup.lights[0].clone())
        .unwrap();
    let truth = r_prepared
        .estimate(&view, Outputs::VISIBILITY)
        .unwrap()
        .visibility;
    Case { setup, view, truth }
}

fn run(c: &Case, t: &dyn ShadowTechnique) -> Estimate {
    let t_prepared = t
        .prepare(c.setup.scene.clone(), c.setup.lights[0].clone())
        .unwrap();
    t_prepared.estimate(&c.view, Outputs::VISIBILITY).unwrap()
}

const CONTOURS: Contours = Contours {
    t: 0.0,
    max_kernel: 256.0,
    beta: 0.05,
};

fn backprojection() -> Filter {
    Filter::Backprojection(Backprojection {
        max_nspp: 1024,
        gap_filling: true,
        peeling_max_bias: None,
        union: false,
    })
}

/// GBP07 Fig. 11 and section 7.1: contours remove gap filling's over-estimation of the shadow
/// (its negative bias) and its error, on occluders with fine detail.
#[test]
fn contours_beat_gap_filling_on_fine_occluders() {
    for scene in ["spot-self-shadow", "contact"] {
        let c = case(scene, 96, 72);
        let gap = compare(
            &run(&c, &ShadowMapFilter::new("bp", backprojection(), 1024)).visibility,
            &c.truth,
        )
        .unwrap();
        let est = run(
            &c,
            &ShadowMapFilter::new("c", Filter::Contours(CONTOURS), 1024),
        );
        let contours = compare(&est.visibility, &c.truth).unwrap();
        assert!(
            contours.rmse < 0.8 * gap.rmse,
            "{scene}: contours {contours:?} gap filling {gap:?}"
        );
        assert!(gap.bias < -0.002, "{scene}: {gap:?}");
        assert!(
            contours.bias.abs() < 0.5 * gap.bias.abs(),
            "{scene}: {contours:?}"
        );
        assert!(est.stats.counter(SsmCounter::ContourEdges).unwrap() > 0);
        assert!(est.stats.counter(SsmCounter::PixelsSkippedLit).unwrap() > 0);
    }
}

/// GBP07 section 7.2: the adaptive scheme does far less work than full-resolution contours on
/// a large penumbra, at comparable error, and reconstructs skipped pixels by pull-push.
#[test]
fn adaptive_contours_do_less_work_at_comparable_error() {
    let c = case("large-light-close", 96, 72);
    let full = run(
        &c,
        &ShadowMapFilter::new("c", Filter::Contours(CONTOURS), 1024),
    );
    let adaptive = ShadowMapFilter::new(
        "a",
        Filter::Contours(Contours {
            max_kernel: 32.0,
            ..CONTOURS
        }),
        1024,
    )
    .with_screen_space(ScreenSpace {
        s_min: 16.0,
        pattern: 4,
    });
    let fast = run(&c, &adaptive);
    let (ef, ea) = (
        compare(&full.visibility, &c.truth).unwrap(),
        compare(&fast.visibility, &c.truth).unwrap(),
    );
    assert!(ea.rmse < 1.15 * ef.rmse, "adaptive {ea:?} full {ef:?}");
    let (wf, wa) = (
        full.stats.counter(SsmCounter::ContourEdges).unwrap(),
        fast.stats.counter(SsmCounter::ContourEdges).unwrap(),
    );
    assert!(wa * 5 < wf, "edges: adaptive {wa}, full {wf}");
    assert!(fast.stats.counter(SsmCounter::PixelsReconstructed).unwrap() > 0);
    assert!(fast.stats.counter(SsmCounter::PixelsBlended).unwrap() > 0);
}

/// Textured rectangle lights: the RGB visibility is the radiance integrated over the uncovered
/// part of the light, close to the reference's per-sample sum in every channel.
#[test]
fn textured_light_is_integrated_per_channel() {
    let c = case("textured-light", 64, 48);
    for filter in [Filter::Contours(CONTOURS), backprojection()] {
        let est = run(&c, &ShadowMapFilter::new("t", filter, 1024));
        let Coefficients::Rgb(v) = est.visibility.coefficients() else {
            panic!("textured lights give RGB");
        };
        let Coefficients::Rgb(want) = c.truth.coefficients() else {
            panic!("the reference is RGB");
        };
        let m = compare(&est.visibility, &c.truth).unwrap();
        assert!(m.rmse < 0.04, "{filter:?}: {m:?}");
        // The channels differ (the texture is red, green and blue bands), as in the reference.
        let mean = |v: &[glam::Vec3]| v.iter().copied().sum::<glam::Vec3>() / v.len() as f32;
        let (got, exp) = (mean(v), mean(want));
        assert!((got - exp).abs().max_element() < 0.03, "{got} vs {exp}");
        assert!((got.x - got.y).abs() > 0.05, "{got}");
    }
    // PCF has no area to weight: textured lights are refused with the reason.
    let pcf = ShadowMapFilter::new("pcf", Filter::Pcf { radius: 1 }, 64);
    let err = pcf
        .prepare(c.setup.scene.clone(), c.setup.lights[0].clone())
        .unwrap_err();
    assert!(matches!(err, TechniqueError::Unsupported { .. }), "{err}");
}
