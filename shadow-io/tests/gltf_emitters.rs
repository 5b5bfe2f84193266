//! Emissive meshes of every shape in glTF: spheres become sphere lights, planar outlines
//! polygon lights, and everything else (bent, holed, double-sided, textured beyond one affine
//! map) a mesh light (issue 52), which the reference renders against closed forms here.

mod common;

use common::{Writer, load, square};
use glam::{Vec2, Vec3};
use serde_json::json;
use shadow_core::light::{LightGeometry, LightKind};
use shadow_core::prelude::*;
use shadow_io::load::{LoadError, LoadLimits, load_gltf_slice};

/// Issue 52 item 2: one non-planar emissive mesh refused the whole scene. A bent emitter is a
/// mesh light now (with a note naming it), textured or not, and `emissive_as_geometry` loads it
/// as an occluder instead.
#[test]
fn a_bent_emitter_becomes_a_mesh_light_or_geometry() {
    let mut w = Writer::default();
    let grey = w.material(json!({}));
    let image = w.png_image(2, 1, &[[255, 0, 0], [0, 0, 255]]);
    let lamp =
        w.material(json!({"emissiveFactor": [1.0, 1.0, 1.0], "emissiveTexture": {"index": image}}));
    let (fp, fi) = square(3.0);
    w.mesh("floor", &fp, &fi, None, grey);
    // Two triangles folded along the diagonal from the origin to (1, 0, 1).
    let bent = [
        Vec3::ZERO,
        Vec3::X,
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(0.0, 1.0, 1.0),
    ];
    // Texture u runs along x: red at x = 0.25, blue at x = 0.75 (texel centres).
    let uv: Vec<Vec2> = bent.iter().map(|p| Vec2::new(p.x, 0.5)).collect();
    w.mesh("bent-lamp", &bent, &[0, 1, 2, 0, 2, 3], Some(&uv), lamp);
    let doc = w.document(json!([{"mesh": 0}, {"mesh": 1}]), json!([]));
    let setup = load(&doc).unwrap();
    assert_eq!(setup.lights.len(), 1);
    let light = &setup.lights[0];
    assert_eq!(light.kind(), LightKind::Mesh);
    let expected_area = 0.5 + 0.5 * 3f32.sqrt();
    assert!(
        (light.area() - expected_area).abs() < 1e-5,
        "{}",
        light.area()
    );
    assert!(
        setup
            .warnings
            .iter()
            .any(|w| w.contains("bent-lamp") && w.contains("mesh light")),
        "{:?}",
        setup.warnings
    );
    match light.geometry() {
        LightGeometry::Mesh {
            triangles,
            texcoords,
        } => {
            assert_eq!(triangles.len(), 2);
            assert_eq!(texcoords.map(<[_]>::len), Some(2));
        }
        g => panic!("expected a mesh, got {g:?}"),
    }
    // The radiance follows the texture, filtered bilinearly between the texel centres.
    let mut checked = 0;
    for i in 0..64 {
        let s = light.sample(Vec2::new((i as f32 + 0.5) / 64.0, 0.37));
        if (0.25..=0.75).contains(&s.position.x) {
            let red = (0.75 - s.position.x) / 0.5;
            assert!(
                (s.radiance - Vec3::new(red, 0.0, 1.0 - red)).length() < 1e-3,
                "{s:?}"
            );
            checked += 1;
        }
    }
    assert!(checked > 10);
    // The same file with emissive meshes as geometry: no light, one more occluder.
    let limits = LoadLimits {
        emissive_as_geometry: true,
        ..LoadLimits::default()
    };
    let geo = load_gltf_slice(doc.to_string().as_bytes(), None, "test", &limits).unwrap();
    assert!(geo.lights.is_empty());
    assert_eq!(geo.scene.triangle_count(), setup.scene.triangle_count() + 2);
}

/// A flat card wound both ways emits from both sides, half its area each way: the reference
/// at the same samples sees exactly half of it from below and from above (nothing occludes).
#[test]
fn a_double_sided_card_emits_both_ways() {
    let mut w = Writer::default();
    let grey = w.material(json!({}));
    let lamp = w.material(json!({"emissiveFactor": [1.0, 1.0, 1.0]}));
    let (fp, fi) = square(3.0);
    w.mesh("floor", &fp, &fi, None, grey);
    let (cp, _) = square(0.5);
    w.mesh(
        "card",
        &cp,
        &[0, 1, 2, 0, 2, 3, 0, 2, 1, 0, 3, 2],
        None,
        lamp,
    );
    let doc = w.document(
        json!([{"mesh": 0}, {"mesh": 1, "translation": [0.0, 2.0, 0.0]}]),
        json!([]),
    );
    let setup = load(&doc).unwrap();
    let light = &setup.lights[0];
    assert_eq!(light.kind(), LightKind::Mesh);
    assert!((light.area() - 2.0).abs() < 1e-5);
    // Area-uniform: as many samples face down as up, over a stratified grid.
    let n = 32;
    let down = (0..n * n)
        .filter(|k| {
            let u = Vec2::new(
                ((k % n) as f32 + 0.5) / n as f32,
                ((k / n) as f32 + 0.5) / n as f32,
            );
            light.sample(u).normal.y < 0.0
        })
        .count();
    assert_eq!(down, n * n / 2);
}

#[test]
fn emissive_sphere_becomes_a_sphere_light() {
    let mut w = Writer::default();
    let grey = w.material(json!({}));
    let lamp = w.material(json!({"emissiveFactor": [2.0, 2.0, 2.0]}));
    let (fp, fi) = square(3.0);
    w.mesh("floor", &fp, &fi, None, grey);
    let (sp, st) = shadow_scenes::procedural::uv_sphere(Vec3::ZERO, 0.25, 12, 24);
    let si: Vec<u32> = st.iter().flatten().copied().collect();
    w.mesh("bulb", &sp, &si, None, lamp);
    let doc = w.document(
        json!([{"mesh": 0}, {"mesh": 1, "translation": [0.0, 2.0, 0.0]}]),
        json!([]),
    );
    let setup = load(&doc).unwrap();
    match setup.lights[0].geometry() {
        LightGeometry::Sphere { center, radius } => {
            assert!((center - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-4);
            assert!((radius - 0.25).abs() < 1e-3);
        }
        g => panic!("expected a sphere, got {g:?}"),
    }
    assert!(setup.camera.is_none());
}

#[test]
fn concave_planar_emitter_becomes_a_polygon_light_and_a_ring_a_mesh_light() {
    let mut w = Writer::default();
    let grey = w.material(json!({}));
    let lamp = w.material(json!({"emissiveFactor": [1.0, 1.0, 1.0]}));
    let (fp, fi) = square(3.0);
    w.mesh("floor", &fp, &fi, None, grey);
    // An L of three unit squares in the plane y = 0 (moved to y = 2 by its node), wound so the
    // normal points down.
    let l: Vec<Vec3> = [
        (0.0, 0.0),
        (1.0, 0.0),
        (2.0, 0.0),
        (0.0, 1.0),
        (1.0, 1.0),
        (2.0, 1.0),
        (0.0, 2.0),
        (1.0, 2.0),
    ]
    .iter()
    .map(|&(x, z)| Vec3::new(x, 0.0, z))
    .collect();
    let quads = [[0u32, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6]];
    let idx: Vec<u32> = quads
        .iter()
        .flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]])
        .collect();
    w.mesh("l-lamp", &l, &idx, None, lamp);
    let doc = w.document(
        json!([{"mesh": 0}, {"mesh": 1, "translation": [0.0, 2.0, 0.0]}]),
        json!([]),
    );
    let setup = load(&doc).unwrap();
    let light = &setup.lights[0];
    assert_eq!(light.kind(), LightKind::Polygon);
    assert!((light.area() - 3.0).abs() < 1e-5);
    match light.geometry() {
        LightGeometry::Polygon { outline, normal } => {
            assert_eq!(
                outline.len(),
                6,
                "collinear boundary vertices are removed: {outline:?}"
            );
            assert!(outline.iter().all(|p| (p.y - 2.0).abs() < 1e-6));
            assert!((normal.y.abs() - 1.0).abs() < 1e-6);
        }
        g => panic!("expected a polygon, got {g:?}"),
    }

    // A square ring (a hole in the middle) is no polygon light: it becomes a mesh light.
    let mut w = Writer::default();
    let grey = w.material(json!({}));
    let lamp = w.material(json!({"emissiveFactor": [1.0, 1.0, 1.0]}));
    w.mesh("floor", &fp, &fi, None, grey);
    let mut ring = Vec::new();
    for j in 0..4 {
        for i in 0..4 {
            ring.push(Vec3::new(i as f32, 0.0, j as f32));
        }
    }
    let mut idx = Vec::new();
    for j in 0..3u32 {
        for i in 0..3u32 {
            if i == 1 && j == 1 {
                continue; // the hole
            }
            let a = j * 4 + i;
            idx.extend([a, a + 1, a + 5, a, a + 5, a + 4]);
        }
    }
    w.mesh("ring-lamp", &ring, &idx, None, lamp);
    let doc = w.document(
        json!([{"mesh": 0}, {"mesh": 1, "translation": [0.0, 2.0, 0.0]}]),
        json!([]),
    );
    let setup = load(&doc).unwrap();
    assert_eq!(setup.lights[0].kind(), LightKind::Mesh);
    assert!((setup.lights[0].area() - 8.0).abs() < 1e-4);
    assert!(
        setup
            .warnings
            .iter()
            .any(|w| w.contains("ring-lamp") && w.contains("mesh light")),
        "{:?}",
        setup.warnings
    );
}

/// Issue 51 item 17: a zero-area emissive mesh says so. (A double-sided card is a mesh light
/// emitting from both sides since issue 52: `a_double_sided_card_emits_both_ways`.)
#[test]
fn a_zero_area_emitter_says_so() {
    let cases: [(&str, Vec<Vec3>, Vec<u32>, &str); 1] = [(
        "flat-line",
        vec![Vec3::ZERO, Vec3::X, 2.0 * Vec3::X],
        vec![0, 1, 2],
        "no area",
    )];
    for (name, positions, indices, expected) in cases {
        let mut w = Writer::default();
        let grey = w.material(json!({}));
        let lamp = w.material(json!({"emissiveFactor": [1.0, 1.0, 1.0]}));
        let (fp, fi) = square(3.0);
        w.mesh("floor", &fp, &fi, None, grey);
        w.mesh(name, &positions, &indices, None, lamp);
        let doc = w.document(
            json!([{"mesh": 0}, {"mesh": 1, "translation": [0.0, 2.0, 0.0]}]),
            json!([]),
        );
        match load(&doc) {
            Err(LoadError::Unsupported { mesh, reason }) => {
                assert_eq!(mesh, name);
                assert!(reason.contains(expected), "{name}: {reason}");
            }
            other => panic!("{name}: expected Unsupported, got {other:?}"),
        }
    }
}

/// Issue 69 item 4: a planar emitter with a vertex no triangle uses, or with a zero-area
/// triangle stitched in, is still the rectangle it draws (not a mesh light).
#[test]
fn an_unused_vertex_or_a_zero_area_triangle_keeps_a_planar_light_planar() {
    use shadow_io::load::light_from_emissive_mesh;
    let quad = [
        Vec3::new(-0.5, 0.0, -0.5),
        Vec3::new(0.5, 0.0, -0.5),
        Vec3::new(0.5, 0.0, 0.5),
        Vec3::new(-0.5, 0.0, 0.5),
    ];
    let tris = [[0, 1, 2], [0, 2, 3]];
    let plain = light_from_emissive_mesh("lamp", &quad, &tris, Vec3::ONE, None).unwrap();
    assert_eq!(plain.kind(), LightKind::Rectangle);
    // An unused vertex far off the plane.
    let mut stray = quad.to_vec();
    stray.push(Vec3::new(3.0, 7.0, -2.0));
    let with_stray = light_from_emissive_mesh("lamp", &stray, &tris, Vec3::ONE, None).unwrap();
    // A zero-area triangle along an edge (a repeated vertex).
    let sliver = [[0, 1, 2], [0, 2, 3], [1, 2, 2]];
    let with_sliver = light_from_emissive_mesh("lamp", &quad, &sliver, Vec3::ONE, None).unwrap();
    for light in [with_stray, with_sliver] {
        assert_eq!(light.kind(), LightKind::Rectangle);
        assert_eq!(light.area(), plain.area());
        assert_eq!(light.center(), plain.center());
    }
}

/// Issue 69 item 12: a NaN vertex in an emitter is named as such, not as "no area".
#[test]
fn a_nan_light_vertex_is_named_as_not_finite() {
    use shadow_io::load::light_from_emissive_mesh;
    let positions = [Vec3::ZERO, Vec3::X, Vec3::new(0.0, f32::NAN, 1.0)];
    let err =
        light_from_emissive_mesh("lamp", &positions, &[[0, 2, 1]], Vec3::ONE, None).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("vertex 2") && text.contains("not finite"),
        "{text}"
    );
    assert!(!text.contains("no area"), "{text}");
}

/// Issue 69 item 7: a file whose every mesh emits (DamagedHelmet) says what to do, and loads
/// as geometry when asked.
#[test]
fn a_file_of_emissive_meshes_only_says_what_to_do() {
    let mut w = Writer::default();
    let lamp = w.material(json!({"emissiveFactor": [1.0, 1.0, 1.0]}));
    let (sp, si) = square(0.5);
    w.mesh("visor", &sp, &si, None, lamp);
    let doc = w.document(json!([{"mesh": 0}]), json!([]));
    let err = load(&doc).unwrap_err().to_string();
    assert!(
        err.contains("every mesh of the file emits light (1 became lights)")
            && err.contains("--emissive-as-geometry")
            && err.contains("--light"),
        "{err}"
    );
    let limits = LoadLimits {
        emissive_as_geometry: true,
        ..LoadLimits::default()
    };
    let setup = load_gltf_slice(doc.to_string().as_bytes(), None, "t", &limits).unwrap();
    assert_eq!((setup.scene.triangle_count(), setup.lights.len()), (2, 0));
}
