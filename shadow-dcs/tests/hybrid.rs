//! The hybrid of DCS and shadow rays (`Dcs::with_rays`, issue 49): tracing a square instead of
//! estimating it changes the cost, never the answer. Checked against DCS alone and the
//! reference on the same samples, with every square traced, with the measured choice (which
//! traces `grass` and none of `bunny`), and where rays must not be used (semi-opaque scenes,
//! depth complexities asked for).

use std::sync::Arc;

use shadow_core::prelude::*;
use shadow_core::visibility::PerSampleVisibility;
use shadow_dcs::statistics::DcsCounter;
use shadow_dcs::{Dcs, PerSampleOutput, RayChoice};
use shadow_io::SceneSetup;
use shadow_ref::{BvhRays, Reference};

fn view_of(setup: &SceneSetup, w: u32, h: u32) -> ViewSamples {
    ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), w, h).unwrap()
}

fn run(t: &dyn ShadowTechnique, setup: &SceneSetup, view: &ViewSamples, o: Outputs) -> Estimate {
    t.prepare(setup.scene.clone(), setup.lights[0].clone())
        .unwrap()
        .estimate(view, o)
        .unwrap()
}

const BITS: Outputs = Outputs {
    per_sample: true,
    direct: false,
};

/// With every square traced, every built-in scene with an opaque planar or sphere light gets
/// the per-sample answers of DCS alone (up to its numerical ties) and of the reference on the
/// same samples, its visibility (RGB on the textured light) and direct illumination too; the
/// shadow-volume pass is skipped and every active pixel is traced.
#[test]
fn tracing_every_square_gives_the_answers_of_dcs_and_the_reference() {
    for scene in [
        "bunny",
        "contact",
        "textured-light",
        "sphere-light",
        "cornell-box",
        "large-light-close",
    ] {
        let setup = shadow_scenes::builtin(scene).unwrap();
        let view = view_of(&setup, 48, 36);
        let dcs = Dcs::new(64, SamplingStrategy::Stratified, 5).unwrap();
        let hybrid = dcs
            .clone()
            .with_rays(RayChoice::EVERYWHERE, Arc::new(BvhRays));
        let reference = Reference::same_samples(dcs.light_sampler().unwrap().clone());
        let with_direct = Outputs {
            per_sample: true,
            direct: true,
        };
        let h = run(&hybrid, &setup, &view, with_direct);
        let d = run(&dcs, &setup, &view, with_direct);
        let r = run(&reference, &setup, &view, with_direct);
        for (other, name) in [(&d, "dcs"), (&r, "reference")] {
            let m = shadow_metrics::compare(&h.visibility, &other.visibility).unwrap();
            assert!(
                m.sample_agreement.unwrap() >= 0.9999,
                "{scene} against {name}: {m:?}"
            );
        }
        // Against the reference on the same samples the traced answers are the reference's.
        let m = shadow_metrics::compare(&h.visibility, &r.visibility).unwrap();
        assert_eq!(m.sample_agreement, Some(1.0), "{scene}");
        assert!(m.rmse <= 1e-6, "{scene}: {m:?}");
        let (a, b) = (h.direct.unwrap(), r.direct.unwrap());
        for (x, y) in a.iter().zip(&b) {
            assert!(x.is_finite());
            assert!(
                (*x - *y).abs().max_element() <= 1e-5 * (1.0 + y.max_element()),
                "{scene}: {x} vs {y}"
            );
        }
        let c = |k: DcsCounter| h.stats.counter(k).unwrap_or(0);
        assert_eq!(c(DcsCounter::ShadowVolumesSkipped), 1, "{scene}");
        assert_eq!(c(DcsCounter::PixelsPerSample), 0, "{scene}");
        assert_eq!(
            c(DcsCounter::PixelsTraced) + c(DcsCounter::PixelsFacingAway),
            view.valid_count() as u64,
            "{scene}"
        );
        assert!(c(DcsCounter::OcclusionRays) > 0, "{scene}");
    }
}

/// The measured choice traces dense grass under its large light (where DCS's wedge pairs are
/// many times the samples) and leaves `bunny` to DCS (no BVH built there); both agree with the
/// reference on the same samples.
#[test]
fn the_measured_choice_traces_grass_and_not_bunny() {
    for (scene, traced) in [("grass", true), ("bunny", false)] {
        let setup = shadow_scenes::builtin(scene).unwrap();
        let view = view_of(&setup, 64, 48);
        let dcs = Dcs::new(64, SamplingStrategy::Stratified, 2)
            .unwrap()
            .with_rays(RayChoice::default(), Arc::new(BvhRays));
        let reference = Reference::same_samples(dcs.light_sampler().unwrap().clone());
        let h = run(&dcs, &setup, &view, BITS);
        let r = run(&reference, &setup, &view, BITS);
        let m = shadow_metrics::compare(&h.visibility, &r.visibility).unwrap();
        assert!(m.sample_agreement.unwrap() >= 0.9999, "{scene}: {m:?}");
        let squares = h.stats.counter(DcsCounter::SquaresTraced).unwrap();
        assert_eq!(squares > 0, traced, "{scene}: {squares} squares traced");
        // The choice weighed what it says: DCS's predicted work against the rays and the BVH.
        let c = |k: DcsCounter| h.stats.counter(k).unwrap();
        let dcs_work = c(DcsCounter::PredictedDcsRays) + c(DcsCounter::PredictedShadowVolumeRays);
        let rays = c(DcsCounter::PredictedTracedRays) + c(DcsCounter::PredictedBvhRays);
        assert_eq!(
            rays < dcs_work,
            traced,
            "{scene}: {dcs_work} against {rays}"
        );
        assert_eq!(
            dcs.parameters()["rays"]["rays_per_candidate"],
            serde_json::json!(RayChoice::default().rays_per_candidate),
        );
    }
}

/// Rays are never used where they would change the answer: on a semi-opaque scene (DCS's
/// saturating opacity sum, section 3, is not the transmittance product rays compute) and when
/// the caller reads depth complexities (rays count none). The output is then DCS's alone.
#[test]
fn rays_stay_out_of_semi_opaque_scenes_and_depth_complexities() {
    let cases = [
        ("semi-opaque", PerSampleOutput::Bits),
        ("bunny", PerSampleOutput::Counters),
    ];
    for (scene, output) in cases {
        let setup = shadow_scenes::builtin(scene).unwrap();
        let view = view_of(&setup, 40, 30);
        let dcs = Dcs::new(64, SamplingStrategy::Stratified, 4)
            .unwrap()
            .with_per_sample(output);
        let h = run(
            &dcs.clone()
                .with_rays(RayChoice::EVERYWHERE, Arc::new(BvhRays)),
            &setup,
            &view,
            BITS,
        );
        let d = run(&dcs, &setup, &view, BITS);
        assert_eq!(
            h.stats.counter(DcsCounter::SquaresTraced),
            Some(0),
            "{scene}"
        );
        let (hv, dv) = (&h.visibility, &d.visibility);
        assert_eq!(hv.coefficients(), dv.coefficients(), "{scene}");
        if output == PerSampleOutput::Counters {
            let counts = |e: &Estimate| match e.visibility.per_sample() {
                Some(PerSampleVisibility::Counters { counts, .. }) => counts.clone(),
                _ => panic!("counters requested"),
            };
            assert_eq!(counts(&h), counts(&d), "{scene}");
        }
    }
}
