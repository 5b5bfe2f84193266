//! Issue 52 item 2: a file whose emissive mesh is neither planar nor a sphere renders with the
//! reference under a mesh light, the techniques that cannot take one say why, and
//! `--emissive-as-geometry` turns the emitter into an occluder under the default light.

mod common;
mod gltf_files;

use common::{temp_dir, xtask};
use gltf_files::{gltf_of, square_at};

/// A folded lamp over the origin: two faces meeting at a ridge at y = `ridge`, both facing down.
fn folded_lamp(ridge: f32) -> Vec<[f32; 3]> {
    let (r, e) = ([0.0, ridge, -0.5], [0.0, ridge, 0.5]);
    let (l0, l1) = ([-0.4, ridge - 0.4, -0.5], [-0.4, ridge - 0.4, 0.5]);
    let (r0, r1) = ([0.4, ridge - 0.4, -0.5], [0.4, ridge - 0.4, 0.5]);
    // Left face wound so its normal points down and to +x, right face down and to -x.
    vec![r, l0, l1, r, l1, e, r, e, r1, r, r1, r0]
}

#[test]
fn a_bent_emitter_renders_as_a_mesh_light() {
    let dir = temp_dir("mesh-light");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("lamp.gltf");
    std::fs::write(
        &file,
        gltf_of(&[
            (square_at(0.0, 3.0, 0.0, false), None),
            (square_at(0.8, 0.3, 0.0, false), None),
            (folded_lamp(2.0), Some([1.0, 1.0, 1.0])),
        ]),
    )
    .unwrap();
    let out_dir = dir.join("out");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "render",
            "--scene",
            file.to_str().unwrap(),
            "--width",
            "32",
            "--camera",
            "0,4,3:0,0,0:50",
            "--out",
            out_dir.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        xtask(&args)
    };
    let out = run(&["--technique", "ref", "--samples", "64"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("mesh light"), "{stderr}");
    let v = image::open(out_dir.join("visibility.exr"))
        .unwrap()
        .to_rgba32f();
    let lit: Vec<f32> = v
        .pixels()
        .filter(|p| p.0[3] > 0.0)
        .map(|p| p.0[0])
        .collect();
    assert!(lit.iter().all(|x| (0.0..=1.0).contains(x)));
    // Shadowed under the occluder, lit beside it.
    assert!(lit.iter().any(|x| *x < 0.2) && lit.iter().any(|x| *x > 0.4));
    // A technique that needs a planar or spherical light says so and fails.
    let out = run(&["--technique", "dcs-64"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("dcs-64 does not support this input: mesh lights"),
        "{stderr}"
    );
    // As geometry: no light in the file, so the default light, and the lamp casts a shadow.
    let out = run(&["--technique", "ref-16", "--emissive-as-geometry"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("no emissive mesh"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}
