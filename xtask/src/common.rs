//! Shared helpers: resolving scenes and techniques, machine facts, progress bars.

use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use shadow_core::prelude::*;
use shadow_io::SceneSetup;
use shadow_io::load::{LoadLimits, load_scene};
use shadow_scenes::{BUILTIN_SCENES, builtin};

/// A built-in scene by name, or a scene file by path. A file without an emissive mesh gets a
/// square light above its bounds (said on stderr) unless `own_light` (the caller brings one).
/// With `emissive_as_geometry`, a file's emissive meshes load as ordinary geometry.
pub fn resolve_scene(
    name: &str,
    own_light: bool,
    emissive_as_geometry: bool,
) -> Result<SceneSetup, String> {
    if BUILTIN_SCENES.contains(&name) || shadow_scenes::corpus::is_corpus_scene(name) {
        if emissive_as_geometry {
            return Err(format!(
                "--emissive-as-geometry applies to scene files; `{name}` is a built-in scene"
            ));
        }
        return builtin(name).map_err(|e| e.to_string());
    }
    let path = Path::new(name);
    if !path.exists() {
        return Err(format!(
            "`{name}` is neither a built-in scene, a corpus scene nor a file; built-in scenes: \
             {} (corpus scenes: `cargo xtask scenes`)",
            BUILTIN_SCENES.join(", ")
        ));
    }
    let limits = LoadLimits {
        emissive_as_geometry,
        ..LoadLimits::default()
    };
    let mut setup = load_scene(path, &limits).map_err(|e| e.to_string())?;
    for w in &setup.warnings {
        eprintln!("note: {w}");
    }
    if setup.lights.is_empty() && !own_light {
        let b = setup.scene.bounds();
        let d = b.diagonal().max(1e-3);
        let c = Vec3::new(b.center().x, b.max.y + 0.8 * d, b.center().z);
        let light = RectLight::facing(
            c,
            Vec3::NEG_Y,
            0.25 * d,
            0.25 * d,
            Radiance::Constant(Vec3::ONE),
        )
        .map_err(|e| e.to_string())?;
        eprintln!(
            "note: `{name}` has no emissive mesh; using a square light of side {:.3} at {c}",
            0.25 * d
        );
        setup.lights.push(Arc::new(light));
    }
    Ok(setup)
}

/// A preset by name, or a family by name, optionally with another sample count
/// ([`shadow_presets::resolve`]).
pub fn resolve_technique(
    name: &str,
    samples: Option<u32>,
    seed: u64,
) -> Result<Box<dyn ShadowTechnique>, String> {
    // A preset with a fixed count, asked for another: name the command line's way round it.
    if let (Some(n), Ok(p)) = (samples, shadow_presets::preset(name))
        && p.with_samples.is_none()
    {
        let family = shadow_presets::family_of(p.name);
        if shadow_presets::resolve(family, Some(n), seed).is_ok() {
            return Err(format!(
                "technique `{name}` has a fixed sample count; use its family: `--technique \
                 {family} --samples {n}`"
            ));
        }
    }
    shadow_presets::resolve(name, samples, seed).map_err(|e| match e {
        TechniqueError::InvalidInput(m) => m,
        e => e.to_string(),
    })
}

/// Prints the built-in scenes.
pub fn list_scenes() -> Result<(), String> {
    println!(
        "{:<24} {:>9} {:>8} {:<10} what it exercises",
        "scene", "triangles", "closed", "light"
    );
    // One line per built-in scene, in order (a new scene without one does not compile).
    let what: [&str; BUILTIN_SCENES.len()] = [
        "square light over a parallel square occluder (closed form)",
        "penumbra fusion of overlapping occluders (survey Fig. 6)",
        "large light close to a small occluder (survey Fig. 7)",
        "Stanford bunny on a plane",
        "closed mesh (Spot) shadowing itself",
        "thin open grass blades, depth complexity far above 255",
        "objects resting on the floor (contact shadows)",
        "panels with opacity 0.3 to 0.7",
        "RGB image on a rectangle light",
        "omni-directional sphere light inside a room",
        "open room, light recessed in a ceiling fixture, two spheres",
        "glTF file's KHR_lights_punctual spot light over a table and a ball",
        "folded mesh light (two one-sided faces) over a box and a sphere",
        "furnished room under a ceiling panel: large light, many occluders",
        "the furnished room lit by a window-sized light in a wall",
    ];
    for (name, what) in BUILTIN_SCENES.iter().zip(what) {
        let s = builtin(name).map_err(|e| e.to_string())?;
        let comps = s.scene.topology().components();
        let closed = comps.iter().filter(|c| c.closed).count();
        println!(
            "{:<24} {:>9} {:>8} {:<10} {}",
            name,
            s.scene.triangle_count(),
            format!("{closed}/{}", comps.len()),
            format!("{:?}", s.lights[0].kind()),
            what
        );
    }
    println!(
        "\nScaled and translated variants are built by the stress suite (`cargo xtask stress`)."
    );
    println!(
        "\nThe corpus of real meshes (`shadow_scenes::corpus`, {} scenes: each mesh at a largest \
         extent of 1 m on a floor, under a tilted rectangle or a disk light of a quarter or the \
         whole of that extent), by name in render, conformance and bench, all of them with \
         `--corpus` (conformance, bench, stress) or `conformance --scenes corpus`: \
         corpus-<mesh>-<light>\n  meshes: {}\n  lights: {}",
        shadow_scenes::corpus::corpus_scene_names().len(),
        shadow_scenes::corpus::CORPUS_MESHES.join(", "),
        shadow_scenes::corpus::CORPUS_LIGHTS.join(", ")
    );
    Ok(())
}

/// Facts about this machine, recorded beside every measurement.
#[derive(Debug, Clone, Serialize)]
pub struct Machine {
    /// CPU model.
    pub cpu: String,
    /// Logical cores.
    pub cores: usize,
    /// rayon threads used.
    pub threads: usize,
    /// UTC date and time.
    pub date: String,
    /// Build profile.
    pub profile: &'static str,
}

pub fn machine() -> Machine {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    let date = std::process::Command::new("date")
        .args(["-u", "+%Y-%m-%d %H:%M UTC"])
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|| "unknown".into());
    Machine {
        cpu,
        cores: std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1),
        threads: rayon::current_num_threads(),
        date,
        profile: if cfg!(debug_assertions) {
            "debug"
        } else {
            "release"
        },
    }
}

/// A progress bar over `n` steps (hidden when stderr is not a terminal).
pub fn progress(n: u64, what: &str) -> ProgressBar {
    let pb = ProgressBar::new(n);
    pb.set_style(
        ProgressStyle::with_template("{spinner} {msg:<40} [{bar:30}] {pos}/{len} {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    pb.set_message(what.to_string());
    pb.enable_steady_tick(Duration::from_millis(200));
    pb
}

/// Writes JSON to `path`.
pub fn write_json(path: &Path, value: &impl Serialize) -> Result<(), String> {
    let text = serde_json::to_string_pretty(value).map_err(|e| e.to_string())?;
    std::fs::write(path, text).map_err(|e| format!("writing {}: {e}", path.display()))
}

/// Occlusion rays per second per thread from a technique's estimate stats, when it counts rays.
pub fn rays_per_second_per_thread(stats: &Stats) -> Option<f64> {
    let rays = stats.counter(shadow_ref::RefCounter::OcclusionRays)?;
    let threads = stats
        .gauge(shadow_ref::RefGauge::Threads)
        .unwrap_or(1)
        .max(1);
    let secs = stats.phase_seconds(shadow_ref::RefPhase::Trace)?;
    (rays > 0 && secs > 0.0).then(|| rays as f64 / secs / threads as f64)
}
