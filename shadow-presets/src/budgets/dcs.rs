//! Measured error tables of the DCS presets against the same-samples reference (scene, [rmse,
//! penumbra rmse, bias, max, share > 0.1]; 128 x 96, seed 1), from `cargo xtask conformance
//! --techniques dcs-16,dcs-64,dcs-64-interleaved,dcs-256,dcs-standard-silhouettes --quick`.
//! The exact presets agree with the reference sample by sample, so only their
//! semi-opaque error (the saturating opacity sum against the exact transmittance product,
//! section 3) is measured; elsewhere they get [`crate::dcs`]'s tie budget, on the built-in
//! scenes and the corpus of real meshes alike. The `corpus` rows hold the largest error over
//! the 44 corpus scenes (`cargo xtask conformance --quick --scenes corpus`, folded by `scripts/measure_budgets.py --report ... --corpus`; [`crate::CORPUS_ROW`]).

/// `dcs-16`.
pub const DCS_16_SEMI: &[(&str, [f64; 5])] =
    &[("semi-opaque", [0.0229, 0.0347, -0.0074, 0.150, 0.0147])];

/// `dcs-64`.
pub const DCS_64_SEMI: &[(&str, [f64; 5])] =
    &[("semi-opaque", [0.0226, 0.0336, -0.0074, 0.145, 0.0140])];

/// `dcs-256`.
pub const DCS_256_SEMI: &[(&str, [f64; 5])] =
    &[("semi-opaque", [0.0226, 0.0336, -0.0074, 0.144, 0.0148])];

/// `dcs-64-discrete` (the paper's tables alone; measured as `dcs-64-interleaved` before that
/// preset took the tables with exact borders, same samples).
pub const DCS_64_DISCRETE: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0080, 0.0201, 0.0001, 0.156, 0.0024]),
    (
        "overlapping-occluders",
        [0.0094, 0.0152, -0.0006, 0.172, 0.0026],
    ),
    (
        "large-light-close",
        [0.0138, 0.0159, -0.0007, 0.250, 0.0071],
    ),
    ("bunny", [0.0040, 0.0112, 0.0000, 0.109, 0.0004]),
    ("spot-self-shadow", [0.0050, 0.0099, 0.0000, 0.125, 0.0003]),
    ("grass", [0.0115, 0.0307, -0.0004, 0.172, 0.0023]),
    ("contact", [0.0017, 0.0052, 0.0000, 0.109, 0.0001]),
    ("semi-opaque", [0.0229, 0.0341, -0.0075, 0.196, 0.0150]),
    ("textured-light", [0.0047, 0.0047, -0.0001, 0.189, 0.0003]),
    ("cornell-box", [0.0077, 0.0128, -0.0006, 0.234, 0.0009]),
    ("spot-lamp", [0.0101, 0.0353, -0.0008, 0.156, 0.0062]),
    ("interior", [0.0058, 0.0199, -0.0000, 0.203, 0.0007]),
    ("interior-window", [0.0109, 0.0204, -0.0001, 0.172, 0.0021]),
    ("corpus", [0.0045, 0.0161, -0.0003, 0.172, 0.0004]),
];

/// `dcs-standard-silhouettes`.
pub const DCS_STANDARD: &[(&str, [f64; 5])] = &[
    ("quad-over-plane", [0.0000, 0.0000, 0.0000, 0.000, 0.0000]),
    (
        "overlapping-occluders",
        [0.0000, 0.0000, 0.0000, 0.000, 0.0000],
    ),
    (
        "large-light-close",
        [0.0508, 0.0586, -0.0162, 0.516, 0.0636],
    ),
    ("bunny", [0.0461, 0.1301, 0.0010, 0.438, 0.0469]),
    ("spot-self-shadow", [0.0583, 0.1175, -0.0009, 0.438, 0.0805]),
    ("grass", [0.0009, 0.0024, 0.0000, 0.078, 0.0000]),
    ("contact", [0.0250, 0.0757, 0.0007, 0.422, 0.0142]),
    ("semi-opaque", [0.0226, 0.0336, -0.0074, 0.145, 0.0140]),
    ("textured-light", [0.0269, 0.0269, -0.0038, 0.653, 0.0123]),
    ("sphere-light", [0.0389, 0.0737, 0.0020, 1.000, 0.0114]),
    ("cornell-box", [0.0162, 0.0277, 0.0002, 0.359, 0.0048]),
    ("spot-lamp", [0.0099, 0.0350, 0.0002, 0.375, 0.0016]),
    ("interior", [0.0085, 0.0276, -0.0001, 0.469, 0.0011]),
    ("interior-window", [0.0196, 0.0370, 0.0025, 0.484, 0.0052]),
    ("corpus", [0.0900, 0.2191, 0.0129, 0.766, 0.0949]),
];

/// `dcs-64-interleaved` (tables with exact borders): semi-opaque only.
pub const DCS_64_INTERLEAVED_SEMI: &[(&str, [f64; 5])] =
    &[("semi-opaque", [0.0225, 0.0336, -0.0074, 0.144, 0.0146])];
