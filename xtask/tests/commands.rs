//! The xtask commands a new user runs first, exercised through the built binary.

use std::path::PathBuf;
use std::process::Command;

fn xtask(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(args)
        .output()
        .expect("xtask runs")
}

/// `direct.exr` in `dir` is finite, non-negative and lit somewhere.
fn assert_direct_image(dir: &std::path::Path) {
    let direct = image::open(dir.join("direct.exr")).unwrap().to_rgba32f();
    assert!(
        direct
            .pixels()
            .all(|p| p.0.iter().all(|v| v.is_finite() && *v >= 0.0))
    );
    assert!(direct.pixels().any(|p| p.0[0] > 0.0));
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("xtask-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

#[test]
fn scenes_lists_every_builtin_scene() {
    let out = xtask(&["scenes"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for name in shadow_core::scenes::BUILTIN_SCENES {
        assert!(text.contains(name), "{name} missing from:\n{text}");
    }
}

#[test]
fn render_writes_view_samples_and_visibility() {
    let dir = temp_dir("render");
    let d = dir.to_str().unwrap();
    let out = xtask(&["render", "--scene", "bunny", "--width", "48", "--out", d]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in ["position.exr", "normal.exr", "stats.json"] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    assert!(!dir.join("visibility.exr").exists());
    let out = xtask(&[
        "render",
        "--scene",
        "bunny",
        "--technique",
        "ref",
        "--samples",
        "16",
        "--width",
        "48",
        "--out",
        d,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in ["visibility.exr", "visibility.png", "shaded.png"] {
        assert!(dir.join(f).is_file(), "{f} missing");
    }
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("stats.json")).unwrap()).unwrap();
    assert_eq!(stats["technique"], "ref-16");
    assert_eq!(stats["samples"], 16);
    assert_eq!(stats["width"], 48);
    assert!(
        stats["estimate"]["counters"]["occlusion-rays"]
            .as_u64()
            .unwrap()
            > 0
    );
    assert!(
        stats["occlusion_rays_per_second_per_thread"]
            .as_f64()
            .unwrap()
            > 0.0
    );
    let exr = image::open(dir.join("visibility.exr"))
        .unwrap()
        .to_rgba32f();
    assert_eq!(exr.width(), 48);
    assert!(
        exr.pixels()
            .all(|p| p.0.iter().all(|v| v.is_finite()) && (p.0[3] == 0.0 || p.0[3] == 1.0))
    );
    // Direct illumination from the reference: finite, non-negative, black on background.
    let out = xtask(&[
        "render",
        "--scene",
        "quad-over-plane",
        "--direct",
        "--samples",
        "16",
        "--width",
        "40",
        "--out",
        d,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_direct_image(&dir);
    assert!(dir.join("direct.png").is_file());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn unknown_names_are_errors_listing_the_valid_ones() {
    let dir = temp_dir("unknown");
    let d = dir.to_str().unwrap();
    let out = xtask(&["render", "--scene", "nope", "--out", d]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("quad-over-plane"));
    let out = xtask(&[
        "render",
        "--scene",
        "bunny",
        "--technique",
        "nope",
        "--out",
        d,
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("ref-64"));
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 51, item 1: a sample count outside a preset's range was a panic
/// ("preset sample counts are valid"); it is an error naming the count.
#[test]
fn samples_out_of_a_presets_range_are_errors_not_panics() {
    let dir = temp_dir("samples-range");
    let d = dir.to_str().unwrap();
    for (technique, samples) in [("ref", "0"), ("ref", "65537"), ("dcs-16", "0")] {
        let out = xtask(&[
            "render",
            "--scene",
            "quad-over-plane",
            "--technique",
            technique,
            "--samples",
            samples,
            "--width",
            "16",
            "--out",
            d,
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{technique} {samples}: {err}");
        assert!(!err.contains("panicked"), "{technique} {samples}: {err}");
        assert!(err.contains(samples), "{technique} {samples}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `--direct` with a sample-based technique shades from that technique's own per-sample
/// visibility (here DCS) and names it in `stats.json`; a technique without light samples says
/// why it cannot.
#[test]
fn direct_illumination_comes_from_the_chosen_sample_based_technique() {
    let dir = temp_dir("direct-dcs");
    let d = dir.to_str().unwrap();
    let out = xtask(&[
        "render",
        "--scene",
        "quad-over-plane",
        "--technique",
        "dcs-16",
        "--direct",
        "--width",
        "40",
        "--out",
        d,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("stats.json")).unwrap()).unwrap();
    assert_eq!(stats["direct_illumination"]["technique"], "dcs-16");
    assert_eq!(stats["direct_illumination"]["samples"], 16);
    assert_direct_image(&dir);
    let out = xtask(&[
        "render",
        "--scene",
        "quad-over-plane",
        "--technique",
        "pcss",
        "--direct",
        "--width",
        "16",
        "--out",
        d,
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("light samples"));
    std::fs::remove_dir_all(&dir).ok();
}
