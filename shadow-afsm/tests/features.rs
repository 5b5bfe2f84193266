//! Temporal jittering, splitting under a memory limit, the plane table and textured lights,
//! each against the reference.

use std::sync::Arc;

use glam::Vec3;
use shadow_afsm::statistics::{AfsmCounter, AfsmPhase};
use shadow_afsm::{Afsm, accumulate};
use shadow_core::gpu::context_for_test;
use shadow_core::prelude::*;
use shadow_io::SceneSetup;
use shadow_metrics::compare;
use shadow_ref::Reference;
use shadow_scenes::builtin;

fn setup_view(name: &str, w: u32, h: u32) -> (SceneSetup, ViewSamples) {
    let setup = builtin(name).unwrap();
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), w, h).unwrap();
    (setup, view)
}

/// A square light of side `side` at height `height`, facing down.
fn square_light(side: f32, height: f32) -> Light {
    let radiance = Radiance::constant(glam::Vec3::ONE).unwrap();
    Arc::new(
        RectLight::facing(
            glam::Vec3::Y * height,
            glam::Vec3::NEG_Y,
            side,
            side,
            radiance,
        )
        .unwrap(),
    )
}

/// Meshes over an 8 x 8 floor, seen from above at `w` x `h`.
fn floor_scene(meshes: Vec<MeshDesc>, w: u32, h: u32) -> (SceneRef, ViewSamples) {
    use glam::Vec3;
    let mut b = SceneBuilder::new();
    let f = shadow_scenes::procedural::floor(8.0, 0.0);
    b.push_mesh(MeshDesc::new(f.0, f.1)).unwrap();
    for m in meshes {
        b.push_mesh(m).unwrap();
    }
    let scene: SceneRef = Arc::new(b.build().unwrap());
    let cam = Camera::look_at(Vec3::new(0.0, 3.5, 3.0), Vec3::ZERO, Vec3::Y, 0.9).unwrap();
    let view = ViewSamples::render(scene.as_ref(), &cam, w, h).unwrap();
    (scene, view)
}

fn stratified_reference(setup: &SceneSetup, view: &ViewSamples) -> VisibilityImage {
    let r = Reference::stratified(1024, 99).unwrap();
    let r_prepared = r
        .prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
        .unwrap();
    r_prepared
        .estimate(view, Outputs::VISIBILITY)
        .unwrap()
        .visibility
}

/// Fig. 7: accumulating frames of rotated sample sets converges toward the true visibility.
#[test]
fn temporal_jittering_converges() {
    if context_for_test("temporal_jittering_converges").is_none() {
        return;
    }
    let (setup, view) = setup_view("quad-over-plane", 48, 36);
    let truth = stratified_reference(&setup, &view);
    let afsm = Afsm::new(16, SamplingStrategy::Correlated, 4).unwrap();
    let mut afsm = afsm
        .prepare_afsm(setup.scene.clone(), Arc::clone(&setup.lights[0]))
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
        let a_prepared = a
            .prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
            .unwrap();
        a_prepared.estimate(&view, Outputs::VISIBILITY).unwrap()
    };
    let whole = run(None);
    let split = run(Some(16 * 1024));
    assert!(split.stats.counter(AfsmCounter::ReceiverBatches).unwrap() > 1);
    assert!(split.stats.counter(AfsmCounter::CasterBatches).unwrap() > 1);
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
        let a_prepared = a
            .prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
            .unwrap();
        a_prepared
            .estimate(&view, Outputs::VISIBILITY)
            .unwrap()
            .visibility
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
    let a = Afsm::new(64, SamplingStrategy::Interleaved { tile: 4 }, 6).unwrap();
    let a_prepared = a
        .prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
        .unwrap();
    let e = a_prepared.estimate(&view, Outputs::VISIBILITY).unwrap();
    assert!(e.visibility.is_rgb());
    let r = Reference::same_samples(a.light_sampler().unwrap().clone());
    let r_prepared = r
        .prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
        .unwrap();
    let m = compare(
        &e.visibility,
        &r_prepared
            .estimate(&view, Outputs::VISIBILITY)
            .unwrap()
            .visibility,
    )
    .unwrap();
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

/// Section 4.3's silhouette stencil: under a finely tessellated closed sphere lit by a small
/// light, view samples in the umbra are off every silhouette edge's influence region, so one
/// sample per pair stands for all; the bits equal those of the full per-sample test and the
/// per-sample work falls. Built-in scenes' large lights leave no texel off the stencil, which
/// is why the stencil is opt-in (`docs/benchmarks.md`).
#[test]
fn silhouette_stencil_changes_no_bit_and_skips_umbra_work() {
    if context_for_test("silhouette_stencil_changes_no_bit_and_skips_umbra_work").is_none() {
        return;
    }
    let s = shadow_scenes::procedural::uv_sphere(glam::Vec3::new(0.0, 1.2, 0.0), 0.7, 24, 48);
    let (scene, view) = floor_scene(vec![MeshDesc::new(s.0, s.1)], 48, 36);
    let light = square_light(0.3, 4.0);
    assert!(scene.topology().components().iter().any(|c| c.closed));
    let run = |stencil: bool| {
        let mut a = Afsm::new(64, SamplingStrategy::Interleaved { tile: 2 }, 4).unwrap();
        if stencil {
            a = a.with_silhouette_stencil();
        }
        let a_prepared = a.prepare(scene.clone(), Arc::clone(&light)).unwrap();
        let est = a_prepared.estimate(&view, Outputs::VISIBILITY).unwrap();
        let r = Reference::same_samples(a.light_sampler().unwrap().clone());
        let r_prepared = r.prepare(scene.clone(), Arc::clone(&light)).unwrap();
        let truth = r_prepared
            .estimate(&view, Outputs::VISIBILITY)
            .unwrap()
            .visibility;
        (est, truth)
    };
    let (plain, truth) = run(false);
    let (restricted, _) = run(true);
    let m = compare(&restricted.visibility, &plain.visibility).unwrap();
    let t = compare(&restricted.visibility, &truth).unwrap();
    let count = |e: &Estimate, k: AfsmCounter| e.stats.counter(k).expect("AFSM counts it");
    println!(
        "silhouette edges {} of the sphere's; per-sample pairs {} -> {}, one-sample pairs {}; \
         agreement with the plain run {:.6}, with the reference {:.6}",
        count(&restricted, AfsmCounter::SilhouetteEdges),
        count(&plain, AfsmCounter::PairsPerSample),
        count(&restricted, AfsmCounter::PairsPerSample),
        count(&restricted, AfsmCounter::PairsOneSample),
        m.sample_agreement.unwrap(),
        t.sample_agreement.unwrap(),
    );
    assert_eq!(count(&plain, AfsmCounter::PairsOneSample), 0);
    assert!(count(&restricted, AfsmCounter::PairsOneSample) > 0);
    // Measured: 1904 -> 1214 per-sample pairs (690 one-sample).
    assert!(
        count(&restricted, AfsmCounter::PairsPerSample) * 4
            < count(&plain, AfsmCounter::PairsPerSample) * 3,
        "the stencil should cut the per-sample work by a quarter or more here"
    );
    assert!(m.sample_agreement.unwrap() >= 0.9999, "{m:?}");
    assert!(t.sample_agreement.unwrap() >= 0.999, "{t:?}");
}

/// Semi-opaque casters (section 6's transparency, kept exactly per sample): with the silhouette
/// stencil on (edges between different opacities count as silhouettes) the values equal the
/// same-samples reference's transmittance products.
#[test]
fn semi_opaque_transmittance_matches_the_reference_with_the_stencil() {
    if context_for_test("semi_opaque_transmittance_matches_the_reference_with_the_stencil")
        .is_none()
    {
        return;
    }
    let (setup, view) = setup_view("semi-opaque", 48, 36);
    let a = Afsm::new(64, SamplingStrategy::Interleaved { tile: 2 }, 6)
        .unwrap()
        .with_silhouette_stencil();
    let a_prepared = a
        .prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
        .unwrap();
    let est = a_prepared.estimate(&view, Outputs::VISIBILITY).unwrap();
    let r = Reference::same_samples(a.light_sampler().unwrap().clone());
    let r_prepared = r
        .prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
        .unwrap();
    let m = compare(
        &est.visibility,
        &r_prepared
            .estimate(&view, Outputs::VISIBILITY)
            .unwrap()
            .visibility,
    )
    .unwrap();
    println!("{m:?}");
    assert!(m.rmse < 1e-4 && m.max_abs < 1e-3, "{m:?}");
    assert!(m.sample_agreement.unwrap() >= 0.999, "{m:?}");
}

/// 298 stacked panels of opacity `1 - 18 * 2^-24` add up an optical depth of 298 x 13.745 =
/// 4096.06 nats, just beyond the 4096 nats a 32-bit sum of 2^-20-nat units holds: wrapping
/// would leave 0.06 nats and light the umbra at 94%. The sums saturate instead (transmittance
/// 0, as the reference's underflowing product).
#[test]
fn optical_depth_sums_saturate_instead_of_wrapping() {
    if context_for_test("optical_depth_sums_saturate_instead_of_wrapping").is_none() {
        return;
    }
    let opacity = 1.0 - 18.0 / 16_777_216.0;
    let panels = (0..298)
        .map(|k| {
            let q = shadow_scenes::procedural::quad(
                glam::Vec3::new(0.0, 1.0 + k as f32 * 0.002, 0.0),
                glam::Vec3::X * 0.6,
                glam::Vec3::Z * 0.6,
            );
            MeshDesc::new(q.0, q.1).with_opacity(opacity)
        })
        .collect();
    let (scene, view) = floor_scene(panels, 32, 24);
    let light = square_light(0.5, 3.0);
    let a = Afsm::new(32, SamplingStrategy::Correlated, 2).unwrap();
    let a_prepared = a.prepare(scene.clone(), Arc::clone(&light)).unwrap();
    let est = a_prepared.estimate(&view, Outputs::VISIBILITY).unwrap();
    let r = Reference::same_samples(a.light_sampler().unwrap().clone());
    let r_prepared = r.prepare(scene, light).unwrap();
    let truth = r_prepared
        .estimate(&view, Outputs::VISIBILITY)
        .unwrap()
        .visibility;
    let m = compare(&est.visibility, &truth).unwrap();
    let umbra = (0..view.len())
        .filter(|&i| view.is_valid(i) && truth.value(i) == 0.0)
        .count();
    println!("umbra pixels {umbra}, {m:?}");
    assert!(umbra > 20);
    assert!(m.rmse < 1e-3 && m.max_abs < 1e-2, "{m:?}");
}

/// A polygon light (a tilted hexagon, no built-in scene has one) over a sphere: the bounding
/// outline of section 4.1 and the sample grid on the polygon's plane, against the
/// same-samples reference.
#[test]
fn polygon_light_agrees_with_the_same_samples_reference() {
    if context_for_test("polygon_light_agrees_with_the_same_samples_reference").is_none() {
        return;
    }
    use glam::Vec3;
    let s = shadow_scenes::procedural::uv_sphere(Vec3::new(0.2, 1.0, 0.0), 0.5, 12, 24);
    let (scene, view) = floor_scene(vec![MeshDesc::new(s.0, s.1)], 48, 36);
    let outline: Vec<Vec3> = (0..6)
        .map(|k| {
            let a = k as f32 * std::f32::consts::TAU / 6.0;
            Vec3::new(0.8 * a.cos(), 2.6 + 0.2 * a.cos(), 0.8 * a.sin())
        })
        .rev()
        .collect();
    let light: Light =
        Arc::new(PolygonLight::new(outline, Radiance::constant(Vec3::ONE).unwrap()).unwrap());
    let a = Afsm::new(256, SamplingStrategy::Interleaved { tile: 2 }, 9).unwrap();
    let a_prepared = a.prepare(scene.clone(), Arc::clone(&light)).unwrap();
    let est = a_prepared.estimate(&view, Outputs::VISIBILITY).unwrap();
    let r = Reference::same_samples(a.light_sampler().unwrap().clone());
    let r_prepared = r.prepare(scene, light).unwrap();
    let m = compare(
        &est.visibility,
        &r_prepared
            .estimate(&view, Outputs::VISIBILITY)
            .unwrap()
            .visibility,
    )
    .unwrap();
    println!("{m:?}");
    assert!(m.sample_agreement.unwrap() >= 0.999, "{m:?}");
    assert!(m.rmse < 0.004, "{m:?}");
}

/// Issue 51, item 7: receivers inside a closed mesh (a camera in a closed box, the light
/// outside above it) got V = 1 from `afsm-hard` and `afsm-128`, because a closed mesh keeps
/// only its light back-facing triangles and the segment from an inside receiver leaves through
/// a front-facing one; the reference gives 0. A closed mesh around the eye keeps every face.
#[test]
fn receivers_inside_a_closed_mesh_are_shadowed() {
    if context_for_test("receivers_inside_a_closed_mesh_are_shadowed").is_none() {
        return;
    }
    let mut b = SceneBuilder::new();
    let f = shadow_scenes::procedural::floor(1.6, 0.05);
    b.push_mesh(MeshDesc::new(f.0, f.1)).unwrap();
    let shell = shadow_scenes::procedural::cuboid(
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, 2.0, 1.0),
        false,
    );
    b.push_mesh(MeshDesc::new(shell.0, shell.1)).unwrap();
    let scene: SceneRef = Arc::new(b.build().unwrap());
    assert!(scene.topology().components().iter().any(|c| c.closed));
    let light: Light = Arc::new(
        RectLight::facing(
            Vec3::new(0.0, 3.0, 0.0),
            Vec3::NEG_Y,
            0.8,
            0.8,
            Radiance::constant(Vec3::ONE).unwrap(),
        )
        .unwrap(),
    );
    let camera = Camera::look_at(Vec3::new(0.0, 1.5, 0.8), Vec3::ZERO, Vec3::Y, 1.2).unwrap();
    let view = ViewSamples::render(scene.as_ref(), &camera, 32, 24).unwrap();
    for afsm in [
        Afsm::hard(),
        Afsm::new(128, SamplingStrategy::Interleaved { tile: 4 }, 1).unwrap(),
    ] {
        let est = afsm
            .prepare(scene.clone(), light.clone())
            .unwrap()
            .estimate(&view, Outputs::VISIBILITY)
            .unwrap();
        let lit = (0..view.len())
            .filter(|&i| view.is_valid(i) && est.visibility.value(i) > 0.01)
            .count();
        assert_eq!(
            lit,
            0,
            "{}: {lit} pixels see the light through the box",
            afsm.name()
        );
    }
}

/// Where the adapter has timestamp queries (lavapipe has), each GPU phase's device time is a
/// counter beside its wall-clock time, and never longer than it: the device time leaves out
/// submission, waiting and readbacks.
#[test]
fn device_times_from_timestamp_queries_fit_inside_their_phases() {
    let Some(gpu) = context_for_test("device_times_from_timestamp_queries_fit_inside_their_phases")
    else {
        return;
    };
    if !gpu.has_timestamps() {
        eprintln!(
            "SKIPPED: adapter {} has no timestamp queries",
            gpu.describe()
        );
        return;
    }
    let (setup, view) = setup_view("contact", 48, 36);
    let a = Afsm::new(32, SamplingStrategy::Interleaved { tile: 2 }, 1).unwrap();
    let est = a
        .prepare(setup.scene.clone(), Arc::clone(&setup.lights[0]))
        .unwrap()
        .estimate(&view, Outputs::VISIBILITY)
        .unwrap();
    for phase in [
        AfsmPhase::GpuLists,
        AfsmPhase::GpuInfluence,
        AfsmPhase::GpuTiles,
        AfsmPhase::GpuOcclude,
        AfsmPhase::GpuResolve,
    ] {
        let wall = est.stats.phase_seconds(phase).expect("phase ran");
        let device = est
            .stats
            .device_seconds(phase)
            .unwrap_or_else(|| panic!("{phase:?}: no device time"));
        println!("{phase:?}: wall {wall:.5} s, device {device:.5} s");
        assert!(device > 0.0, "{phase:?}");
        assert!(device <= wall * 1.01 + 1e-4, "{phase:?}");
    }
}
