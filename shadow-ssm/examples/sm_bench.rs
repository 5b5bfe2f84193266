//! Times the shadow map's parts (frustum fitting, rasterization) on a scene:
//! `cargo run --release -p shadow-ssm --example sm_bench -- SCENE [RESOLUTION] [REPEATS]`.
use std::time::Instant;

use shadow_core::prelude::*;
use shadow_ssm::light_frame::LightFrame;
use shadow_ssm::light_view::LightView;
use shadow_ssm::shadow_map::ShadowMap;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("bunny", |s| s.as_str());
    let res: u32 = args.get(2).map_or(Ok(1024), |s| s.parse())?;
    let reps: usize = args.get(3).map_or(Ok(10), |s| s.parse())?;
    let setup = match shadow_scenes::corpus::corpus_scene(name) {
        Some(s) => s?,
        None => shadow_scenes::builtin(name)?,
    };
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 128, 96)?;
    let receivers: Vec<glam::Vec3> = (0..view.len())
        .filter_map(|i| view.get(i).map(|s| s.position))
        .collect();
    let frame = LightFrame::new(setup.lights[0].as_ref(), "bench")?;
    {
        use rayon::prelude::*;
        let warm: u64 = (0..1_000_000u64).into_par_iter().map(|x| x % 7).sum();
        println!("rayon warm ({warm})");
    }
    for _ in 0..reps {
        let t0 = Instant::now();
        let light = LightView::new(setup.scene.as_ref(), &frame);
        let t1 = Instant::now();
        let window = ShadowMap::window(setup.scene.as_ref(), &light, &receivers)
            .ok_or("no receiver in front of the light")?;
        let t2 = Instant::now();
        let m = ShadowMap::render_view(setup.scene.as_ref(), light.raster_view(window, res), 1)?;
        let t3 = Instant::now();
        println!(
            "{name} {res}: light view {:.2} ms, window {:.2} ms, raster {:.2} ms ({} texels)",
            (t1 - t0).as_secs_f64() * 1e3,
            (t2 - t1).as_secs_f64() * 1e3,
            (t3 - t2).as_secs_f64() * 1e3,
            m.depth.len()
        );
    }
    Ok(())
}
