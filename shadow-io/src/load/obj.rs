//! Wavefront OBJ loading through `tobj`: faces triangulated (n-gons by constrained Delaunay
//! triangulation in their plane), positions welded (exactly equal
//! positions share one vertex, so meshes split at UV seams become closed), normals dropped (OBJ
//! normals are per corner and often split; the scene's geometric normals are exact).

use std::collections::HashMap;
use std::io::BufReader;
use std::path::Path;
use std::sync::Arc;

use glam::Vec3;
use shadow_core::scene::{DegeneratePolicy, MeshDesc, SceneBuilder, TriangleScene};

use super::{LoadError, LoadLimits, SceneSetup, read_limited};

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
        punctual: Vec::new(),
        layouts: Vec::new(),
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
        triangulate: false,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // Every statement `tobj` will index by is checked first (see `first_bad_line`).
    if let Some((line, why)) = first_bad_line(bytes) {
        return Err(LoadError::Obj(format!("line {line}: {why}")));
    }
    let text = readable_text(bytes);
    let mut reader = BufReader::new(text.as_bytes());
    let (models, _) =
        tobj::load_obj_buf(&mut reader, &opts, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| LoadError::Obj(with_line(bytes, e.to_string())))?;
    let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
    let mut positions: Vec<Vec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut faces = 0usize;
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
        let mut corners = Vec::new();
        let mut at = 0usize;
        let arities: Vec<usize> = if m.mesh.face_arities.is_empty() {
            vec![3; m.mesh.indices.len() / 3]
        } else {
            m.mesh.face_arities.iter().map(|&a| a as usize).collect()
        };
        for arity in arities {
            let face =
                m.mesh.indices.get(at..at + arity).ok_or_else(|| {
                    LoadError::Obj(format!("model `{}` has a partial face", m.name))
                })?;
            at += arity;
            corners.clear();
            for &k in face {
                corners.push(*local.get(k as usize).ok_or_else(|| {
                    LoadError::Obj(with_line(
                        bytes,
                        format!("model `{}` face refers to missing vertex {}", m.name, k + 1),
                    ))
                })?);
            }
            faces += 1;
            triangulate_face(&corners, &positions, &mut triangles).map_err(|why| {
                LoadError::Obj(match face_line(bytes, faces) {
                    Some(line) => format!("line {line}: a face of {arity} vertices {why}"),
                    None => format!("model `{}`: a face of {arity} vertices {why}", m.name),
                })
            })?;
        }
    }
    if triangles.is_empty() {
        return Err(LoadError::Obj("no faces".into()));
    }
    Ok((positions, triangles))
}

/// The OBJ text as `tobj` reads it: bytes that are not UTF-8 (a Latin-1 comment) replaced by
/// U+FFFD, and a texture coordinate with one component (`vt u`, legal OBJ) given `v = 0`.
/// Line numbers are kept.
fn readable_text(bytes: &[u8]) -> std::borrow::Cow<'_, str> {
    let text = String::from_utf8_lossy(bytes);
    let one_component = |line: &str| {
        let mut words = line.split_whitespace();
        words.next() == Some("vt") && words.count() == 1
    };
    if !text.lines().any(one_component) {
        return text;
    }
    let mut out = String::with_capacity(text.len() + 64);
    for line in text.lines() {
        out.push_str(line);
        if one_component(line) {
            out.push_str(" 0");
        }
        out.push('\n');
    }
    std::borrow::Cow::Owned(out)
}

/// `message` prefixed with the line of the first statement in `bytes` that cannot be read
/// (`tobj` reports what failed, not where), when one is found.
fn with_line(bytes: &[u8], message: String) -> String {
    match first_bad_line(bytes) {
        Some((line, why)) => format!("line {line}: {why} ({message})"),
        None => message,
    }
}

/// The first `v`, `vt`, `vn` or `f` statement that is malformed, non-finite or names a vertex,
/// texture coordinate or normal that does not exist yet, with its 1-based line number and the
/// reason. Run before `tobj` as well as after its errors: `tobj` does index arithmetic on
/// references it has not checked (a texture index of `-11` after one `vt` overflowed inside it,
/// found by the loaders' fuzz test).
fn first_bad_line(bytes: &[u8]) -> Option<(usize, String)> {
    let text = String::from_utf8_lossy(bytes);
    let (mut v, mut vt, mut vn) = (0i64, 0i64, 0i64);
    let in_range = |k: i64, count: i64| (k > 0 && k <= count) || (k < 0 && k >= -count);
    for (i, raw) in text.lines().enumerate() {
        let mut words = raw.split_whitespace();
        let keyword = words.next();
        let numbers = |need: usize, words: std::str::SplitWhitespace<'_>| {
            let c: Vec<_> = words.take(need).map(str::parse::<f32>).collect();
            if c.len() < need || c.iter().any(Result::is_err) {
                Some(format!("needs {need} numbers"))
            } else if c.iter().flatten().any(|x| !x.is_finite()) {
                Some("a number is not finite".to_string())
            } else {
                None
            }
        };
        match keyword {
            Some("v") => {
                if let Some(why) = numbers(3, words) {
                    return Some((i + 1, format!("a vertex {why}")));
                }
                v += 1;
            }
            Some("vt") => {
                if let Some(why) = numbers(1, words) {
                    return Some((i + 1, format!("a texture coordinate {why}")));
                }
                vt += 1;
            }
            Some("vn") => {
                if let Some(why) = numbers(3, words) {
                    return Some((i + 1, format!("a normal {why}")));
                }
                vn += 1;
            }
            Some("f") => {
                let refs: Vec<&str> = words.collect();
                if refs.len() < 3 {
                    return Some((i + 1, "a face needs three vertices".into()));
                }
                for r in refs {
                    for (slot, (what, count)) in r.split('/').zip([
                        ("vertex", v),
                        ("texture coordinate", vt),
                        ("normal", vn),
                    ]) {
                        if slot.is_empty() && what != "vertex" {
                            continue;
                        }
                        match slot.parse::<i64>() {
                            Ok(k) if in_range(k, count) => {}
                            Ok(k) => {
                                return Some((
                                    i + 1,
                                    format!("face {what} {k} does not exist ({count} so far)"),
                                ));
                            }
                            Err(_) => {
                                return Some((
                                    i + 1,
                                    format!("face {what} `{slot}` is not an index"),
                                ));
                            }
                        }
                    }
                    if r.split('/').count() > 3 {
                        return Some((i + 1, format!("face vertex `{r}` has more than 3 parts")));
                    }
                }
            }
            _ => {}
        }
    }
    None
}

/// Appends the triangles of one face (vertex ids into `positions`): triangles as they are, a
/// convex quad as two triangles from its first corner, anything else by the constrained
/// Delaunay triangulation of the face projected on its plane ([`shadow_core::triangulate`]): a fan
/// over a large n-gon gives needles that make the BVH build quadratic (issue 51 item 16) and
/// covers a concave face wrongly.
fn triangulate_face(
    corners: &[u32],
    positions: &[Vec3],
    out: &mut Vec<[u32; 3]>,
) -> Result<(), String> {
    let p = |k: usize| positions[corners[k] as usize].as_dvec3();
    match corners.len() {
        0..=2 => return Err("has fewer than three vertices".into()),
        3 => {
            out.push([corners[0], corners[1], corners[2]]);
            return Ok(());
        }
        4 => {
            let (n0, n1) = (
                (p(1) - p(0)).cross(p(2) - p(0)),
                (p(2) - p(0)).cross(p(3) - p(0)),
            );
            let (m0, m1) = (
                (p(2) - p(1)).cross(p(3) - p(1)),
                (p(3) - p(1)).cross(p(0) - p(1)),
            );
            if n0.dot(n1) > 0.0 && m0.dot(m1) > 0.0 {
                out.push([corners[0], corners[1], corners[2]]);
                out.push([corners[0], corners[2], corners[3]]);
                return Ok(());
            }
        }
        _ => {}
    }
    // Newell's normal, then the face in its plane.
    let n = corners.len();
    let mut normal = glam::DVec3::ZERO;
    for k in 0..n {
        let (a, b) = (p(k), p((k + 1) % n));
        normal += glam::DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let normal = normal.try_normalize().ok_or("has no area")?;
    let (t, b) = normal.any_orthonormal_pair();
    let flat: Vec<glam::DVec2> = (0..n)
        .map(|k| glam::DVec2::new(p(k).dot(t), p(k).dot(b)))
        .collect();
    let tris = shadow_core::triangulate::triangulate_simple(&flat).map_err(|e| e.to_string())?;
    // Triangles wind like the face (counter-clockwise about its Newell normal in the plane
    // frame `t, b`, whose normal `t x b` is the Newell normal).
    out.extend(tris.into_iter().map(|t| t.map(|k| corners[k])));
    Ok(())
}

/// The 1-based line of the `face`-th (1-based) face statement in `bytes`.
fn face_line(bytes: &[u8], face: usize) -> Option<usize> {
    String::from_utf8_lossy(bytes)
        .lines()
        .enumerate()
        .filter(|(_, l)| l.split_whitespace().next() == Some("f"))
        .nth(face.checked_sub(1)?)
        .map(|(i, _)| i + 1)
}
