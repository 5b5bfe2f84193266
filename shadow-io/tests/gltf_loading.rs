//! glTF loading of files the test writes itself: emissive rectangle, disk and textured quad,
//! a camera and a semi-opaque mesh; and malformed files that must give errors. Emitters of
//! other shapes are in `gltf_emitters.rs`.

mod common;

use std::f32::consts::TAU;

use base64::Engine;
use common::{Writer, load, square};
use glam::{Vec2, Vec3};
use serde_json::{Value, json};
use shadow_core::light::{LightGeometry, LightKind};
use shadow_core::prelude::*;
use shadow_io::load::{LoadError, LoadLimits, load_gltf, load_gltf_slice};

fn disk(r: f32, n: u32) -> (Vec<Vec3>, Vec<u32>) {
    let mut p = vec![Vec3::ZERO];
    let mut idx = Vec::new();
    for i in 0..n {
        let a = TAU * i as f32 / n as f32;
        p.push(Vec3::new(r * a.cos(), 0.0, r * a.sin()));
        idx.extend([0, 1 + i, 1 + (i + 1) % n]);
    }
    (p, idx)
}

fn test_document() -> Value {
    let mut w = Writer::default();
    let grey =
        w.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.6, 0.7, 1.0]}}));
    let glass = w.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 0.4]}, "alphaMode": "BLEND"}));
    let masked = w.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 0.6]}, "alphaMode": "MASK"}));
    let lamp = w.material(json!({"emissiveFactor": [1.0, 0.5, 0.25], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}}));
    let image = w.png_image(2, 1, &[[255, 0, 0], [0, 0, 255]]);
    let textured =
        w.material(json!({"emissiveFactor": [1.0, 1.0, 1.0], "emissiveTexture": {"index": image}}));
    let (fp, fi) = square(3.0);
    let floor_idx: Vec<u32> = fi.chunks(3).flat_map(|c| [c[0], c[2], c[1]]).collect();
    w.mesh("floor", &fp, &floor_idx, None, grey);
    let (sp, si) = square(0.5);
    w.mesh("glass", &sp, &si, None, glass);
    w.mesh("masked", &sp, &si, None, masked);
    w.mesh("rect-lamp", &sp, &si, None, lamp);
    let (dp, di) = disk(0.3, 48);
    w.mesh("disk-lamp", &dp, &di, None, lamp);
    let uv = [
        Vec2::new(0.0, 0.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(0.0, 1.0),
    ];
    w.mesh("textured-lamp", &sp, &si, Some(&uv), textured);
    let nodes = json!([
        {"mesh": 0},
        {"mesh": 1, "translation": [0.0, 1.0, 0.0]},
        {"mesh": 2, "translation": [0.0, 1.5, 0.0]},
        {"mesh": 3, "translation": [0.0, 3.0, 0.0], "scale": [2.0, 1.0, 1.0]},
        {"mesh": 4, "translation": [1.0, 3.0, 0.0]},
        {"mesh": 5, "translation": [-1.0, 3.0, 0.0]},
        {"camera": 0, "translation": [0.0, 2.0, 6.0]}
    ]);
    w.document(nodes, json!([{"type": "perspective", "perspective": {"yfov": 0.8, "aspectRatio": 1.5, "znear": 0.01}}]))
}

#[test]
fn lights_camera_and_opacities_load_as_written() {
    let setup = load(&test_document()).unwrap();
    assert_eq!(setup.lights.len(), 3);
    // Rectangle: scaled by 2 along x -> 2 x 1, emission x strength.
    let rect = &setup.lights[0];
    assert_eq!(rect.kind(), LightKind::Rectangle);
    assert!((rect.area() - 2.0).abs() < 1e-5);
    assert!((rect.center() - Vec3::new(0.0, 3.0, 0.0)).length() < 1e-5);
    match rect.geometry() {
        LightGeometry::Rectangle { normal, .. } => assert!((normal - Vec3::NEG_Y).length() < 1e-5),
        g => panic!("expected a rectangle, got {g:?}"),
    }
    assert!((rect.radiance().mean() - Vec3::new(4.0, 2.0, 1.0)).length() < 1e-5);
    // Disk: recognised exactly (48 rim vertices).
    let disk = &setup.lights[1];
    match disk.geometry() {
        LightGeometry::Disk {
            center,
            radius,
            normal,
        } => {
            assert!((center - Vec3::new(1.0, 3.0, 0.0)).length() < 1e-5);
            assert!((radius - 0.3).abs() < 1e-5);
            assert!((normal - Vec3::NEG_Y).length() < 1e-5);
        }
        g => panic!("expected a disk, got {g:?}"),
    }
    // Textured: red at uv u < 0.5, blue at u > 0.5 (sRGB 255 -> linear 1).
    let tex = &setup.lights[2];
    assert!(tex.is_textured());
    assert_eq!(tex.kind(), LightKind::Rectangle);
    // Texture u follows the mesh's x (vertex x = -0.5 has u = 0; node at x = -1), so texel
    // centres u = 0.25 (red) and 0.75 (blue) sit at world x = -1.25 and -0.75.
    let (mut reds, mut blues) = (0, 0);
    for j in 0..64 {
        for i in 0..64 {
            let s = tex.sample(Vec2::new((i as f32 + 0.5) / 64.0, (j as f32 + 0.5) / 64.0));
            if (s.position.x + 1.25).abs() < 0.01 {
                assert!(
                    (s.radiance - Vec3::new(1.0, 0.0, 0.0)).length() < 0.05,
                    "{:?}",
                    s.radiance
                );
                reds += 1;
            }
            if (s.position.x + 0.75).abs() < 0.01 {
                assert!(
                    (s.radiance - Vec3::new(0.0, 0.0, 1.0)).length() < 0.05,
                    "{:?}",
                    s.radiance
                );
                blues += 1;
            }
        }
    }
    assert!(reds > 0 && blues > 0);
    // Camera.
    let cam = setup.camera.unwrap();
    assert!((cam.position() - Vec3::new(0.0, 2.0, 6.0)).length() < 1e-5);
    assert!((cam.forward() - Vec3::NEG_Z).length() < 1e-5);
    assert!((cam.yfov() - 0.8).abs() < 1e-6);
    // The file's near plane (issue 51, item 10: it was ignored for a fixed 1e-4).
    assert_eq!(cam.near(), 0.01);
    assert_eq!(setup.aspect, Some(1.5));
    // Opacities: floor opaque, BLEND glass 0.4, MASK at alpha 0.6 (above its cutoff) opaque.
    let s = &setup.scene;
    assert_eq!(s.triangle_count(), 6);
    assert_eq!(s.opacities(), &[1.0, 1.0, 0.4, 0.4, 1.0, 1.0]);
    assert!((s.albedo(0) - Vec3::new(0.5, 0.6, 0.7)).length() < 1e-6);
    assert!(s.has_semi_opaque());
    // Below its cutoff a masked mesh is fully transparent: not loaded, and a note says so.
    let mut doc = test_document();
    doc["materials"][2]["pbrMetallicRoughness"]["baseColorFactor"] = json!([1.0, 1.0, 1.0, 0.4]);
    doc["materials"][2]["name"] = json!("leaf");
    let setup = load(&doc).unwrap();
    assert_eq!(setup.scene.triangle_count(), 4);
    assert!(
        setup
            .warnings
            .iter()
            .any(|w| w.contains("masked out") && w.contains("leaf") && w.contains("0.5")),
        "{:?}",
        setup.warnings
    );
}

#[test]
fn glb_and_external_buffers_load() {
    let dir = std::env::temp_dir().join(format!("shadow-core-gltf-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // External .bin next to the .gltf.
    let mut doc = test_document();
    let uri = doc["buffers"][0]["uri"].as_str().unwrap().to_string();
    let bin = base64::engine::general_purpose::STANDARD
        .decode(uri.split_once(";base64,").unwrap().1)
        .unwrap();
    // Percent-encoded bytes other than spaces decode too (issue 69 item 11).
    std::fs::write(dir.join("scene data#1+\u{fc}.bin"), &bin).unwrap();
    doc["buffers"][0]["uri"] = json!("scene%20data%231%2B%C3%BC.bin");
    std::fs::write(dir.join("scene.gltf"), doc.to_string()).unwrap();
    let external = load_gltf(&dir.join("scene.gltf"), &LoadLimits::default()).unwrap();
    assert_eq!(external.lights.len(), 3);
    // GLB: JSON chunk + BIN chunk.
    let mut glb_doc = test_document();
    glb_doc["buffers"][0] = json!({"byteLength": bin.len()});
    let glb = shadow_io::load::glb_bytes(&glb_doc.to_string(), &bin);
    std::fs::write(dir.join("scene.glb"), &glb).unwrap();
    let from_glb = load_gltf(&dir.join("scene.glb"), &LoadLimits::default()).unwrap();
    assert_eq!(from_glb.lights.len(), 3);
    assert_eq!(from_glb.scene.triangle_count(), 6);
    // Truncated GLB.
    std::fs::write(dir.join("cut.glb"), &glb[..glb.len() / 2]).unwrap();
    assert!(load_gltf(&dir.join("cut.glb"), &LoadLimits::default()).is_err());
    // Missing external buffer.
    std::fs::remove_file(dir.join("scene data#1+\u{fc}.bin")).unwrap();
    assert!(matches!(
        load_gltf(&dir.join("scene.gltf"), &LoadLimits::default()),
        Err(LoadError::Io { .. })
    ));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn malformed_gltf_gives_errors() {
    let limits = LoadLimits::default();
    assert!(matches!(
        load_gltf_slice(b"not json at all", None, "x", &limits),
        Err(LoadError::Gltf(_))
    ));
    assert!(load_gltf_slice(b"{\"asset\":{\"version\":\"2.0\"}}", None, "x", &limits).is_err());

    // Absurd declared buffer size.
    let mut doc = test_document();
    doc["buffers"][0]["byteLength"] = json!(1u64 << 50);
    assert!(matches!(load(&doc), Err(LoadError::Limit { .. })));
    // Declared size larger than the data present.
    let mut doc = test_document();
    let n = doc["buffers"][0]["byteLength"].as_u64().unwrap();
    doc["buffers"][0]["byteLength"] = json!(n + 1000);
    assert!(matches!(
        load(&doc),
        Err(LoadError::Limit { .. }) | Err(LoadError::Gltf(_))
    ));
    // Accessor reading past its view.
    let mut doc = test_document();
    doc["accessors"][0]["count"] = json!(1_000_000);
    assert!(matches!(
        load(&doc),
        Err(LoadError::Accessor(_)) | Err(LoadError::Gltf(_))
    ));
    // Buffer view past the buffer.
    let mut doc = test_document();
    doc["bufferViews"][0]["byteLength"] = json!(1u64 << 40);
    assert!(load(&doc).is_err());
    // External buffer with no base directory.
    let mut doc = test_document();
    doc["buffers"][0]["uri"] = json!("missing.bin");
    assert!(matches!(load(&doc), Err(LoadError::Missing(_))));
    // Index out of range.
    let mut doc = test_document();
    doc["accessors"][0]["count"] = json!(2);
    doc["accessors"][0]["min"] = json!([0.0, 0.0, 0.0]);
    assert!(matches!(load(&doc), Err(LoadError::Accessor(_))));
    // Wrong accessor type for positions.
    let mut doc = test_document();
    doc["accessors"][0]["type"] = json!("VEC2");
    doc["accessors"][0].as_object_mut().unwrap().remove("min");
    doc["accessors"][0].as_object_mut().unwrap().remove("max");
    assert!(load(&doc).is_err());
    // Non-finite vertex data gives a scene error.
    let mut w = Writer::default();
    let m = w.material(json!({}));
    w.mesh(
        "bad",
        &[Vec3::ZERO, Vec3::X, Vec3::new(f32::NAN, 0.0, 1.0)],
        &[0, 1, 2],
        None,
        m,
    );
    let mut doc = w.document(json!([{"mesh": 0}]), json!([]));
    doc["accessors"][0]["min"] = json!([0.0, 0.0, 0.0]);
    doc["accessors"][0]["max"] = json!([1.0, 0.0, 1.0]);
    assert!(matches!(load(&doc), Err(LoadError::Scene(_))));
    // Bad base64.
    let mut doc = test_document();
    doc["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,@@@@");
    assert!(load(&doc).is_err());
}

/// Issue 51, item 2: a bufferView or accessor `byteOffset` near 2^64 wrapped the bounds
/// check (`offset + length`) and panicked; it is an error.
#[test]
fn offsets_near_two_to_the_64_are_errors_not_panics() {
    let near = u64::MAX - 7;
    let mut doc = test_document();
    doc["bufferViews"][0]["byteOffset"] = json!(near);
    assert!(load(&doc).is_err());
    let mut doc = test_document();
    doc["accessors"][0]["byteOffset"] = json!(near);
    assert!(load(&doc).is_err());
    // An image's buffer view as well.
    let mut doc = test_document();
    let view = doc["images"][0]["bufferView"].as_u64().unwrap() as usize;
    doc["bufferViews"][view]["byteOffset"] = json!(near);
    assert!(load(&doc).is_err());
}

/// Issue 51, item 3: a primitive whose POSITION (or another attribute, its indices or its
/// material) names a missing accessor panicked inside gltf-json's validation; it is an error
/// naming what is missing.
#[test]
fn a_primitive_naming_a_missing_accessor_is_an_error() {
    for field in ["POSITION", "NORMAL"] {
        let mut doc = test_document();
        doc["meshes"][0]["primitives"][0]["attributes"][field] = json!(9999);
        match load(&doc) {
            Err(LoadError::Missing(m)) => assert!(m.contains("9999"), "{m}"),
            other => panic!("{field}: {other:?}"),
        }
    }
    let mut doc = test_document();
    doc["meshes"][0]["primitives"][0]["indices"] = json!(4242);
    assert!(matches!(load(&doc), Err(LoadError::Missing(m)) if m.contains("4242")));
    let mut doc = test_document();
    doc["meshes"][0]["primitives"][0]["material"] = json!(77);
    assert!(matches!(load(&doc), Err(LoadError::Missing(m)) if m.contains("77")));
}

/// Issue 51, item 17: a relative buffer URI that climbs out of the scene's folder
/// (`../../etc/...`) is refused, even when the file it names exists.
#[test]
fn uris_may_not_leave_the_scenes_folder() {
    let root = std::env::temp_dir().join(format!("shadow-core-uri-{}", std::process::id()));
    let dir = root.join("scene");
    std::fs::create_dir_all(&dir).unwrap();
    let mut doc = test_document();
    let uri = doc["buffers"][0]["uri"].as_str().unwrap().to_string();
    let bin = base64::engine::general_purpose::STANDARD
        .decode(uri.split_once(";base64,").unwrap().1)
        .unwrap();
    std::fs::write(root.join("outside.bin"), &bin).unwrap();
    for climbing in [
        "../outside.bin",
        "./../outside.bin",
        "sub/../../outside.bin",
    ] {
        doc["buffers"][0]["uri"] = json!(climbing);
        std::fs::write(dir.join("scene.gltf"), doc.to_string()).unwrap();
        match load_gltf(&dir.join("scene.gltf"), &LoadLimits::default()) {
            Err(LoadError::Unsupported { reason, .. }) => {
                assert!(reason.contains(".."), "{reason}")
            }
            other => panic!("{climbing}: {other:?}"),
        }
    }
    // Beside the file is fine.
    std::fs::write(dir.join("inside.bin"), &bin).unwrap();
    doc["buffers"][0]["uri"] = json!("./inside.bin");
    std::fs::write(dir.join("scene.gltf"), doc.to_string()).unwrap();
    assert!(load_gltf(&dir.join("scene.gltf"), &LoadLimits::default()).is_ok());
    std::fs::remove_dir_all(&root).ok();
}

/// Issue 51, item 8: a light node with a mirroring scale (negative determinant) flipped the
/// light's facing, and direct illumination became 0; the winding is reversed back, so the
/// light's front is the mirror image of its front: the local normal under the node's
/// inverse-transpose (unchanged by a mirror within the light's plane, reversed by one across it).
#[test]
fn a_mirrored_light_node_keeps_its_facing() {
    let normal_of = |doc: &Value| match load(doc).unwrap().lights[0].geometry() {
        LightGeometry::Rectangle { normal, .. } => normal,
        g => panic!("expected a rectangle, got {g:?}"),
    };
    // Unmirrored (scale [2, 1, 1]) the lamp faces down: its local normal is -Y.
    assert!((normal_of(&test_document()) - Vec3::NEG_Y).length() < 1e-5);
    for scale in [[-2.0f32, 1.0, 1.0], [2.0, 1.0, -1.0], [-2.0, -1.0, -1.0]] {
        let mut doc = test_document();
        doc["nodes"][3]["scale"] = json!(scale);
        let expected = Vec3::new(0.0, -1.0 / scale[1], 0.0).normalize();
        let n = normal_of(&doc);
        assert!(
            (n - expected).length() < 1e-5,
            "{scale:?}: {n} against {expected}"
        );
    }
}

/// Issue 51, item 17: garbage that is neither GLB nor JSON said "expected value at line 1
/// column 1"; it says it is not a glTF file. A limit names its quantity and unit, and an
/// accessor count is not called bytes.
#[test]
fn load_errors_say_what_is_wrong() {
    let limits = LoadLimits::default();
    let e = load_gltf_slice(b"\x89PNG garbage", None, "x", &limits).unwrap_err();
    assert!(e.to_string().contains("not a glTF file"), "{e}");
    let mut doc = test_document();
    doc["accessors"][0]["count"] = json!(1u64 << 40);
    let e = load(&doc).unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("element count") && !text.contains("bytes"),
        "{text}"
    );
}

/// Issue 52, item 7: material data was dropped without a word. Extensions the loader does not
/// read and base-colour textures (albedo is the factor) are named in the setup's warnings.
#[test]
fn ignored_material_data_is_named_in_a_note() {
    let mut doc = test_document();
    doc["extensionsUsed"] = json!([
        "KHR_materials_emissive_strength",
        "KHR_materials_transmission"
    ]);
    doc["materials"][0]["name"] = json!("grey paint");
    doc["materials"][1]["name"] = json!("window");
    doc["materials"][1]["extensions"] =
        json!({"KHR_materials_transmission": {"transmissionFactor": 1.0}});
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
    let setup = load(&doc).unwrap();
    let all = setup.warnings.join("\n");
    assert!(all.contains("KHR_materials_transmission"), "{all}");
    assert!(all.contains("opaque shadows"), "{all}");
    // The note names the material that uses the extension.
    assert!(all.contains("materials: window"), "{all}");
    assert!(
        !all.contains("extension KHR_materials_emissive_strength"),
        "{all}"
    );
    assert!(
        all.contains("base-colour textures") && all.contains("grey paint"),
        "{all}"
    );
    // A file that uses nothing unread says nothing.
    let plain = load(&test_document()).unwrap();
    assert!(plain.warnings.is_empty(), "{:?}", plain.warnings);
}

/// Issue 51 item 17: truncated files said "could not completely read the object"; a GLB or a
/// JSON cut anywhere now says that the file is truncated.
#[test]
fn truncated_files_say_they_are_truncated() {
    let limits = LoadLimits::default();
    let doc = test_document();
    let text = doc.to_string();
    let glb = shadow_io::load::glb_bytes(&text, b"");
    for cut in [13, 40, glb.len() / 2, glb.len() - 1] {
        let e = load_gltf_slice(&glb[..cut], None, "cut", &limits).unwrap_err();
        assert!(e.to_string().contains("truncated"), "GLB cut at {cut}: {e}");
    }
    for cut in [1, text.len() / 3, text.len() - 1] {
        let e = load_gltf_slice(&text.as_bytes()[..cut], None, "cut", &limits).unwrap_err();
        assert!(
            e.to_string().contains("truncated"),
            "JSON cut at {cut}: {e}"
        );
    }
}

/// Issue 51 item 17: a legal hierarchy deeper than 256 nodes was refused; cycles and nodes
/// with two parents are refused by name.
#[test]
fn deep_hierarchies_load_and_cycles_are_named() {
    let mut doc = test_document();
    // Nodes 0..7 as written, then a chain of 1000 empty nodes under node 7 ending in the floor.
    let base = doc["nodes"].as_array().unwrap().len();
    let chain = 1000;
    let mut nodes = doc["nodes"].as_array().unwrap().clone();
    for k in 0..chain {
        let mut n = json!({"translation": [0.0, 0.0, 0.0]});
        if k + 1 < chain {
            n["children"] = json!([base + k + 1]);
        } else {
            n["mesh"] = json!(0);
        }
        nodes.push(n);
    }
    doc["nodes"] = json!(nodes);
    doc["scenes"][0]["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!(base));
    let deep = load(&doc).unwrap();
    assert_eq!(
        deep.scene.triangle_count(),
        8,
        "the floor twice, the rest once"
    );
    // A cycle: the chain's last node points back to its first.
    let mut cyclic = doc.clone();
    cyclic["nodes"][base + chain - 1]["children"] = json!([base]);
    let e = load(&cyclic).unwrap_err();
    assert!(e.to_string().contains("reached twice"), "{e}");
}

/// Issue 51 item 15: a 218 KB 8192 x 8192 emissive PNG took 2.9 GB as floats. Textures longer
/// than `EMISSIVE_TEXTURE_SIDE` are box-filtered down when loaded (block means keep the light's
/// integrals), and the file's note says so.
#[test]
fn an_oversized_emissive_texture_is_box_filtered_and_named() {
    use shadow_io::load::EMISSIVE_TEXTURE_SIDE;
    let mut w = Writer::default();
    let grey =
        w.material(json!({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0]}}));
    // Red on the left half, blue on the right: 2 x EMISSIVE_TEXTURE_SIDE + 4 texels wide.
    let (tw, th) = (2 * EMISSIVE_TEXTURE_SIDE + 4, 2);
    let texels: Vec<[u8; 3]> = (0..tw * th)
        .map(|i| {
            if i % tw < tw / 2 {
                [255, 0, 0]
            } else {
                [0, 0, 255]
            }
        })
        .collect();
    let image = w.png_image(tw, th, &texels);
    let lamp =
        w.material(json!({"emissiveFactor": [1.0, 1.0, 1.0], "emissiveTexture": {"index": image}}));
    let (fp, fi) = square(3.0);
    let floor_idx: Vec<u32> = fi.chunks(3).flat_map(|c| [c[0], c[2], c[1]]).collect();
    w.mesh("floor", &fp, &floor_idx, None, grey);
    let (sp, si) = square(0.5);
    let uv = [
        Vec2::new(0.0, 0.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(0.0, 1.0),
    ];
    w.mesh("big-texture-lamp", &sp, &si, Some(&uv), lamp);
    let doc = w.document(
        json!([{"mesh": 0}, {"mesh": 1, "translation": [0.0, 3.0, 0.0]}]),
        json!([]),
    );
    let setup = load(&doc).unwrap();
    let all = setup.warnings.join("\n");
    // The smallest whole factor, 3, gives ceil(4100 / 3) = 1367 texels.
    assert!(
        all.contains("big-texture-lamp")
            && all.contains("4100x2 emissive texture is box-filtered to 1367x1"),
        "{all}"
    );
    // Half red, half blue on average, as before filtering (one block straddles the middle).
    let mean = setup.lights[0].radiance().mean();
    assert!(
        (mean - Vec3::new(0.5, 0.0, 0.5)).abs().max_element() < 2e-3,
        "{mean}"
    );
    // A texture within the side loads as it is, without a note.
    let plain = load(&test_document()).unwrap();
    assert!(plain.warnings.is_empty(), "{:?}", plain.warnings);
}
