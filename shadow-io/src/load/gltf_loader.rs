//! glTF 2.0 loading through the `gltf` crate, with every buffer, accessor and image bound-checked
//! by hand before reading (DESIGN section 8: Y up, metres; emissive meshes are area lights,
//! `KHR_materials_emissive_strength` honoured; base-colour alpha of `BLEND` materials is occluder
//! opacity; base-colour textures are the albedo of shaded and direct output
//! ([`shadow_core::albedo`]); the first perspective camera is the view).

use std::io::Read;
use std::path::Path;
use std::sync::Arc;

use gltf::Document;

use super::gltf_nodes::NodeWalk;
use super::uri::{decode_data_uri, resolve};
use super::{LoadError, LoadLimits, SceneSetup, read_limited};

/// Loads a `.gltf` or `.glb` file; external buffers and images are resolved next to it.
///
/// # Errors
/// [`LoadError`] for unreadable, malformed, oversized or unsupported content.
pub fn load_gltf(path: &Path, limits: &LoadLimits) -> Result<SceneSetup, LoadError> {
    let bytes = read_limited(path, limits.max_file_bytes)?;
    let base = path.parent().map(Path::to_path_buf);
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "gltf".into());
    load_gltf_slice(&bytes, base.as_deref(), &name, limits)
}

/// A GLB container (glTF 2.0 section 4.4) holding `json` and one binary chunk `bin`, each
/// padded to four bytes, for tools and tests that write scenes.
pub fn glb_bytes(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((j.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(j);
    out.extend((b.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(b);
    out
}

/// Loads glTF from memory; `base` resolves relative URIs (none allowed when `None`).
///
/// # Errors
/// [`LoadError`] for malformed, oversized or unsupported content.
pub fn load_gltf_slice(
    bytes: &[u8],
    base: Option<&Path>,
    name: &str,
    limits: &LoadLimits,
) -> Result<SceneSetup, LoadError> {
    let (doc, blob) = parse(bytes)?;
    let buffers = load_buffers(&doc, blob, base, limits)?;
    let mut walk = NodeWalk::new(&buffers, base, limits);
    walk.warnings = unread_extensions(&doc);
    walk.walk(&doc)?;
    if walk.occluders == 0 {
        let reason = if walk.lights.is_empty() {
            "the file has no geometry".to_string()
        } else {
            // A model whose every mesh has an emissive factor (DamagedHelmet's lit panels):
            // nothing is left to cast or receive shadows.
            format!(
                "every mesh of the file emits light ({} became lights), so none is left as \
                 geometry to shadow; to see the model lit, load its emissive meshes as geometry \
                 (`--emissive-as-geometry`; `LoadLimits::emissive_as_geometry`; Python \
                 `load(path, emissive_as_geometry=True)`) and give a light (`--light`)",
                walk.lights.len()
            )
        };
        return Err(LoadError::Unsupported {
            mesh: name.to_string(),
            reason,
        });
    }
    let NodeWalk {
        builder,
        mut lights,
        layouts,
        camera,
        aspect,
        mut warnings,
        mut punctual,
        untextured_albedo,
        ..
    } = walk;
    if !untextured_albedo.is_empty() {
        warnings.push(format!(
            "base-colour textures without texture coordinates are not read (albedo is the \
             material's factor): {}",
            untextured_albedo.join(", ")
        ));
    }
    let scene = builder.build()?;
    super::dropped_warning(&scene, &mut warnings);
    // Punctual lights after the emissive meshes, in node order, sized by the scene.
    use shadow_core::scene::Scene;
    let (centre, diagonal) = (scene.bounds().center(), scene.bounds().diagonal());
    for p in &mut punctual {
        let radius = super::punctual::DEFAULT_RADIUS_SHARE * diagonal;
        let (light, what) = p.area_light(radius, centre, diagonal)?;
        p.light_index = lights.len();
        p.radius = radius;
        lights.push(light);
        warnings.push(format!(
            "punctual light '{}' ({:?}) is light {}: {what}; --light-size sets the radius",
            p.name, p.kind, p.light_index
        ));
    }
    Ok(SceneSetup {
        name: name.to_string(),
        scene: Arc::new(scene),
        lights,
        camera,
        aspect,
        warnings,
        punctual,
        layouts: layouts.into_iter().map(|(_, l)| l).collect(),
    })
}

/// The document and its GLB binary chunk, with every index a primitive or a punctual light
/// names checked (gltf-json's validation dereferences a primitive's POSITION accessor
/// unchecked, and a missing one panics).
///
/// # Errors
/// A truncated GLB or JSON, a file that is neither, and dangling indices, each said plainly.
fn parse(bytes: &[u8]) -> Result<(Document, Option<Vec<u8>>), LoadError> {
    // A GLB shorter than its header's length is a truncated file: say so before the parser
    // reports which chunk it could not read.
    if bytes.starts_with(b"glTF") && bytes.len() >= 12 {
        let declared = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize;
        if declared > bytes.len() {
            return Err(LoadError::Gltf(format!(
                "the GLB header declares {declared} bytes but the file holds {}: the file is \
                 truncated",
                bytes.len()
            )));
        }
    }
    let gltf = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| {
        // Neither a GLB (magic `glTF`) nor a JSON object: say so, not what the JSON parser met.
        let json_like = bytes.iter().find(|b| !b.is_ascii_whitespace()) == Some(&b'{');
        let text = e.to_string();
        if json_like && text.contains("EOF") {
            LoadError::Gltf(format!(
                "the glTF JSON ends before it is complete: the file is truncated ({text})"
            ))
        } else if bytes.starts_with(b"glTF") || json_like {
            LoadError::Gltf(text)
        } else {
            LoadError::Gltf(format!(
                "not a glTF file: neither GLB (magic `glTF`) nor a JSON object ({e})"
            ))
        }
    })?;
    check_primitive_indices(gltf.document.as_json())?;
    super::punctual::check_references(gltf.document.as_json())?;
    let doc = gltf::Document::from_json(gltf.document.into_json())
        .map_err(|e| LoadError::Gltf(e.to_string()))?;
    Ok((doc, gltf.blob))
}

/// A note for each extension the file uses and the loader does not read, naming the materials
/// that use it, so that data is never dropped without a word (glass that casts an opaque
/// shadow, say).
fn unread_extensions(doc: &Document) -> Vec<String> {
    let mut notes = Vec::new();
    for ext in doc.extensions_used() {
        if HONOURED_EXTENSIONS.contains(&ext) {
            continue;
        }
        let users: Vec<String> = doc
            .materials()
            .filter(|m| m.extension_value(ext).is_some())
            .map(|m| {
                m.name()
                    .map_or_else(|| format!("#{}", m.index().unwrap_or(0)), String::from)
            })
            .collect();
        notes.push(format!(
            "extension {ext} is not read: what it adds is ignored{}{}",
            match ext {
                "KHR_materials_transmission" | "KHR_materials_volume" => {
                    " (transmissive materials cast opaque shadows)"
                }
                "KHR_materials_unlit" => " (unlit materials are shaded and cast shadows)",
                _ => "",
            },
            if users.is_empty() {
                String::new()
            } else {
                format!("; materials: {}", users.join(", "))
            }
        ));
    }
    notes
}

/// The glTF extensions whose data the loader reads.
const HONOURED_EXTENSIONS: &[&str] = &["KHR_materials_emissive_strength", "KHR_lights_punctual"];

fn load_buffers(
    doc: &Document,
    blob: Option<Vec<u8>>,
    base: Option<&Path>,
    limits: &LoadLimits,
) -> Result<Vec<Vec<u8>>, LoadError> {
    let mut blob = blob;
    let mut out = Vec::new();
    for buffer in doc.buffers() {
        let declared = buffer.length() as u64;
        if declared > limits.max_buffer_bytes {
            return Err(LoadError::Limit {
                what: format!("buffer {}'s declared length in bytes", buffer.index()),
                size: declared,
                limit: limits.max_buffer_bytes,
            });
        }
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                LoadError::Missing(format!(
                    "buffer {} refers to a missing GLB chunk",
                    buffer.index()
                ))
            })?,
            gltf::buffer::Source::Uri(uri) => {
                match decode_data_uri(uri, limits.max_buffer_bytes)? {
                    Some(d) => d,
                    None => {
                        let path = resolve(base, uri)?;
                        let io = |source| LoadError::Io {
                            path: path.display().to_string(),
                            source,
                        };
                        let file = std::fs::File::open(&path).map_err(io)?;
                        let mut d = Vec::new();
                        file.take(declared).read_to_end(&mut d).map_err(io)?;
                        d
                    }
                }
            }
        };
        if (data.len() as u64) < declared {
            return Err(LoadError::Limit {
                what: format!(
                    "buffer {}'s declared length in bytes (the limit is the bytes present)",
                    buffer.index()
                ),
                size: declared,
                limit: data.len() as u64,
            });
        }
        out.push(data);
    }
    Ok(out)
}

/// Every accessor and material a mesh primitive (or its morph targets) names exists.
fn check_primitive_indices(root: &gltf::json::Root) -> Result<(), LoadError> {
    let accessors = root.accessors.len();
    let bad = |what: String| Err(LoadError::Missing(what));
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (k, prim) in mesh.primitives.iter().enumerate() {
            let at = || format!("mesh {m} primitive {k}");
            for (semantic, acc) in &prim.attributes {
                if acc.value() >= accessors {
                    return bad(format!(
                        "accessor {} (attribute {semantic:?} of {}; the file has {accessors})",
                        acc.value(),
                        at()
                    ));
                }
            }
            if let Some(i) = prim.indices
                && i.value() >= accessors
            {
                return bad(format!("accessor {} (indices of {})", i.value(), at()));
            }
            if let Some(mat) = prim.material
                && mat.value() >= root.materials.len()
            {
                return bad(format!("material {} (of {})", mat.value(), at()));
            }
            for target in prim.targets.iter().flatten() {
                for acc in [&target.positions, &target.normals, &target.tangents]
                    .into_iter()
                    .flatten()
                {
                    if acc.value() >= accessors {
                        return bad(format!(
                            "accessor {} (morph target of {})",
                            acc.value(),
                            at()
                        ));
                    }
                }
            }
        }
    }
    Ok(())
}
