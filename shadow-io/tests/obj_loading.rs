//! OBJ loading: triangulation, welding, and malformed input returning errors.

use shadow_core::prelude::*;
use shadow_io::SceneSetup;
use shadow_io::load::{LoadError, LoadLimits, load_obj_slice};

fn load(text: &str) -> Result<SceneSetup, LoadError> {
    load_obj_slice(text.as_bytes(), "t", &LoadLimits::default())
}

#[test]
fn quads_are_triangulated_and_seams_welded() {
    // A cube written with duplicated corner positions (as UV seams produce) and quad faces.
    let mut text = String::new();
    let corners = [
        [0, 0, 0],
        [1, 0, 0],
        [1, 1, 0],
        [0, 1, 0],
        [0, 0, 1],
        [1, 0, 1],
        [1, 1, 1],
        [0, 1, 1],
    ];
    let faces = [
        [0, 3, 2, 1],
        [4, 5, 6, 7],
        [0, 1, 5, 4],
        [2, 3, 7, 6],
        [0, 4, 7, 3],
        [1, 2, 6, 5],
    ];
    let mut n = 0;
    for f in faces {
        for c in f {
            let p = corners[c];
            text += &format!("v {} {} {}\n", p[0], p[1], p[2]);
        }
        text += &format!("f {} {} {} {}\n", n + 1, n + 2, n + 3, n + 4);
        n += 4;
    }
    let s = load(&text).unwrap();
    assert_eq!(s.scene.triangle_count(), 12);
    assert_eq!(s.scene.positions().len(), 8);
    assert!(s.scene.topology().all_closed());
    assert!(s.lights.is_empty() && s.camera.is_none());
}

#[test]
fn committed_spot_is_closed_once_welded() {
    let bytes = include_bytes!("../../shadow-scenes/assets/models/spot.obj");
    let s = load_obj_slice(bytes, "spot", &LoadLimits::default()).unwrap();
    assert_eq!(s.scene.triangle_count(), 5856);
    assert!(s.scene.topology().all_closed());
}

#[test]
fn malformed_obj_gives_errors() {
    assert!(load("").is_err());
    assert!(load("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").is_err());
    assert!(load("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n").is_err());
    assert!(load("v 0 0 zz\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").is_err());
    assert!(load("v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").is_err());
    // Only degenerate faces: nothing left.
    assert!(matches!(
        load("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"),
        Err(LoadError::Scene(_))
    ));
    // A vertex-count limit is honoured.
    let limits = LoadLimits {
        max_vertices: 2,
        ..LoadLimits::default()
    };
    assert!(matches!(
        load_obj_slice(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "t", &limits),
        Err(LoadError::Limit { .. })
    ));
}

/// Issue 51 item 17: OBJ errors gave no line number.
#[test]
fn obj_errors_name_the_line() {
    for (text, line) in [
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", 4),
        ("v 0 0 0\n# c\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", 5),
        ("v 0 0 0\nv 0 0 zz\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 2),
        ("v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n", 3),
    ] {
        let e = load(text).unwrap_err().to_string();
        assert!(e.contains(&format!("line {line}:")), "{text:?}: {e}");
    }
}

/// Issue 51 item 16: a 100,000-gon face was fan-triangulated into needles, and the BVH build
/// over them took 73 s. n-gons are now triangulated in their plane (constrained Delaunay):
/// concave faces are covered exactly once, winding follows the face, and a self-crossing face
/// is an error naming its line.
#[test]
fn ngon_faces_are_triangulated_in_their_plane() {
    // A concave "U" in the plane y = 1, counter-clockwise seen from +y (normal +y).
    let u = [
        (0.0, 0.0),
        (0.0, 3.0),
        (1.0, 3.0),
        (1.0, 1.0),
        (2.0, 1.0),
        (2.0, 3.0),
        (3.0, 3.0),
        (3.0, 0.0),
    ];
    let mut text = String::new();
    for (x, z) in u {
        text += &format!("v {x} 1 {z}\n");
    }
    text += "f 1 2 3 4 5 6 7 8\n";
    let s = load(&text).unwrap();
    assert_eq!(s.scene.triangle_count(), 6);
    let mut area = 0.0;
    for t in 0..6 {
        let [a, b, c] = s.scene.triangle(t);
        let n = (b - a).cross(c - a);
        assert!(n.y > 0.0, "triangle {t} winds against the face: {n:?}");
        area += 0.5 * n.length();
    }
    assert!((area - 7.0).abs() < 1e-5, "{area}");
    // A bow-tie pentagon crosses itself.
    let e = load("v 0 0 0\nv 2 0 0\nv 0 0 2\nv 2 0 2\nv 1 0 3\nf 1 2 3 4 5\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("line 6:"), "{e}");
    // A large circle: n - 2 triangles, none of them a needle from one vertex.
    let n = 20_000;
    let mut text = String::new();
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        text += &format!("v {} 0 {}\n", a.cos(), -a.sin());
    }
    text += "f";
    for k in 1..=n {
        text += &format!(" {k}");
    }
    text += "\n";
    let s = load(&text).unwrap();
    assert_eq!(s.scene.triangle_count(), n - 2);
    let mut degree = vec![0u32; s.scene.positions().len()];
    for t in s.scene.triangles() {
        for v in t {
            degree[*v as usize] += 1;
        }
    }
    let most = degree.into_iter().max().unwrap();
    assert!(most < 64, "a vertex in {most} triangles: a fan");
}

/// Found by the loaders' fuzz test: a texture-coordinate index of `-11` after one `vt` made
/// `tobj` overflow (a panic in debug builds, a wrapped index in release). References are
/// checked before `tobj` sees them.
#[test]
fn out_of_range_texture_and_normal_indices_are_errors_not_overflows() {
    for (text, what) in [
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/-11 3/1\n",
            "texture coordinate -11",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n",
            "normal 2",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 18446744073709551615\n",
            "is not an index",
        ),
    ] {
        let e = load(text).unwrap_err().to_string();
        assert!(e.contains("line 5:") || e.contains("line 4:"), "{e}");
        assert!(e.contains(what), "{e}");
    }
}

/// Issue 69 item 10: a one-component `vt` (legal OBJ) and a Latin-1 byte in a comment load.
#[test]
fn a_one_component_vt_and_a_latin1_comment_load() {
    let mut bytes = b"# caf".to_vec();
    bytes.push(0xE9); // Latin-1 e-acute: not UTF-8
    bytes.extend_from_slice(b"\nv 0 0 0\nv 1 0 0\nv 0 0 1\nvt 0.5\nvt 0.25\nvt 1\nf 1/1 3/2 2/3\n");
    let setup = load_obj_slice(&bytes, "latin", &LoadLimits::default()).unwrap();
    assert_eq!(setup.scene.triangle_count(), 1);
    // A face naming a texture coordinate that does not exist is still refused, by line.
    let bad = b"v 0 0 0\nv 1 0 0\nv 0 0 1\nvt 0.5\nf 1/1 3/2 2/1\n";
    let err = load_obj_slice(bad, "bad", &LoadLimits::default()).unwrap_err();
    assert!(err.to_string().contains("line 5"), "{err}");
}
