//! The shadow map against ray casting and closed forms; PCSS against the reference.

use glam::Vec3;
use shadow_core::light::{Radiance, RectLight};
use shadow_core::prelude::*;
use shadow_metrics::compare;
use shadow_ssm::light_frame::LightFrame;
use shadow_ssm::shadow_map::ShadowMap;
use shadow_ssm::{Filter, ShadowMapFilter};

fn light() -> RectLight {
    RectLight::facing(
        Vec3::new(0.0, 4.0, 0.0),
        Vec3::NEG_Y,
        1.0,
        1.0,
        Radiance::constant(Vec3::ONE).unwrap(),
    )
    .unwrap()
}

#[test]
fn fraction_of_the_light_above_a_plane_is_exact() {
    let frame = LightFrame::new(&light(), "t").unwrap();
    assert_eq!(frame.width, 1.0);
    // A vertical plane through the light's centre halves it; planes beside it keep all or none.
    let c = Vec3::new(0.0, 4.0, 0.0);
    assert!((frame.fraction_above(c, Vec3::X) - 0.5).abs() < 1e-6);
    assert!((frame.fraction_above(c + Vec3::X * 0.25, Vec3::X) - 0.25).abs() < 1e-6);
    assert_eq!(frame.fraction_above(Vec3::ZERO, Vec3::Y), 1.0);
    assert_eq!(frame.fraction_above(Vec3::new(0.0, 5.0, 0.0), Vec3::Y), 0.0);
    // A diagonal plane through a corner cuts off a triangle of an eighth of the area.
    let corner = Vec3::new(0.5, 4.0, 0.5);
    let n = Vec3::new(1.0, 0.0, 1.0).normalize();
    let f = frame.fraction_above(corner - n * (0.5f32.sqrt() * 0.5), n);
    assert!((f - 0.125).abs() < 1e-5, "{f}");
}

#[test]
fn shadow_map_depths_equal_the_distance_to_the_light_plane_and_eq1_holds() {
    // A floor at y = 0 and a square occluder at y = 1.5 under a light at y = 4.
    let mut b = SceneBuilder::new();
    let f = shadow_scenes::procedural::floor(6.0, 0.0);
    b.push_mesh(MeshDesc::new(f.0, f.1)).unwrap();
    let q = shadow_scenes::procedural::quad(Vec3::new(0.0, 1.5, 0.0), Vec3::X * 0.4, Vec3::Z * 0.4);
    b.push_mesh(MeshDesc::new(q.0, q.1)).unwrap();
    let scene = b.build().unwrap();
    let frame = LightFrame::new(&light(), "t").unwrap();
    let receivers: Vec<Vec3> = (-10..=10)
        .flat_map(|i| (-10..=10).map(move |j| Vec3::new(i as f32 * 0.2, 0.0, j as f32 * 0.2)))
        .collect();
    let sm = ShadowMap::render(&scene, &frame, &receivers, 256, 2)
        .unwrap()
        .unwrap();
    // Two layers: the occluder, then the floor, straight below the light.
    let (x0, y0, _) = sm.project(Vec3::ZERO).unwrap();
    assert!((sm.layer_at(x0 as i64, y0 as i64, 0) - 2.5).abs() < 1e-4);
    assert!((sm.layer_at(x0 as i64, y0 as i64, 1) - 4.0).abs() < 1e-4);
    // Straight below the light: the occluder at depth 2.5; far out: the floor at depth 4.
    let (x, y, z) = sm.project(Vec3::new(0.0, 0.0, 0.0)).unwrap();
    assert!((z - 4.0).abs() < 1e-4);
    assert!((sm.at(x as i64, y as i64) - 2.5).abs() < 1e-4);
    let (x, y, _) = sm.project(Vec3::new(1.8, 0.0, 1.8)).unwrap();
    assert!((sm.at(x as i64, y as i64) - 4.0).abs() < 1e-3);
    assert!((sm.min_depth - 2.5).abs() < 1e-4);
    // GBP07 eq. 1 by hand: a 1-wide light, occluders at depth 2, receiver at depth 4:
    // w_l (1/2 - 1/4) = 0.25 units at unit depth.
    let w = sm.kernel_width(1.0, 2.0, 4.0);
    assert!((w - 0.25 * sm.texels_per_unit).abs() < 1e-9);
    // Receivers are in the frustum.
    for r in &receivers {
        let (x, y, _) = sm.project(*r).unwrap();
        assert!(x >= 0.0 && y >= 0.0 && x < 256.0 && y < 256.0);
    }
}

#[test]
fn pcss_is_closer_to_the_reference_than_pcf_under_a_planar_occluder() {
    let setup = shadow_scenes::builtin("quad-over-plane").unwrap();
    let view =
        ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 64, 48).unwrap();
    let run = |t: &dyn ShadowTechnique| {
        let t_prepared = t
            .prepare(setup.scene.clone(), setup.lights[0].clone())
            .unwrap();
        t_prepared
            .estimate(&view, Outputs::VISIBILITY)
            .unwrap()
            .visibility
    };
    let truth = run(&mut shadow_ref::Reference::stratified(512, 3).unwrap());
    let pcss = compare(
        &run(&mut ShadowMapFilter::new("pcss", Filter::Pcss, 512)),
        &truth,
    )
    .unwrap();
    let pcf = compare(
        &run(&mut ShadowMapFilter::new(
            "pcf",
            Filter::Pcf { radius: 2 },
            512,
        )),
        &truth,
    )
    .unwrap();
    assert!(pcss.rmse < 0.02, "{pcss:?}");
    assert!(pcf.rmse > 3.0 * pcss.rmse, "{pcf:?} {pcss:?}");
    // Sphere lights are refused with the reason.
    let sphere = shadow_scenes::builtin("sphere-light").unwrap();
    let t = ShadowMapFilter::new("pcss", Filter::Pcss, 64);
    let err = t
        .prepare(sphere.scene.clone(), sphere.lights[0].clone())
        .unwrap_err();
    assert!(matches!(err, TechniqueError::Unsupported { .. }), "{err}");
}

/// Issue 51, item 6: when the view sees a small area, the map's margin was capped at the
/// receivers' own extent, so an occluder close to a wide light but beside the receivers fell
/// outside the map: every SSM preset gave V of about 0.98 where the reference gives about 0.4.
/// The margin covers every point that can stand between a receiver and the light.
#[test]
fn occluders_beside_a_small_view_stay_in_the_map() {
    let mut b = SceneBuilder::new();
    let f = shadow_scenes::procedural::floor(20.0, 0.0);
    b.push_mesh(MeshDesc::new(f.0, f.1)).unwrap();
    // A plate just under a wide light, beside the small patch the camera sees.
    let plate = shadow_scenes::procedural::quad(
        Vec3::new(0.6, 2.8, 0.0),
        Vec3::new(0.5, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.8),
    );
    b.push_mesh(MeshDesc::new(plate.0, plate.1)).unwrap();
    let scene: SceneRef = std::sync::Arc::new(b.build().unwrap());
    let light: Light = std::sync::Arc::new(
        RectLight::facing(
            Vec3::new(0.0, 3.0, 0.0),
            Vec3::NEG_Y,
            2.0,
            2.0,
            Radiance::constant(Vec3::ONE).unwrap(),
        )
        .unwrap(),
    );
    // A narrow view of a patch of floor about 0.2 across around the origin.
    let camera = Camera::look_at(Vec3::new(0.0, 1.0, 0.5), Vec3::ZERO, Vec3::Y, 0.15).unwrap();
    let view = ViewSamples::render(scene.as_ref(), &camera, 16, 16).unwrap();
    let truth = shadow_ref::Reference::stratified(256, 3)
        .unwrap()
        .prepare(scene.clone(), light.clone())
        .unwrap()
        .estimate(&view, Outputs::VISIBILITY)
        .unwrap()
        .visibility;
    let mean = |v: &VisibilityImage| {
        let (mut s, mut n) = (0.0, 0);
        for i in 0..v.len() {
            if v.is_valid(i) {
                s += v.value(i) as f64;
                n += 1;
            }
        }
        s / n as f64
    };
    let t = mean(&truth);
    assert!(t < 0.9, "the plate must shadow the patch: mean V {t}");
    // The presets that integrate over the light (PCF and PCSS filter around the light centre's
    // projection and are held to their own budgets elsewhere).
    for p in shadow_presets::ssm::presets()
        .into_iter()
        .filter(|p| p.name.starts_with("ssm-"))
    {
        let tech = (p.make)(1);
        let est = tech
            .prepare(scene.clone(), light.clone())
            .unwrap()
            .estimate(&view, Outputs::VISIBILITY)
            .unwrap()
            .visibility;
        let m = mean(&est);
        assert!((m - t).abs() < 0.1, "{}: mean V {m} against {t}", p.name);
    }
}

/// Issue 51: a light recessed in a fixture at the ceiling of a room. The walls rise to 9 cm
/// below the light and the fixture's walls cross its plane, so the receivers and their
/// occluders reach 89 degrees off the light's axis; one light-centre map gave RMSE 0.15 to 0.53
/// there. Every shadow-map filter refuses it with the reason instead.
#[test]
fn a_room_around_a_recessed_light_is_refused_not_drawn_wrong() {
    let setup = shadow_scenes::builtin("cornell-box").unwrap();
    let view =
        ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 32, 24).unwrap();
    for filter in [Filter::Pcf { radius: 2 }, Filter::Pcss] {
        let t = ShadowMapFilter::new("t", filter, 256);
        let p = t
            .prepare(setup.scene.clone(), setup.lights[0].clone())
            .unwrap();
        let err = p.estimate(&view, Outputs::VISIBILITY).unwrap_err();
        let reason = err.unsupported_reason().expect("a refusal").to_string();
        assert!(reason.contains("degrees off the light's axis"), "{reason}");
    }
    // The same filters still draw the built-in scenes (all within 80 degrees).
    let setup = shadow_scenes::builtin("large-light-close").unwrap();
    let view =
        ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 32, 24).unwrap();
    let t = ShadowMapFilter::new("t", Filter::Pcss, 256);
    let p = t
        .prepare(setup.scene.clone(), setup.lights[0].clone())
        .unwrap();
    assert!(p.estimate(&view, Outputs::VISIBILITY).is_ok());
}
