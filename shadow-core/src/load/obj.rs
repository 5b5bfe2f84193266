//! Wavefront OBJ loading through `tobj`: faces triangulated, positions welded (exactly equal
//! positions share one vertex, so meshes split at UV seams become closed), normals dropped (OBJ
//! normals are per corner and often split; the scene's geometric normals are exact).

use std::collections::HashMap;
use std::io::BufReader;
use std::path::Path;
use std::sync::Arc;

use glam::Vec3;

use super::{LoadError, LoadLimits, SceneSetup, read_limited};
use crate::scene::{DegeneratePolicy, MeshDesc, SceneBuilder, TriangleScene};

/// Loads an OBJ file (materials are not read).
///
/// # Errors
/// [`LoadError`] for unreadable, malformed or oversized files, or invalid geometry.
pub fn load_obj(path: &Path, limits: &LoadLimits) -> Result<SceneSetup, LoadError> {
    let bytes = read_limited(path, limits.max_file_bytes)?;
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "obj".into());
    load_obj_slice(&bytes, &name, limits)
}

/// Loads OBJ text from memory; returns the welded scene without lights or camera.
///
/// # Errors
/// As [`load_obj`].
pub fn load_obj_slice(
    bytes: &[u8],
    name: &str,
    limits: &LoadLimits,
) -> Result<SceneSetup, LoadError> {
    let (positions, triangles) = read_obj_mesh(bytes, limits)?;
    let mut b = SceneBuilder::new().degenerate_policy(DegeneratePolicy::Drop);
    b.push_mesh(MeshDesc::new(positions, triangles))?;
    let scene: TriangleScene = b.build()?;
    let mut warnings = Vec::new();
    super::dropped_warning(&scene, &mut warnings);
    Ok(SceneSetup {
        name: name.to_string(),
        scene: Arc::new(scene),
        lights: Vec::new(),
        camera: None,
        aspect: None,
        warnings,
    })
}

/// Parses OBJ text into welded positions and triangles.
///
/// # Errors
/// [`LoadError::Obj`] for malformed text, [`LoadError::Limit`] for too many vertices.
pub fn read_obj_mesh(
    bytes: &[u8],
    limits: &LoadLimits,
) -> Result<(Vec<Vec3>, Vec<[u32; 3]>), LoadError> {
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = BufReader::new(bytes);
    let (models, _) =
        tobj::load_obj_buf(&mut reader, &opts, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| LoadError::Obj(with_line(bytes, e.to_string())))?;
    let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
    let mut positions: Vec<Vec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    for m in &models {
        let p = &m.mesh.positions;
        if p.len() % 3 != 0 {
            return Err(LoadError::Obj(format!(
                "model `{}` has a partial position",
                m.name
            )));
        }
        if (positions.len() + p.len() / 3) as u64 > limits.max_vertices {
            return Err(LoadError::Limit {
                what: "the scene's vertex count".into(),
                size: (positions.len() + p.len() / 3) as u64,
                limit: limits.max_vertices,
            });
        }
        let mut local = Vec::with_capacity(p.len() / 3);
        for c in p.chunks_exact(3) {
            let v = Vec3::new(c[0], c[1], c[2]);
            if !v.is_finite() {
                return Err(LoadError::Obj(with_line(
                    bytes,
                    format!("model `{}` has a non-finite vertex", m.name),
                )));
            }
            let next = positions.len() as u32;
            let id = *ids
                .entry(v.to_array().map(f32::to_bits))
                .or_insert_with(|| {
                    positions.push(v);
                    next
                });
            local.push(id);
        }
        if m.mesh.indices.len() % 3 != 0 {
            return Err(LoadError::Obj(format!(
                "model `{}` was not triangulated",
                m.name
            )));
        }
        for t in m.mesh.indices.chunks_exact(3) {
            let mut tri = [0u32; 3];
            for k in 0..3 {
                tri[k] = *local.get(t[k] as usize).ok_or_else(|| {
                    LoadError::Obj(with_line(
                        bytes,
                        format!(
                            "model `{}` face refers to missing vertex {}",
                            m.name,
                            t[k] + 1
                        ),
                    ))
                })?;
            }
            triangles.push(tri);
        }
    }
    if triangles.is_empty() {
        return Err(LoadError::Obj("no faces".into()));
    }
    Ok((positions, triangles))
}

/// `message` prefixed with the line of the first statement in `bytes` that cannot be read
/// (`tobj` reports what failed, not where), when one is found.
fn with_line(bytes: &[u8], message: String) -> String {
    match first_bad_line(bytes) {
        Some((line, why)) => format!("line {line}: {why} ({message})"),
        None => message,
    }
}

/// The first `v` or `f` statement that is malformed, non-finite or names a vertex that does not
/// exist yet, with its 1-based line number and the reason.
fn first_bad_line(bytes: &[u8]) -> Option<(usize, String)> {
    let text = String::from_utf8_lossy(bytes);
    let mut vertices = 0i64;
    for (i, raw) in text.lines().enumerate() {
        let mut words = raw.split_whitespace();
        match words.next() {
            Some("v") => {
                let coords: Vec<_> = words.take(3).map(str::parse::<f32>).collect();
                if coords.len() < 3 || coords.iter().any(Result::is_err) {
                    return Some((i + 1, "a vertex needs three numbers".into()));
                }
                if coords.iter().flatten().any(|c| !c.is_finite()) {
                    return Some((i + 1, "a vertex coordinate is not finite".into()));
                }
                vertices += 1;
            }
            Some("f") => {
                let refs: Vec<&str> = words.collect();
                if refs.len() < 3 {
                    return Some((i + 1, "a face needs three vertices".into()));
                }
                for r in refs {
                    let first = r.split('/').next().unwrap_or("");
                    match first.parse::<i64>() {
                        Ok(k) if k > 0 && k <= vertices => {}
                        Ok(k) if k < 0 && -k <= vertices => {}
                        Ok(k) => {
                            return Some((
                                i + 1,
                                format!("face vertex {k} does not exist ({vertices} so far)"),
                            ));
                        }
                        Err(_) => {
                            return Some((i + 1, format!("face vertex `{r}` is not an index")));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    None
}
