//! `cargo xtask`: the workspace's commands.
//!
//! * `scenes`: list the built-in scenes.
//! * `render`: view samples (and a technique's visibility) of a built-in scene or a file.
//! * `conformance`: the main job, every preset on every supported built-in scene, with a report.
//! * `bench`: run time against error, reference curves and scaling sweeps, CSV/JSON and plots.
//! * `stress`: the numerical-stability suite against every preset.

mod bench;
mod common;
mod conformance;
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
    /// Run every preset on every supported built-in scene against the reference.
    Conformance(conformance::ConformanceArgs),
    /// Benchmark run time against error; scaling sweeps; CSV, JSON and plots.
    Bench(bench::BenchArgs),
    /// The numerical-stability suite against every preset.
    Stress(stress::StressArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Scenes => common::list_scenes(),
        Command::Render(a) => render::run(a),
        Command::Conformance(a) => conformance::run(a),
        Command::Bench(a) => bench::run(a),
        Command::Stress(a) => stress::run(a),
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
