//! `cargo xtask bench-receivers`: what receivers handed in cost against the camera path
//! (issue 67). For each scene and preset, the median time of making the receivers and
//! shadowing them (prepare and estimate): the camera path rasterizes its view samples; a
//! foreign G-buffer (the same surfaces, rounded as a float G-buffer, with the camera) and
//! shuffled points without a camera are snapped onto the scene (`shadow_core::receivers`)
//! and, for points, put back in order by the technique. The ratio foreign / camera is
//! reported per preset as the median and the worst over the scenes.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use serde::Serialize;
use shadow_conformance::conformance::ReceiverMode;
use shadow_core::prelude::*;

use crate::bench_summary::median;
use crate::common::{machine, progress, write_json};
use crate::ensure_dir;

#[derive(Args)]
pub struct BenchReceiversArgs {
    /// Output directory.
    #[arg(long, default_value = "out/bench-receivers")]
    out: PathBuf,
    /// Scenes (comma-separated).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "quad-over-plane,bunny,contact,cornell-box,spot-self-shadow,mesh-light,interior"
    )]
    scenes: Vec<String>,
    /// Presets (comma-separated): one per technique family by default.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "ref-64,dcs-64,pcss,ssm-contours,afsm-256,auto-0.01"
    )]
    techniques: Vec<String>,
    /// Image width.
    #[arg(long, default_value_t = 512)]
    width: u32,
    /// Image height.
    #[arg(long, default_value_t = 512)]
    height: u32,
    /// Timed runs per point (median reported), after one warm-up.
    #[arg(long, default_value_t = 3)]
    repeats: usize,
    /// Also write the table between the markers of this Markdown page (`docs/benchmarks.md`).
    #[arg(long)]
    write_docs: Option<PathBuf>,
}

/// The modes compared, the camera path first.
const MODES: [ReceiverMode; 3] = [
    ReceiverMode::Camera,
    ReceiverMode::Gbuffer,
    ReceiverMode::Points,
];

/// Markers of the table in the page `--write-docs` names.
const BEGIN: &str = "<!-- bench-receivers:begin -->";
const END: &str = "<!-- bench-receivers:end -->";

/// One (scene, preset, mode): median seconds of receivers, and of prepare plus estimate.
#[derive(Debug, Clone, Serialize)]
struct Timing {
    scene: String,
    technique: String,
    mode: &'static str,
    receivers_seconds: f64,
    shadow_seconds: f64,
    /// Why the technique refused these receivers, when it did.
    refused: Option<String>,
}

/// Median seconds of `f` over `repeats` runs after a warm-up, and its last answer.
fn timed<T>(repeats: usize, mut f: impl FnMut() -> Result<T, String>) -> Result<(f64, T), String> {
    let mut runs = Vec::new();
    let mut last = f()?;
    for _ in 0..repeats {
        let t0 = Instant::now();
        last = f()?;
        runs.push(t0.elapsed().as_secs_f64());
    }
    Ok((median(runs), last))
}

/// The timings of `technique` on `setup` in every mode.
fn time_scene(
    a: &BenchReceiversArgs,
    setup: &shadow_io::SceneSetup,
    preset: &shadow_presets::Preset,
) -> Result<Vec<Timing>, String> {
    let scene = setup.scene.as_ref();
    let camera = setup.camera_or_default();
    let render =
        || ViewSamples::render(scene, &camera, a.width, a.height).map_err(|e| e.to_string());
    let rendered = render()?;
    let mut out = Vec::new();
    for mode in MODES {
        let (receivers_seconds, view) = match mode {
            ReceiverMode::Camera => timed(a.repeats, render)?,
            m => timed(a.repeats, || m.receivers(scene, rendered.clone()))?,
        };
        let shadow = || {
            let t = (preset.make)(1);
            let lights = &setup.lights[..1];
            let all = PreparedLights::prepare(t.as_ref(), None, setup.scene.clone(), lights)?;
            all.estimate(&view, Outputs::VISIBILITY).map(|_| ())
        };
        let (shadow_seconds, refused) = match shadow() {
            Err(e) if e.unsupported_reason().is_some() => (f64::NAN, Some(e.to_string())),
            Err(e) => return Err(format!("{} on {}: {e}", preset.name, setup.name)),
            Ok(()) => (
                timed(a.repeats, || shadow().map_err(|e| e.to_string()))?.0,
                None,
            ),
        };
        out.push(Timing {
            scene: setup.name.clone(),
            technique: preset.name.to_string(),
            mode: mode.label(),
            receivers_seconds,
            shadow_seconds,
            refused,
        });
    }
    Ok(out)
}

pub fn run(a: BenchReceiversArgs) -> Result<(), String> {
    let presets = a
        .techniques
        .iter()
        .map(|t| shadow_presets::preset(t))
        .collect::<Result<Vec<_>, _>>()?;
    let setups = a
        .scenes
        .iter()
        .map(|s| shadow_scenes::builtin(s).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, _>>()?;
    ensure_dir(&a.out)?;
    let pb = progress((setups.len() * presets.len()) as u64, "receivers");
    let mut timings = Vec::new();
    for setup in &setups {
        for p in &presets {
            pb.set_message(format!("{}: {}", setup.name, p.name));
            timings.extend(time_scene(&a, setup, p)?);
            pb.inc(1);
        }
    }
    pb.finish_and_clear();
    let table = summary(&a, &presets, &timings);
    println!("{table}");
    std::fs::write(a.out.join("summary.md"), &table).map_err(|e| e.to_string())?;
    write_json(
        &a.out.join("timings.json"),
        &serde_json::json!({"machine": machine(), "width": a.width, "height": a.height,
            "repeats": a.repeats, "timings": timings}),
    )?;
    if let Some(page) = &a.write_docs {
        crate::bench_summary::replace_between(page, BEGIN, END, &table)?;
    }
    Ok(())
}

/// The ratio foreign / camera of receivers plus shadowing, per preset and foreign mode: the
/// median and the worst over the scenes the camera path runs, and the scenes a foreign mode
/// was refused on where the camera path was not.
fn summary(
    a: &BenchReceiversArgs,
    presets: &[shadow_presets::Preset],
    timings: &[Timing],
) -> String {
    let m = machine();
    let mut md = String::new();
    writeln!(
        md,
        "`cargo xtask bench-receivers` ({} x {}, median of {} runs after a warm-up; {}; {} \
         threads; {}). Time = making the receivers (camera: rasterizing; G-buffer and points: \
         snapping a foreign float G-buffer or shuffled points onto the scene) + prepare + \
         estimate of the first light. Ratio = foreign / camera over the scenes {}.\n",
        a.width,
        a.height,
        a.repeats,
        m.cpu,
        m.threads,
        m.date,
        a.scenes.join(", ")
    )
    .ok();
    writeln!(
        md,
        "| technique | G-buffer median | G-buffer worst | points median | points worst | refused (camera path not) |\n|---|---|---|---|---|---|"
    )
    .ok();
    let total = |t: &Timing| t.receivers_seconds + t.shadow_seconds;
    for p in presets {
        let mut cells = Vec::new();
        let mut refused = Vec::new();
        for mode in [ReceiverMode::Gbuffer, ReceiverMode::Points] {
            let ratios: Vec<f64> = timings
                .iter()
                .filter(|t| t.technique == p.name && t.mode == mode.label())
                .filter_map(|t| {
                    let camera = timings.iter().find(|c| {
                        c.technique == t.technique && c.scene == t.scene && c.mode == "camera"
                    })?;
                    if camera.refused.is_some() {
                        return None;
                    }
                    if t.refused.is_some() {
                        refused.push(format!("{} ({})", t.scene, mode.label()));
                        return None;
                    }
                    Some(total(t) / total(camera))
                })
                .collect();
            let worst = ratios.iter().copied().fold(f64::NAN, f64::max);
            if ratios.is_empty() {
                cells.extend(["-".to_string(), "-".to_string()]);
            } else {
                cells.push(format!("{:.2}x", median(ratios)));
                cells.push(format!("{worst:.2}x"));
            }
        }
        let refused = if refused.is_empty() {
            "-".to_string()
        } else {
            refused.join(", ")
        };
        writeln!(md, "| {} | {} | {refused} |", p.name, cells.join(" | ")).ok();
    }
    md
}
