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

/// Issue 69 item 2: morph targets and skins are applied in glTF's default pose (node weights
/// over mesh weights; joints placed by the default scene, the skinned node's own transform
/// ignored), not dropped for the bind pose.
#[test]
fn morph_targets_and_skins_take_the_default_pose() {
    let mut w = writer();
    let grey = w.material(json!({}));
    let (sp, si) = square(0.5);
    let morphed = w.mesh("morphed", &sp, &si, None, grey);
    let skinned = w.mesh("skinned", &sp, &si, None, grey);
    let bytes =
        |values: &[f32]| -> Vec<u8> { values.iter().flat_map(|v| v.to_le_bytes()).collect() };
    let up: Vec<f32> = (0..4).flat_map(|_| [0.0, 1.0, 0.0]).collect();
    let up_view = w.view(&bytes(&up), None);
    let target = w.accessor(
        up_view,
        5126,
        4,
        "VEC3",
        json!({"min": [0.0, 1.0, 0.0], "max": [0.0, 1.0, 0.0]}),
    );
    let joints_view = w.view(&[0u8; 16], None);
    let joints = w.accessor(joints_view, 5121, 4, "VEC4", json!({}));
    let weights: Vec<f32> = (0..4).flat_map(|_| [1.0, 0.0, 0.0, 0.0]).collect();
    let weights_view = w.view(&bytes(&weights), None);
    let weights = w.accessor(weights_view, 5126, 4, "VEC4", json!({}));
    let nodes = json!([
        {"mesh": 0},
        {"mesh": morphed, "translation": [2.0, 0.0, 0.0]},
        {"mesh": skinned, "skin": 0, "translation": [100.0, 0.0, 0.0]},
        {"translation": [-2.0, 2.0, 0.0]},
        {"mesh": morphed, "translation": [0.0, 0.0, 2.0], "weights": [2.0]},
    ]);
    let mut doc = w.document(nodes, json!([]));
    doc["meshes"][morphed]["primitives"][0]["targets"] = json!([{"POSITION": target}]);
    doc["meshes"][morphed]["weights"] = json!([0.5]);
    doc["meshes"][skinned]["primitives"][0]["attributes"]["JOINTS_0"] = json!(joints);
    doc["meshes"][skinned]["primitives"][0]["attributes"]["WEIGHTS_0"] = json!(weights);
    doc["skins"] = json!([{"joints": [3]}]);
    let setup = load(&doc).unwrap();
    let b = setup.scene.bounds();
    assert_eq!(
        b.max.x, 3.0,
        "the skinned node's own translation is ignored"
    );
    let at = |x: f32, z: f32| -> Vec<f32> {
        let s = setup.scene.as_ref();
        (0..s.triangle_count())
            .flat_map(|t| s.triangle(t))
            .filter(|p| (p.x - x).abs() <= 0.5 && (p.z - z).abs() <= 0.5)
            .map(|p| p.y)
            .collect()
    };
    assert!(
        at(2.0, 0.0).iter().all(|&y| y == 0.5),
        "mesh weight 0.5: {:?}",
        at(2.0, 0.0)
    );
    assert!(
        at(0.0, 2.0).iter().all(|&y| y == 2.0),
        "node weight 2: {:?}",
        at(0.0, 2.0)
    );
    assert!(
        at(-2.0, 0.0).iter().all(|&y| y == 2.0),
        "placed by its joint: {:?}",
        at(-2.0, 0.0)
    );
    assert!(!at(-2.0, 0.0).is_empty());
}
