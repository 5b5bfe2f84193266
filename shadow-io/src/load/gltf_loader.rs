//! glTF 2.0 loading through the `gltf` crate, with every buffer, accessor and image bound-checked
//! by hand before reading (DESIGN section 8: Y up, metres; emissive meshes are area lights,
//! `KHR_materials_emissive_strength` honoured; base-colour alpha of `BLEND` materials is occluder
//! opacity; base-colour textures are the albedo of shaded and direct output
//! ([`shadow_core::albedo`]); the first perspective camera is the view).

use std::collections::HashMap;
use std::io::Read;
use std::path::Path;
use std::sync::Arc;

use glam::{Affine3A, Mat4, Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use gltf::{Document, Semantic};
use shadow_core::albedo::{AlbedoTexture, TexturedAlbedo};
use shadow_core::camera::Camera;
use shadow_core::light::Light;
use shadow_core::lightmap::UvLayout;
use shadow_core::scene::{DegeneratePolicy, MeshDesc, PerTriangle, SceneBuilder};

use super::emissive::{EmissiveTexture, light_from_emissive_mesh};
use super::texture::{EMISSIVE_TEXTURE_SIDE, LoadedImage, load_image};
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
    // gltf-json's validation dereferences a primitive's POSITION accessor unchecked (a missing
    // one panics): every index a primitive names is checked here first.
    check_primitive_indices(gltf.document.as_json())?;
    super::punctual::check_references(gltf.document.as_json())?;
    let doc = gltf::Document::from_json(gltf.document.into_json())
        .map_err(|e| LoadError::Gltf(e.to_string()))?;
    let buffers = load_buffers(&doc, gltf.blob, base, limits)?;
    let mut builder = SceneBuilder::new().degenerate_policy(DegeneratePolicy::Drop);
    let mut lights: Vec<Light> = Vec::new();
    let mut layouts: Vec<(usize, UvLayout)> = Vec::new();
    let mut camera = None;
    let mut aspect = None;
    let mut warnings = Vec::new();
    // Extensions the loader reads; every other one the file uses is named in a note, so that
    // data dropped is never dropped without a word (glass that casts an opaque shadow, say).
    for ext in doc.extensions_used() {
        if !HONOURED_EXTENSIONS.contains(&ext) {
            // The materials that use it, by name.
            let users: Vec<String> = doc
                .materials()
                .filter(|m| m.extension_value(ext).is_some())
                .map(|m| {
                    m.name()
                        .map_or_else(|| format!("#{}", m.index().unwrap_or(0)), String::from)
                })
                .collect();
            warnings.push(format!(
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
    }
    // Base-colour textures by (image, factor): meshes sharing a material share one texture.
    let mut albedo_textures: HashMap<(usize, [u32; 3]), Arc<AlbedoTexture>> = HashMap::new();
    let mut untextured_albedo: Vec<String> = Vec::new();
    let mut punctual = Vec::new();
    let mut vertices_total = 0u64;
    let mut occluders = 0usize;

    let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(s) => s.nodes().collect(),
        None => doc.nodes().collect(),
    };
    let mut stack: Vec<(gltf::Node, Mat4, u32)> = roots
        .into_iter()
        .rev()
        .map(|n| (n, Mat4::IDENTITY, 0))
        .collect();
    // glTF node hierarchies are disjoint strict trees: a node reached twice is a cycle, or a
    // node with two parents, and is refused by name. Depth itself is not limited (the walk
    // uses this explicit stack, not recursion).
    let mut reached = vec![false; doc.nodes().len()];
    while let Some((node, parent, depth)) = stack.pop() {
        let seen = reached
            .get_mut(node.index())
            .map(|r| std::mem::replace(r, true));
        if seen != Some(false) {
            return Err(LoadError::Gltf(format!(
                "node {} is reached twice (at depth {depth}): the node hierarchy has a cycle or \
                 a node with two parents, where glTF requires disjoint trees",
                node.index()
            )));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        let world = parent * local;
        if !world.is_finite() {
            return Err(LoadError::Gltf(format!(
                "node {} has a non-finite transform",
                node.index()
            )));
        }
        if let Some(p) = super::punctual::on_node(doc.as_json(), node.index(), world)? {
            punctual.push(p);
        }
        if let Some(cam) = node.camera()
            && camera.is_none()
        {
            match cam.projection() {
                gltf::camera::Projection::Perspective(p) => {
                    // The file's near plane, so that a scene modelled at a small scale keeps
                    // its geometry in front of it.
                    camera = Some(
                        Camera::from_world_transform(Affine3A::from_mat4(world), p.yfov())?
                            .with_near(p.znear())?,
                    );
                    aspect = p.aspect_ratio();
                }
                gltf::camera::Projection::Orthographic(_) => warnings.push(format!(
                    "camera on node {} is orthographic and was ignored",
                    node.index()
                )),
            }
        }
        if let Some(mesh) = node.mesh() {
            let mesh_name = mesh
                .name()
                .map(str::to_string)
                .unwrap_or_else(|| format!("mesh {}", mesh.index()));
            for prim in mesh.primitives() {
                let pos_acc = prim.get(&Semantic::Positions).ok_or_else(|| {
                    LoadError::Accessor(format!(
                        "mesh `{mesh_name}` primitive {} has no POSITION",
                        prim.index()
                    ))
                })?;
                let positions = read_vec3(&buffers, &pos_acc, limits)?;
                vertices_total += positions.len() as u64;
                if vertices_total > limits.max_vertices {
                    return Err(LoadError::Limit {
                        what: "the scene's vertex count".into(),
                        size: vertices_total,
                        limit: limits.max_vertices,
                    });
                }
                let indices = match prim.indices() {
                    Some(a) => read_indices(&buffers, &a, limits)?,
                    None => (0..positions.len() as u32).collect(),
                };
                let mut triangles = assemble(prim.mode(), &indices, &mesh_name)?;
                // A mirroring node (negative determinant) reverses the winding that makes the
                // front face (glTF 2.0, "Transformations"): reverse it back, so that lights
                // keep facing where they face and closed meshes keep their outward side.
                if glam::Mat3::from_mat4(world).determinant() < 0.0 {
                    for t in &mut triangles {
                        t.swap(1, 2);
                    }
                }
                if let Some(&bad) = triangles
                    .iter()
                    .flatten()
                    .find(|&&v| v as usize >= positions.len())
                {
                    return Err(LoadError::Accessor(format!(
                        "mesh `{mesh_name}` index {bad} is out of range for {} vertices",
                        positions.len()
                    )));
                }
                let material = prim.material();
                let strength = material.emissive_strength().unwrap_or(1.0);
                let emission = Vec3::from(material.emissive_factor()) * strength;
                if emission.max_element() > 0.0 && !limits.emissive_as_geometry {
                    let world_pos: Vec<Vec3> = positions
                        .iter()
                        .map(|p| world.transform_point3(*p))
                        .collect();
                    let texture = match material.emissive_texture() {
                        Some(info) => {
                            let tc_acc = prim
                                .get(&Semantic::TexCoords(info.tex_coord()))
                                .ok_or_else(|| LoadError::Unsupported {
                                    mesh: mesh_name.clone(),
                                    reason: "emissive texture without texture coordinates".into(),
                                })?;
                            let texcoords = read_vec2(&buffers, &tc_acc, limits)?;
                            let LoadedImage {
                                width,
                                height,
                                texels,
                                decoded,
                            } = load_image(&buffers, info.texture().source(), base, limits)?;
                            if decoded != (width, height) {
                                warnings.push(format!(
                                    "mesh '{mesh_name}': its {}x{} emissive texture is \
                                     box-filtered to {width}x{height} (at most \
                                     {EMISSIVE_TEXTURE_SIDE} a side)",
                                    decoded.0, decoded.1
                                ));
                            }
                            Some(EmissiveTexture {
                                width,
                                height,
                                texels,
                                texcoords,
                            })
                        }
                        None => None,
                    };
                    let light = light_from_emissive_mesh(
                        &mesh_name, &world_pos, &triangles, emission, texture,
                    )?;
                    if light.kind() == shadow_core::light::LightKind::Mesh {
                        warnings.push(format!(
                            "mesh '{mesh_name}': emissive but not one planar outline or a \
                             sphere, so a mesh light (each triangle emits from its front; \
                             only the reference techniques render it; \
                             --emissive-as-geometry loads it as geometry)"
                        ));
                    }
                    lights.push(light);
                    continue;
                }
                let pbr = material.pbr_metallic_roughness();
                let base_color = pbr.base_color_factor();
                let factor = Vec3::new(base_color[0], base_color[1], base_color[2])
                    .clamp(Vec3::ZERO, Vec3::ONE);
                let albedo_texture = match pbr.base_color_texture() {
                    None => None,
                    Some(info) => match prim.get(&Semantic::TexCoords(info.tex_coord())) {
                        None => {
                            let name = format!(
                                "{} (mesh '{mesh_name}')",
                                material.name().unwrap_or("unnamed material")
                            );
                            if !untextured_albedo.contains(&name) {
                                untextured_albedo.push(name);
                            }
                            None
                        }
                        Some(acc) => {
                            let image = info.texture().source();
                            let key = (image.index(), factor.to_array().map(f32::to_bits));
                            let texture = match albedo_textures.get(&key) {
                                Some(t) => Arc::clone(t),
                                None => {
                                    let img = load_image(&buffers, image, base, limits)?;
                                    if img.decoded != (img.width, img.height) {
                                        warnings.push(format!(
                                            "mesh '{mesh_name}': its {}x{} base-colour texture \
                                             is box-filtered to {}x{}",
                                            img.decoded.0, img.decoded.1, img.width, img.height
                                        ));
                                    }
                                    let t = Arc::new(
                                        AlbedoTexture::new(
                                            img.width, img.height, img.texels, factor,
                                        )
                                        .map_err(LoadError::Texture)?,
                                    );
                                    albedo_textures.insert(key, Arc::clone(&t));
                                    t
                                }
                            };
                            Some(TexturedAlbedo {
                                texture,
                                texcoords: read_vec2(&buffers, &acc, limits)?,
                            })
                        }
                    },
                };
                let material_name = || {
                    material.name().map_or_else(
                        || format!("#{}", material.index().unwrap_or(0)),
                        String::from,
                    )
                };
                let alpha = base_color[3].clamp(0.0, 1.0);
                let textured_alpha = pbr.base_color_texture().is_some();
                let opacity = match material.alpha_mode() {
                    gltf::material::AlphaMode::Blend => {
                        if textured_alpha {
                            warnings.push(format!(
                                "mesh '{mesh_name}': the alpha of material {}'s base-colour \
                                 texture is not read (its opacity is the factor's, {alpha})",
                                material_name()
                            ));
                        }
                        alpha
                    }
                    gltf::material::AlphaMode::Mask => {
                        // glTF: fully opaque at or above the cutoff, fully transparent below.
                        let cutoff = material.alpha_cutoff().unwrap_or(0.5);
                        if textured_alpha {
                            warnings.push(format!(
                                "mesh '{mesh_name}': the alpha mask of material {}'s \
                                 base-colour texture is not read (the mask is the factor's \
                                 alpha {alpha} against the cutoff {cutoff})",
                                material_name()
                            ));
                        }
                        if alpha < cutoff {
                            warnings.push(format!(
                                "mesh '{mesh_name}' is masked out (material {}: alpha {alpha} \
                                 below its cutoff {cutoff}) and casts no shadow",
                                material_name()
                            ));
                            continue;
                        }
                        1.0
                    }
                    gltf::material::AlphaMode::Opaque => 1.0,
                };
                let normals = match prim.get(&Semantic::Normals) {
                    Some(a) => Some(read_vec3(&buffers, &a, limits)?),
                    None => None,
                };
                let mut desc = MeshDesc::new(positions, triangles);
                desc.normals = normals;
                desc.opacity = PerTriangle::All(opacity);
                desc.albedo = PerTriangle::All(factor);
                desc.albedo_texture = albedo_texture;
                desc.transform = Affine3A::from_mat4(world);
                if let Some(acc) = prim.get(&Semantic::TexCoords(0)) {
                    desc.texcoords = Some(read_vec2(&buffers, &acc, limits)?);
                    desc.name = Some(mesh_name.clone());
                    add_layout(&mut layouts, node.index(), &desc)?;
                }
                builder.push_mesh(desc)?;
                occluders += 1;
            }
        }
        for child in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((child, world, depth + 1));
        }
    }
    if occluders == 0 {
        return Err(LoadError::Unsupported {
            mesh: name.to_string(),
            reason: "the file has no non-emissive geometry".into(),
        });
    }
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

/// Adds the texture layout of `desc` (a primitive of node `node`) to `layouts`: the node's
/// primitives make one layout, named after the mesh (`NAME#NODE` for a second node showing the
/// same mesh).
fn add_layout(
    layouts: &mut Vec<(usize, UvLayout)>,
    node: usize,
    desc: &MeshDesc,
) -> Result<(), LoadError> {
    let mut layout =
        UvLayout::of(desc, "unnamed").map_err(|e| LoadError::Accessor(e.to_string()))?;
    if let Some((n, last)) = layouts.last_mut()
        && *n == node
        && last.name == layout.name
    {
        let offset = last.positions.len() as u32;
        last.positions.extend(layout.positions);
        last.texcoords.extend(layout.texcoords);
        last.triangles
            .extend(layout.triangles.iter().map(|t| t.map(|v| v + offset)));
        return Ok(());
    }
    if layouts.iter().any(|(_, l)| l.name == layout.name) {
        layout.name = format!("{}#{node}", layout.name);
    }
    layouts.push((node, layout));
    Ok(())
}

fn assemble(mode: Mode, idx: &[u32], mesh: &str) -> Result<Vec<[u32; 3]>, LoadError> {
    Ok(match mode {
        Mode::Triangles => idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        Mode::TriangleStrip => (2..idx.len())
            .map(|i| {
                if i % 2 == 0 {
                    [idx[i - 2], idx[i - 1], idx[i]]
                } else {
                    [idx[i - 1], idx[i - 2], idx[i]]
                }
            })
            .collect(),
        Mode::TriangleFan => (2..idx.len())
            .map(|i| [idx[0], idx[i - 1], idx[i]])
            .collect(),
        other => {
            return Err(LoadError::Unsupported {
                mesh: mesh.to_string(),
                reason: format!("primitive mode {other:?} has no surface"),
            });
        }
    })
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

fn read_vec3(
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

fn read_vec2(
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

fn read_indices(
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
