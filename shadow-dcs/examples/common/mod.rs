//! What the DCS examples share: a built-in scene with its view samples, a preset by name, and
//! the best wall time of repeated estimates.

use std::time::Instant;

use shadow_core::prelude::*;

/// Built-in scene `name` and its view samples at `size` x `size` from the scene's camera.
pub fn scene_and_view(
    name: &str,
    size: u32,
) -> Result<(SceneSetup, ViewSamples), Box<dyn std::error::Error>> {
    let setup = shadow_core::scenes::builtin(name)?;
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), size, size)?;
    Ok((setup, view))
}

/// The DCS preset called `name`; `what` names the other accepted arguments in the error.
pub fn preset(name: &str, what: &str) -> Result<Preset, String> {
    shadow_dcs::presets()
        .into_iter()
        .find(|p| p.name == name)
        .ok_or_else(|| format!("{name}: neither {what} nor a DCS preset"))
}

/// `runs` estimates of `view`: the best wall time and the last estimate (`None` for no run).
pub fn best_of(
    runs: u32,
    t: &mut dyn ShadowTechnique,
    view: &ViewSamples,
) -> Result<(f64, Option<Estimate>), TechniqueError> {
    let mut secs = f64::INFINITY;
    let mut last = None;
    for _ in 0..runs {
        let t0 = Instant::now();
        let e = t.estimate(view)?;
        secs = secs.min(t0.elapsed().as_secs_f64());
        last = Some(e);
    }
    Ok((secs, last))
}
