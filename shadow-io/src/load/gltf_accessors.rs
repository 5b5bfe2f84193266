//! Reading glTF accessors (glTF 2.0 section 3.6): bound-checked element views over the
//! loaded buffers, and the typed readers of positions, texture coordinates and indices.

use glam::{Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};

use super::{LoadError, LoadLimits};

/// Bound-checked element reader: returns the bytes of each element.
fn elements<'a>(
    buffers: &'a [Vec<u8>],
    acc: &gltf::Accessor,
    limits: &LoadLimits,
) -> Result<Vec<&'a [u8]>, LoadError> {
    if acc.sparse().is_some() {
        return Err(LoadError::Accessor(format!(
            "accessor {} is sparse (unsupported)",
            acc.index()
        )));
    }
    let view = acc.view().ok_or_else(|| {
        LoadError::Accessor(format!("accessor {} has no buffer view", acc.index()))
    })?;
    let buf = buffers
        .get(view.buffer().index())
        .ok_or_else(|| LoadError::Missing(format!("buffer {}", view.buffer().index())))?;
    let (voff, vlen) = (view.offset() as u64, view.length() as u64);
    // Offsets near 2^64 must not wrap the checks: every sum below is checked.
    if voff
        .checked_add(vlen)
        .is_none_or(|end| end > buf.len() as u64)
    {
        return Err(LoadError::Accessor(format!(
            "buffer view {} exceeds its buffer",
            view.index()
        )));
    }
    let elem = acc.size() as u64;
    let stride = view.stride().map(|s| s as u64).unwrap_or(elem);
    let count = acc.count() as u64;
    if count > limits.max_vertices * 3 {
        return Err(LoadError::Limit {
            what: format!("accessor {}'s element count", acc.index()),
            size: count,
            limit: limits.max_vertices * 3,
        });
    }
    if stride < elem {
        return Err(LoadError::Accessor(format!(
            "accessor {} stride {stride} below element size {elem}",
            acc.index()
        )));
    }
    let off = acc.offset() as u64;
    let end = (count.max(1) - 1)
        .checked_mul(stride)
        .and_then(|x| x.checked_add(off))
        .and_then(|x| x.checked_add(elem));
    if count > 0 && end.is_none_or(|end| end > vlen) {
        return Err(LoadError::Accessor(format!(
            "accessor {} reads past its buffer view",
            acc.index()
        )));
    }
    let start = (voff + off) as usize;
    Ok((0..count as usize)
        .map(|i| {
            let s = start + i * stride as usize;
            &buf[s..s + elem as usize]
        })
        .collect())
}

fn check_type(acc: &gltf::Accessor, dims: Dimensions, types: &[DataType]) -> Result<(), LoadError> {
    if acc.dimensions() != dims || !types.contains(&acc.data_type()) {
        return Err(LoadError::Accessor(format!(
            "accessor {} is {:?} {:?}, expected {dims:?} of {types:?}",
            acc.index(),
            acc.dimensions(),
            acc.data_type()
        )));
    }
    Ok(())
}

fn f32_at(b: &[u8], i: usize) -> f32 {
    f32::from_le_bytes([b[4 * i], b[4 * i + 1], b[4 * i + 2], b[4 * i + 3]])
}

pub(super) fn read_vec3(
    buffers: &[Vec<u8>],
    acc: &gltf::Accessor,
    limits: &LoadLimits,
) -> Result<Vec<Vec3>, LoadError> {
    check_type(acc, Dimensions::Vec3, &[DataType::F32])?;
    Ok(elements(buffers, acc, limits)?
        .into_iter()
        .map(|b| Vec3::new(f32_at(b, 0), f32_at(b, 1), f32_at(b, 2)))
        .collect())
}

pub(super) fn read_vec2(
    buffers: &[Vec<u8>],
    acc: &gltf::Accessor,
    limits: &LoadLimits,
) -> Result<Vec<Vec2>, LoadError> {
    check_type(
        acc,
        Dimensions::Vec2,
        &[DataType::F32, DataType::U8, DataType::U16],
    )?;
    let t = acc.data_type();
    if t != DataType::F32 && !acc.normalized() {
        return Err(LoadError::Accessor(format!(
            "accessor {} integer texcoords must be normalized",
            acc.index()
        )));
    }
    let out: Vec<Vec2> = elements(buffers, acc, limits)?
        .into_iter()
        .map(|b| match t {
            DataType::U8 => Vec2::new(b[0] as f32, b[1] as f32) / 255.0,
            DataType::U16 => {
                Vec2::new(
                    u16::from_le_bytes([b[0], b[1]]) as f32,
                    u16::from_le_bytes([b[2], b[3]]) as f32,
                ) / 65535.0
            }
            _ => Vec2::new(f32_at(b, 0), f32_at(b, 1)),
        })
        .collect();
    if out.iter().any(|v| !v.is_finite()) {
        return Err(LoadError::Accessor(format!(
            "accessor {} has non-finite texcoords",
            acc.index()
        )));
    }
    Ok(out)
}

pub(super) fn read_indices(
    buffers: &[Vec<u8>],
    acc: &gltf::Accessor,
    limits: &LoadLimits,
) -> Result<Vec<u32>, LoadError> {
    check_type(
        acc,
        Dimensions::Scalar,
        &[DataType::U8, DataType::U16, DataType::U32],
    )?;
    let t = acc.data_type();
    Ok(elements(buffers, acc, limits)?
        .into_iter()
        .map(|b| match t {
            DataType::U8 => b[0] as u32,
            DataType::U16 => u16::from_le_bytes([b[0], b[1]]) as u32,
            _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        })
        .collect())
}

/// Four joint indices per vertex (`JOINTS_n`: unsigned byte or short).
pub(super) fn read_joints(
    buffers: &[Vec<u8>],
    acc: &gltf::Accessor,
    limits: &LoadLimits,
) -> Result<Vec<[u16; 4]>, LoadError> {
    check_type(acc, Dimensions::Vec4, &[DataType::U8, DataType::U16])?;
    let wide = acc.data_type() == DataType::U16;
    Ok(elements(buffers, acc, limits)?
        .into_iter()
        .map(|b| {
            std::array::from_fn(|k| {
                if wide {
                    u16::from_le_bytes([b[2 * k], b[2 * k + 1]])
                } else {
                    u16::from(b[k])
                }
            })
        })
        .collect())
}

/// Four weights per vertex (`WEIGHTS_n`: float, or normalized unsigned byte or short).
pub(super) fn read_weights(
    buffers: &[Vec<u8>],
    acc: &gltf::Accessor,
    limits: &LoadLimits,
) -> Result<Vec<[f32; 4]>, LoadError> {
    check_type(
        acc,
        Dimensions::Vec4,
        &[DataType::F32, DataType::U8, DataType::U16],
    )?;
    let t = acc.data_type();
    let out: Vec<[f32; 4]> = elements(buffers, acc, limits)?
        .into_iter()
        .map(|b| {
            std::array::from_fn(|k| match t {
                DataType::U8 => f32::from(b[k]) / 255.0,
                DataType::U16 => f32::from(u16::from_le_bytes([b[2 * k], b[2 * k + 1]])) / 65535.0,
                _ => f32_at(b, k),
            })
        })
        .collect();
    if out.iter().flatten().any(|w| !w.is_finite()) {
        return Err(LoadError::Accessor(format!(
            "accessor {} has non-finite weights",
            acc.index()
        )));
    }
    Ok(out)
}

/// Column-major 4x4 float matrices (a skin's inverse bind matrices).
pub(super) fn read_mat4(
    buffers: &[Vec<u8>],
    acc: &gltf::Accessor,
    limits: &LoadLimits,
) -> Result<Vec<glam::Mat4>, LoadError> {
    check_type(acc, Dimensions::Mat4, &[DataType::F32])?;
    let out: Vec<glam::Mat4> = elements(buffers, acc, limits)?
        .into_iter()
        .map(|b| glam::Mat4::from_cols_array(&std::array::from_fn(|k| f32_at(b, k))))
        .collect();
    if out.iter().any(|m| !m.is_finite()) {
        return Err(LoadError::Accessor(format!(
            "accessor {} has non-finite matrices",
            acc.index()
        )));
    }
    Ok(out)
}
