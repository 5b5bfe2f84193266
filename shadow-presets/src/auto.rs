//! The chooser's presets: `auto` under image RMSE budgets 0.01 and 0.003, in the registry like
//! every technique's, so the conformance suite, bench and stress run them.
//!
//! Budgets are errors measured by the conformance suite (128 x 96 pixels, seed 1, reference at
//! 1024 samples with another seed) with the margins of [`Budget::from_measured`];
//! `scripts/measure_budgets.py` regenerates the tables. The reference's own error at 1024
//! samples adds to what `auto` achieves against the study's 4096-sample one. The `corpus` rows
//! hold the largest error over the 44 scenes of the corpus of real meshes
//! (`cargo xtask conformance --quick --scenes corpus`, folded by `scripts/measure_budgets.py --report ... --corpus`; [`crate::CORPUS_ROW`]).

use shadow_auto::{Auto, AutoBudget};
use shadow_core::technique::ShadowTechnique;

use crate::{Budget, Preset};

/// `auto` under RMSE budget `rmse`, named `name`.
fn auto(name: &str, rmse: f64, seed: u64) -> Box<dyn ShadowTechnique> {
    Box::new(
        Auto::new(AutoBudget::Rmse(rmse), seed, crate::build)
            .expect("the preset's budget and the committed model are valid")
            .named(name),
    )
}

/// Measured errors: scene, [rmse, penumbra rmse, bias, max, share > 0.1].
const AUTO_01: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0076, 0.0186, 0.0002, 0.070, 0.0000]),
    (
        "overlapping-occluders",
        [0.0041, 0.0066, 0.0001, 0.026, 0.0000],
    ),
    (
        "large-light-close",
        [0.0055, 0.0062, -0.0001, 0.029, 0.0000],
    ),
    ("bunny", [0.0065, 0.0180, 0.0001, 0.068, 0.0000]),
    ("spot-self-shadow", [0.0092, 0.0182, 0.0002, 0.076, 0.0000]),
    ("grass", [0.0103, 0.0269, -0.0001, 0.108, 0.0001]),
    ("contact", [0.0061, 0.0182, 0.0001, 0.055, 0.0000]),
    ("semi-opaque", [0.0087, 0.0126, 0.0001, 0.078, 0.0000]),
    ("textured-light", [0.0060, 0.0060, 0.0000, 0.034, 0.0000]),
    ("sphere-light", [0.0036, 0.0090, -0.0000, 0.034, 0.0000]),
    ("cornell-box", [0.0048, 0.0077, 0.0000, 0.034, 0.0000]),
    ("mesh-light", [0.0099, 0.0150, -0.0001, 0.095, 0.0000]),
    ("spot-lamp", [0.0053, 0.0183, 0.0000, 0.055, 0.0000]),
    ("interior", [0.0054, 0.0181, 0.0001, 0.071, 0.0000]),
    ("interior-window", [0.0047, 0.0087, 0.0001, 0.034, 0.0000]),
    ("corpus", [0.0088, 0.0557, 0.0002, 0.188, 0.0017]),
    // `interior`'s light 1, the disk pendant, shadowed with the scene's other lights: a small
    // light where the chooser's cheaper pick lands near its target (`cargo xtask conformance
    // --scenes interior --quick`).
    ("interior#1", [0.0094, 0.0536, 0.0001, 0.177, 0.0020]),
];

const AUTO_003: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0026, 0.0063, 0.0000, 0.034, 0.0000]),
    (
        "overlapping-occluders",
        [0.0027, 0.0042, 0.0000, 0.051, 0.0000],
    ),
    ("large-light-close", [0.0031, 0.0034, 0.0000, 0.054, 0.0000]),
    ("bunny", [0.0024, 0.0068, -0.0000, 0.022, 0.0000]),
    ("spot-self-shadow", [0.0025, 0.0049, 0.0000, 0.034, 0.0000]),
    ("grass", [0.0038, 0.0097, 0.0000, 0.057, 0.0000]),
    ("contact", [0.0024, 0.0071, -0.0000, 0.026, 0.0000]),
    ("semi-opaque", [0.0019, 0.0027, -0.0000, 0.017, 0.0000]),
    ("textured-light", [0.0016, 0.0016, -0.0000, 0.012, 0.0000]),
    ("sphere-light", [0.0026, 0.0062, 0.0000, 0.058, 0.0000]),
    ("cornell-box", [0.0030, 0.0045, 0.0000, 0.047, 0.0000]),
    ("mesh-light", [0.0026, 0.0039, 0.0000, 0.024, 0.0000]),
    ("spot-lamp", [0.0020, 0.0067, 0.0000, 0.023, 0.0000]),
    ("interior", [0.0021, 0.0072, -0.0000, 0.026, 0.0000]),
    ("interior-window", [0.0032, 0.0059, -0.0000, 0.116, 0.0001]),
    ("corpus", [0.0031, 0.0201, 0.0001, 0.068, 0.0000]),
    ("interior#1", [0.0033, 0.0189, -0.0000, 0.058, 0.0000]),
];

/// The chooser's presets.
pub fn presets() -> Vec<Preset> {
    vec![
        Preset {
            name: "auto-0.01",
            description: "auto: the CPU configuration predicted fastest to meet image RMSE 0.01",
            make: |seed| auto("auto-0.01", 0.01, seed),
            budget: |scene| Budget::lookup(AUTO_01, scene),
            with_samples: None,
            known_limitations: &[],
        },
        Preset {
            name: "auto-0.003",
            description: "auto: the CPU configuration predicted fastest to meet image RMSE 0.003",
            make: |seed| auto("auto-0.003", 0.003, seed),
            budget: |scene| Budget::lookup(AUTO_003, scene),
            with_samples: None,
            known_limitations: &[],
        },
    ]
}
