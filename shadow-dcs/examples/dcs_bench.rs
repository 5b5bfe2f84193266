//! DCS against the reference with the same samples, in one process:
//!
//!     cargo run --release -p shadow-dcs --example dcs_bench -- [SCENE] [SIZE] [SAMPLES] [RUNS]
//!
//! `SAMPLES` is a number of stratified samples (the `dcs-64` configuration at 64) or the name
//! of a DCS preset (`dcs-64-interleaved`, `dcs-64-discrete`, ...).
//!
//! Prints the best-of-`RUNS` wall time of each (all threads), DCS's phase times and counters of
//! its last run, the ratio and the per-sample agreement; fails when agreement is below 99.9%
//! (below the preset's own bound for a named preset: 99% for `dcs-64-discrete`).
//!
//! `DCS_LIGHT_SCALE=K` in the environment scales the scene's rectangle light's sides by `K`
//! (`bunny`'s penumbrae, and with them DCS's pairs, grow with the light).

use shadow_core::prelude::*;
use shadow_dcs::Dcs;
use shadow_ref::Reference;

mod common;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene = args.first().map_or("bunny", String::as_str);
    let size: u32 = args.get(1).map_or(Ok(512), |s| s.parse())?;
    let samples = args.get(2).map_or("64", String::as_str);
    let runs: u32 = args.get(3).map_or(Ok(5), |s| s.parse())?;
    let (setup, view) = common::scene_and_view(scene, size)?;
    let light = setup.lights[0].clone();
    let mut min_agreement = 0.999;
    let dcs: Box<dyn ShadowTechnique> = match samples.parse::<u32>() {
        Ok(n) => Box::new(Dcs::new(n, SamplingStrategy::Stratified, 1)?),
        Err(_) => {
            let preset = common::preset(samples, "a sample count")?;
            if let Some(a) = (preset.budget)(scene).and_then(|b| b.min_sample_agreement) {
                min_agreement = a;
            }
            (preset.make)(1)
        }
    };
    let prepared_dcs = dcs.prepare(setup.scene.clone(), light.clone())?;
    let sampler = dcs.light_sampler().ok_or("no sampler")?.clone();
    let n = sampler.count();
    let r = Reference::same_samples(sampler).prepare(setup.scene.clone(), light)?;
    let best = |t: &dyn PreparedShadows| -> Result<(f64, Estimate), Box<dyn std::error::Error>> {
        let (secs, last) = common::best_of(runs.max(1), t, &view)?;
        Ok((secs, last.ok_or("no estimate")?))
    };
    let (td, ed) = best(prepared_dcs.as_ref())?;
    let (tr, er) = best(r.as_ref())?;
    let m = shadow_metrics::compare(&ed.visibility, &er.visibility)?;
    for p in &ed.stats.phases {
        print!("{} {:.4}s  ", p.name, p.seconds);
    }
    println!();
    for (k, v) in &ed.stats.counters {
        print!("{k}={v} ");
    }
    println!();
    let agree = m.sample_agreement.unwrap_or(0.0);
    println!(
        "{scene} {size}x{size}, {samples} ({n} samples): DCS {td:.4}s, reference {tr:.4}s, DCS is {:.2}x the reference; agreement {agree:.7}",
        tr / td
    );
    if agree < min_agreement {
        return Err(format!("per-sample agreement below {min_agreement}").into());
    }
    Ok(())
}
