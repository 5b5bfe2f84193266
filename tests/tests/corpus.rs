//! Issue 49: the corpus of real meshes (`shadow_scenes::corpus`) in `cargo test`, a small,
//! low-resolution share of it (the main measurements are `cargo xtask bench`'s): every corpus
//! scene loads with its mesh in view and in a shadow, and DCS, which is exact, gives the
//! reference's answer on the same samples on one light variant of every mesh (no pixel off by
//! more than two samples' share, the numerical ties).

use shadow_conformance::conformance::{Outcome, SceneContext, SuiteConfig, run_case};
use shadow_core::prelude::*;
use shadow_scenes::builtin;
use shadow_scenes::corpus::{CORPUS_LIGHTS, CORPUS_MESHES, corpus_scene_names, corpus_share};

fn small() -> SuiteConfig {
    SuiteConfig {
        width: 32,
        height: 24,
        ref_samples: 64,
        seed: 1,
        extra_checks: false,
        ..SuiteConfig::default()
    }
}

#[test]
fn every_corpus_scene_loads_in_view_and_in_shadow() {
    let names = corpus_scene_names();
    assert_eq!(names.len(), CORPUS_MESHES.len() * CORPUS_LIGHTS.len());
    for name in &names {
        let setup = builtin(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(setup.scene.triangle_count() > 100, "{name}");
        // Light variants of one mesh share the geometry; check the view on one of each.
        if !name.ends_with("disk-quarter") {
            continue;
        }
        let ctx = SceneContext::new(setup, small()).unwrap();
        let (reference, _) = ctx.reference().unwrap();
        let values: Vec<f32> = (0..ctx.view.len())
            .filter(|&i| ctx.view.is_valid(i))
            .map(|i| reference.value(i))
            .collect();
        assert!(values.len() > 300, "{name}: {} pixels", values.len());
        // Lit floor and a shadow under the mesh.
        assert!(values.iter().any(|v| *v > 0.95), "{name}: nothing lit");
        assert!(values.iter().any(|v| *v < 0.5), "{name}: no shadow");
    }
}

#[test]
fn dcs_equals_the_same_samples_reference_on_a_share_of_the_corpus() {
    let dcs = shadow_presets::preset("dcs-64").unwrap();
    for name in corpus_share() {
        let ctx = SceneContext::new(builtin(&name).unwrap(), small()).unwrap();
        match run_case(&dcs, &ctx) {
            Outcome::Ran(r) => {
                assert!(r.same_samples, "{name}");
                assert!(
                    r.metrics.max_abs <= 2.0 / 64.0 + 1e-6,
                    "{name}: a pixel off by {} against the same samples",
                    r.metrics.max_abs
                );
            }
            Outcome::Unsupported { reason } => panic!("{name}: refused: {reason}"),
            Outcome::Failed { error } => panic!("{name}: {error}"),
        }
    }
}
