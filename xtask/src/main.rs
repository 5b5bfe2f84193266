//! `cargo xtask`: the workspace's commands.
//!
//! * `scenes`: list the built-in scenes.
//! * `render`: view samples (and a technique's visibility) of a built-in scene or a file.
//! * `bake`: a lightmap over a mesh's texture layout, from every light.
//! * `conformance`: the main job, every preset on every supported built-in scene, with a report.
//! * `bench`: run time against error, reference curves and scaling sweeps, CSV/JSON and plots.
//! * `bench-receivers`: receivers handed in (a G-buffer, points) against the camera path.
//! * `stress`: the numerical-stability suite against every preset.
//! * `budgets`: the adaptive reference against the uniform one at equal error, and the ratio
//!   estimator of direct light against eq. 6.

mod auto_study;
mod bake;
mod bench;
mod bench_receivers;
mod bench_summary;
mod budgets;
mod common;
mod conformance;
mod flip;
mod html;
mod overrides;
mod plot;
mod render;
mod stress;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "xtask", about = "Soft-shadow workspace automation")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the built-in scenes.
    Scenes,
    /// Render view samples (position.exr, normal.exr, stats.json) and, with a technique, its
    /// visibility (visibility.exr, visibility.png, shaded.png).
    Render(render::RenderArgs),
    /// Bake a lightmap: the texels of a mesh's texture layout (TEXCOORD_0) shadowed from every
    /// light (position.exr, normal.exr, visibility.exr, direct.exr with --direct).
    Bake(bake::BakeArgs),
    /// Run every preset on every supported built-in scene against the reference.
    Conformance(conformance::ConformanceArgs),
    /// Benchmark run time against error; scaling sweeps; CSV, JSON and plots.
    Bench(bench::BenchArgs),
    /// What receivers handed in (a foreign G-buffer, points) cost against the camera path.
    BenchReceivers(bench_receivers::BenchReceiversArgs),
    /// The numerical-stability suite against every preset.
    Stress(stress::StressArgs),
    /// The adaptive reference against the uniform one at equal error; the ratio estimator of
    /// direct light against eq. 6 at equal samples.
    Budgets(budgets::BudgetsArgs),
}

/// Marks a process that [`quiet_headless_vulkan`] started, so it never starts another.
const RESPAWNED: &str = "SHADOW_XTASK_RUNTIME_DIR_SET";

/// On a headless machine without `XDG_RUNTIME_DIR`, the Vulkan loader's window-system
/// platforms print `error: XDG_RUNTIME_DIR is invalid or not set` on every successful GPU run,
/// which a user reads as a failure. Setting the variable in this process would need `unsafe`
/// (`std::env::set_var`), so the command runs once more as a child with a private runtime
/// directory and hands back its exit code. `None` when nothing needs doing (the variable is a
/// directory, or this is the child).
fn quiet_headless_vulkan() -> Option<ExitCode> {
    let set =
        std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir());
    if set || std::env::var_os(RESPAWNED).is_some() {
        return None;
    }
    let dir = std::env::temp_dir().join(format!("shadow-xtask-runtime-{}", std::process::id()));
    std::fs::create_dir_all(&dir).ok()?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700)).ok()?;
    }
    let exe = std::env::current_exe().ok()?;
    // Not started: run here, with the note. Started: its exit code, whatever it is.
    let status = std::process::Command::new(exe)
        .args(std::env::args_os().skip(1))
        .env("XDG_RUNTIME_DIR", &dir)
        .env(RESPAWNED, "1")
        .status()
        .ok();
    std::fs::remove_dir_all(&dir).ok();
    let code = status?.code().unwrap_or(1);
    Some(ExitCode::from(u8::try_from(code).unwrap_or(1)))
}

fn main() -> ExitCode {
    if let Some(code) = quiet_headless_vulkan() {
        return code;
    }
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Scenes => common::list_scenes(),
        Command::Render(a) => render::run(a),
        Command::Bake(a) => bake::run(a),
        Command::Conformance(a) => conformance::run(a),
        Command::Bench(a) => bench::run(a),
        Command::BenchReceivers(a) => bench_receivers::run(a),
        Command::Stress(a) => stress::run(a),
        Command::Budgets(a) => budgets::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Creates `dir` (and parents).
fn ensure_dir(dir: &PathBuf) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("creating {}: {e}", dir.display()))
}
