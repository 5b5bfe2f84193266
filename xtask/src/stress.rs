//! `cargo xtask stress`: the numerical-stability suite against every registered preset.

use std::path::PathBuf;

use clap::Args;
use shadow_conformance::stress::{input_cases, known_limitation, technique_cases};

use crate::common::{machine, write_json};
use crate::ensure_dir;

#[derive(Args)]
pub struct StressArgs {
    /// Image width of the technique cases.
    #[arg(long, default_value_t = 96)]
    width: u32,
    /// Image height of the technique cases.
    #[arg(long, default_value_t = 72)]
    height: u32,
    /// Only these presets (comma-separated).
    #[arg(long, value_delimiter = ',')]
    techniques: Vec<String>,
    /// Run the far-away cases on every scene of the corpus of real meshes (default: its share,
    /// every mesh once).
    #[arg(long)]
    corpus: bool,
    /// Where to write stress.json.
    #[arg(long, default_value = "out/stress")]
    out: PathBuf,
}

pub fn run(a: StressArgs) -> Result<(), String> {
    let mut results = input_cases();
    let presets = shadow_presets::registry();
    let corpus = if a.corpus {
        shadow_scenes::corpus::corpus_scene_names()
    } else {
        shadow_scenes::corpus::corpus_share()
    };
    for p in &presets {
        if a.techniques.is_empty() || a.techniques.iter().any(|t| t == p.name) {
            results.extend(technique_cases(p, a.width, a.height, &corpus));
        }
    }
    let known = |r: &shadow_conformance::stress::StressResult| {
        presets
            .iter()
            .find(|p| p.name == r.technique)
            .and_then(|p| known_limitation(p, &r.case))
            .is_some()
    };
    println!("{:<42} {:<12} {:<7} detail", "case", "technique", "result");
    for r in &results {
        println!(
            "{:<42} {:<12} {:<7} {}",
            r.case,
            r.technique,
            if r.held {
                "held"
            } else if known(r) {
                "KNOWN"
            } else {
                "FAILED"
            },
            r.detail
        );
    }
    let failed = results.iter().filter(|r| !r.held && !known(r)).count();
    println!("\n{} held, {} failed", results.len() - failed, failed);
    ensure_dir(&a.out)?;
    write_json(
        &a.out.join("stress.json"),
        &serde_json::json!({"machine": machine(), "results": results}),
    )?;
    if failed > 0 {
        return Err(format!("{failed} stress cases failed"));
    }
    Ok(())
}
