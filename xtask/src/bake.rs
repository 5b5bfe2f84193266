//! `cargo xtask bake`: a lightmap. The texels of one mesh's texture layout (`TEXCOORD_0`) as
//! receivers ([`shadow_core::lightmap`]), shadowed from every light by any technique that takes
//! receivers without a camera, written in that layout.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use glam::Vec3;
use serde_json::json;
use shadow_core::lightmap::max_side;
use shadow_core::prelude::*;
use shadow_core::receivers::Snapping;

use crate::common::{machine, resolve_scene, resolve_technique, write_json};
use crate::ensure_dir;
use crate::render::{
    chosen_lights, light_error, lights_json, remove_outputs, write_direct, write_receivers,
    write_visibilities,
};

#[derive(Args)]
pub struct BakeArgs {
    /// Built-in scene name or a .gltf/.glb file.
    #[arg(long)]
    scene: String,
    /// The mesh whose texture layout (`TEXCOORD_0`) to bake: its glTF mesh name (`floor` in
    /// the built-in scenes).
    #[arg(long)]
    mesh: String,
    /// The lightmap's side in texels.
    #[arg(long)]
    size: u32,
    /// Technique preset; it must take receivers without a camera (not `ssm-adaptive`).
    #[arg(long, default_value = "ref")]
    technique: String,
    /// Samples per texel, for presets with a sample count.
    #[arg(long)]
    samples: Option<u32>,
    /// Shadow only this one of the scene's lights (0-based); by default every light.
    #[arg(long)]
    light_index: Option<usize>,
    /// A preset that traces the lights `--technique` refuses.
    #[arg(long)]
    fallback: Option<String>,
    /// Also write the direct illumination summed over the lights (DCS eq. 6) as `direct.exr`.
    #[arg(long)]
    direct: bool,
    /// Seed of the technique's sampling.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output directory.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(a: BakeArgs) -> Result<(), String> {
    let mut setup = resolve_scene(&a.scene, false, false)?;
    if a.size == 0 || a.size > max_side() {
        return Err(format!(
            "--size {}: a lightmap's side is 1 to {}",
            a.size,
            max_side()
        ));
    }
    let technique = resolve_technique(&a.technique, a.samples, a.seed)?;
    let fallback = match &a.fallback {
        Some(f) => Some(resolve_technique(f, None, a.seed)?),
        None => None,
    };
    // Far from the origin, work where single precision is dense, as `render` does.
    let mut shift = Vec3::ZERO;
    if let Some((moved, by)) = shadow_scenes::recentred(&setup).map_err(|e| e.to_string())? {
        setup = moved;
        shift = by;
    }
    let layout = setup.layout(&a.mesh)?.clone();
    let indices = chosen_lights(&setup, a.light_index)?;
    let lights: Vec<Light> = indices.iter().map(|&i| setup.lights[i].clone()).collect();
    ensure_dir(&a.out)?;
    remove_outputs(&a.out)?;
    let t0 = Instant::now();
    let scene = setup.scene.as_ref();
    let texels = layout
        .texels(scene, a.size, Snapping::for_scene(scene))
        .map_err(|e| e.to_string())?;
    let texel_seconds = t0.elapsed().as_secs_f64();
    let outputs = Outputs {
        per_sample: a.direct && technique.light_sampler().is_some(),
        direct: a.direct,
    };
    let all = PreparedLights::prepare(
        technique.as_ref(),
        fallback.as_deref(),
        setup.scene.clone(),
        &lights,
    )
    .map_err(|e| light_error(e, &indices))?;
    let est = all
        .estimate(&texels, outputs)
        .map_err(|e| light_error(e, &indices))?;
    write_receivers(&a.out, &texels, shift)?;
    write_visibilities(&a.out, &indices, &est)?;
    if let Some(direct) = &est.direct {
        write_direct(&a.out, "direct", &texels, direct)?;
    }
    let stats = json!({
        "scene": setup.name,
        "mesh": layout.name,
        "size": a.size,
        "texels": texels.valid_count(),
        "unmatched_texels": texels.unmatched_receivers(),
        "texels_seconds": texel_seconds,
        "technique": technique.name(),
        "parameters": technique.parameters(),
        "light_index": a.light_index,
        "lights": lights_json(&indices, &lights, &est),
        "prepare": all.preparation(),
        "estimate": est.stats,
        "seed": a.seed,
        "recentred_by": (shift != Vec3::ZERO).then(|| shift.to_array()),
        "machine": machine(),
    });
    write_json(&a.out.join("stats.json"), &stats)?;
    println!(
        "wrote {} ({side}x{side} lightmap of `{}`, {} texels)",
        a.out.display(),
        layout.name,
        texels.valid_count(),
        side = a.size,
    );
    Ok(())
}
