//! The single-ray occlusion query on the reference's own segments, both traversals:
//!
//!     cargo run --release -p shadow-ref --example query_bench -- [SCENE] [WIDTH] [HEIGHT] [DIR]
//!
//! SCENE is a built-in or corpus scene name. With DIR, the segments and the scene's triangles
//! are also written there as `<SCENE>-rays.bin` and `<SCENE>-triangles.bin` (little-endian f32:
//! origin, unit direction, length per ray; three corners per triangle) for
//! `scripts/embree_peer.py DIR SCENE`, which answers the same segments with Embree.
//!
//! Prints rays per second on one thread for the reference's trace phase answering the segments
//! (best of eight) and for the single-ray query alone on the wide tree and on the `obvhs`
//! CWBVH (best of six), and fails when the two queries' answers differ on any segment.

use std::time::Instant;

use glam::Vec3;
use shadow_core::prelude::*;
use shadow_ref::Reference;

/// Origin, unit direction, length and the receiver's triangle.
type Segment = (Vec3, Vec3, f32, u32);

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene = args.first().map_or("bunny", String::as_str);
    let w: u32 = args.get(1).map_or(Ok(160), |s| s.parse())?;
    let h: u32 = args.get(2).map_or(Ok(120), |s| s.parse())?;
    let setup = shadow_scenes::builtin(scene)?;
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), w, h)?;
    let r = Reference::stratified(64, 1)?;
    let r_prepared = r.prepare_reference(setup.scene.clone(), setup.lights[0].clone())?;
    let segs = r_prepared.segments(&view);
    if let Some(dir) = args.get(3) {
        export(std::path::Path::new(dir), scene, &setup, &segs)?;
    }
    // The reference's whole trace phase (sampling, offsets, beam culling, queries) answering
    // the same segments, on one thread.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let mut trace = f64::INFINITY;
    for _ in 0..8 {
        let est = pool.install(|| r_prepared.estimate(&view, Outputs::VISIBILITY))?;
        let secs = est
            .stats
            .phases
            .iter()
            .find(|p| p.name == "trace")
            .map_or(f64::INFINITY, |p| p.seconds);
        trace = trace.min(secs);
    }
    let bvh = r_prepared.bvh();
    let time = |f: &dyn Fn(&Segment) -> bool| {
        let mut best = f64::INFINITY;
        let mut blocked = 0;
        for _ in 0..6 {
            let t0 = Instant::now();
            blocked = segs.iter().filter(|s| f(s)).count();
            best = best.min(t0.elapsed().as_secs_f64());
        }
        (segs.len() as f64 / best / 1e6, blocked)
    };
    let (wide, wb) = time(&|s| bvh.occluded(s.0, s.1, s.2, s.3));
    let (cw, cb) = time(&|s| bvh.occluded_cwbvh(s.0, s.1, s.2, s.3));
    let differ = segs
        .iter()
        .filter(|s| bvh.occluded(s.0, s.1, s.2, s.3) != bvh.occluded_cwbvh(s.0, s.1, s.2, s.3))
        .count();
    println!(
        "{scene} {w}x{h}: {} segments, {:.1}% blocked; reference trace {:.2} M rays/s; single-ray query: wide tree {wide:.2} M rays/s, CWBVH {cw:.2} M rays/s ({:.2}x); {differ} answers differ",
        segs.len(),
        100.0 * wb as f64 / segs.len().max(1) as f64,
        segs.len() as f64 / trace / 1e6,
        wide / cw
    );
    if differ > 0 || wb != cb {
        return Err("the two traversals disagree".into());
    }
    Ok(())
}

/// Writes the segments and the triangles for the Embree peer (see the module docs).
fn export(
    dir: &std::path::Path,
    scene: &str,
    setup: &shadow_io::load::SceneSetup,
    segs: &[Segment],
) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let mut rays = Vec::with_capacity(segs.len() * 28);
    for (o, d, t, _) in segs {
        for v in o.to_array().into_iter().chain(d.to_array()).chain([*t]) {
            rays.extend_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(dir.join(format!("{scene}-rays.bin")), rays)?;
    let mut tris = Vec::new();
    for t in 0..setup.scene.triangle_count() {
        for p in setup.scene.triangle(t) {
            for v in p.to_array() {
                tris.extend_from_slice(&v.to_le_bytes());
            }
        }
    }
    std::fs::write(dir.join(format!("{scene}-triangles.bin")), tris)
}
