//! A profiling driver: prepares one technique on one built-in scene and runs a given number of
//! estimates, nothing else, so that a profiler's count for `RUNS = 1` minus its count for
//! `RUNS = 0` is the cost of exactly one estimate (`scripts/dcs_instructions.sh` does this under
//! `valgrind --tool=callgrind`):
//!
//!     cargo run --release -p shadow-dcs --example dcs_estimates -- [SCENE] [SIZE] [TECHNIQUE] [RUNS]
//!
//! `TECHNIQUE` is a DCS preset name (`dcs-64` by default), `reference` (the reference on the
//! samples of `dcs-64`: 64 stratified samples, seed 1, as `dcs_bench` compares them), or
//! `stratified-N` / `reference-N` (the `dcs-64` configuration with `N` stratified samples, and
//! the reference on the same samples, as `dcs_bench SCENE SIZE N` compares them), or
//! `interleaved-N` / `reference-interleaved-N` (the same with 4 x 4 interleaved sets). Prints the
//! best wall time of the runs and, for a DCS preset, the counters of the last one, which tell
//! two builds apart when they should do the same work (pairs, covered updates).
//! `DCS_LIGHT_SCALE=K` in the environment scales the scene's rectangle light's sides by `K`.

use shadow_core::prelude::*;
use shadow_dcs::Dcs;
use shadow_ref::Reference;

mod common;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene = args.first().map_or("bunny", String::as_str);
    let size: u32 = args.get(1).map_or(Ok(512), |s| s.parse())?;
    let name = args.get(2).map_or("dcs-64", String::as_str);
    let runs: u32 = args.get(3).map_or(Ok(1), |s| s.parse())?;
    let (setup, view) = common::scene_and_view(scene, size)?;
    let count = |prefix: &str| -> Result<Option<u32>, String> {
        name.strip_prefix(prefix)
            .map(|n| n.parse().map_err(|_| format!("{name}: not {prefix}N")))
            .transpose()
    };
    // `interleaved-N`: 4 x 4 interleaved sets, as the paper samples (section 5).
    let interleaved = SamplingStrategy::Interleaved { tile: 4 };
    let technique: Box<dyn ShadowTechnique> = if let Some(n) = count("reference-interleaved-")? {
        Box::new(Reference::same_samples(LightSampler::new(
            interleaved,
            n,
            1,
        )?))
    } else if let Some(n) = count("interleaved-")? {
        Box::new(Dcs::new(n, interleaved, 1)?)
    } else if let Some(n) = count("reference-")? {
        let sampler = LightSampler::new(SamplingStrategy::Stratified, n, 1)?;
        Box::new(Reference::same_samples(sampler))
    } else if let Some(n) = count("stratified-")? {
        Box::new(Dcs::new(n, SamplingStrategy::Stratified, 1)?)
    } else if name == "reference" {
        let sampler = LightSampler::new(SamplingStrategy::Stratified, 64, 1)?;
        Box::new(Reference::same_samples(sampler))
    } else {
        (common::preset(
            name,
            "`reference`, `reference-N`, `stratified-N`, `interleaved-N` or `reference-interleaved-N`",
        )?
        .make)(1)
    };
    let prepared = technique.prepare(setup.scene.clone(), setup.lights[0].clone())?;
    let (best, last) = common::best_of(runs, prepared.as_ref(), &view)?;
    match last {
        Some(e) => {
            println!("{name} on {scene} {size}x{size}: best of {runs} runs {best:.4} s");
            let counters: Vec<String> = e
                .stats
                .counters
                .iter()
                .map(|(k, v)| format!("{k}={v}"))
                .collect();
            if !counters.is_empty() {
                println!("{}", counters.join(" "));
            }
        }
        None => println!("{name} on {scene} {size}x{size}: prepared, no estimate"),
    }
    Ok(())
}
