//! What the DCS examples share: a built-in scene with its view samples, a preset by name, and
//! the best wall time of repeated estimates.

use std::time::Instant;

use shadow_core::prelude::*;
use shadow_io::SceneSetup;
use shadow_presets::Preset;

/// Built-in scene `name` and its view samples at `size` x `size` from the scene's camera.
///
/// With `DCS_LIGHT_SCALE=K` in the environment, a rectangle light's sides are scaled by `K`
/// about its centre (same plane, same radiance), so that one scene measures how the cost of
/// both DCS and the reference follows the penumbrae's width; any other light is an error.
pub fn scene_and_view(
    name: &str,
    size: u32,
) -> Result<(SceneSetup, ViewSamples), Box<dyn std::error::Error>> {
    let mut setup = shadow_scenes::builtin(name)?;
    if let Ok(k) = std::env::var("DCS_LIGHT_SCALE") {
        let k: f32 = k
            .parse()
            .ok()
            .filter(|k: &f32| k.is_finite() && *k > 0.0)
            .ok_or_else(|| format!("DCS_LIGHT_SCALE={k}: not a positive number"))?;
        let light = &setup.lights[0];
        let shadow_core::light::LightGeometry::Rectangle {
            center,
            half_u,
            half_v,
            ..
        } = light.geometry()
        else {
            return Err(format!("DCS_LIGHT_SCALE: {name}'s light is not a rectangle").into());
        };
        let scaled = RectLight::new(center, half_u * k, half_v * k, light.radiance().clone())?;
        setup.lights[0] = std::sync::Arc::new(scaled);
    }
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), size, size)?;
    Ok((setup, view))
}

/// The DCS preset called `name`; `what` names the other accepted arguments in the error.
pub fn preset(name: &str, what: &str) -> Result<Preset, String> {
    shadow_presets::dcs::presets()
        .into_iter()
        .find(|p| p.name == name)
        .ok_or_else(|| format!("{name}: neither {what} nor a DCS preset"))
}

/// `runs` estimates of `view`: the best wall time and the last estimate (`None` for no run).
pub fn best_of(
    runs: u32,
    t: &dyn PreparedShadows,
    view: &ViewSamples,
) -> Result<(f64, Option<Estimate>), TechniqueError> {
    let mut secs = f64::INFINITY;
    let mut last = None;
    for _ in 0..runs {
        let t0 = Instant::now();
        let e = t.estimate(view, Outputs::VISIBILITY)?;
        secs = secs.min(t0.elapsed().as_secs_f64());
        last = Some(e);
    }
    Ok((secs, last))
}
