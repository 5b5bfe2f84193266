//! Every light of a scene (`shadow_core::lights`): V per light equals each light prepared
//! alone, direct light is the sum of the lights' (DCS eq. 6 is linear in the lights), the BVH is
//! built once, a light behind every receiver is skipped with the V the reference gives it, and
//! a refused light is named or traced by the fallback.

use shadow_ref::statistics::RefCounter;
use std::sync::Arc;

use glam::Vec3;
use shadow_core::lights::PreparedLights;
use shadow_core::prelude::*;
use shadow_core::stats::CoreCounter;
use shadow_io::SceneSetup;
use shadow_ref::Reference;

fn interior() -> (SceneSetup, ViewSamples) {
    let setup = shadow_scenes::builtin("interior").unwrap();
    let view =
        ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 48, 36).unwrap();
    (setup, view)
}

const DIRECT: Outputs = Outputs {
    per_sample: true,
    direct: true,
};

#[test]
fn each_light_as_alone_and_direct_light_summed() {
    let (setup, view) = interior();
    assert_eq!(setup.lights.len(), 3);
    let r = Reference::stratified(16, 5).unwrap();
    let all = PreparedLights::prepare(&r, None, setup.scene.clone(), &setup.lights).unwrap();
    assert_eq!(all.preparation().counter(RefCounter::BvhShared), Some(2));
    let est = all.estimate(&view, DIRECT).unwrap();
    assert_eq!(est.stats.counter(CoreCounter::LightsShadowed), Some(3));
    let mut sum = vec![Vec3::ZERO; view.len()];
    for (i, light) in setup.lights.iter().enumerate() {
        let alone = r
            .prepare(setup.scene.clone(), light.clone())
            .unwrap()
            .estimate(&view, DIRECT)
            .unwrap();
        let each = &est.lights[i];
        assert_eq!((each.index, each.skipped), (i, false));
        assert_eq!(
            each.estimate.visibility.coefficients(),
            alone.visibility.coefficients(),
            "light {i}"
        );
        for (s, d) in sum.iter_mut().zip(alone.direct.unwrap()) {
            *s += d;
        }
    }
    let direct = est.direct.unwrap();
    for (i, (a, b)) in direct.iter().zip(&sum).enumerate() {
        assert!(
            (*a - *b).abs().max_element() <= 1e-5 * b.max_element().max(1.0),
            "{i}"
        );
    }
    // Three lights of three colours: the sum is not any one light's.
    assert!(direct.iter().any(|d| d.max_element() > 0.0));
}

#[test]
fn a_light_behind_every_receiver_is_skipped_with_the_v_the_reference_gives_it() {
    let (setup, view) = interior();
    // A panel under the floor facing down: every receiver is behind its plane.
    let below: Light = Arc::new(
        RectLight::facing(
            Vec3::new(0.0, -0.5, 0.0),
            Vec3::NEG_Y,
            0.5,
            0.5,
            Radiance::Constant(Vec3::ONE),
        )
        .unwrap(),
    );
    let lights = vec![setup.lights[0].clone(), below.clone()];
    let r = Reference::stratified(16, 5).unwrap();
    let all = PreparedLights::prepare(&r, None, setup.scene.clone(), &lights).unwrap();
    let est = all.estimate(&view, DIRECT).unwrap();
    assert_eq!(est.stats.counter(CoreCounter::LightsSkipped), Some(1));
    assert!(est.lights[1].skipped && !est.lights[0].skipped);
    let alone = r
        .prepare(setup.scene.clone(), below)
        .unwrap()
        .estimate(&view, DIRECT)
        .unwrap();
    assert_eq!(
        est.lights[1].estimate.visibility.coefficients(),
        alone.visibility.coefficients()
    );
    let per = est.lights[1].estimate.visibility.per_sample().unwrap();
    assert_eq!((per.pixels(), per.samples()), (view.len(), 16));
    assert!(
        est.lights[1]
            .estimate
            .direct
            .as_ref()
            .unwrap()
            .iter()
            .all(|d| *d == Vec3::ZERO)
    );
}

/// The reference, refusing every light but rectangles: a technique with a gap in its light
/// kinds.
struct RectanglesOnly(Reference);

impl ShadowTechnique for RectanglesOnly {
    fn name(&self) -> &str {
        "rectangles-only"
    }
    fn capabilities(&self) -> Capabilities {
        Capabilities {
            lights: vec![LightKind::Rectangle],
            ..self.0.capabilities()
        }
    }
    fn prepare(
        &self,
        scene: SceneRef,
        light: Light,
    ) -> Result<Box<dyn PreparedShadows>, TechniqueError> {
        self.capabilities()
            .require(self.name(), scene.as_ref(), light.as_ref())?;
        self.0.prepare(scene, light)
    }
}

#[test]
fn a_refused_light_is_named_or_traced_by_the_fallback() {
    let (setup, view) = interior();
    let t = RectanglesOnly(Reference::stratified(16, 5).unwrap());
    let e = PreparedLights::prepare(&t, None, setup.scene.clone(), &setup.lights).unwrap_err();
    assert!(matches!(e, TechniqueError::Light { index: 1, .. }), "{e}");
    assert!(matches!(
        e.unsupported_reason(),
        Some(UnsupportedReason::Light {
            kind: LightKind::Disk,
            ..
        })
    ));
    assert!(e.to_string().starts_with("light 1: "), "{e}");
    let fallback = Reference::stratified(16, 9).unwrap();
    let all =
        PreparedLights::prepare(&t, Some(&fallback), setup.scene.clone(), &setup.lights).unwrap();
    assert_eq!(
        all.preparation().counter(CoreCounter::LightsFallback),
        Some(2)
    );
    let est = all.estimate(&view, Outputs::VISIBILITY).unwrap();
    let names: Vec<&str> = est.lights.iter().map(|l| l.technique.as_str()).collect();
    assert_eq!(names, ["ref-16", "ref-16", "ref-16"]);
    assert!(est.lights[0].fallback.is_none());
    assert!(matches!(
        est.lights[2].fallback,
        Some(UnsupportedReason::Light {
            kind: LightKind::Sphere,
            ..
        })
    ));
    let alone = fallback
        .prepare(setup.scene.clone(), setup.lights[2].clone())
        .unwrap()
        .estimate(&view, Outputs::VISIBILITY)
        .unwrap();
    assert_eq!(
        est.lights[2].estimate.visibility.coefficients(),
        alone.visibility.coefficients()
    );
}

#[test]
fn no_lights_is_an_error() {
    let (setup, _) = interior();
    let r = Reference::stratified(4, 1).unwrap();
    let e = PreparedLights::prepare(&r, None, setup.scene.clone(), &[]).unwrap_err();
    assert!(matches!(e, TechniqueError::InvalidInput(_)));
}

#[test]
fn progress_is_reported_after_each_light_and_its_error_stops_the_estimate() {
    let (setup, view) = interior();
    let r = Reference::stratified(4, 5).unwrap();
    let all = PreparedLights::prepare(&r, None, setup.scene.clone(), &setup.lights).unwrap();
    let mut calls = Vec::new();
    let est = all
        .estimate_with_progress(&view, Outputs::VISIBILITY, &mut |done, total| {
            calls.push((done, total));
            Ok(())
        })
        .unwrap();
    assert_eq!(calls, [(1, 3), (2, 3), (3, 3)]);
    let plain = all.estimate(&view, Outputs::VISIBILITY).unwrap();
    for (a, b) in est.lights.iter().zip(&plain.lights) {
        assert_eq!(
            a.estimate.visibility.coefficients(),
            b.estimate.visibility.coefficients()
        );
    }
    let mut seen = 0;
    let stopped = all.estimate_with_progress(&view, Outputs::VISIBILITY, &mut |done, _| {
        seen = done;
        if done == 2 {
            Err(TechniqueError::InvalidInput("cancelled".into()))
        } else {
            Ok(())
        }
    });
    assert_eq!(seen, 2, "no light after the cancelling one");
    assert_eq!(
        stopped.unwrap_err(),
        TechniqueError::InvalidInput("cancelled".into())
    );
}
