//! # shadow-python: the `soft_shadows` Python package
//!
//! The workspace's techniques for Python: scenes from vertex and index arrays or files, lights,
//! receivers from points or a camera, and any registered preset estimating `V(p)` (DESIGN
//! section 3's [`shadow_core::technique::ShadowTechnique`] through
//! [`shadow_core::lights::PreparedLights`]), with per-sample visibility, direct light (DCS
//! eq. 6) and the statistics. It converts arrays and calls the crates; every algorithm lives in
//! them, so a Python estimate is the Rust call's, bit for bit.
//!
//! * [`arrays`]: numpy in (float32 or float64, any order; borrowed without a copy where the
//!   layout allows) and out.
//! * [`errors`]: the crates' typed errors as Python exceptions carrying the reason.
//! * [`scene`], [`light`], [`receivers`]: the inputs; [`estimate`]: techniques and results.
//!
//! Built with maturin (`pip install ./python`); the API is documented in
//! `python/soft_shadows/_native.pyi` and `docs/python.md`.

pub mod arrays;
pub mod errors;
pub mod estimate;
pub mod light;
pub mod receivers;
pub mod scene;

use pyo3::prelude::*;

/// The extension module `soft_shadows._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<scene::Scene>()?;
    m.add_class::<scene::Setup>()?;
    m.add_class::<scene::Camera>()?;
    m.add_class::<light::Light>()?;
    m.add_class::<receivers::Receivers>()?;
    m.add_class::<estimate::Frame>()?;
    m.add_class::<estimate::LightResult>()?;
    m.add_function(wrap_pyfunction!(scene::builtin, m)?)?;
    m.add_function(wrap_pyfunction!(scene::builtin_scenes, m)?)?;
    m.add_function(wrap_pyfunction!(scene::load, m)?)?;
    m.add_function(wrap_pyfunction!(estimate::techniques, m)?)?;
    m.add_function(wrap_pyfunction!(estimate::estimate, m)?)?;
    m.add_function(wrap_pyfunction!(estimate::sample_points, m)?)?;
    Ok(())
}
