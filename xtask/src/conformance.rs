//! `cargo xtask conformance`: the main job. Every preset on every supported built-in scene,
//! against the reference on the same view samples; a table, `report.md`, `report.json`,
//! `report.html` (self-contained: every image and a time-error plot per scene, [`crate::html`])
//! and per case images (visibility, signed error, shaded, FLIP map). FLIP ([`crate::flip`])
//! compares each shaded image with the reference's.

use std::fmt::Write as _;
use std::path::PathBuf;

use clap::Args;
use serde_json::json;
use shadow_conformance::conformance::{
    BUDGET_RESOLUTION, CaseReport, CurvePoint, Outcome, ReceiverMode, SceneContext, SuiteConfig,
    reference_curve, reference_time_at, run_case,
};
use shadow_conformance::lights::EveryLight;
use shadow_core::visibility::VisibilityImage;
use shadow_io::image_io::{shaded_image, write_error_png, write_visibility_png};
use shadow_metrics::compare;
use shadow_scenes::{BUILTIN_SCENES, builtin};

use crate::common::{Machine, machine, progress, write_json};
use crate::ensure_dir;
use crate::flip::{Flip, flip};
use crate::html::{self, Picture};

fn picture(caption: &str, path: PathBuf) -> Picture {
    Picture {
        caption: caption.into(),
        path,
    }
}

fn save(img: &image::RgbImage, path: &std::path::Path) -> Result<(), String> {
    img.save(path)
        .map_err(|e| format!("writing {}: {e}", path.display()))
}

#[derive(Args)]
pub struct ConformanceArgs {
    /// Scenes to run (comma-separated built-in or corpus names, or `corpus` for every corpus
    /// scene; default: all built-in scenes).
    #[arg(long, value_delimiter = ',')]
    scenes: Vec<String>,
    /// Add every scene of the corpus of real meshes (`cargo xtask scenes` lists them).
    #[arg(long)]
    corpus: bool,
    /// Presets to run (comma-separated; default: all registered presets).
    #[arg(long, value_delimiter = ',')]
    techniques: Vec<String>,
    /// Output directory.
    #[arg(long, default_value = "out/conformance")]
    out: PathBuf,
    /// Image width (budgets' max-error bounds hold at the default 128x96).
    #[arg(long, default_value_t = BUDGET_RESOLUTION.0)]
    width: u32,
    /// Image height.
    #[arg(long, default_value_t = BUDGET_RESOLUTION.1)]
    height: u32,
    /// Samples per pixel of the reference.
    #[arg(long, default_value_t = 1024)]
    ref_samples: u32,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Skip the determinism and convergence re-runs.
    #[arg(long)]
    quick: bool,
    /// Where the receivers come from: `camera` (the built-in rasterizer), `gbuffer` (the same
    /// surfaces as another renderer's float G-buffer with its camera) or `points` (shuffled
    /// points with normals, no camera). A technique that needs a camera refuses `points` with
    /// its reason.
    #[arg(long, default_value = "camera", value_parser = ReceiverMode::parse)]
    receivers: ReceiverMode,
}

/// The scenes of a run, in order: the built-in ones named (all of them when no scene is
/// named), then the corpus scenes named or, with `corpus`, all of them.
fn conformance_scenes(named: &[String], corpus: bool) -> Vec<String> {
    let wanted = |s: &str| named.iter().any(|x| x == s);
    let builtin_all = named.is_empty();
    let mut scenes: Vec<String> = BUILTIN_SCENES
        .iter()
        .filter(|s| builtin_all || wanted(s))
        .map(|s| (*s).to_string())
        .collect();
    scenes.extend(
        shadow_scenes::corpus::corpus_scene_names()
            .into_iter()
            .filter(|s| corpus || wanted(s)),
    );
    scenes
}

/// Reference sample counts of the equal-error speed-up curve.
const CURVE: [u32; 6] = [1, 4, 16, 64, 256, 1024];

/// The report's table of multi-light scenes: each light's RMSE (with who shadowed it where the
/// preset refused it) and the summed direct light's relative RMSE, per preset.
fn every_light_section(md: &mut String, cases: &[(String, String, EveryLight)]) {
    if cases.is_empty() {
        return;
    }
    writeln!(md, "\n## Every light\n\nScenes with several lights: every light shadowed at once; each light's V against the reference's for that light (RMSE; `->` names the fallback where the preset refused the light), and the direct light summed over the lights against the reference's from the same samples (relative RMSE, and its bound).\n\n| technique | scene | lights (RMSE) | summed direct |\n|---|---|---|---|").ok();
    for (technique, scene, e) in cases {
        let lights: Vec<String> = e
            .lights
            .iter()
            .map(|l| {
                let by = if l.fallback_because.is_some() {
                    format!(" -> {}", l.technique)
                } else {
                    String::new()
                };
                let skipped = if l.skipped { " skipped" } else { "" };
                format!(
                    "{} {:?}{by}{skipped} {:.4}",
                    l.index, l.kind, l.metrics.rmse
                )
            })
            .collect();
        let direct = match (e.direct_relative_rmse, e.direct_tolerance) {
            (Some(r), Some(t)) => format!("{r:.4} (bound {t:.4})"),
            _ => "-".into(),
        };
        writeln!(
            md,
            "| {technique} | {scene} | {} | {direct} |",
            lights.join(", ")
        )
        .ok();
    }
}

pub fn run(a: ConformanceArgs) -> Result<(), String> {
    let presets = shadow_presets::registry();
    for t in &a.techniques {
        shadow_presets::preset(t)?;
    }
    for s in &a.scenes {
        if !shadow_scenes::is_named_scene(s) && s != "corpus" {
            return Err(format!(
                "unknown scene `{s}`; valid names: {}, the corpus scenes `cargo xtask scenes` \
                 lists, and `corpus` for all of them",
                BUILTIN_SCENES.join(", ")
            ));
        }
    }
    let corpus = a.corpus || a.scenes.iter().any(|s| s == "corpus");
    let scenes = conformance_scenes(&a.scenes, corpus);
    let chosen: Vec<_> = presets
        .iter()
        .filter(|p| a.techniques.is_empty() || a.techniques.iter().any(|t| t == p.name))
        .collect();
    let cfg = SuiteConfig {
        width: a.width,
        height: a.height,
        ref_samples: a.ref_samples,
        seed: a.seed,
        extra_checks: !a.quick,
        receivers: a.receivers,
    };
    ensure_dir(&a.out)?;
    let pb = progress((scenes.len() * (chosen.len() + 1)) as u64, "conformance");
    let m = machine();
    let name_width = chosen.iter().map(|p| p.name.len()).max().unwrap_or(9);
    let mut report = Report::new(&a, &m, name_width, &scenes);
    for scene in &scenes {
        pb.set_message(format!("{scene}: reference"));
        let ctx = SceneContext::new(builtin(scene).map_err(|e| e.to_string())?, cfg)?;
        let mut run = SceneRun::new(&ctx, a.out.join(scene), scene)?;
        pb.inc(1);
        for p in &chosen {
            pb.set_message(format!("{scene}: {}", p.name));
            let outcome = run_case(p, &ctx);
            pb.inc(1);
            report.case(p.name, &mut run, outcome)?;
        }
        report.html_scenes.push(run.html);
    }
    pb.finish_and_clear();
    report.write(&a, &m, cfg)
}

/// One scene's reference and what each case on it is compared and shown with.
struct SceneRun<'a> {
    ctx: &'a SceneContext,
    dir: PathBuf,
    scene: &'a str,
    curve: Vec<CurvePoint>,
    reference: &'a VisibilityImage,
    ref_secs: f64,
    reference_shaded: image::RgbImage,
    html: html::Scene,
}

impl<'a> SceneRun<'a> {
    /// The reference and its curve, their images written under `dir`.
    fn new(ctx: &'a SceneContext, dir: PathBuf, scene: &'a str) -> Result<Self, String> {
        let curve = reference_curve(ctx, &CURVE)?;
        ensure_dir(&dir)?;
        let (reference, ref_secs) = ctx.reference()?;
        write_visibility_png(&dir.join("reference.png"), reference).map_err(|e| e.to_string())?;
        let reference_shaded = shade(ctx, reference)?;
        save(&reference_shaded, &dir.join("reference-shaded.png"))?;
        let html = html::Scene {
            name: scene.to_string(),
            reference: vec![
                picture("visibility", dir.join("reference.png")),
                picture("shaded", dir.join("reference-shaded.png")),
            ],
            curve: curve.iter().map(|c| (c.seconds, c.rmse)).collect(),
            cases: Vec::new(),
        };
        Ok(Self {
            ctx,
            dir,
            scene,
            curve,
            reference,
            ref_secs: *ref_secs,
            reference_shaded,
            html,
        })
    }

    /// Writes a case's visibility, signed error, shaded and FLIP images; its FLIP.
    fn case_images(&self, case_dir: &PathBuf, r: &CaseReport) -> Result<Flip, String> {
        ensure_dir(case_dir)?;
        write_visibility_png(&case_dir.join("visibility.png"), &r.estimate)
            .map_err(|e| e.to_string())?;
        write_error_png(&case_dir.join("error.png"), &r.estimate, &r.reference, 0.5)
            .map_err(|e| e.to_string())?;
        let shaded = shade(self.ctx, &r.estimate)?;
        save(&shaded, &case_dir.join("shaded.png"))?;
        let perceptual = flip(&self.reference_shaded, &shaded, &self.ctx.view)?;
        save(&perceptual.map, &case_dir.join("flip.png"))?;
        Ok(perceptual)
    }

    /// The case's RMSE against the independent reference: for a sample-based technique the
    /// same-samples error is its own approximation only (0 for exact DCS).
    fn independent_rmse(&self, r: &CaseReport) -> Result<f64, String> {
        Ok(if r.same_samples {
            compare(&r.estimate, self.reference)
                .map_err(|e| e.to_string())?
                .rmse
        } else {
            r.metrics.rmse
        })
    }
}

/// The scene's diffuse shading under `v`.
fn shade(
    ctx: &SceneContext,
    v: &dyn shadow_core::visibility::VisibilityBuffer,
) -> Result<image::RgbImage, String> {
    shaded_image(ctx.setup.scene.as_ref(), &ctx.view, ctx.light().as_ref(), v)
        .map_err(|e| e.to_string())
}

/// An empty HTML case with its status.
fn html_case(technique: &str, status: String) -> html::Case {
    html::Case {
        technique: technique.to_string(),
        status,
        rmse: None,
        penumbra_rmse: None,
        flip: None,
        seconds: None,
        independent_rmse: None,
        speedup: String::new(),
        pictures: Vec::new(),
    }
}

/// The report as it fills: the console table, `report.md`, the JSON rows, the HTML scenes.
struct Report {
    md: String,
    rows: Vec<serde_json::Value>,
    failures: Vec<String>,
    html_scenes: Vec<html::Scene>,
    every_light: Vec<(String, String, EveryLight)>,
    name_width: usize,
    scene_width: usize,
}

impl Report {
    /// The report's header, printed and written.
    fn new(a: &ConformanceArgs, m: &Machine, name_width: usize, scenes: &[String]) -> Self {
        let mut md = String::new();
        writeln!(md, "# Conformance report\n\n{} x {} pixels, reference {} samples per pixel, seed {}. Machine: {} ({} threads), {}.\n", a.width, a.height, a.ref_samples, a.seed, m.cpu, m.threads, m.date).ok();
        writeln!(md, "Speed-up: the reference's time at the technique's RMSE against the independent reference (the stratified reference at {} samples with its own seed, never the same-samples one a sample-based technique's budget is checked against), by log-log interpolation of the reference at {CURVE:?} samples measured against the same independent reference, divided by the technique's time; `>` when the technique beats every reference run.\n", a.ref_samples).ok();
        writeln!(md, "FLIP: the mean FLIP (NVIDIA's perceptual difference, Andersson et al. 2020, at 67 pixels per degree) of the technique's shaded image against the reference's, over the pixels holding a view sample.\n").ok();
        writeln!(md, "| technique | scene | RMSE | penumbra RMSE | FLIP | bias | max | share > 0.1 | phases (s) | speed-up | status |\n|---|---|---|---|---|---|---|---|---|---|---|").ok();
        // The first column fits the longest preset name, the second the longest scene name
        // (corpus names run to 34 characters).
        let name_width = name_width.max(9);
        let scene_width = scenes.iter().map(String::len).max().unwrap_or(5).max(22);
        println!(
            "{:<name_width$} {:<scene_width$} {:>8} {:>8} {:>7} {:>8} {:>6} {:>7} {:>28} {:>9}  status",
            "technique",
            "scene",
            "RMSE",
            "pen.RMSE",
            "FLIP",
            "bias",
            "max",
            ">0.1",
            "phases (s)",
            "speed-up"
        );
        Self {
            md,
            rows: Vec::new(),
            failures: Vec::new(),
            html_scenes: Vec::new(),
            every_light: Vec::new(),
            name_width,
            scene_width,
        }
    }

    /// Records one case's outcome.
    fn case(&mut self, name: &str, run: &mut SceneRun, outcome: Outcome) -> Result<(), String> {
        let (nw, sw, scene) = (self.name_width, self.scene_width, run.scene);
        match outcome {
            Outcome::Unsupported { reason } => {
                println!("{name:<nw$} {scene:<sw$} unsupported: {reason}");
                writeln!(
                    self.md,
                    "| {name} | {scene} | | | | | | | | unsupported: {reason} |"
                )
                .ok();
                self.rows.push(json!({"technique": name, "scene": scene, "status": "unsupported", "reason": reason}));
                run.html
                    .cases
                    .push(html_case(name, format!("unsupported: {reason}")));
            }
            Outcome::Failed { error } => {
                println!("{name:<nw$} {scene:<sw$} FAILED: {error}");
                writeln!(
                    self.md,
                    "| {name} | {scene} | | | | | | | | FAILED: {error} |"
                )
                .ok();
                self.failures.push(format!("{name} on {scene}: {error}"));
                self.rows.push(
                    json!({"technique": name, "scene": scene, "status": "failed", "error": error}),
                );
                run.html
                    .cases
                    .push(html_case(name, format!("FAILED: {error}")));
            }
            Outcome::Ran(r) => self.ran(name, run, &r)?,
        }
        Ok(())
    }

    /// A case that ran: its images, its table row, its JSON row and its HTML case.
    fn ran(&mut self, name: &str, run: &mut SceneRun, r: &CaseReport) -> Result<(), String> {
        let scene = run.scene;
        let case_dir = run.dir.join(name);
        let perceptual = run.case_images(&case_dir, r)?;
        let independent_rmse = run.independent_rmse(r)?;
        let speedup_at_equal_error =
            reference_time_at(&run.curve, independent_rmse).map(|t| t / r.seconds);
        let speedup = match speedup_at_equal_error {
            Some(x) => format!("{x:.2}x"),
            None => format!(
                ">{:.2}x",
                run.curve.last().map_or(0.0, |c| c.seconds) / r.seconds
            ),
        };
        for v in &r.violations {
            self.failures.push(format!("{name} on {scene}: {v}"));
        }
        let cells = case_cells(name, scene, r, perceptual.mean, speedup);
        self.print_row(&cells);
        writeln!(self.md, "| {} |", cells.join(" | ")).ok();
        if let Some(e) = &r.every_light {
            self.every_light
                .push((name.to_string(), scene.to_string(), e.clone()));
        }
        let mut row = serde_json::to_value(r).map_err(|e| e.to_string())?;
        row["status"] = json!(if r.passed() { "ok" } else { "fail" });
        row["rmse_against_independent_reference"] = json!(independent_rmse);
        row["flip"] = json!(perceptual.mean);
        row["speedup_at_equal_error"] = json!(speedup_at_equal_error);
        row["reference_curve"] = json!(run.curve);
        row["reference_seconds_high"] = json!(run.ref_secs);
        self.rows.push(row);
        let mut case = html_case(name, cells[cells.len() - 1].clone());
        case.rmse = Some(r.metrics.rmse);
        case.penumbra_rmse = r.metrics.penumbra_rmse;
        case.flip = Some(perceptual.mean);
        case.seconds = Some(r.seconds);
        case.independent_rmse = Some(independent_rmse);
        case.speedup = cells[cells.len() - 2].clone();
        case.pictures = ["visibility", "error", "shaded", "flip"]
            .iter()
            .map(|n| picture(n, case_dir.join(format!("{n}.png"))))
            .collect();
        run.html.cases.push(case);
        Ok(())
    }

    /// One row of the console table, its columns aligned with the header's.
    fn print_row(&self, cells: &[String]) {
        let widths = [
            self.name_width,
            self.scene_width,
            8,
            8,
            7,
            8,
            6,
            7,
            28,
            9,
            0,
        ];
        let line: Vec<String> = cells
            .iter()
            .zip(widths)
            .enumerate()
            .map(|(k, (c, w))| {
                if k < 2 {
                    format!("{c:<w$}")
                } else {
                    format!("{c:>w$}")
                }
            })
            .collect();
        println!("{}", line.join(" "));
    }

    /// Writes `report.md`, `report.html` and `report.json`; an error listing the failures.
    fn write(mut self, a: &ConformanceArgs, m: &Machine, cfg: SuiteConfig) -> Result<(), String> {
        every_light_section(&mut self.md, &self.every_light);
        writeln!(self.md, "\nImages per case in `<scene>/<technique>/`: `visibility.png`, `error.png` (signed error, blue = too dark, red = too bright, full scale 0.5), `shaded.png` and `flip.png` (FLIP's error map, magma); the reference in `<scene>/reference.png`. All of them, the table and a time-error plot per scene in `report.html`.").ok();
        html::write_report(
            &a.out.join("report.html"),
            "Conformance report",
            &format!(
                "{} x {} pixels, reference {} samples per pixel, seed {}. Machine: {} ({} threads), {}. Images: visibility, signed error (blue too dark, red too bright, full scale 0.5), shaded, FLIP map. Click a column to sort.",
                a.width, a.height, a.ref_samples, a.seed, m.cpu, m.threads, m.date
            ),
            &self.html_scenes,
        )?;
        std::fs::write(a.out.join("report.md"), self.md).map_err(|e| e.to_string())?;
        write_json(
            &a.out.join("report.json"),
            &json!({"machine": m, "config": cfg, "cases": self.rows}),
        )?;
        println!("\nreport: {}", a.out.join("report.md").display());
        if self.failures.is_empty() {
            Ok(())
        } else {
            Err(format!(
                "{} conformance failures:\n{}",
                self.failures.len(),
                self.failures.join("\n")
            ))
        }
    }
}

/// A case's cells in the table: metrics, phases, speed-up and status (with its notes).
fn case_cells(name: &str, scene: &str, r: &CaseReport, flip: f64, speedup: String) -> Vec<String> {
    let phases = r
        .prepare_stats
        .phases
        .iter()
        .chain(&r.estimate_stats.phases)
        .map(|ph| format!("{} {:.3}", ph.name, ph.seconds))
        .collect::<Vec<_>>()
        .join(", ");
    let status = if r.passed() {
        "ok".to_string()
    } else {
        format!("FAIL: {}", r.violations.join("; "))
    };
    let status = if r.notes.is_empty() {
        status
    } else {
        format!("{status} (note: {})", r.notes.join("; "))
    };
    let pen = r
        .metrics
        .penumbra_rmse
        .map_or("-".to_string(), |v| format!("{v:.4}"));
    vec![
        name.to_string(),
        scene.to_string(),
        format!("{:.4}", r.metrics.rmse),
        pen,
        format!("{:.4}", flip),
        format!("{:+.4}", r.metrics.bias),
        format!("{:.3}", r.metrics.max_abs),
        format!("{:.4}", r.metrics.share_over_0_1),
        phases,
        speedup,
        status,
    ]
}
