//! Issue 67 through the built binary: every light of a scene (`render`), and lightmaps
//! (`bake`) held to the closed form of `quad-over-plane`.

mod common;
mod gltf_files;

use common::{assert_success, read_stats, temp_dir, xtask};
use gltf_files::{gltf_of, square_at};
use shadow_conformance::closed_form::quad_over_plane_visibility;

/// Issue 51, item 9: a second emissive mesh was ignored without a word. Issue 67: every
/// light is shadowed (V per light as `visibility-K.*`), or `--light-index K` picks one.
#[test]
fn a_scene_with_several_lights_shadows_each_or_the_one_chosen() {
    let dir = temp_dir("two-lights");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("two.gltf");
    let gltf = gltf_of(&[
        (square_at(0.0, 3.0, 0.0, false), None),
        (square_at(2.0, 0.3, -1.0, true), Some([1.0, 1.0, 1.0])),
        (square_at(2.0, 0.3, 1.0, true), Some([1.0, 1.0, 1.0])),
    ]);
    std::fs::write(&file, gltf).unwrap();
    let out_dir = dir.join("out");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "render",
            "--scene",
            file.to_str().unwrap(),
            "--technique",
            "ref-16",
            "--width",
            "16",
            "--out",
            out_dir.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        xtask(&args)
    };
    let out = run(&["--direct"]);
    assert_success(&out);
    for f in [
        "visibility-0.exr",
        "visibility-1.png",
        "shaded.png",
        "direct.exr",
    ] {
        assert!(out_dir.join(f).is_file(), "{f}");
    }
    assert!(!out_dir.join("visibility.exr").exists());
    let s = read_stats(&out_dir);
    assert_eq!(s["lights"].as_array().unwrap().len(), 2);
    assert_eq!(s["estimate"]["counters"]["lights-shadowed"], 2);
    let out = run(&["--light-index", "1"]);
    assert_success(&out);
    assert_eq!(read_stats(&out_dir)["light_index"], 1);
    // One light chosen: `visibility.exr`, and the earlier run's per-light files are gone.
    assert!(out_dir.join("visibility.exr").is_file());
    assert!(!out_dir.join("visibility-0.exr").exists());
    assert!(!run(&["--light-index", "2"]).status.success());
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 67: `interior`'s sphere bulb is outside the light kinds of DCS's tables; the refusal
/// names the light, and `--fallback ref-16` traces it.
#[test]
fn a_refused_light_is_named_and_the_fallback_traces_it() {
    let dir = temp_dir("fallback");
    let d = dir.to_str().unwrap();
    let args = [
        "render",
        "--scene",
        "interior",
        "--technique",
        "dcs-64-interleaved",
        "--width",
        "24",
        "--out",
        d,
    ];
    let out = xtask(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("light 2") && err.contains("--fallback"),
        "{err}"
    );
    let out = xtask(&[&args[..], &["--fallback", "ref-16"]].concat());
    assert_success(&out);
    let stats = read_stats(&dir);
    let lights = stats["lights"].as_array().unwrap();
    let who: Vec<&str> = lights
        .iter()
        .map(|l| l["technique"].as_str().unwrap())
        .collect();
    assert_eq!(who, ["dcs-64-interleaved", "dcs-64-interleaved", "ref-16"]);
    assert!(
        lights[2]["fallback_because"]
            .as_str()
            .unwrap()
            .contains("sphere")
    );
    assert_eq!(stats["prepare"]["counters"]["lights-fallback"], 1);
    std::fs::remove_dir_all(&dir).ok();
}

/// The channels of an EXR as `(width, height, RGBA per pixel)`.
fn read_exr(path: &std::path::Path) -> (u32, u32, Vec<[f32; 4]>) {
    let img = image::open(path).unwrap().to_rgba32f();
    let (w, h) = img.dimensions();
    (w, h, img.pixels().map(|p| p.0).collect())
}

/// Bakes `quad-over-plane`'s floor with `technique` and returns the RMSE of its lightmap
/// against the closed form at the texels, and how many texels it held.
fn bake_against_closed_form(technique: &str, size: u32) -> (f64, usize) {
    let dir = temp_dir(&format!("bake-{technique}"));
    let side = size.to_string();
    let out = xtask(&[
        "bake",
        "--scene",
        "quad-over-plane",
        "--mesh",
        "floor",
        "--size",
        &side,
        "--technique",
        technique,
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_success(&out);
    let (w, h, v) = read_exr(&dir.join("visibility.exr"));
    let (_, _, p) = read_exr(&dir.join("position.exr"));
    assert_eq!((w, h), (size, size));
    let (mut sq, mut n) = (0.0f64, 0usize);
    for (v, p) in v.iter().zip(&p) {
        if p[3] == 0.0 {
            continue;
        }
        let at = glam::Vec3::new(p[0], p[1], p[2]);
        assert!(at.y.abs() < 1e-5, "a floor texel at {at}");
        sq += (f64::from(v[0]) - quad_over_plane_visibility(at)).powi(2);
        n += 1;
    }
    std::fs::remove_dir_all(&dir).ok();
    ((sq / n.max(1) as f64).sqrt(), n)
}

/// `bake` writes the floor's lightmap in its layout, and the lightmap's V agrees with the
/// closed form at every texel within each preset's RMSE budget for `quad-over-plane` (the
/// reference at 64 samples, and three of the SSM family, whose budgets differ by an order of
/// magnitude).
#[test]
fn bake_agrees_with_the_closed_form_at_the_texels() {
    for technique in ["ref-64", "ssm-backprojection", "ssm-contours", "pcss"] {
        let (rmse, texels) = bake_against_closed_form(technique, 40);
        assert_eq!(
            texels,
            40 * 40,
            "the floor's layout covers its whole lightmap"
        );
        let preset = shadow_presets::preset(technique).unwrap();
        let budget = (preset.budget)("quad-over-plane").unwrap();
        println!("{technique}: rmse {rmse:.5} (budget {:.5})", budget.rmse);
        assert!(
            rmse <= budget.rmse,
            "{technique}: rmse {rmse} above {}",
            budget.rmse
        );
    }
}

/// A technique that needs a camera refuses texels with its reason; an unknown mesh names the
/// meshes that have a layout; a zero size is refused.
#[test]
fn bake_refusals_say_why() {
    let dir = temp_dir("bake-refusals");
    let d = dir.to_str().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["bake", "--scene", "quad-over-plane", "--out", d];
        args.extend_from_slice(extra);
        let out = xtask(&args);
        assert!(!out.status.success());
        String::from_utf8_lossy(&out.stderr).to_string()
    };
    let e = run(&[
        "--mesh",
        "floor",
        "--size",
        "16",
        "--technique",
        "ssm-adaptive",
    ]);
    assert!(e.contains("no camera"), "{e}");
    let e = run(&["--mesh", "ceiling", "--size", "16"]);
    assert!(e.contains("meshes with them: floor"), "{e}");
    let e = run(&["--mesh", "floor", "--size", "0"]);
    assert!(e.contains("--size 0"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
