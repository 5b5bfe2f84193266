//! The crates' typed errors as Python exceptions.
//!
//! Every exception derives from `ShadowError`. `UnsupportedError` is a technique's refusal
//! ([`TechniqueError::Unsupported`]) and carries `technique`, `reason` (the
//! [`UnsupportedReason`]'s kind: `light`, `semi_opaque`, `textured_light`, `open_meshes`,
//! `view`, `no_adapter`, `device_limit`, `configuration`) and `light_index` (the light it
//! concerns when several were given). `InvalidInputError` (also a `ValueError`) is bad input:
//! an array of the wrong shape or dtype, a NaN, mismatched lengths, a bad light or scene.
//! `LimitError` is input over a documented limit (receivers, file sizes). `DeviceError` is a
//! GPU failure.
//!
//! The classes are defined in Python (`soft_shadows/errors.py`, for the two bases of
//! `InvalidInputError`); this module makes instances of them.

use pyo3::prelude::*;

use shadow_core::raster::RasterError;
use shadow_core::receivers::ReceiverError;
use shadow_core::technique::{TechniqueError, UnsupportedReason};
use shadow_io::LoadError;

/// An instance of the exception class `class` of `soft_shadows.errors` with `message` and the
/// attributes `attributes`, as a [`PyErr`] (the import's own error if it fails).
pub fn new_error(class: &str, message: String, attributes: &[(&str, Py<PyAny>)]) -> PyErr {
    Python::attach(|py| {
        let value = py
            .import("soft_shadows.errors")?
            .getattr(class)?
            .call1((message,))?;
        for (name, v) in attributes {
            value.setattr(*name, v)?;
        }
        Ok(PyErr::from_value(value))
    })
    .unwrap_or_else(|e: PyErr| e)
}

/// An `InvalidInputError` with `message`.
pub fn invalid(message: impl Into<String>) -> PyErr {
    new_error("InvalidInputError", message.into(), &[])
}

/// The kind of an [`UnsupportedReason`], as the exception's `reason`.
pub fn reason_kind(reason: &UnsupportedReason) -> &'static str {
    match reason {
        UnsupportedReason::Light { .. } => "light",
        UnsupportedReason::SemiOpaque => "semi_opaque",
        UnsupportedReason::TexturedLight => "textured_light",
        UnsupportedReason::OpenMeshes => "open_meshes",
        UnsupportedReason::View(_) => "view",
        UnsupportedReason::NoAdapter(_) => "no_adapter",
        UnsupportedReason::DeviceLimit(_) => "device_limit",
        UnsupportedReason::Configuration(_) => "configuration",
    }
}

/// A [`TechniqueError`] as its exception, with `light_index` (the light it concerns when
/// several were given), and `technique`, `reason` and `detail` on refusals.
pub fn technique_error(py: Python<'_>, error: &TechniqueError) -> PyErr {
    let (light_index, inner) = match error {
        TechniqueError::Light { index, error } => (Some(*index), error.as_ref()),
        e => (None, e),
    };
    let message = error.to_string();
    let object = |v: &str| v.into_pyobject(py).map(|s| s.into_any().unbind());
    let index = match light_index {
        Some(i) => pyo3::types::PyInt::new(py, i).into_any().unbind(),
        None => py.None(),
    };
    match inner {
        TechniqueError::Unsupported { technique, reason } => {
            let attributes = (|| -> PyResult<Vec<(&str, Py<PyAny>)>> {
                Ok(vec![
                    ("technique", object(technique)?),
                    ("reason", object(reason_kind(reason))?),
                    ("detail", object(&reason.to_string())?),
                    ("light_index", index.clone_ref(py)),
                ])
            })();
            match attributes {
                Ok(a) => new_error("UnsupportedError", message, &a),
                Err(e) => e,
            }
        }
        TechniqueError::Raster(e) => raster_error(e),
        TechniqueError::InvalidInput(_) => {
            new_error("InvalidInputError", message, &[("light_index", index)])
        }
        TechniqueError::Device(_) => new_error("DeviceError", message, &[("light_index", index)]),
        _ => new_error("ShadowError", message, &[("light_index", index)]),
    }
}

/// A [`RasterError`] as its exception: `LimitError` for an image over the largest view, else
/// `InvalidInputError`.
pub fn raster_error(error: &RasterError) -> PyErr {
    match error {
        RasterError::TooManyPixels { .. } => new_error("LimitError", error.to_string(), &[]),
        e => invalid(e.to_string()),
    }
}

/// A [`ReceiverError`] as its exception: `LimitError` for too many receivers, else
/// `InvalidInputError`.
pub fn receiver_error(error: &ReceiverError) -> PyErr {
    match error {
        ReceiverError::TooMany { .. } => new_error("LimitError", error.to_string(), &[]),
        e => invalid(e.to_string()),
    }
}

/// A [`LoadError`] as its exception: `LimitError` for a size over the limits, else
/// `InvalidInputError` naming the file.
pub fn load_error(path: &str, error: &LoadError) -> PyErr {
    let message = format!("{path}: {error}");
    match error {
        LoadError::Limit { .. } => new_error("LimitError", message, &[]),
        _ => invalid(message),
    }
}
