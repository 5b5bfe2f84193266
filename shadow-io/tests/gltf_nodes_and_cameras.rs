//! Legal glTF node hierarchies and cameras the loader once refused or changed silently
//! (issue 69 items 3, 5, 8 and 9): a file without scenes whose nodes form a hierarchy, a node
//! scaled to nothing, a camera with a mirroring scale and a camera's far plane.

mod common;

use common::{Writer, load, square};
use glam::Vec3;
use serde_json::{Value, json};
use shadow_core::prelude::*;

/// A grey floor (mesh 0) and a small grey square (mesh 1).
fn writer() -> Writer {
    let mut w = Writer::default();
    let grey =
        w.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0]}}));
    let (fp, fi) = square(3.0);
    let up: Vec<u32> = fi.chunks(3).flat_map(|c| [c[0], c[2], c[1]]).collect();
    w.mesh("floor", &fp, &up, None, grey);
    let (sp, si) = square(0.5);
    w.mesh("box-top", &sp, &si, None, grey);
    w
}

fn without_scenes(mut doc: Value) -> Value {
    let o = doc.as_object_mut().unwrap();
    o.remove("scene");
    o.remove("scenes");
    doc
}

#[test]
fn a_file_without_scenes_keeps_its_node_hierarchy() {
    let w = writer();
    // Node 0 holds node 1 as its child, translated; node 1 holds the square.
    let nodes = json!([
        {"mesh": 0, "children": [1], "translation": [0.0, 1.0, 0.0]},
        {"mesh": 1, "translation": [0.0, 0.5, 0.0]},
    ]);
    let setup = load(&without_scenes(w.document(nodes, json!([])))).unwrap();
    assert_eq!(setup.scene.triangle_count(), 4);
    // The child's world height is its parent's plus its own.
    assert_eq!(setup.scene.bounds().max.y, 1.5);
    // A true cycle is still refused, by name.
    let cycle = json!([{"mesh": 0, "children": [1]}, {"mesh": 1, "children": [0]}]);
    let err = load(&without_scenes(w.document(cycle, json!([])))).unwrap_err();
    assert!(err.to_string().contains("cycle"), "{err}");
}

#[test]
fn a_node_scaled_to_nothing_is_hidden_with_a_note() {
    let w = writer();
    let nodes = json!([
        {"mesh": 0},
        {"mesh": 1, "translation": [0.0, 1.0, 0.0], "scale": [0.0, 0.0, 0.0]},
    ]);
    let setup = load(&w.document(nodes, json!([]))).unwrap();
    assert_eq!(setup.scene.triangle_count(), 2, "only the floor");
    assert!(
        setup
            .warnings
            .iter()
            .any(|n| n.contains("`box-top`") && n.contains("node 1") && n.contains("zero scale")),
        "{:?}",
        setup.warnings
    );
}

#[test]
fn a_camera_with_a_mirroring_scale_keeps_its_up() {
    let w = writer();
    let nodes = json!([
        {"mesh": 0},
        {"camera": 0, "translation": [0.0, 2.0, 6.0], "scale": [-1.0, 1.0, 1.0]},
    ]);
    let cameras = json!([{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.05}}]);
    let setup = load(&w.document(nodes, cameras)).unwrap();
    let m = setup.camera.unwrap().world_from_camera().matrix3;
    assert_eq!(
        Vec3::from(m.y_axis),
        Vec3::Y,
        "the image is the right way up"
    );
    assert_eq!(Vec3::from(m.z_axis), Vec3::Z);
    assert!(
        setup.warnings.iter().any(|n| n.contains("mirroring scale")),
        "{:?}",
        setup.warnings
    );
    // Rendered, the floor (below the camera) fills the bottom rows, not the top ones.
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera.unwrap(), 16, 12).unwrap();
    assert!(view.get_at(8, 11).is_some() && view.get_at(8, 0).is_none());
}

#[test]
fn a_cameras_far_plane_clips_what_lies_beyond_it() {
    let w = writer();
    let nodes = json!([{"mesh": 0}, {"camera": 0, "translation": [0.0, 1.0, 3.5]}]);
    let with_far =
        json!([{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.05, "zfar": 4.0}}]);
    let setup = load(&w.document(nodes.clone(), with_far)).unwrap();
    let cam = setup.camera.unwrap();
    assert_eq!(cam.far(), Some(4.0));
    let clipped = ViewSamples::render(setup.scene.as_ref(), &cam, 32, 24).unwrap();
    let open = json!([{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.05}}]);
    let setup_open = load(&w.document(nodes, open)).unwrap();
    let all = ViewSamples::render(
        setup_open.scene.as_ref(),
        &setup_open.camera.unwrap(),
        32,
        24,
    )
    .unwrap();
    assert!(clipped.valid_count() > 0 && clipped.valid_count() < all.valid_count());
    for i in 0..all.len() {
        match (clipped.get(i), all.get(i)) {
            (Some(c), Some(a)) => assert_eq!(c, a, "pixel {i} within the far plane is unchanged"),
            (None, Some(a)) => assert!(
                clipped.depths()[i].is_infinite() && all.depths()[i] > 4.0,
                "{a:?}"
            ),
            (Some(_), None) => panic!("pixel {i} appeared"),
            (None, None) => {}
        }
    }
}

/// Issue 69 item 12: an extreme `aspectRatio` is named, not turned into a 4294967295-pixel
/// height.
#[test]
fn an_extreme_aspect_ratio_is_named_not_a_huge_height() {
    let w = writer();
    let nodes = json!([{"mesh": 0}, {"camera": 0, "translation": [0.0, 1.0, 3.5]}]);
    let camera = |aspect: f64| json!([{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.05, "aspectRatio": aspect}}]);
    let limit = 1 << 25;
    let wide = load(&w.document(nodes.clone(), camera(2.0))).unwrap();
    assert_eq!(wide.image_height(512, limit), Ok(256));
    let thin = load(&w.document(nodes.clone(), camera(1e-9))).unwrap();
    let err = thin.image_height(512, limit).unwrap_err();
    assert!(
        err.contains("aspect ratio 0.000000001") && err.contains("give the height"),
        "{err}"
    );
    let flat = load(&w.document(nodes, camera(1e9))).unwrap();
    assert_eq!(flat.image_height(512, limit), Ok(1));
}
