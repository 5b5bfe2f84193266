//! NumPy `.npy` output (format version 1.0, little-endian float32, C order): visibility
//! buffers for notebooks and the Python package's tests, which read them with `numpy.load`
//! and no image library.
//!
//! A scalar buffer is written as an array of shape `(height, width)`, an RGB buffer (textured
//! lights) as `(height, width, 3)`; background pixels hold 0, as [`VisibilityBuffer::value`]
//! gives them.

use std::io::Write;
use std::path::Path;

use shadow_core::visibility::VisibilityBuffer;

/// The `.npy` bytes of a little-endian float32 array of `shape` holding `values` in C order.
///
/// The header is the format's Python dictionary literal, padded with spaces and ended by a
/// newline so that the data starts at a multiple of 64 bytes.
///
/// # Panics
/// Never for consistent input; `values.len()` must be the product of `shape` (checked in debug
/// builds).
pub fn npy_f32(shape: &[usize], values: &[f32]) -> Vec<u8> {
    debug_assert_eq!(shape.iter().product::<usize>(), values.len());
    let dims = match shape {
        [one] => format!("({one},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut header = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {dims}, }}");
    // magic (6) + version (2) + header length (2) + header + '\n', a multiple of 64.
    let unpadded = 10 + header.len() + 1;
    header.push_str(&" ".repeat(unpadded.next_multiple_of(64) - unpadded));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + 4 * values.len());
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for v in values {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

/// Writes `v` as `.npy` (see the module documentation for the layout).
///
/// # Errors
/// The file-system error, with the path.
pub fn write_visibility_npy(path: &Path, v: &dyn VisibilityBuffer) -> Result<(), NpyError> {
    let (w, h) = (v.width() as usize, v.height() as usize);
    let bytes = if v.is_rgb() {
        let values: Vec<f32> = (0..v.len())
            .flat_map(|i| {
                if v.is_valid(i) {
                    v.rgb(i).to_array()
                } else {
                    [0.0; 3]
                }
            })
            .collect();
        npy_f32(&[h, w, 3], &values)
    } else {
        let values: Vec<f32> = (0..v.len()).map(|i| v.value(i)).collect();
        npy_f32(&[h, w], &values)
    };
    std::fs::File::create(path)
        .and_then(|mut f| f.write_all(&bytes))
        .map_err(|source| NpyError {
            path: path.display().to_string(),
            source,
        })
}

/// A `.npy` file could not be written.
#[derive(Debug, thiserror::Error)]
#[error("writing {path}: {source}")]
pub struct NpyError {
    /// Destination.
    pub path: String,
    /// Cause.
    pub source: std::io::Error,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_is_padded_to_64_bytes_and_data_follows_in_c_order() {
        let bytes = npy_f32(&[2, 3], &[0.0, 1.0, 2.0, 3.0, 4.0, 5.5]);
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + header_len) % 64, 0);
        let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
        assert!(header.starts_with("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }"));
        assert!(header.ends_with('\n'));
        let data = &bytes[10 + header_len..];
        assert_eq!(data.len(), 24);
        assert_eq!(f32::from_le_bytes(data[20..24].try_into().unwrap()), 5.5);
    }

    #[test]
    fn a_one_dimensional_shape_has_the_trailing_comma() {
        let bytes = npy_f32(&[4], &[0.0; 4]);
        let header = String::from_utf8_lossy(&bytes[10..]);
        assert!(header.contains("'shape': (4,)"));
    }
}
