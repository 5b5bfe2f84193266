//! `cargo xtask bench`: run time against error for every preset and its sample sweep, with the
//! reference at 1 to 4096 samples as the baseline curve; scaling sweeps over triangle count,
//! light size, image size and sample count; the reference's occlusion throughput. Times are
//! medians of `--repeats` runs after one warm-up; the machine, date and threads are recorded.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use clap::Args;
use glam::Vec3;
use serde::Serialize;
use serde_json::json;
use shadow_conformance::conformance::run_technique;
use shadow_core::image_io::shaded_image;
use shadow_core::metrics::compare;
use shadow_core::prelude::*;
use shadow_core::procedural::{floor, uv_sphere};
use shadow_core::scenes::{BUILTIN_SCENES, builtin};
use shadow_ref::Reference;

use crate::common::{machine, progress, rays_per_second_per_thread, write_json};
use crate::ensure_dir;
use crate::flip::flip;
use crate::plot::{Series, log_log, pareto_front};

#[derive(Args)]
pub struct BenchArgs {
    /// Output directory.
    #[arg(long, default_value = "out/bench")]
    out: PathBuf,
    /// Scenes of the time-error study (comma-separated).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "quad-over-plane,overlapping-occluders,bunny,grass"
    )]
    scenes: Vec<String>,
    /// Presets (comma-separated; default all).
    #[arg(long, value_delimiter = ',')]
    techniques: Vec<String>,
    /// Image width of the time-error study.
    #[arg(long, default_value_t = 128)]
    width: u32,
    /// Image height of the time-error study.
    #[arg(long, default_value_t = 96)]
    height: u32,
    /// Timed runs per point (median reported), after one warm-up.
    #[arg(long, default_value_t = 3)]
    repeats: usize,
    /// Smaller sweeps (for a quick look).
    #[arg(long)]
    quick: bool,
    /// Also write the bunny occlusion rays and triangles for `scripts/embree_peer.py`.
    #[arg(long)]
    export_rays: bool,
}

#[derive(Debug, Clone, Serialize)]
struct Point {
    scene: String,
    technique: String,
    samples: Option<u32>,
    rmse: f64,
    penumbra_rmse: Option<f64>,
    /// Mean FLIP of the shaded image against the ground truth's ([`crate::flip`]).
    flip: f64,
    bias: f64,
    max_abs: f64,
    seconds: f64,
    runs: Vec<f64>,
}

#[derive(Debug, Clone, Serialize)]
struct ScalingPoint {
    sweep: String,
    technique: String,
    x: f64,
    seconds: f64,
    triangles: usize,
    pixels: usize,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Warm-up plus `repeats` timed runs of a fresh technique: (median seconds, runs, last estimate).
fn timed(
    make: &dyn Fn() -> Box<dyn ShadowTechnique>,
    setup: &SceneSetup,
    view: &ViewSamples,
    repeats: usize,
) -> Result<(f64, Vec<f64>, Estimate), String> {
    let mut last = None;
    let mut runs = Vec::new();
    for k in 0..=repeats {
        let mut t = make();
        let t0 = Instant::now();
        let (e, _, _) = run_technique(t.as_mut(), setup, setup.lights[0].clone(), view)
            .map_err(|e| e.to_string())?;
        let s = t0.elapsed().as_secs_f64();
        if k > 0 {
            runs.push(s);
        }
        last = Some(e);
    }
    Ok((median(runs.clone()), runs, last.expect("at least one run")))
}

/// Technique parameters without the sample count and name, to recognise identical sweeps.
fn without_samples(mut v: serde_json::Value) -> serde_json::Value {
    if let Some(o) = v.as_object_mut() {
        o.remove("samples");
        o.remove("name");
    }
    v
}

fn sphere_scene(rings: u32) -> SceneSetup {
    let mut b = SceneBuilder::new();
    let f = floor(6.0, 0.0);
    b.push_mesh(MeshDesc::new(f.0, f.1)).expect("valid");
    let s = uv_sphere(Vec3::new(0.0, 0.6, 0.0), 0.5, rings, 2 * rings);
    b.push_mesh(MeshDesc::new(s.0, s.1)).expect("valid");
    SceneSetup {
        name: format!("sphere-{rings}"),
        scene: Arc::new(b.build().expect("valid")),
        lights: vec![Arc::new(
            RectLight::facing(
                Vec3::new(0.3, 2.5, 0.2),
                Vec3::NEG_Y,
                1.0,
                1.0,
                Radiance::Constant(Vec3::ONE),
            )
            .expect("valid"),
        )],
        camera: Some(
            Camera::look_at(
                Vec3::new(0.0, 2.0, 3.0),
                Vec3::new(0.0, 0.3, 0.0),
                Vec3::Y,
                0.9,
            )
            .expect("valid"),
        ),
        aspect: None,
        warnings: vec![],
        punctual: vec![],
    }
}

fn light_size_scene(side: f32) -> Result<SceneSetup, String> {
    let mut s = builtin("quad-over-plane").map_err(|e| e.to_string())?;
    s.lights = vec![Arc::new(
        RectLight::facing(
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::NEG_Y,
            side,
            side,
            Radiance::Constant(Vec3::ONE),
        )
        .map_err(|e| e.to_string())?,
    )];
    s.name = format!("light-{side}");
    Ok(s)
}

pub fn run(a: BenchArgs) -> Result<(), String> {
    for s in &a.scenes {
        if !BUILTIN_SCENES.contains(&s.as_str()) {
            return Err(format!(
                "unknown scene `{s}`; valid names: {}",
                BUILTIN_SCENES.join(", ")
            ));
        }
    }
    for t in &a.techniques {
        shadow_conformance::preset(t)?;
    }
    let presets: Vec<_> = shadow_conformance::registry()
        .into_iter()
        .filter(|p| a.techniques.is_empty() || a.techniques.iter().any(|t| t == p.name))
        .collect();
    ensure_dir(&a.out)?;
    let m = machine();
    let seed = 1u64;
    let ref_counts: Vec<u32> = if a.quick {
        vec![1, 4, 16, 64, 256]
    } else {
        vec![1, 4, 16, 64, 256, 1024, 4096]
    };
    let sweep: Vec<u32> = if a.quick {
        vec![4, 16, 64]
    } else {
        vec![4, 16, 64, 256, 1024]
    };
    let truth_samples = if a.quick { 1024 } else { 4096 };
    let mut points: Vec<Point> = Vec::new();
    let pb = progress(
        (a.scenes.len() * (ref_counts.len() + presets.len() * sweep.len())) as u64,
        "time against error",
    );
    for scene in &a.scenes {
        let setup = builtin(scene).map_err(|e| e.to_string())?;
        let view = ViewSamples::render(
            setup.scene.as_ref(),
            &setup.camera_or_default(),
            a.width,
            a.height,
        )
        .map_err(|e| e.to_string())?;
        pb.set_message(format!("{scene}: ground truth"));
        let truth = Reference::stratified(truth_samples, 0xfeed).map_err(|e| e.to_string())?;
        let truth = run_technique(&truth, &setup, setup.lights[0].clone(), &view)
            .map_err(|e| e.to_string())?
            .0
            .visibility;
        let shade = |v: &VisibilityImage| {
            shaded_image(setup.scene.as_ref(), &view, setup.lights[0].as_ref(), v)
                .map_err(|e| e.to_string())
        };
        let truth_shaded = shade(&truth)?;
        let mut record = |technique: &str,
                          samples: Option<u32>,
                          make: &dyn Fn() -> Box<dyn ShadowTechnique>|
         -> Result<(), String> {
            let (secs, runs, est) = timed(make, &setup, &view, a.repeats)?;
            let mt = compare(&est.visibility, &truth).map_err(|e| e.to_string())?;
            let perceptual = flip(&truth_shaded, &shade(&est.visibility)?, &view)?;
            points.push(Point {
                scene: scene.clone(),
                technique: technique.into(),
                samples,
                rmse: mt.rmse,
                penumbra_rmse: mt.penumbra_rmse,
                flip: perceptual.mean,
                bias: mt.bias,
                max_abs: mt.max_abs,
                seconds: secs,
                runs,
            });
            Ok(())
        };
        for &n in &ref_counts {
            pb.set_message(format!("{scene}: reference {n}"));
            record("reference", Some(n), &|| {
                Box::new(Reference::stratified(n, seed).expect("valid count"))
            })?;
            pb.inc(1);
        }
        let mut swept: Vec<(serde_json::Value, String)> = Vec::new();
        for p in &presets {
            pb.set_message(format!("{scene}: {}", p.name));
            let caps = (p.make)(seed).capabilities();
            if caps
                .check(setup.scene.as_ref(), setup.lights[0].as_ref())
                .is_err()
            {
                pb.inc(sweep.len() as u64);
                continue;
            }
            match p.with_samples {
                Some(f) => {
                    // Presets that differ only in their default sample count share one sweep.
                    let make =
                        |n: u32| f(n, seed).map_err(|e| format!("{} at {n} samples: {e}", p.name));
                    let params = without_samples(make(sweep[0])?.parameters());
                    if let Some(first) = swept
                        .iter()
                        .find(|(q, _)| *q == params)
                        .map(|(_, n)| n.clone())
                    {
                        println!("{scene}: {} shares the sample sweep of {first}", p.name);
                        pb.inc(sweep.len() as u64);
                        continue;
                    }
                    swept.push((params, p.name.to_string()));
                    for &n in &sweep {
                        // A count out of the preset's range is an error here, before timing.
                        make(n)?;
                        record(p.name, Some(n), &|| f(n, seed).expect("checked above"))?;
                        pb.inc(1);
                    }
                }
                None => {
                    record(p.name, None, &|| (p.make)(seed))?;
                    pb.inc(sweep.len() as u64);
                }
            }
        }
    }
    pb.finish_and_clear();

    // Scaling sweeps: every preset at its own parameters.
    let mut scaling: Vec<ScalingPoint> = Vec::new();
    let rings: Vec<u32> = if a.quick {
        vec![8, 32, 64]
    } else {
        vec![8, 16, 32, 64, 128, 256]
    };
    let sides: Vec<f32> = vec![0.1, 0.25, 0.5, 1.0, 2.0, 4.0];
    let widths: Vec<u32> = if a.quick {
        vec![64, 128, 256]
    } else {
        vec![64, 128, 256, 512]
    };
    let pb = progress(
        (presets.len() * (rings.len() + sides.len() + widths.len())) as u64,
        "scaling",
    );
    for p in &presets {
        let make = || (p.make)(seed);
        for &r in &rings {
            let s = sphere_scene(r);
            let v =
                ViewSamples::render(s.scene.as_ref(), &s.camera_or_default(), a.width, a.height)
                    .map_err(|e| e.to_string())?;
            let (secs, ..) = timed(&make, &s, &v, a.repeats)?;
            scaling.push(ScalingPoint {
                sweep: "triangles".into(),
                technique: p.name.into(),
                x: s.scene.triangle_count() as f64,
                seconds: secs,
                triangles: s.scene.triangle_count(),
                pixels: v.valid_count(),
            });
            pb.inc(1);
        }
        for &side in &sides {
            let s = light_size_scene(side)?;
            let v =
                ViewSamples::render(s.scene.as_ref(), &s.camera_or_default(), a.width, a.height)
                    .map_err(|e| e.to_string())?;
            let (secs, ..) = timed(&make, &s, &v, a.repeats)?;
            scaling.push(ScalingPoint {
                sweep: "light-size".into(),
                technique: p.name.into(),
                x: side as f64,
                seconds: secs,
                triangles: s.scene.triangle_count(),
                pixels: v.valid_count(),
            });
            pb.inc(1);
        }
        for &w in &widths {
            let s = builtin("bunny").map_err(|e| e.to_string())?;
            let v = ViewSamples::render(s.scene.as_ref(), &s.camera_or_default(), w, w * 3 / 4)
                .map_err(|e| e.to_string())?;
            let (secs, ..) = timed(&make, &s, &v, a.repeats)?;
            scaling.push(ScalingPoint {
                sweep: "image-size".into(),
                technique: p.name.into(),
                x: v.len() as f64,
                seconds: secs,
                triangles: s.scene.triangle_count(),
                pixels: v.valid_count(),
            });
            pb.inc(1);
        }
    }
    pb.finish_and_clear();

    // Throughput of the reference's occlusion query on bunny.
    let bunny = builtin("bunny").map_err(|e| e.to_string())?;
    let size = if a.quick { 256 } else { 512 };
    let view = ViewSamples::render(bunny.scene.as_ref(), &bunny.camera_or_default(), size, size)
        .map_err(|e| e.to_string())?;
    let throughput = |threads: usize| -> Result<f64, String> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| e.to_string())?;
        pool.install(|| {
            let mut best: f64 = 0.0;
            for _ in 0..=a.repeats {
                let r = Reference::stratified(64, seed).expect("valid");
                let (e, _, _) = run_technique(&r, &bunny, bunny.lights[0].clone(), &view)
                    .map_err(|e| e.to_string())?;
                best = best.max(rays_per_second_per_thread(&e.stats).unwrap_or(0.0));
            }
            Ok(best)
        })
    };
    let one = throughput(1)?;
    let all = throughput(m.threads)?;
    println!(
        "bunny {size}x{size}, 64 samples: {:.2} M occlusion rays/s on one thread, {:.2} M rays/s per thread with {} threads",
        one / 1e6,
        all / 1e6,
        m.threads
    );
    let query = query_throughput(&bunny, &a, seed)?;
    println!(
        "bunny, {} identical segments, one thread: single-ray query {:.2} M rays/s (wide tree; {:.2} M rays/s on the CWBVH); reference trace with beam culling {:.2} M rays/s ({:.1}% occluded)",
        query.rays,
        query.rays_per_second / 1e6,
        query.cwbvh_rays_per_second / 1e6,
        query.reference_rays_per_second / 1e6,
        100.0 * query.occluded_share
    );

    // Files.
    let mut csv = format!(
        "# {} | {} threads | {} | {}x{} | ground truth: reference at {truth_samples} samples\nscene,technique,samples,rmse,penumbra_rmse,flip,bias,max_abs,seconds_median\n",
        m.cpu, m.threads, m.date, a.width, a.height
    );
    for p in &points {
        writeln!(
            csv,
            "{},{},{},{:.6},{},{:.6},{:.6},{:.5},{:.5}",
            p.scene,
            p.technique,
            p.samples.map_or(String::new(), |s| s.to_string()),
            p.rmse,
            p.penumbra_rmse.map_or(String::new(), |v| format!("{v:.6}")),
            p.flip,
            p.bias,
            p.max_abs,
            p.seconds
        )
        .ok();
    }
    std::fs::write(a.out.join("bench.csv"), csv).map_err(|e| e.to_string())?;
    let mut csv = format!(
        "# {} | {} threads | {}\nsweep,technique,x,seconds_median,triangles,valid_pixels\n",
        m.cpu, m.threads, m.date
    );
    for s in &scaling {
        writeln!(
            csv,
            "{},{},{},{:.5},{},{}",
            s.sweep, s.technique, s.x, s.seconds, s.triangles, s.pixels
        )
        .ok();
    }
    std::fs::write(a.out.join("scaling.csv"), csv).map_err(|e| e.to_string())?;
    write_json(
        &a.out.join("bench.json"),
        &json!({
            "machine": m, "width": a.width, "height": a.height, "repeats": a.repeats, "ground_truth_samples": truth_samples,
            "time_error": points, "scaling": scaling,
            "throughput": {"scene": "bunny", "size": size, "samples": 64, "rays_per_second_one_thread": one, "rays_per_second_per_thread_all": all, "threads": m.threads},
        "query_throughput": query,
        }),
    )?;
    for scene in &a.scenes {
        let mut series: Vec<Series> = Vec::new();
        let mut names: Vec<&str> = points
            .iter()
            .filter(|p| &p.scene == scene)
            .map(|p| p.technique.as_str())
            .collect();
        names.dedup();
        for n in names {
            series.push(Series {
                name: n.to_string(),
                points: points
                    .iter()
                    .filter(|p| &p.scene == scene && p.technique == n)
                    .map(|p| (p.seconds, p.rmse.max(1e-6)))
                    .collect(),
                dashed: false,
            });
        }
        let all: Vec<(f64, f64)> = series.iter().flat_map(|s| s.points.clone()).collect();
        series.push(Series {
            name: "Pareto front".into(),
            points: pareto_front(&all),
            dashed: true,
        });
        log_log(
            &a.out.join(format!("pareto-{scene}")),
            &format!("{scene}: error against time ({}x{})", a.width, a.height),
            "seconds (median)",
            "RMSE against the reference",
            &series,
        )?;
    }
    for (sweep, label) in [
        ("triangles", "triangles"),
        ("light-size", "light side (m)"),
        ("image-size", "pixels"),
    ] {
        let mut names: Vec<&str> = scaling
            .iter()
            .filter(|s| s.sweep == sweep)
            .map(|s| s.technique.as_str())
            .collect();
        names.dedup();
        let series: Vec<Series> = names
            .iter()
            .map(|n| Series {
                name: n.to_string(),
                points: scaling
                    .iter()
                    .filter(|s| s.sweep == sweep && s.technique == *n)
                    .map(|s| (s.x, s.seconds))
                    .collect(),
                dashed: false,
            })
            .collect();
        log_log(
            &a.out.join(format!("scaling-{sweep}")),
            &format!("scaling with {label}"),
            label,
            "seconds (median)",
            &series,
        )?;
    }
    // Samples sweep from the time-error points.
    let mut names: Vec<&str> = points
        .iter()
        .filter(|p| p.samples.is_some())
        .map(|p| p.technique.as_str())
        .collect();
    names.sort_unstable();
    names.dedup();
    let first = a.scenes.first().cloned().unwrap_or_default();
    let series: Vec<Series> = names
        .iter()
        .map(|n| Series {
            name: n.to_string(),
            points: points
                .iter()
                .filter(|p| p.scene == first && p.technique == *n)
                .filter_map(|p| p.samples.map(|s| (s as f64, p.seconds)))
                .collect(),
            dashed: false,
        })
        .collect();
    log_log(
        &a.out.join("scaling-samples"),
        &format!("scaling with samples per pixel ({first})"),
        "samples per pixel",
        "seconds (median)",
        &series,
    )?;
    println!("wrote {}", a.out.display());
    Ok(())
}

#[derive(Debug, Clone, Serialize)]
struct QueryThroughput {
    rays: usize,
    /// The single-ray BVH query alone (wide tree).
    rays_per_second: f64,
    /// The same query on `obvhs`'s CWBVH.
    cwbvh_rays_per_second: f64,
    /// The reference's trace phase (beam culling on) answering the same segments.
    reference_rays_per_second: f64,
    occluded_share: f64,
}

/// The BVH occlusion query alone, one thread, on the exact rays of `ref-64` for bunny at
/// 160x120 (the rays a peer ray tracer is given by `--export-rays`).
fn query_throughput(
    bunny: &SceneSetup,
    a: &BenchArgs,
    seed: u64,
) -> Result<QueryThroughput, String> {
    let view = ViewSamples::render(bunny.scene.as_ref(), &bunny.camera_or_default(), 160, 120)
        .map_err(|e| e.to_string())?;
    let r = Reference::stratified(64, seed)
        .map_err(|e| e.to_string())?
        .prepare_reference(bunny.scene.clone(), bunny.lights[0].clone())
        .map_err(|e| e.to_string())?;
    let segs = r.segments(&view);
    let bvh = r.bvh();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| e.to_string())?;
    let (best, cwbvh_best, occluded, trace_best) =
        pool.install(|| -> Result<(f64, f64, usize, f64), String> {
            let mut best = f64::INFINITY;
            let mut occluded = 0;
            for _ in 0..=a.repeats {
                let t0 = Instant::now();
                occluded = segs
                    .iter()
                    .filter(|(o, d, t, tri)| bvh.occluded(*o, *d, *t, *tri))
                    .count();
                best = best.min(t0.elapsed().as_secs_f64());
            }
            let mut cwbvh_best = f64::INFINITY;
            for _ in 0..=a.repeats {
                let t0 = Instant::now();
                let n = segs
                    .iter()
                    .filter(|(o, d, t, tri)| bvh.occluded_cwbvh(*o, *d, *t, *tri))
                    .count();
                cwbvh_best = cwbvh_best.min(t0.elapsed().as_secs_f64());
                if n != occluded {
                    return Err(format!("CWBVH query: {n} occluded, wide tree: {occluded}"));
                }
            }
            // The reference's whole trace phase (sampling, offsets, beam culling, queries) on the
            // same view answers the same segments.
            let mut trace_best = f64::INFINITY;
            for _ in 0..=a.repeats {
                let r = Reference::stratified(64, seed).map_err(|e| e.to_string())?;
                let (e, _, _) = run_technique(&r, bunny, bunny.lights[0].clone(), &view)
                    .map_err(|e| e.to_string())?;
                let secs = e
                    .stats
                    .phase_seconds(shadow_ref::reference::TRACE_PHASE)
                    .unwrap_or(f64::INFINITY);
                trace_best = trace_best.min(secs);
            }
            Ok((best, cwbvh_best, occluded, trace_best))
        })?;
    if a.export_rays {
        let mut rays = Vec::with_capacity(segs.len() * 28);
        for (o, d, t, _) in &segs {
            for v in [o.x, o.y, o.z, d.x, d.y, d.z, *t] {
                rays.extend_from_slice(&v.to_le_bytes());
            }
        }
        std::fs::write(a.out.join("bunny-rays.bin"), rays).map_err(|e| e.to_string())?;
        let mut tris = Vec::new();
        for t in 0..bunny.scene.triangle_count() {
            for p in bunny.scene.triangle(t) {
                for v in p.to_array() {
                    tris.extend_from_slice(&v.to_le_bytes());
                }
            }
        }
        std::fs::write(a.out.join("bunny-triangles.bin"), tris).map_err(|e| e.to_string())?;
        println!(
            "wrote {} rays and {} triangles for scripts/embree_peer.py",
            segs.len(),
            bunny.scene.triangle_count()
        );
    }
    Ok(QueryThroughput {
        rays: segs.len(),
        rays_per_second: segs.len() as f64 / best,
        cwbvh_rays_per_second: segs.len() as f64 / cwbvh_best,
        reference_rays_per_second: segs.len() as f64 / trace_best,
        occluded_share: occluded as f64 / segs.len().max(1) as f64,
    })
}
