//! Measured error tables of the AFSM presets whose error is not a numerical tie (scene, [rmse,
//! penumbra rmse, bias, max, share > 0.1]; seed 1), each value the larger of the two sizes the
//! presets run at: 128 x 96 (`cargo xtask conformance --techniques afsm-hard,afsm-128-lut
//! --quick`) and 48 x 36 (the same with `--width 48 --height 36`, the size `cargo test` uses for
//! GPU presets) on lavapipe. The `corpus` rows hold the largest error over the 44
//! scenes of the corpus of real meshes at both sizes (`--scenes corpus`, folded by
//! `scripts/measure_budgets.py --report ... --corpus`, then `--max` for the second size;
//! [`crate::CORPUS_ROW`]).

/// `afsm-hard` against the area light's reference (the error of a hard shadow).
pub const AFSM_HARD: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.1186, 0.2991, -0.0036, 0.729, 0.1189]),
    (
        "overlapping-occluders",
        [0.1764, 0.2854, 0.0040, 0.743, 0.2808],
    ),
    ("large-light-close", [0.2044, 0.2329, 0.0414, 0.747, 0.4399]),
    ("bunny", [0.1057, 0.3023, -0.0010, 0.801, 0.0970]),
    ("spot-self-shadow", [0.1411, 0.2832, -0.0005, 0.697, 0.1918]),
    ("grass", [0.1110, 0.2988, -0.0046, 0.871, 0.1028]),
    ("contact", [0.0784, 0.2353, 0.0140, 0.714, 0.0923]),
    ("semi-opaque", [0.0790, 0.1175, 0.0030, 0.478, 0.1861]),
    ("textured-light", [0.3703, 0.3705, 0.2980, 0.889, 0.7107]),
    ("sphere-light", [0.1284, 0.3193, -0.0046, 0.778, 0.1393]),
    ("cornell-box", [0.1446, 0.2407, 0.0450, 0.720, 0.2258]),
    ("spot-lamp", [0.0811, 0.2846, -0.0036, 0.720, 0.0708]),
    ("mesh-light", [0.2710, 0.4254, 0.1283, 0.750, 0.3537]),
    ("interior", [0.0857, 0.2927, -0.0037, 0.762, 0.0694]),
    ("interior-window", [0.1697, 0.3191, -0.0122, 0.848, 0.2471]),
    ("corpus", [0.1804, 0.3501, 0.0655, 0.931, 0.2141]),
];

/// `afsm-128-lut` against the same-samples reference (the plane table's discretisation).
pub const AFSM_128_LUT: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0047, 0.0116, 0.0002, 0.055, 0.0000]),
    (
        "overlapping-occluders",
        [0.0076, 0.0122, -0.0008, 0.047, 0.0000],
    ),
    (
        "large-light-close",
        [0.0095, 0.0107, -0.0007, 0.055, 0.0000],
    ),
    ("bunny", [0.0084, 0.0239, -0.0023, 0.086, 0.0000]),
    ("spot-self-shadow", [0.0056, 0.0113, -0.0012, 0.047, 0.0000]),
    ("grass", [0.0091, 0.0237, -0.0014, 0.125, 0.0002]),
    ("contact", [0.0019, 0.0057, -0.0001, 0.039, 0.0000]),
    ("semi-opaque", [0.0029, 0.0041, 0.0001, 0.023, 0.0000]),
    ("textured-light", [0.0035, 0.0034, 0.0001, 0.057, 0.0000]),
    ("sphere-light", [0.0034, 0.0083, 0.0001, 0.031, 0.0000]),
    ("cornell-box", [0.0103, 0.0169, 0.0006, 0.078, 0.0000]),
    ("spot-lamp", [0.0031, 0.0106, 0.0002, 0.031, 0.0000]),
    ("interior", [0.0034, 0.0113, -0.0003, 0.055, 0.0000]),
    ("interior-window", [0.0100, 0.0186, -0.0016, 0.125, 0.0002]),
    ("corpus", [0.0100, 0.0260, -0.0031, 0.102, 0.0001]),
];
