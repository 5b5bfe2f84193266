//! DCS against the ray-traced reference evaluating the same light samples: direct illumination
//! (eq. 6), the Fig. 4 artifact of standard silhouettes, counter overflow handling, and the
//! claim that the only disagreements are numerical ties.

use glam::{DVec3, Vec3};
use shadow_core::prelude::*;
use shadow_core::visibility::PerSampleVisibility;
use shadow_dcs::statistics::{DcsCounter, DcsGauge};
use shadow_dcs::{CoveredSamples, Dcs, PerSampleOutput, Silhouettes};
use shadow_io::SceneSetup;
use shadow_metrics::compare;
use shadow_ref::Reference;

fn view_of(setup: &SceneSetup, w: u32, h: u32) -> ViewSamples {
    ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), w, h).unwrap()
}

fn run(t: &dyn ShadowTechnique, setup: &SceneSetup, view: &ViewSamples) -> Estimate {
    run_with(t, setup, view, Outputs::VISIBILITY)
}

fn run_with(
    t: &dyn ShadowTechnique,
    setup: &SceneSetup,
    view: &ViewSamples,
    outputs: Outputs,
) -> Estimate {
    t.prepare(setup.scene.clone(), setup.lights[0].clone())
        .unwrap()
        .estimate(view, outputs)
        .unwrap()
}

fn same_samples_reference(dcs: &Dcs) -> Reference {
    Reference::same_samples(dcs.light_sampler().unwrap().clone())
}

#[test]
fn direct_illumination_equals_the_reference_with_the_same_samples() {
    for scene in ["bunny", "textured-light", "sphere-light"] {
        let setup = shadow_scenes::builtin(scene).unwrap();
        let view = view_of(&setup, 48, 36);
        let dcs = Dcs::new(32, SamplingStrategy::Stratified, 3).unwrap();
        let r = same_samples_reference(&dcs);
        let direct = Outputs {
            per_sample: true,
            direct: true,
        };
        let (d, e) = (
            run_with(&dcs, &setup, &view, direct),
            run_with(&r, &setup, &view, direct),
        );
        let agreement = shadow_metrics::compare(&d.visibility, &e.visibility)
            .unwrap()
            .sample_agreement
            .unwrap();
        assert_eq!(agreement, 1.0, "{scene}");
        let (a, b) = (d.direct.unwrap(), e.direct.unwrap());
        let mut lit = 0;
        for (x, y) in a.iter().zip(&b) {
            assert!(x.is_finite());
            let tol = 1e-5 * (1.0 + y.max_element());
            assert!((*x - *y).abs().max_element() <= tol, "{scene}: {x} vs {y}");
            lit += (y.max_element() > 0.0) as u32;
        }
        assert!(lit > 100, "{scene}");
    }
}

#[test]
fn standard_silhouettes_underestimate_the_penumbra_of_a_large_close_light() {
    let setup = shadow_scenes::builtin("large-light-close").unwrap();
    let view = view_of(&setup, 64, 48);
    let accurate = Dcs::new(64, SamplingStrategy::Stratified, 1).unwrap();
    let standard = Dcs::new(64, SamplingStrategy::Stratified, 1)
        .unwrap()
        .with_silhouettes(Silhouettes::Standard);
    let r = same_samples_reference(&accurate);
    let truth = run(&r, &setup, &view).visibility;
    let a = compare(&run(&accurate, &setup, &view).visibility, &truth).unwrap();
    let s = compare(&run(&standard, &setup, &view).visibility, &truth).unwrap();
    assert!(a.rmse < 1e-3, "{a:?}");
    assert!(s.rmse > 0.02, "{s:?}");
    assert!(s.sample_agreement.unwrap() < 0.995);
}

#[test]
fn narrow_counters_overflow_into_wider_ones_without_changing_the_answer() {
    // 300 stacked quads between a floor and the light: depth complexity 300 in the umbra.
    let mut b = SceneBuilder::new();
    let f = shadow_scenes::procedural::floor(8.0, 0.0);
    b.push_mesh(MeshDesc::new(f.0, f.1)).unwrap();
    for k in 0..300 {
        let q = shadow_scenes::procedural::quad(
            Vec3::new(0.0, 1.0 + k as f32 * 0.002, 0.0),
            Vec3::X * 0.5,
            Vec3::Z * 0.5,
        );
        b.push_mesh(MeshDesc::new(q.0, q.1)).unwrap();
    }
    let scene: SceneRef = std::sync::Arc::new(b.build().unwrap());
    let light: Light = std::sync::Arc::new(
        RectLight::facing(
            Vec3::new(0.0, 3.0, 0.0),
            Vec3::NEG_Y,
            1.0,
            1.0,
            Radiance::constant(Vec3::ONE).unwrap(),
        )
        .unwrap(),
    );
    let cam = Camera::look_at(Vec3::new(0.0, 4.0, 4.0), Vec3::ZERO, Vec3::Y, 0.8).unwrap();
    let view = ViewSamples::render(scene.as_ref(), &cam, 48, 36).unwrap();
    let narrow = Dcs::new(16, SamplingStrategy::Stratified, 2)
        .unwrap()
        .with_counter_bits(8)
        .with_per_sample(PerSampleOutput::Counters);
    let narrow_prepared = narrow.prepare(scene.clone(), light.clone()).unwrap();
    let est = narrow_prepared
        .estimate(&view, Outputs::VISIBILITY)
        .unwrap();
    assert!(est.stats.counter(DcsCounter::CounterEscalations).unwrap() > 0);
    assert!(est.stats.gauge(DcsGauge::MaxIntegrationConstant).unwrap() >= 300);
    let Some(PerSampleVisibility::Counters { counts, .. }) = est.visibility.per_sample() else {
        panic!("counters requested")
    };
    // Depth complexities beyond 255 survive: nothing wrapped.
    assert!(counts.iter().any(|&c| c >= 300 && c != u32::MAX));
    let r = same_samples_reference(&narrow);
    let r_prepared = r.prepare(scene.clone(), light.clone()).unwrap();
    let truth = r_prepared
        .estimate(&view, Outputs::VISIBILITY)
        .unwrap()
        .visibility;
    let m = compare(&est.visibility, &truth).unwrap();
    assert_eq!(m.sample_agreement, Some(1.0));
    // The same with only the visible samples read (the bit-sliced counters).
    let bits = Dcs::new(16, SamplingStrategy::Stratified, 2)
        .unwrap()
        .with_counter_bits(8);
    let bits_prepared = bits.prepare(scene.clone(), light.clone()).unwrap();
    let est = bits_prepared.estimate(&view, Outputs::VISIBILITY).unwrap();
    assert!(est.stats.counter(DcsCounter::CounterEscalations).unwrap() > 0);
    let m = compare(&est.visibility, &truth).unwrap();
    assert_eq!(m.sample_agreement, Some(1.0));
}

/// Distance from segment `p q` to segment `a b`.
fn segment_distance(p: DVec3, q: DVec3, a: DVec3, b: DVec3) -> f64 {
    let n = 64;
    let mut best = f64::INFINITY;
    // Coarse-to-exact: closest points of two segments by clamped projection, refined.
    for i in 0..=n {
        let x = p + (q - p) * (i as f64 / n as f64);
        let ab = b - a;
        let t = ((x - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
        best = best.min((a + ab * t - x).length());
    }
    best
}

#[test]
fn remaining_disagreements_are_numerical_ties() {
    // Many overlapping thin occluders: the hardest built-in case for agreement.
    let setup = shadow_scenes::builtin("grass").unwrap();
    let view = view_of(&setup, 32, 24);
    let dcs = Dcs::new(64, SamplingStrategy::Stratified, 5).unwrap();
    let r = same_samples_reference(&dcs);
    let d = run(&dcs, &setup, &view).visibility;
    let e = run(&r, &setup, &view).visibility;
    let (Some(a), Some(b)) = (d.per_sample(), e.per_sample()) else {
        panic!("per-sample output")
    };
    let scene = setup.scene.as_ref();
    let light = setup.lights[0].as_ref();
    let sampler = dcs.light_sampler().unwrap();
    let extent = scene.bounds().union(light.bounds()).diagonal();
    let offset = shadow_core::offset::RayOffset::for_light(light);
    let (mut pairs, mut differ) = (0u64, 0u64);
    let mut units = Vec::new();
    for i in 0..view.len() {
        let Some(s) = view.get(i) else { continue };
        sampler.unit_samples(s.pixel, &mut units);
        for k in 0..sampler.count() {
            pairs += 1;
            if a.visible(i, k) == b.visible(i, k) {
                continue;
            }
            differ += 1;
            // A tie: the segment grazes a triangle edge, or the sample sits on the horizon.
            let o = offset.offset(s.position, s.geometric_normal).as_dvec3();
            let y = light.sample(units[k as usize]).position.as_dvec3();
            let horizon = (y - s.position.as_dvec3())
                .dot(s.geometric_normal.as_dvec3())
                .abs();
            let graze = (0..scene.triangle_count())
                .flat_map(|t| {
                    let [p0, p1, p2] = scene.triangle(t).map(|v| v.as_dvec3());
                    [(p0, p1), (p1, p2), (p2, p0)]
                })
                .map(|(u, v)| segment_distance(o, y, u, v))
                .fold(f64::INFINITY, f64::min);
            assert!(
                graze < 1e-4 * extent as f64 || horizon < 1e-5 * extent as f64,
                "pixel {i} sample {k}: nearest edge {graze}, horizon {horizon}"
            );
        }
    }
    assert!(pairs > 10_000);
    assert!(differ as f64 <= 1e-3 * pairs as f64, "{differ} of {pairs}");
}

/// Every number of sample words the per-pixel pass handles its own way agrees with the
/// reference on the same samples: one word, two to four (fixed-size words of the angular
/// index and the light-plane test, one of them with a partly used last word) and five (words
/// of any length).
#[test]
fn every_number_of_sample_words_agrees_with_the_reference() {
    let setup = shadow_scenes::builtin("bunny").unwrap();
    let view = view_of(&setup, 40, 30);
    for n in [64, 100, 192, 256, 320] {
        let dcs = Dcs::new(n, SamplingStrategy::Stratified, 6).unwrap();
        let r = same_samples_reference(&dcs);
        let (d, e) = (run(&dcs, &setup, &view), run(&r, &setup, &view));
        let m = shadow_metrics::compare(&d.visibility, &e.visibility).unwrap();
        assert!(m.sample_agreement.unwrap() >= 0.9999, "{n} samples: {m:?}");
        // The pixels took per-sample work, through the light-plane test.
        assert!(
            d.stats.counter(DcsCounter::PixelsPerSample).unwrap() > 50,
            "{n} samples"
        );
        assert!(
            d.stats.counter(DcsCounter::CoveredUpdates).unwrap() > 500,
            "{n} samples"
        );
    }
}

#[test]
fn concave_polygon_lights_and_every_sampling_strategy_agree_with_the_reference() {
    let setup = shadow_scenes::builtin("bunny").unwrap();
    let view = view_of(&setup, 40, 30);
    let c = setup.lights[0].center();
    // An L-shaped light facing down, 1.2 across, at the scene light's centre.
    let mut outline: Vec<Vec3> = [
        (0.0, 0.0),
        (1.2, 0.0),
        (1.2, 0.4),
        (0.4, 0.4),
        (0.4, 1.2),
        (0.0, 1.2),
    ]
    .iter()
    .map(|(x, z)| c + Vec3::new(x - 0.6, 0.0, z - 0.6))
    .collect();
    let mut light =
        PolygonLight::new(outline.clone(), Radiance::constant(Vec3::ONE).unwrap()).unwrap();
    if light.geometry().plane_normal().unwrap().y > 0.0 {
        outline.reverse();
        light = PolygonLight::new(outline, Radiance::constant(Vec3::ONE).unwrap()).unwrap();
    }
    let light: Light = std::sync::Arc::new(light);
    for strategy in [
        SamplingStrategy::Correlated,
        SamplingStrategy::Decorrelated,
        SamplingStrategy::Stratified,
        SamplingStrategy::Interleaved { tile: 3 },
    ] {
        let dcs = Dcs::new(32, strategy, 4).unwrap();
        let r = same_samples_reference(&dcs);
        let dcs_prepared = dcs.prepare(setup.scene.clone(), light.clone()).unwrap();
        let r_prepared = r.prepare(setup.scene.clone(), light.clone()).unwrap();
        let (d, e) = (
            dcs_prepared.estimate(&view, Outputs::VISIBILITY).unwrap(),
            r_prepared.estimate(&view, Outputs::VISIBILITY).unwrap(),
        );
        let m = compare(&d.visibility, &e.visibility).unwrap();
        assert!(m.sample_agreement.unwrap() >= 0.9999, "{strategy:?}: {m:?}");
        assert!(d.stats.counter(DcsCounter::WedgePairs).unwrap() > 0);
    }
}

/// The refined tables of section 7.3 (`dcs-64-interleaved`) give exactly the depth complexity
/// of the exact covered-sample test with the same samples, on every built-in scene with a
/// planar light (`grass` left to the conformance run for time), and their line table decides
/// pairs on the way.
#[test]
fn refined_tables_give_the_exact_depth_complexity() {
    let strategy = SamplingStrategy::Interleaved { tile: 4 };
    let (mut scenes, mut cells) = (0, 0);
    for name in shadow_scenes::BUILTIN_SCENES {
        if name == "grass" {
            continue;
        }
        let setup = shadow_scenes::builtin(name).unwrap();
        let view = view_of(&setup, 96, 72);
        let make = |c| {
            Dcs::new(64, strategy, 5)
                .unwrap()
                .with_covered_samples(c)
                .unwrap()
                .with_per_sample(PerSampleOutput::Counters)
        };
        let refined = make(CoveredSamples::Refined);
        if !refined
            .capabilities()
            .lights
            .contains(&setup.lights[0].kind())
        {
            // The tables are defined on planar lights only (the configuration says so).
            assert!(
                matches!(setup.lights[0].kind(), LightKind::Sphere | LightKind::Mesh),
                "{name}"
            );
            continue;
        }
        let r = run(&refined, &setup, &view);
        let e = run(&make(CoveredSamples::Exact), &setup, &view);
        let counts = |e: &Estimate| match e.visibility.per_sample() {
            Some(PerSampleVisibility::Counters { counts, .. }) => counts.clone(),
            _ => panic!("counters requested"),
        };
        let (cr, ce) = (counts(&r), counts(&e));
        assert_eq!(cr.len(), ce.len(), "{name}");
        let differ = cr.iter().zip(&ce).filter(|(a, b)| a != b).count();
        assert_eq!(differ, 0, "{name}: {differ} samples differ");
        // The same pairs update, but for ties: the table's line test and the exact test may
        // part on a sample lying on an edge's line, where a room's walls meet the light's
        // plane (`interior-window`: 2 of 33 948 updates, and no count, asserted above).
        let (ur, ue) = (
            r.stats.counter(DcsCounter::CoveredUpdates).unwrap(),
            e.stats.counter(DcsCounter::CoveredUpdates).unwrap(),
        );
        assert!(
            ur.abs_diff(ue) * 10_000 <= ue,
            "{name}: {ur} against {ue} updates"
        );
        cells += r.stats.counter(DcsCounter::RefinedLineCells).unwrap();
        scenes += 1;
    }
    assert!(scenes >= 8, "{scenes} scenes");
    assert!(cells > 100, "{cells} pairs decided by the line table");
}
