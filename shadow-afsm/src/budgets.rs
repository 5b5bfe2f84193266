//! Measured error tables of the AFSM presets whose error is not a numerical tie (scene, [rmse,
//! penumbra rmse, bias, max, share > 0.1]; 128 x 96, seed 1).

/// `afsm-hard` against the area light's reference.
pub const AFSM_HARD: &[(&str, [f64; 5])] = &[];

/// `afsm-128-lut` against the same-samples reference.
pub const AFSM_128_LUT: &[(&str, [f64; 5])] = &[];
