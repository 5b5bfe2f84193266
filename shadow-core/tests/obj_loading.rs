//! OBJ loading: triangulation, welding, and malformed input returning errors.

use shadow_core::load::{LoadError, LoadLimits, load_obj_slice};
use shadow_core::prelude::*;

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
    let bytes = include_bytes!("../assets/models/spot.obj");
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
