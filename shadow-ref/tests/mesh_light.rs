//! The reference under a mesh light (issue 52) against the same scene lit by the mesh's faces
//! as separate rectangle lights: with each triangle emitting from its front only, the mesh
//! light's visibility is the area-weighted mean of its faces' (a face's receivers behind it
//! get nothing from it, as behind any planar light).

use std::sync::Arc;

use shadow_core::light::LightKind;
use shadow_core::prelude::*;
use shadow_io::SceneSetup;
use shadow_ref::Reference;
use shadow_scenes::{builtin, folded_lamp};

fn visibility(setup: &SceneSetup, light: Light, view: &ViewSamples, seed: u64) -> VisibilityImage {
    Reference::stratified(1024, seed)
        .unwrap()
        .prepare_reference(setup.scene.clone(), light)
        .unwrap()
        .estimate(view, Outputs::VISIBILITY)
        .unwrap()
        .visibility
}

#[test]
fn a_mesh_light_is_the_area_weighted_mean_of_its_one_sided_faces() {
    let setup = builtin("mesh-light").unwrap();
    assert_eq!(setup.lights[0].kind(), LightKind::Mesh);
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera.unwrap(), 64, 48).unwrap();
    let mesh = visibility(&setup, setup.lights[0].clone(), &view, 3);
    let [left, right] = folded_lamp::faces(Radiance::Constant(glam::Vec3::ONE)).unwrap();
    assert!((left.area() - right.area()).abs() < 1e-6);
    let vl = visibility(&setup, Arc::new(left), &view, 5);
    let vr = visibility(&setup, Arc::new(right), &view, 7);
    let (mut sq, mut max, mut n) = (0.0f64, 0.0f64, 0usize);
    let (mut one_face, mut both) = (0, 0);
    for i in 0..view.len() {
        if view.get(i).is_none() {
            continue;
        }
        let expected = 0.5 * (vl.value(i) + vr.value(i));
        let e = f64::from(mesh.value(i) - expected);
        sq += e * e;
        max = max.max(e.abs());
        n += 1;
        let (l, r) = (vl.value(i) > 0.0, vr.value(i) > 0.0);
        one_face += usize::from(l != r);
        both += usize::from(l && r);
    }
    let rmse = (sq / n as f64).sqrt();
    // The view holds receivers that see one face only and receivers that see both.
    assert!(one_face > 100 && both > 100, "{one_face} {both}");
    assert!(rmse < 0.006, "rmse {rmse}");
    assert!(max < 0.08, "max {max}");
}

/// The hard-shadow mode (the lamp's centre as a point) and few samples run on a mesh light.
#[test]
fn hard_mode_and_same_samples_take_a_mesh_light() {
    let setup = builtin("mesh-light").unwrap();
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera.unwrap(), 32, 24).unwrap();
    for r in [Reference::hard(), Reference::stratified(16, 1).unwrap()] {
        let v = r
            .prepare_reference(setup.scene.clone(), setup.lights[0].clone())
            .unwrap()
            .estimate(&view, Outputs::VISIBILITY)
            .unwrap()
            .visibility;
        let lit = (0..view.len()).filter(|&i| v.value(i) > 0.0).count();
        assert!(lit > view.valid_count() / 2, "{lit}");
        assert!((0..view.len()).all(|i| (0.0..=1.0).contains(&v.value(i))));
    }
}
