//! Time against error of AFSM beside the reference on the same samples, per-phase GPU times
//! and the list statistics of the paper's Fig. 9 inlay, on the adapter the environment selects:
//! `cargo run --release -p shadow-afsm --example afsm_bench -- [scene] [width] [height] [N]
//! [exact|unculled|lut|stencil]`: exact plane tests on 4x4 interleaved sets (default), the same
//! without cluster culling, the plane lookup table of section 4.2 (one correlated set), or
//! exact tests with the silhouette stencil. The last line is a markdown table row (scene, AFSM
//! s, reference s, AFSM / reference, pairs tested, share of them empty, tiles culled, pairs
//! skipped after umbra) for `scripts/afsm_table.sh`.

use std::sync::Arc;
use std::time::Instant;

use shadow_afsm::Afsm;
use shadow_afsm::statistics::{AfsmCounter, AfsmGauge};
use shadow_core::prelude::*;
use shadow_core::stats::Counter;
use shadow_metrics::compare;
use shadow_ref::Reference;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let scene = args.get(1).map_or("bunny", String::as_str);
    let w: u32 = args.get(2).map_or(Ok(128), |s| s.parse())?;
    let h: u32 = args.get(3).map_or(Ok(96), |s| s.parse())?;
    let n: u32 = args.get(4).map_or(Ok(128), |s| s.parse())?;
    let setup = shadow_scenes::builtin(scene)?;
    let light = Arc::clone(&setup.lights[0]);
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), w, h)?;
    let mode = args.get(5).map_or("exact", String::as_str);
    let interleaved = SamplingStrategy::Interleaved { tile: 4 };
    let afsm = match mode {
        "exact" => Afsm::new(n, interleaved, 1)?,
        "unculled" => Afsm::new(n, interleaved, 1)?.without_cluster_culling(),
        "stencil" => Afsm::new(n, interleaved, 1)?.with_silhouette_stencil(),
        "lut" => Afsm::new(n, SamplingStrategy::Correlated, 1)?.with_lut()?,
        other => {
            return Err(format!("unknown mode `{other}`: exact, unculled, lut or stencil").into());
        }
    };
    let t0 = Instant::now();
    let afsm_prepared = afsm.prepare_afsm(setup.scene.clone(), Arc::clone(&light))?;
    let t_prepare = t0.elapsed().as_secs_f64();
    afsm_prepared.estimate(&view, Outputs::VISIBILITY)?; // warm-up
    let t0 = Instant::now();
    let est = afsm_prepared.estimate(&view, Outputs::VISIBILITY)?;
    let t_afsm = t0.elapsed().as_secs_f64();
    let r = Reference::same_samples(afsm.light_sampler().expect("soft").clone());
    let t0 = Instant::now();
    let r_prepared = r.prepare(setup.scene.clone(), Arc::clone(&light))?;
    let t_ref_prepare = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let re = r_prepared.estimate(&view, Outputs::VISIBILITY)?;
    let t_ref = t0.elapsed().as_secs_f64();
    let m = compare(&est.visibility, &re.visibility)?;
    // Error against the converged answer (1024 stratified samples): equal for both at equal N.
    let truth = Reference::stratified(1024, 77)?;
    let truth_prepared = truth.prepare(setup.scene.clone(), Arc::clone(&light))?;
    let truth = truth_prepared
        .estimate(&view, Outputs::VISIBILITY)?
        .visibility;
    let e_afsm = compare(&est.visibility, &truth)?.rmse;
    let e_ref = compare(&re.visibility, &truth)?.rmse;
    println!("adapter: {}", afsm_prepared.adapter());
    println!(
        "{scene} {w}x{h} N={n} {mode}: afsm {t_afsm:.3} s, reference (same samples, CPU) {t_ref:.3} s, ratio {:.2}",
        t_ref / t_afsm
    );
    println!(
        "prepare (once per scene and light, not in the ratio): afsm {t_prepare:.3} s, \
         reference {t_ref_prepare:.3} s"
    );
    println!(
        "agreement with the same-samples reference {:.6}, rmse {:.5}; rmse against 1024 \
         stratified samples: afsm {e_afsm:.5}, same-samples reference {e_ref:.5}",
        m.sample_agreement.unwrap_or(0.0),
        m.rmse
    );
    for p in &est.stats.phases {
        match p.device_seconds {
            Some(device) => println!(
                "  phase {:<16} {:.4} s (device {device:.4} s by timestamp queries)",
                p.name, p.seconds
            ),
            None => println!("  phase {:<16} {:.4} s", p.name, p.seconds),
        }
    }
    let occupied = est.stats.counter(AfsmCounter::ListsOccupied).unwrap();
    let listed = est.stats.counter(AfsmCounter::ReceiversListed).unwrap();
    let side = est.stats.gauge(AfsmGauge::MapSide).unwrap();
    println!(
        "  lists: {occupied} occupied of {} ({:.1}%), average length {:.2}, longest {}",
        side * side,
        100.0 * occupied as f64 / (side * side) as f64,
        listed as f64 / occupied.max(1) as f64,
        est.stats.gauge(AfsmGauge::ListLengthMax).unwrap()
    );
    for &k in AfsmCounter::ALL {
        println!("  {} {}", k.name(), est.stats.counter(k).unwrap_or(0));
    }
    let count = |k: AfsmCounter| est.stats.counter(k).unwrap_or(0);
    println!(
        "| {scene} | {t_afsm:.3} | {t_ref:.3} | {:.1} | {} | {:.0}% | {} | {} |",
        t_afsm / t_ref,
        count(AfsmCounter::PairsTested),
        100.0 * count(AfsmCounter::PairsEmpty) as f64
            / count(AfsmCounter::PairsTested).max(1) as f64,
        count(AfsmCounter::TilesCulled),
        count(AfsmCounter::PairsAfterUmbra),
    );
    Ok(())
}
