//! numpy arrays in and out.
//!
//! In: float arrays as float32 or float64, in C order, Fortran order or strided; a C-ordered
//! float32 array is read in place (no copy), any other is copied once into float32 in logical
//! (row-major) order. Python sequences are taken through `numpy.asarray`. Shapes and dtypes
//! are checked first, and every error names the argument. Out: arrays own the Rust buffers
//! they were computed in (`PyArray::from_vec`, no copy) and are reshaped in place.

use glam::Vec3;
use numpy::prelude::*;
use numpy::{PyArray1, PyArrayDyn, PyReadonlyArrayDyn, PyUntypedArray};
use pyo3::prelude::*;

use crate::errors::invalid;

/// A float array read as float32: borrowed in place or copied.
pub struct Floats<'py> {
    /// The array's shape.
    pub shape: Vec<usize>,
    data: Data<'py>,
    what: String,
}

enum Data<'py> {
    /// A C-contiguous float32 array, read in place.
    Borrowed(PyReadonlyArrayDyn<'py, f32>),
    /// Any other float array, converted.
    Owned(Vec<f32>),
}

impl Floats<'_> {
    /// The values in row-major order.
    ///
    /// # Errors
    /// Never for an array this module built (a borrowed one was checked to be C-contiguous).
    pub fn values(&self) -> PyResult<&[f32]> {
        match &self.data {
            Data::Borrowed(a) => a
                .as_slice()
                .map_err(|e| invalid(format!("{}: {e}", self.what))),
            Data::Owned(v) => Ok(v),
        }
    }

    /// The values as points or directions (the last axis has length 3, checked by
    /// [`vec3s`]).
    ///
    /// # Errors
    /// As [`Floats::values`].
    pub fn vec3s(&self) -> PyResult<&[Vec3]> {
        let values = self.values()?;
        bytemuck::try_cast_slice(values)
            .map_err(|e| invalid(format!("{}: not triples of floats ({e:?})", self.what)))
    }

    /// Whether the values were read in place.
    pub fn borrowed(&self) -> bool {
        matches!(self.data, Data::Borrowed(_))
    }
}

/// `obj` as a numpy array (`numpy.asarray` for anything else).
fn ndarray<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Bound<'py, PyUntypedArray>> {
    if let Ok(a) = obj.cast::<PyUntypedArray>() {
        return Ok(a.clone());
    }
    let converted = obj
        .py()
        .import("numpy")?
        .call_method1("asarray", (obj,))
        .map_err(|e| invalid(format!("{what}: not an array ({e})")))?;
    converted
        .cast_into::<PyUntypedArray>()
        .map_err(|e| invalid(format!("{what}: not an array ({e})")))
}

/// The dtype's name, for messages.
fn dtype_name(a: &Bound<'_, PyUntypedArray>) -> String {
    a.dtype()
        .str()
        .map(|s| s.to_string())
        .unwrap_or_else(|_| "unknown".into())
}

/// `obj` as float32 values; float32 or float64 only.
///
/// # Errors
/// `InvalidInputError` naming `what` for another dtype or an array numpy cannot make.
pub fn floats<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Floats<'py>> {
    let a = ndarray(obj, what)?;
    let shape = a.shape().to_vec();
    let what = what.to_string();
    if let Ok(f) = a.cast::<PyArrayDyn<f32>>() {
        let ro = f
            .try_readonly()
            .map_err(|e| invalid(format!("{what}: {e}")))?;
        let data = if a.is_c_contiguous() {
            Data::Borrowed(ro)
        } else {
            Data::Owned(ro.as_array().iter().copied().collect())
        };
        return Ok(Floats { shape, data, what });
    }
    if let Ok(f) = a.cast::<PyArrayDyn<f64>>() {
        let ro = f
            .try_readonly()
            .map_err(|e| invalid(format!("{what}: {e}")))?;
        let values = ro.as_array().iter().map(|&v| v as f32).collect();
        return Ok(Floats {
            shape,
            data: Data::Owned(values),
            what,
        });
    }
    Err(invalid(format!(
        "{what}: dtype {} is not float32 or float64",
        dtype_name(&a)
    )))
}

/// `obj` as an array of 3-vectors: shape `(..., 3)` with at least one leading axis.
///
/// # Errors
/// `InvalidInputError` naming `what` for another shape or dtype.
pub fn vec3s<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Floats<'py>> {
    let f = floats(obj, what)?;
    if f.shape.len() < 2 || f.shape.last() != Some(&3) {
        return Err(invalid(format!(
            "{what}: shape {:?} is not (..., 3)",
            f.shape
        )));
    }
    Ok(f)
}

/// The leading shape of an array of 3-vectors (its shape without the last axis).
pub fn leading(f: &Floats) -> Vec<usize> {
    f.shape[..f.shape.len() - 1].to_vec()
}

/// `obj` as a 3-vector: any sequence of three numbers (a tuple, a list, a numpy array).
///
/// # Errors
/// `InvalidInputError` naming `what`.
pub fn vec3(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec3> {
    let v: [f64; 3] = obj.extract().map_err(|_| {
        invalid(format!(
            "{what}: {} is not a sequence of three numbers",
            obj.repr().map(|r| r.to_string()).unwrap_or_default()
        ))
    })?;
    Ok(Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32))
}

/// `obj` as triangles: an integer array of shape `(M, 3)` (any signed or unsigned integer
/// dtype) with every index in `[0, 2^32)`.
///
/// # Errors
/// `InvalidInputError` naming `what` and the first bad index.
pub fn triangles(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<[u32; 3]>> {
    let a = ndarray(obj, what)?;
    let shape = a.shape().to_vec();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(invalid(format!("{what}: shape {shape:?} is not (M, 3)")));
    }
    let flat = integers(&a, what)?;
    let mut out = Vec::with_capacity(shape[0]);
    for (t, tri) in flat.chunks_exact(3).enumerate() {
        let mut idx = [0u32; 3];
        for (k, &v) in tri.iter().enumerate() {
            idx[k] = u32::try_from(v).map_err(|_| {
                invalid(format!(
                    "{what}: triangle {t} has index {v}, outside 0..2^32"
                ))
            })?;
        }
        out.push(idx);
    }
    Ok(out)
}

/// An integer array's values, in logical order, widened to `i128`.
fn integers(a: &Bound<'_, PyUntypedArray>, what: &str) -> PyResult<Vec<i128>> {
    macro_rules! widen {
        ($($t:ty),*) => {
            $(
                if let Ok(x) = a.cast::<PyArrayDyn<$t>>() {
                    let ro = x.try_readonly().map_err(|e| invalid(format!("{what}: {e}")))?;
                    return Ok(ro.as_array().iter().map(|&v| i128::from(v)).collect());
                }
            )*
        };
    }
    widen!(i64, i32, u32, u64, i16, u16, i8, u8);
    Err(invalid(format!(
        "{what}: dtype {} is not an integer type",
        dtype_name(a)
    )))
}

/// `obj` as a boolean mask of `shape`.
///
/// # Errors
/// `InvalidInputError` naming `what` for another dtype or shape.
pub fn mask(obj: &Bound<'_, PyAny>, what: &str, shape: &[usize]) -> PyResult<Vec<bool>> {
    let a = ndarray(obj, what)?;
    if a.shape() != shape {
        return Err(invalid(format!(
            "{what}: shape {:?} is not {shape:?}",
            a.shape()
        )));
    }
    let b = a
        .cast::<PyArrayDyn<bool>>()
        .map_err(|_| invalid(format!("{what}: dtype {} is not bool", dtype_name(&a))))?;
    let ro = b
        .try_readonly()
        .map_err(|e| invalid(format!("{what}: {e}")))?;
    Ok(ro.as_array().iter().copied().collect())
}

/// `values` as a numpy array of `shape`, owning the vector (no copy).
///
/// # Errors
/// A shape whose product is not `values.len()` (a bug, reported rather than hidden).
pub fn to_array<'py, T: numpy::Element>(
    py: Python<'py>,
    values: Vec<T>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_vec(py, values)
        .reshape(shape.to_vec())?
        .into_any())
}

/// 3-vectors as a float32 array of `shape + (3,)`.
///
/// # Errors
/// As [`to_array`].
pub fn vec3s_to_array<'py>(
    py: Python<'py>,
    values: &[Vec3],
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f32> = values.iter().flat_map(|v| v.to_array()).collect();
    let mut s = shape.to_vec();
    s.push(3);
    to_array(py, flat, &s)
}
