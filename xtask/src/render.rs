//! `cargo xtask render`: view samples of a scene and, with a technique, its visibility.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use glam::Vec3;
use serde_json::json;
use shadow_core::prelude::*;
use shadow_core::stats::CorePhase;
use shadow_io::SceneSetup;
use shadow_io::image_io::{
    write_normal_exr, write_position_exr, write_radiance_png, write_rgb_exr, write_shaded_png,
    write_visibility_exr, write_visibility_png,
};
use shadow_io::npy::write_visibility_npy;

use crate::common::{
    machine, progress, rays_per_second_per_thread, resolve_scene, resolve_technique, write_json,
};
use crate::ensure_dir;

#[derive(Args)]
pub struct RenderArgs {
    /// Built-in scene name or a .gltf/.glb/.obj file.
    #[arg(long)]
    scene: String,
    /// Technique preset (see `cargo xtask conformance --help`); view samples only when absent.
    #[arg(long)]
    technique: Option<String>,
    /// Samples per pixel, for presets with a sample count.
    #[arg(long)]
    samples: Option<u32>,
    /// With `--technique auto`: the image RMSE to meet (against an independent many-sample
    /// reference).
    #[arg(long)]
    rmse: Option<f64>,
    /// With `--technique auto`: the seconds to fit in (preparation and estimate, the chooser's
    /// probe included).
    #[arg(long)]
    seconds: Option<f64>,
    /// Image width.
    #[arg(long, default_value_t = 512)]
    width: u32,
    /// Image height (default: from the camera's aspect ratio, else 3/4 of the width).
    #[arg(long)]
    height: Option<u32>,
    /// Shadow only this one of the scene's lights (0-based, in file order); by default every
    /// light is shadowed, V per light and direct light summed.
    #[arg(long)]
    light_index: Option<usize>,
    /// A preset that traces the lights `--technique` refuses (their kind, a texture), for
    /// example `ref`; without it such a light is an error naming it.
    #[arg(long)]
    fallback: Option<String>,
    /// A light in place of the file's: `rect:CENTER:NORMAL:WIDTHxHEIGHT`,
    /// `disk:CENTER:NORMAL:RADIUS` or `sphere:CENTER:RADIUS` (points and directions `x,y,z`).
    #[arg(long)]
    light: Option<String>,
    /// The radius of the file's `KHR_lights_punctual` point and spot lights (default: a
    /// hundredth of the scene's diagonal).
    #[arg(long)]
    light_size: Option<f32>,
    /// The radiance of `--light`: `R,G,B`, or one value for all three (default 1).
    #[arg(long)]
    light_radiance: Option<String>,
    /// Load the file's emissive meshes as ordinary geometry (occluders with their base colour)
    /// rather than as lights.
    #[arg(long)]
    emissive_as_geometry: bool,
    /// A camera in place of the file's: `EYE:TARGET:FOV` (points `x,y,z`, vertical field of
    /// view in degrees, +Y up).
    #[arg(long)]
    camera: Option<String>,
    /// Seed of the technique's sampling.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Also write the direct illumination (DCS eq. 6, diffuse albedo) as `direct.exr` and
    /// `direct.png`: the technique's own, from its per-sample visibility (sample-based
    /// techniques), or without `--technique` the reference's at `--samples` (default 256);
    /// and, for planar lights of constant radiance, the same samples' ratio estimator (the
    /// closed-form unshadowed light times the visible share, Heitz et al. 2018) as
    /// `direct-ratio.exr` and `direct-ratio.png`.
    #[arg(long)]
    direct: bool,
    /// Receivers from another renderer instead of the built-in rasterizer: a folder holding
    /// `position.exr` and `normal.exr` (float RGBA, alpha = valid pixel; the layout `render`
    /// itself writes). They are snapped onto the scene. They carry no camera, so techniques
    /// that work in the camera's image (DCS, `ssm-adaptive`) refuse them unless `--camera`
    /// names the camera they were rendered with.
    #[arg(long)]
    gbuffer: Option<PathBuf>,
    /// Output directory.
    #[arg(long)]
    out: PathBuf,
}

/// Every file a render may write; each run removes them first.
const OUTPUTS: [&str; 11] = [
    "position.exr",
    "normal.exr",
    "stats.json",
    "visibility.exr",
    "visibility.npy",
    "visibility.png",
    "shaded.png",
    "direct.exr",
    "direct.png",
    "direct-ratio.exr",
    "direct-ratio.png",
];

/// Writes the receivers' `position.exr` (in the file's coordinates: `shift` subtracted where
/// the scene was recentred) and `normal.exr`.
pub(crate) fn write_receivers(
    out: &std::path::Path,
    view: &ViewSamples,
    shift: Vec3,
) -> Result<(), String> {
    let position = out.join("position.exr");
    if shift == Vec3::ZERO {
        write_position_exr(&position, view).map_err(|e| e.to_string())?;
    } else {
        let file: Vec<Vec3> = view.positions().iter().map(|p| *p - shift).collect();
        write_rgb_exr(&position, view, &file).map_err(|e| e.to_string())?;
    }
    write_normal_exr(&out.join("normal.exr"), view).map_err(|e| e.to_string())
}

/// Removes every file a render may write from `out` (the per-light `visibility-K.*` too).
pub(crate) fn remove_outputs(out: &std::path::Path) -> Result<(), String> {
    let per_light = |name: &str| {
        name.strip_prefix("visibility-").is_some_and(|rest| {
            let k = [".exr", ".npy", ".png"]
                .iter()
                .fold(rest, |k, ext| k.trim_end_matches(ext));
            !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit())
        })
    };
    let entries = std::fs::read_dir(out).map_err(|e| format!("{}: {e}", out.display()))?;
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().to_string();
        if OUTPUTS.contains(&name.as_str()) || per_light(&name) {
            let f = entry.path();
            std::fs::remove_file(&f).map_err(|e| format!("removing {}: {e}", f.display()))?;
        }
    }
    Ok(())
}

/// The receivers of a foreign G-buffer in `dir` (`position.exr`, `normal.exr`), in the scene's
/// coordinates (`shift` subtracted where the scene was recentred), with `camera` when the
/// caller named the one they were rendered with.
fn foreign_gbuffer(
    dir: &std::path::Path,
    setup: &SceneSetup,
    camera: Option<&Camera>,
    shift: Vec3,
) -> Result<ViewSamples, String> {
    use shadow_core::receivers::{GBuffer, Snapping};
    use shadow_core::view_samples::MAX_VIEW_PIXELS;
    use shadow_io::image_io::read_aov_exr;
    let read =
        |name: &str| read_aov_exr(&dir.join(name), MAX_VIEW_PIXELS).map_err(|e| e.to_string());
    let (w, h, positions, valid) = read("position.exr")?;
    let (nw, nh, normals, normal_valid) = read("normal.exr")?;
    if (w, h) != (nw, nh) {
        return Err(format!(
            "{}: position.exr is {w}x{h}, normal.exr {nw}x{nh}",
            dir.display()
        ));
    }
    let positions: Vec<Vec3> = positions.iter().map(|p| *p - shift).collect();
    let valid: Vec<bool> = valid
        .iter()
        .zip(&normal_valid)
        .map(|(a, b)| *a && *b)
        .collect();
    let g = GBuffer {
        width: w,
        height: h,
        positions: &positions,
        geometric_normals: &normals,
        shading_normals: None,
        albedo: None,
        valid: Some(&valid),
        camera: camera.map(|c| c.raster_view(w, h)),
    };
    let scene = setup.scene.as_ref();
    ViewSamples::from_gbuffer(scene, &g, Snapping::for_scene(scene))
        .map_err(|e| format!("{}: {e}", dir.display()))
}

/// The scene with the command line's overrides (light size, light, camera), recentred when it
/// sits far from the origin, and the shift that was added to every position.
fn scene_for(a: &RenderArgs) -> Result<(SceneSetup, Vec3), String> {
    let mut setup = resolve_scene(&a.scene, a.light.is_some(), a.emissive_as_geometry)?;
    if let Some(r) = a.light_size {
        if a.light.is_some() || setup.punctual.is_empty() {
            return Err(format!(
                "--light-size sizes the file's KHR_lights_punctual lights; `{}` has none{}",
                a.scene,
                if a.light.is_some() {
                    " in use (--light replaces them)"
                } else {
                    ""
                }
            ));
        }
        setup
            .set_punctual_radius(r)
            .map_err(|e| format!("--light-size {r}: {e}"))?;
    }
    if let Some(spec) = &a.light {
        let radiance = crate::overrides::radiance(a.light_radiance.as_deref())?;
        setup.lights = vec![crate::overrides::light(spec, radiance)?];
    } else if a.light_radiance.is_some() {
        return Err("--light-radiance needs --light".into());
    }
    if let Some(spec) = &a.camera {
        setup.camera = Some(crate::overrides::camera(spec)?);
        setup.aspect = None;
    }
    // Far from the origin, work where single precision is dense (issue 51 item 11); positions
    // are written back in the file's coordinates.
    match shadow_scenes::recentred(&setup).map_err(|e| e.to_string())? {
        Some((moved, by)) => Ok((moved, by)),
        None => Ok((setup, Vec3::ZERO)),
    }
}

/// The technique `--technique` names (with `--samples`, or `auto` under `--rmse` or
/// `--seconds`), if any.
fn technique_for(a: &RenderArgs) -> Result<Option<Box<dyn ShadowTechnique>>, String> {
    let technique = match a.technique.as_deref() {
        Some("auto") => Some(auto_technique(a)?),
        Some(t) => {
            if a.rmse.is_some() || a.seconds.is_some() {
                return Err("--rmse and --seconds go with --technique auto".into());
            }
            Some(resolve_technique(t, a.samples, a.seed)?)
        }
        None => None,
    };
    if a.technique.is_none() && a.samples.is_some() && !a.direct {
        return Err("--samples needs --technique or --direct".into());
    }
    Ok(technique)
}

/// The receivers (the camera's view samples, or `--gbuffer`'s snapped onto the scene) and the
/// seconds they took; an error when none is valid.
fn view_for(a: &RenderArgs, setup: &SceneSetup, shift: Vec3) -> Result<(ViewSamples, f64), String> {
    use shadow_core::view_samples::MAX_VIEW_PIXELS;
    let height = match a.height {
        Some(h) => h,
        None => setup.image_height(a.width, MAX_VIEW_PIXELS)?,
    };
    let camera = setup.camera_or_default();
    let t0 = Instant::now();
    let view = match &a.gbuffer {
        Some(dir) => foreign_gbuffer(dir, setup, a.camera.is_some().then_some(&camera), shift)?,
        None => ViewSamples::render(setup.scene.as_ref(), &camera, a.width, height)
            .map_err(|e| e.to_string())?,
    };
    if view.valid_count() == 0 {
        return Err(format!(
            "the camera sees no surface of `{}` at {}x{} (is the scene in front of the \
             camera and beyond its near plane?)",
            setup.name,
            view.width(),
            view.height()
        ));
    }
    Ok((view, t0.elapsed().as_secs_f64()))
}

/// What a render shadows and where it writes: the lights chosen, with their indices in the
/// scene, and the receivers.
struct Shading<'a> {
    out: &'a std::path::Path,
    setup: &'a SceneSetup,
    lights: Vec<Light>,
    indices: Vec<usize>,
    view: &'a ViewSamples,
}

impl Shading<'_> {
    /// Every chosen light shadowed by `t` (the refused ones by `fallback`): V per light,
    /// `shaded.png`, direct light with `outputs.direct`, and their statistics in `stats`.
    fn with_technique(
        &self,
        t: &dyn ShadowTechnique,
        fallback: Option<&dyn ShadowTechnique>,
        outputs: Outputs,
        stats: &mut serde_json::Value,
    ) -> Result<(), String> {
        let (lights, indices, view) = (&self.lights, &self.indices, self.view);
        let all = PreparedLights::prepare(t, fallback, self.setup.scene.clone(), lights)
            .map_err(|e| light_error(e, indices))?;
        let est = all
            .estimate(view, outputs)
            .map_err(|e| light_error(e, indices))?;
        write_lights(self.out, self.setup, lights, indices, view, &est)?;
        if let Some(direct) = &est.direct {
            write_direct(self.out, "direct", view, direct)?;
            let ratio = match t.light_sampler() {
                Some(sampler) => write_ratio(self.out, self.setup, lights, sampler, view, &est)?,
                None => false,
            };
            stats["direct_illumination"] = json!({
                "technique": t.name(),
                "samples": t.light_sampler().map(|s| s.count()),
                "seconds": est.stats.phase_seconds(CorePhase::Direct),
                "ratio_estimator": ratio,
            });
        }
        stats["technique"] = json!(t.name());
        stats["parameters"] = t.parameters();
        stats["samples"] = t.light_sampler().map_or(json!(null), |s| json!(s.count()));
        stats["prepare"] = serde_json::to_value(all.preparation()).map_err(|e| e.to_string())?;
        stats["estimate"] = serde_json::to_value(&est.stats).map_err(|e| e.to_string())?;
        stats["lights"] = lights_json(indices, lights, &est);
        if let [one] = est.lights.as_slice() {
            stats["classes"] = json!(one.estimate.visibility.class_counts());
            if let Some(decision) = &one.estimate.decision {
                let mut d = decision.to_json();
                d["achieved_seconds"] = json!(est.stats.total_seconds());
                stats["decision"] = d;
            }
        }
        if let Some(r) = rays_per_second_per_thread(&est.stats) {
            stats["occlusion_rays_per_second_per_thread"] = json!(r);
        }
        Ok(())
    }

    /// Direct light without a technique: the reference's at `samples`, summed over the lights,
    /// with its ratio estimator.
    fn reference_direct(
        &self,
        samples: u32,
        seed: u64,
        stats: &mut serde_json::Value,
    ) -> Result<(), String> {
        let r = shadow_ref::Reference::stratified(samples, seed).map_err(|e| e.to_string())?;
        let t0 = Instant::now();
        let outputs = Outputs {
            per_sample: true,
            direct: true,
        };
        let est = PreparedLights::prepare(&r, None, self.setup.scene.clone(), &self.lights)
            .and_then(|all| all.estimate(self.view, outputs))
            .map_err(|e| light_error(e, &self.indices))?;
        let direct = est
            .direct
            .as_deref()
            .ok_or("the reference gave no direct light")?;
        write_direct(self.out, "direct", self.view, direct)?;
        let sampler = r.light_sampler().ok_or("the reference has no sampler")?;
        let ratio = write_ratio(self.out, self.setup, &self.lights, sampler, self.view, &est)?;
        stats["direct_illumination"] = json!({
            "technique": r.name(),
            "samples": samples,
            "seconds": t0.elapsed().as_secs_f64(),
            "ratio_estimator": ratio,
        });
        Ok(())
    }
}

pub fn run(a: RenderArgs) -> Result<(), String> {
    let (setup, shift) = scene_for(&a)?;
    let technique = technique_for(&a)?;
    let fallback = match &a.fallback {
        Some(f) if technique.is_some() => Some(resolve_technique(f, None, a.seed)?),
        Some(_) => return Err("--fallback goes with --technique".into()),
        None => None,
    };
    let indices = chosen_lights(&setup, a.light_index)?;
    ensure_dir(&a.out)?;
    // A failed run must not leave an older run's images beside its error.
    remove_outputs(&a.out)?;
    let pb = progress(if technique.is_some() { 3 } else { 2 }, "view samples");
    let (view, view_seconds) = view_for(&a, &setup, shift)?;
    pb.inc(1);
    write_receivers(&a.out, &view, shift)?;
    pb.inc(1);
    let mut stats = json!({
        "scene": setup.name,
        "triangles": setup.scene.triangle_count(),
        "light_index": a.light_index,
        "width": view.width(),
        "height": view.height(),
        "receivers": if a.gbuffer.is_some() { "gbuffer" } else { "camera" },
        "unmatched_receivers": view.unmatched_receivers(),
        "valid_pixels": view.valid_count(),
        "seed": a.seed,
        "threads": rayon::current_num_threads(),
        "gpu_adapter": serde_json::Value::Null,
        "view_samples_seconds": view_seconds,
        "recentred_by": (shift != Vec3::ZERO).then(|| shift.to_array()),
        "machine": machine(),
    });
    let shading = Shading {
        out: &a.out,
        setup: &setup,
        lights: indices.iter().map(|&i| setup.lights[i].clone()).collect(),
        indices,
        view: &view,
    };
    match &technique {
        Some(t) => {
            pb.set_message(format!("{}: every light", t.name()));
            let outputs = Outputs {
                per_sample: a.direct && t.light_sampler().is_some(),
                direct: a.direct,
            };
            shading.with_technique(t.as_ref(), fallback.as_deref(), outputs, &mut stats)?;
            pb.inc(1);
        }
        None if a.direct => {
            pb.set_message("direct illumination");
            shading.reference_direct(a.samples.unwrap_or(256), a.seed, &mut stats)?;
        }
        None => {}
    }
    pb.finish_and_clear();
    write_json(&a.out.join("stats.json"), &stats)?;
    println!(
        "wrote {} ({}x{}, {} valid pixels)",
        a.out.display(),
        view.width(),
        view.height(),
        view.valid_count()
    );
    Ok(())
}

/// The `auto` chooser under the budget `--rmse` or `--seconds` names (exactly one).
fn auto_technique(a: &RenderArgs) -> Result<Box<dyn ShadowTechnique>, String> {
    use shadow_auto::{Auto, AutoBudget};
    if a.samples.is_some() {
        return Err("`auto` chooses its own sample count: give --rmse or --seconds".into());
    }
    let budget = match (a.rmse, a.seconds) {
        (Some(r), None) => AutoBudget::Rmse(r),
        (None, Some(s)) => AutoBudget::Seconds(s),
        _ => return Err("--technique auto needs exactly one of --rmse and --seconds".into()),
    };
    Ok(Box::new(
        Auto::new(budget, a.seed, shadow_presets::build).map_err(|e| e.to_string())?,
    ))
}

/// Writes direct illumination as `STEM.exr` and `STEM.png` in `out`.
pub(crate) fn write_direct(
    out: &std::path::Path,
    stem: &str,
    view: &ViewSamples,
    direct: &[glam::Vec3],
) -> Result<(), String> {
    write_rgb_exr(&out.join(format!("{stem}.exr")), view, direct).map_err(|e| e.to_string())?;
    write_radiance_png(&out.join(format!("{stem}.png")), view, direct).map_err(|e| e.to_string())
}

/// Writes the ratio estimator of each light's per-sample visibility, summed over the lights,
/// as `direct-ratio.*`; `false` (and nothing written) when a light has no closed form.
fn write_ratio(
    out: &std::path::Path,
    setup: &SceneSetup,
    lights: &[Light],
    sampler: &LightSampler,
    view: &ViewSamples,
    est: &LightsEstimate,
) -> Result<bool, String> {
    let mut sum = vec![Vec3::ZERO; view.len()];
    for (light, each) in lights.iter().zip(&est.lights) {
        let ratio = shadow_core::technique::ratio_direct_from_per_sample(
            setup.scene.as_ref(),
            light.as_ref(),
            sampler,
            view,
            &each.estimate.visibility,
        )
        .map_err(|e| e.to_string())?;
        let Some(r) = ratio else { return Ok(false) };
        for (s, v) in sum.iter_mut().zip(r) {
            *s += v;
        }
    }
    write_direct(out, "direct-ratio", view, &sum).map(|()| true)
}

/// Writes V (`visibility.exr` and `.png`, or with several lights `visibility-K.*` for the
/// scene's light K) and `shaded.png` under every light.
fn write_lights(
    out: &std::path::Path,
    setup: &SceneSetup,
    lights: &[Light],
    indices: &[usize],
    view: &ViewSamples,
    est: &LightsEstimate,
) -> Result<(), String> {
    write_visibilities(out, indices, est)?;
    let pairs: Vec<(&dyn AreaLight, &dyn VisibilityBuffer)> = lights
        .iter()
        .zip(&est.lights)
        .map(|(l, e)| (l.as_ref(), &e.estimate.visibility as &dyn VisibilityBuffer))
        .collect();
    write_shaded_png(&out.join("shaded.png"), setup.scene.as_ref(), view, &pairs)
        .map_err(|e| e.to_string())
}

/// Writes V: `visibility.exr`, `.npy` and `.png` for one light, `visibility-K.*` for the
/// scene's light K of several.
pub(crate) fn write_visibilities(
    out: &std::path::Path,
    indices: &[usize],
    est: &LightsEstimate,
) -> Result<(), String> {
    let lights = indices;
    for (each, k) in est.lights.iter().zip(indices) {
        let stem = if lights.len() == 1 {
            "visibility".to_string()
        } else {
            format!("visibility-{k}")
        };
        let v = &each.estimate.visibility;
        write_visibility_exr(&out.join(format!("{stem}.exr")), v).map_err(|e| e.to_string())?;
        write_visibility_npy(&out.join(format!("{stem}.npy")), v).map_err(|e| e.to_string())?;
        write_visibility_png(&out.join(format!("{stem}.png")), v).map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Each light in `stats.json`: its index in the scene, kind, who shadowed it, and why the
/// fallback did or why it was skipped.
pub(crate) fn lights_json(
    indices: &[usize],
    lights: &[Light],
    est: &LightsEstimate,
) -> serde_json::Value {
    json!(
        indices
            .iter()
            .zip(lights)
            .zip(&est.lights)
            .map(|((k, l), e)| json!({
                "index": k,
                "kind": format!("{:?}", l.kind()),
                "technique": e.technique,
                "fallback_because": e.fallback.as_ref().map(ToString::to_string),
                "skipped": e.skipped,
                "classes": e.estimate.visibility.class_counts(),
            }))
            .collect::<Vec<_>>()
    )
}

/// A light's error with the scene's index of the light (the list shadowed may be one light
/// that `--light-index` chose), and the way out of a refusal.
pub(crate) fn light_error(e: TechniqueError, indices: &[usize]) -> String {
    match e {
        TechniqueError::Light { index, error } => {
            let k = indices.get(index).copied().unwrap_or(index);
            let by_light = matches!(
                error.unsupported_reason(),
                Some(UnsupportedReason::Light { .. } | UnsupportedReason::TexturedLight)
            );
            let hint = if by_light {
                " (--fallback ref traces it, --light-index K shadows another light alone)"
            } else {
                ""
            };
            format!("light {k}: {error}{hint}")
        }
        e => e.to_string(),
    }
}

/// The lights to shadow: `chosen` alone, or every light of the scene.
pub(crate) fn chosen_lights(
    setup: &SceneSetup,
    chosen: Option<usize>,
) -> Result<Vec<usize>, String> {
    let n = setup.lights.len();
    match chosen {
        Some(k) if k < n => Ok(vec![k]),
        Some(k) => Err(format!(
            "--light-index {k}: `{}` has {n} light(s) ({})",
            setup.name,
            setup
                .lights
                .iter()
                .enumerate()
                .map(|(i, l)| format!("{i}: {:?} at {:.3}", l.kind(), l.center()))
                .collect::<Vec<_>>()
                .join(", ")
        )),
        None => Ok((0..n).collect()),
    }
}
