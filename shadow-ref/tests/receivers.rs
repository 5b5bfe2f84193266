//! Receivers handed in by the caller (`shadow_core::receivers`): a foreign G-buffer and bare
//! points snap back onto the surfaces the rasterizer found, the reference answers on them as on
//! the camera path, and bad input is a typed error naming the receiver.

use glam::Vec3;
use shadow_core::prelude::*;
use shadow_core::receivers::{GBuffer, ReceiverError, Snapping};
use shadow_core::view_samples::FREE_RECEIVER;
use shadow_io::SceneSetup;
use shadow_ref::Reference;

const SCENES: [&str; 4] = ["quad-over-plane", "bunny", "contact", "interior"];

fn scene_and_view(name: &str) -> (SceneSetup, ViewSamples) {
    let setup = shadow_scenes::builtin(name).unwrap();
    let view =
        ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 64, 48).unwrap();
    (setup, view)
}

/// A hash in `[-1, 1)` per index: a renderer's rounding, reproducibly.
fn jitter(i: usize) -> f32 {
    let h = (i as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    (h >> 40) as f32 / (1u64 << 23) as f32 - 1.0
}

/// `view`'s receivers as another renderer's float G-buffer: each position moved along its
/// normal by up to `1e-6` of the scene's size (a renderer's depth precision), no triangle ids.
fn foreign_gbuffer(setup: &SceneSetup, view: &ViewSamples) -> ViewSamples {
    let scale = 1e-6 * setup.scene.bounds().diagonal();
    let positions: Vec<Vec3> = (0..view.len())
        .map(|i| view.positions()[i] + view.geometric_normals()[i] * (scale * jitter(i)))
        .collect();
    let valid = view.valid_mask();
    let g = GBuffer {
        width: view.width(),
        height: view.height(),
        positions: &positions,
        geometric_normals: view.geometric_normals(),
        shading_normals: None,
        albedo: None,
        valid: Some(&valid),
        camera: view.raster_view().copied(),
    };
    ViewSamples::from_gbuffer(
        setup.scene.as_ref(),
        &g,
        Snapping::for_scene(setup.scene.as_ref()),
    )
    .unwrap()
}

/// The positions and geometric normals of `view`'s receivers `order`.
fn points_of(view: &ViewSamples, order: &[usize]) -> (Vec<Vec3>, Vec<Vec3>) {
    (
        order.iter().map(|&i| view.positions()[i]).collect(),
        order.iter().map(|&i| view.geometric_normals()[i]).collect(),
    )
}

fn values(v: &VisibilityImage) -> Vec<f32> {
    (0..(v.width() * v.height()) as usize)
        .map(|i| if v.is_valid(i) { v.value(i) } else { -1.0 })
        .collect()
}

#[test]
fn a_foreign_gbuffer_snaps_back_onto_the_rasterized_surfaces() {
    for name in SCENES {
        let (setup, view) = scene_and_view(name);
        let snapped = foreign_gbuffer(&setup, &view);
        assert_eq!(snapped.valid_mask(), view.valid_mask(), "{name}");
        assert_eq!(snapped.unmatched_receivers(), 0, "{name}");
        assert_eq!(snapped.eye(), view.eye(), "{name}");
        let diag = setup.scene.bounds().diagonal();
        let mut other_triangle = 0;
        for i in 0..view.len() {
            let (Some(a), Some(b)) = (view.get(i), snapped.get(i)) else {
                continue;
            };
            // Exactly on a shared edge either neighbour is the surface.
            other_triangle += usize::from(a.triangle != b.triangle);
            assert!(
                (a.position - b.position).length() <= 1e-5 * diag,
                "{name} pixel {i}: {} from {}",
                b.position,
                a.position
            );
            assert!(
                a.geometric_normal.dot(b.geometric_normal) > 0.0,
                "{name} pixel {i}"
            );
            assert!(
                (a.depth - b.depth).abs() <= 1e-4 * a.depth.max(1.0),
                "{name} pixel {i}"
            );
        }
        assert!(
            other_triangle * 200 <= view.valid_count(),
            "{name}: {other_triangle} receivers moved to another triangle"
        );
    }
}

#[test]
fn the_reference_on_a_foreign_gbuffer_matches_the_camera_path() {
    for name in SCENES {
        let (setup, view) = scene_and_view(name);
        let snapped = foreign_gbuffer(&setup, &view);
        let reference = Reference::stratified(64, 3).unwrap();
        let prepared = reference
            .prepare(setup.scene.clone(), setup.lights[0].clone())
            .unwrap();
        let own = values(
            &prepared
                .estimate(&view, Outputs::VISIBILITY)
                .unwrap()
                .visibility,
        );
        let foreign = values(
            &prepared
                .estimate(&snapped, Outputs::VISIBILITY)
                .unwrap()
                .visibility,
        );
        let differ = own.iter().zip(&foreign).filter(|(a, b)| a != b).count();
        let sq: f32 = own
            .iter()
            .zip(&foreign)
            .map(|(a, b)| (a - b) * (a - b))
            .sum();
        let rmse = (sq / view.valid_count() as f32).sqrt();
        assert!(rmse < 2e-3, "{name}: RMSE {rmse} ({differ} pixels differ)");
    }
}

#[test]
fn shuffled_points_without_a_camera_are_answered_in_the_callers_order() {
    for name in SCENES {
        let (setup, view) = scene_and_view(name);
        let mut receivers: Vec<usize> = (0..view.len()).filter(|&i| view.is_valid(i)).collect();
        // A fixed shuffle: the caller's order is not the image's.
        receivers.sort_by_key(|&i| (i as u64).wrapping_mul(0x2545_F491_4F6C_DD1D));
        let (positions, normals) = points_of(&view, &receivers);
        let snapping = Snapping::for_scene(setup.scene.as_ref());
        let points =
            ViewSamples::from_points(setup.scene.as_ref(), &positions, &normals, snapping).unwrap();
        assert_eq!(
            (points.width() as usize, points.height()),
            (receivers.len(), 1)
        );
        assert_eq!(points.eye(), None, "points have no camera");
        // One sample set for every receiver, so that a point and its pixel see the same light
        // samples whatever their place.
        let sampler = LightSampler::new(SamplingStrategy::Correlated, 64, 5).unwrap();
        let reference = Reference::same_samples(sampler)
            .prepare(setup.scene.clone(), setup.lights[0].clone())
            .unwrap();
        let own = values(
            &reference
                .estimate(&view, Outputs::VISIBILITY)
                .unwrap()
                .visibility,
        );
        let at_points = values(
            &reference
                .estimate(&points, Outputs::VISIBILITY)
                .unwrap()
                .visibility,
        );
        for (k, &i) in receivers.iter().enumerate() {
            assert_eq!(
                points.get(k).map(|s| s.triangle),
                view.get(i).map(|s| s.triangle),
                "{name}: point {k} (pixel {i})"
            );
            assert!(
                (at_points[k] - own[i]).abs() <= 1.0 / 64.0 + 1e-6,
                "{name}: point {k} has V {} where its pixel {i} has {}",
                at_points[k],
                own[i]
            );
        }
    }
}

#[test]
fn a_point_off_every_surface_is_offset_by_the_tolerance_and_counted() {
    let (setup, _) = scene_and_view("quad-over-plane");
    // Half a metre above the floor and below the occluder: no surface within 1 mm.
    let positions = [Vec3::new(2.5, 0.5, 2.5), Vec3::new(2.5, 0.0, 2.5)];
    let normals = [Vec3::Y, Vec3::Y];
    let snapping = Snapping { tolerance: 1e-3 };
    let points =
        ViewSamples::from_points(setup.scene.as_ref(), &positions, &normals, snapping).unwrap();
    assert_eq!(points.unmatched_receivers(), 1);
    let free = points.get(0).unwrap();
    assert_eq!(free.triangle, FREE_RECEIVER);
    assert_eq!(free.position, Vec3::new(2.5, 0.501, 2.5));
    assert_ne!(points.get(1).unwrap().triangle, FREE_RECEIVER);
    let est = Reference::stratified(64, 1)
        .unwrap()
        .prepare(setup.scene.clone(), setup.lights[0].clone())
        .unwrap()
        .estimate(
            &points,
            Outputs {
                per_sample: false,
                direct: true,
            },
        )
        .unwrap();
    let v = values(&est.visibility);
    assert!(v.iter().all(|x| (0.0..=1.0).contains(x)), "{v:?}");
    assert!(est.direct.unwrap().iter().all(|d| d.is_finite()));
}

#[test]
fn bad_receivers_are_typed_errors_naming_the_receiver() {
    let (setup, _) = scene_and_view("quad-over-plane");
    let scene = setup.scene.as_ref();
    let ok = Snapping::for_scene(scene);
    let p = [Vec3::ZERO, Vec3::X];
    let n = [Vec3::Y, Vec3::Y];
    let err = |positions: &[Vec3], normals: &[Vec3], snapping| {
        ViewSamples::from_points(scene, positions, normals, snapping).unwrap_err()
    };
    assert!(matches!(
        err(&p, &n[..1], ok),
        ReceiverError::Length {
            what: "geometric normals",
            expected: 2,
            got: 1
        }
    ));
    assert!(matches!(err(&[], &[], ok), ReceiverError::Empty(_)));
    assert_eq!(
        err(&[Vec3::ZERO, Vec3::NAN], &n, ok),
        ReceiverError::NonFinite {
            receiver: 1,
            what: "position"
        }
    );
    assert_eq!(
        err(&p, &[Vec3::Y, Vec3::ZERO], ok),
        ReceiverError::ZeroNormal {
            receiver: 1,
            what: "geometric normal"
        }
    );
    assert_eq!(
        err(&p, &[Vec3::INFINITY, Vec3::Y], ok),
        ReceiverError::NonFinite {
            receiver: 0,
            what: "geometric normal"
        }
    );
    for t in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        assert!(matches!(
            err(&p, &n, Snapping { tolerance: t }),
            ReceiverError::Tolerance(_)
        ));
    }
    let (_, view) = scene_and_view("quad-over-plane");
    let valid = vec![false; view.len()];
    let mut g = GBuffer {
        width: view.width(),
        height: view.height(),
        positions: view.positions(),
        geometric_normals: view.geometric_normals(),
        shading_normals: None,
        albedo: None,
        valid: Some(&valid),
        camera: None,
    };
    assert!(matches!(
        ViewSamples::from_gbuffer(scene, &g, ok),
        Err(ReceiverError::Empty(_))
    ));
    g.valid = None;
    g.camera = Some(shadow_core::raster::RasterView {
        width: 3,
        ..*view.raster_view().unwrap()
    });
    assert!(matches!(
        ViewSamples::from_gbuffer(scene, &g, ok),
        Err(ReceiverError::CameraSize {
            camera_width: 3,
            ..
        })
    ));
    // Background pixels of a G-buffer are not receivers: their zero normals are not checked.
    g.camera = None;
    let mask = view.valid_mask();
    g.valid = Some(&mask);
    assert!(ViewSamples::from_gbuffer(scene, &g, ok).is_ok());
}

/// Screen-space selection needs a camera and refuses points with a typed reason; DCS counts
/// each point's integration constant along its own segment (section 4.1) and, on shuffled
/// points, gives per-sample visibility and direct light bit for bit as the reference on the
/// same light samples.
#[test]
fn points_are_refused_only_by_screen_space_selection_and_dcs_answers_them_exactly() {
    let (setup, view) = scene_and_view("bunny");
    let mut receivers: Vec<usize> = (0..view.len()).filter(|&i| view.is_valid(i)).collect();
    receivers.sort_by_key(|&i| (i as u64).wrapping_mul(0x2545_F491_4F6C_DD1D));
    let (positions, normals) = points_of(&view, &receivers);
    let points = ViewSamples::from_points(
        setup.scene.as_ref(),
        &positions,
        &normals,
        Snapping::for_scene(setup.scene.as_ref()),
    )
    .unwrap();
    let prepare = |name: &str| {
        let technique = (shadow_presets::preset(name).unwrap().make)(1);
        let prepared = technique
            .prepare(setup.scene.clone(), setup.lights[0].clone())
            .unwrap();
        (technique, prepared)
    };
    let (_, ssm) = prepare("ssm-adaptive");
    let e = ssm.estimate(&points, Outputs::VISIBILITY).unwrap_err();
    assert!(
        matches!(e.unsupported_reason(), Some(UnsupportedReason::View(_))),
        "ssm-adaptive: {e}"
    );
    let (dcs, dcs_prepared) = prepare("dcs-64");
    let both = Outputs {
        per_sample: true,
        direct: true,
    };
    let d = dcs_prepared.estimate(&points, both).unwrap();
    let reference = Reference::same_samples(dcs.light_sampler().unwrap().clone())
        .prepare(setup.scene.clone(), setup.lights[0].clone())
        .unwrap()
        .estimate(&points, both)
        .unwrap();
    let (pd, pr) = (
        d.visibility.per_sample().unwrap(),
        reference.visibility.per_sample().unwrap(),
    );
    let n = dcs.light_sampler().unwrap().count();
    let mut disagree = 0u64;
    for i in 0..points.len() {
        for k in 0..n {
            disagree += u64::from(pd.visible(i, k) != pr.visible(i, k));
        }
    }
    let total = points.valid_count() as u64 * u64::from(n);
    assert!(
        disagree * 10_000 <= total,
        "dcs-64 on points: {disagree} of {total} samples differ from the reference"
    );
    let (dd, dr) = (d.direct.unwrap(), reference.direct.unwrap());
    let off = dd
        .iter()
        .zip(&dr)
        .filter(|(a, b)| (**a - **b).abs().max_element() > 1e-4 * (1.0 + b.max_element()))
        .count();
    assert!(
        off * 1000 <= points.len(),
        "{off} receivers' direct light differ"
    );
    assert!(
        d.stats
            .counter(shadow_dcs::DcsCounter::ReceiverConstantSegments)
            > Some(0)
    );
}
