//! The walk over a glTF node hierarchy (glTF 2.0 sections 3.5 "Nodes and hierarchy" and 3.7
//! "Meshes"): world transforms, the first perspective camera, each primitive as an occluder
//! mesh (base colour, its texture, alpha modes) or, when emissive, as an area light.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::{Affine3A, Mat4, Vec3};
use gltf::Semantic;
use gltf::mesh::Mode;
use shadow_core::albedo::{AlbedoTexture, TexturedAlbedo};
use shadow_core::camera::Camera;
use shadow_core::light::Light;
use shadow_core::lightmap::UvLayout;
use shadow_core::scene::{DegeneratePolicy, MeshDesc, PerTriangle, SceneBuilder};

use super::emissive::{EmissiveTexture, light_from_emissive_mesh};
use super::gltf_accessors::{read_indices, read_vec2, read_vec3};
use super::punctual::PunctualLight;
use super::texture::{EMISSIVE_TEXTURE_SIDE, LoadedImage, load_image};
use super::{LoadError, LoadLimits};

/// What the walk gathers from the nodes, in node order.
pub(super) struct NodeWalk<'a> {
    buffers: &'a [Vec<u8>],
    base: Option<&'a Path>,
    limits: &'a LoadLimits,
    /// The occluder meshes.
    pub builder: SceneBuilder,
    /// Lights from emissive meshes.
    pub lights: Vec<Light>,
    /// Texture layouts by node.
    pub layouts: Vec<(usize, UvLayout)>,
    /// The first perspective camera.
    pub camera: Option<Camera>,
    /// Its aspect ratio, when the file gives one.
    pub aspect: Option<f32>,
    /// Notes on what was read differently from the file or not at all.
    pub warnings: Vec<String>,
    /// Punctual lights on nodes, sized once the scene's bounds are known.
    pub punctual: Vec<PunctualLight>,
    /// Base-colour textures by (image, factor): meshes sharing a material share one texture.
    albedo_textures: HashMap<(usize, [u32; 3]), Arc<AlbedoTexture>>,
    /// Materials whose base-colour texture has no texture coordinates.
    pub untextured_albedo: Vec<String>,
    vertices_total: u64,
    /// Occluder primitives loaded.
    pub occluders: usize,
    /// Every node's world matrix in the walked scene, for skins' joints.
    node_world: Vec<Option<Mat4>>,
}

/// One primitive of a mesh on a node.
struct Primitive<'p> {
    prim: gltf::Primitive<'p>,
    mesh_name: &'p str,
    node: usize,
    world: Mat4,
    /// The default morph target weights (the node's, else the mesh's).
    weights: &'p [f32],
    /// The node's skin.
    skin: Option<gltf::Skin<'p>>,
}

impl<'a> NodeWalk<'a> {
    /// A walk reading accessors from `buffers` and images next to `base`.
    pub fn new(buffers: &'a [Vec<u8>], base: Option<&'a Path>, limits: &'a LoadLimits) -> Self {
        Self {
            buffers,
            base,
            limits,
            builder: SceneBuilder::new().degenerate_policy(DegeneratePolicy::Drop),
            lights: Vec::new(),
            layouts: Vec::new(),
            camera: None,
            aspect: None,
            warnings: Vec::new(),
            punctual: Vec::new(),
            albedo_textures: HashMap::new(),
            untextured_albedo: Vec::new(),
            vertices_total: 0,
            occluders: 0,
            node_world: Vec::new(),
        }
    }

    /// Walks the default scene's nodes (or every node when the file has no scene) depth first,
    /// in document order.
    ///
    /// # Errors
    /// A node reached twice (glTF node hierarchies are disjoint strict trees), a non-finite
    /// transform, and what reading a node's camera, lights and meshes refuses.
    pub fn walk(&mut self, doc: &gltf::Document) -> Result<(), LoadError> {
        let roots: Vec<gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
            Some(s) => s.nodes().collect(),
            None => parentless(doc)?,
        };
        self.node_world = super::gltf_pose::world_matrices(doc, &roots);
        let mut stack: Vec<(gltf::Node, Mat4, u32)> = roots
            .into_iter()
            .rev()
            .map(|n| (n, Mat4::IDENTITY, 0))
            .collect();
        // A node reached twice is a cycle, or a node with two parents, and is refused by
        // name. Depth itself is not limited (the walk uses this explicit stack, not recursion).
        let mut reached = vec![false; doc.nodes().len()];
        while let Some((node, parent, depth)) = stack.pop() {
            let seen = reached
                .get_mut(node.index())
                .map(|r| std::mem::replace(r, true));
            if seen != Some(false) {
                return Err(LoadError::Gltf(format!(
                    "node {} is reached twice (at depth {depth}): the node hierarchy has a \
                     cycle or a node with two parents, where glTF requires disjoint trees",
                    node.index()
                )));
            }
            let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
            if !world.is_finite() {
                return Err(LoadError::Gltf(format!(
                    "node {} has a non-finite transform",
                    node.index()
                )));
            }
            self.node(doc, &node, world)?;
            for child in node.children().collect::<Vec<_>>().into_iter().rev() {
                stack.push((child, world, depth + 1));
            }
        }
        Ok(())
    }

    /// A node's punctual light, camera and mesh.
    fn node(
        &mut self,
        doc: &gltf::Document,
        node: &gltf::Node,
        world: Mat4,
    ) -> Result<(), LoadError> {
        if let Some(p) = super::punctual::on_node(doc.as_json(), node.index(), world)? {
            self.punctual.push(p);
        }
        if let Some(cam) = node.camera()
            && self.camera.is_none()
        {
            self.camera(&cam, node.index(), world)?;
        }
        if let Some(mesh) = node.mesh() {
            let mesh_name = mesh
                .name()
                .map(str::to_string)
                .unwrap_or_else(|| format!("mesh {}", mesh.index()));
            let weights = node.weights().or_else(|| mesh.weights()).unwrap_or(&[]);
            for prim in mesh.primitives() {
                self.primitive(Primitive {
                    prim,
                    mesh_name: &mesh_name,
                    node: node.index(),
                    world,
                    weights,
                    skin: node.skin(),
                })?;
            }
        }
        Ok(())
    }

    /// The first camera: perspective, with the file's near plane so that a scene modelled at a
    /// small scale keeps its geometry in front of it; an orthographic one is noted and skipped.
    fn camera(&mut self, cam: &gltf::Camera, node: usize, world: Mat4) -> Result<(), LoadError> {
        match cam.projection() {
            gltf::camera::Projection::Perspective(p) => {
                let mut camera =
                    Camera::from_world_transform(Affine3A::from_mat4(world), p.yfov())?
                        .with_near(p.znear())?;
                if let Some(far) = p.zfar() {
                    camera = camera.with_far(far)?;
                }
                if glam::Mat3::from_mat4(world).determinant() < 0.0 {
                    self.warnings.push(format!(
                        "camera on node {node} has a mirroring scale: it was removed, keeping \
                         the camera's up and forward (the image is not mirrored left to right)"
                    ));
                }
                self.camera = Some(camera);
                self.aspect = p.aspect_ratio();
            }
            gltf::camera::Projection::Orthographic(_) => self.warnings.push(format!(
                "camera on node {node} is orthographic and was ignored"
            )),
        }
        Ok(())
    }

    /// One primitive: its triangles in the node's frame, then a light when its material emits,
    /// else an occluder mesh (unless masked out).
    fn primitive(&mut self, mut p: Primitive) -> Result<(), LoadError> {
        let positions = self.posed_positions(&mut p)?;
        let (prim, mesh_name) = (&p.prim, p.mesh_name);
        // A node scaled to nothing (a hidden object) has no surface: skipped with a note.
        if !(glam::Mat3::from_mat4(p.world).determinant().abs() >= f32::MIN_POSITIVE) {
            self.warnings.push(format!(
                "mesh `{mesh_name}` primitive {} on node {} has a zero scale (a hidden object) \
                 and was skipped",
                prim.index(),
                p.node
            ));
            return Ok(());
        }
        self.vertices_total += positions.len() as u64;
        if self.vertices_total > self.limits.max_vertices {
            return Err(LoadError::Limit {
                what: "the scene's vertex count".into(),
                size: self.vertices_total,
                limit: self.limits.max_vertices,
            });
        }
        let triangles = self.triangles(&p, positions.len())?;
        let material = prim.material();
        let strength = material.emissive_strength().unwrap_or(1.0);
        let emission = Vec3::from(material.emissive_factor()) * strength;
        if emission.max_element() > 0.0 && !self.limits.emissive_as_geometry {
            return self.emissive_light(&p, &positions, &triangles, emission);
        }
        let pbr = material.pbr_metallic_roughness();
        let base_color = pbr.base_color_factor();
        let factor =
            Vec3::new(base_color[0], base_color[1], base_color[2]).clamp(Vec3::ZERO, Vec3::ONE);
        let albedo_texture = self.albedo_texture(&p, factor)?;
        let Some(opacity) = self.opacity(&p, base_color[3].clamp(0.0, 1.0)) else {
            return Ok(());
        };
        let normals = match prim.get(&Semantic::Normals) {
            Some(a) => Some(read_vec3(self.buffers, &a, self.limits)?),
            None => None,
        };
        let mut desc = MeshDesc::new(positions, triangles);
        desc.normals = normals;
        desc.opacity = PerTriangle::All(opacity);
        desc.albedo = PerTriangle::All(factor);
        desc.albedo_texture = albedo_texture;
        desc.transform = Affine3A::from_mat4(p.world);
        if let Some(acc) = prim.get(&Semantic::TexCoords(0)) {
            desc.texcoords = Some(read_vec2(self.buffers, &acc, self.limits)?);
            desc.name = Some(mesh_name.to_string());
            add_layout(&mut self.layouts, p.node, &desc)?;
        }
        self.builder.push_mesh(desc)?;
        self.occluders += 1;
        Ok(())
    }

    /// The primitive's positions in glTF's default pose ([`super::gltf_pose`]): morphed by
    /// the default weights, then skinned (and `p.world` made the identity, the joints having
    /// placed them in the world).
    fn posed_positions(&self, p: &mut Primitive) -> Result<Vec<Vec3>, LoadError> {
        let (prim, mesh_name) = (&p.prim, p.mesh_name);
        let pos_acc = prim.get(&Semantic::Positions).ok_or_else(|| {
            LoadError::Accessor(format!(
                "mesh `{mesh_name}` primitive {} has no POSITION",
                prim.index()
            ))
        })?;
        let named = |e: LoadError| LoadError::Accessor(format!("mesh `{mesh_name}`: {e}"));
        let mut positions = read_vec3(self.buffers, &pos_acc, self.limits)?;
        super::gltf_pose::morph(self.buffers, prim, p.weights, &mut positions, self.limits)
            .map_err(named)?;
        if let Some(skin) = &p.skin {
            super::gltf_pose::skin(
                self.buffers,
                prim,
                skin,
                &self.node_world,
                &mut positions,
                self.limits,
            )
            .map_err(named)?;
            p.world = Mat4::IDENTITY;
        }
        Ok(positions)
    }

    /// The primitive's triangles, wound so that a mirroring node keeps their front side, each
    /// index checked against the `vertices`.
    fn triangles(&self, p: &Primitive, vertices: usize) -> Result<Vec<[u32; 3]>, LoadError> {
        let indices = match p.prim.indices() {
            Some(a) => read_indices(self.buffers, &a, self.limits)?,
            None => (0..vertices as u32).collect(),
        };
        let mut triangles = assemble(p.prim.mode(), &indices, p.mesh_name)?;
        // A mirroring node (negative determinant) reverses the winding that makes the front
        // face (glTF 2.0, "Transformations"): reverse it back, so that lights keep facing
        // where they face and closed meshes keep their outward side.
        if glam::Mat3::from_mat4(p.world).determinant() < 0.0 {
            for t in &mut triangles {
                t.swap(1, 2);
            }
        }
        if let Some(&bad) = triangles
            .iter()
            .flatten()
            .find(|&&v| v as usize >= vertices)
        {
            return Err(LoadError::Accessor(format!(
                "mesh `{}` index {bad} is out of range for {vertices} vertices",
                p.mesh_name
            )));
        }
        Ok(triangles)
    }

    /// An emissive primitive as an area light (its emissive texture read when it has one).
    fn emissive_light(
        &mut self,
        p: &Primitive,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        emission: Vec3,
    ) -> Result<(), LoadError> {
        let mesh_name = p.mesh_name;
        let world_pos: Vec<Vec3> = positions
            .iter()
            .map(|v| p.world.transform_point3(*v))
            .collect();
        let texture = match p.prim.material().emissive_texture() {
            Some(info) => Some(self.emissive_texture(p, &info)?),
            None => None,
        };
        let light = light_from_emissive_mesh(mesh_name, &world_pos, triangles, emission, texture)?;
        if light.kind() == shadow_core::light::LightKind::Mesh {
            self.warnings.push(format!(
                "mesh '{mesh_name}': emissive but not one planar outline or a sphere, so a mesh \
                 light (each triangle emits from its front; only the reference techniques \
                 render it; --emissive-as-geometry loads it as geometry)"
            ));
        }
        self.lights.push(light);
        Ok(())
    }

    /// The emissive texture and the texture coordinates it is read with.
    fn emissive_texture(
        &mut self,
        p: &Primitive,
        info: &gltf::texture::Info,
    ) -> Result<EmissiveTexture, LoadError> {
        let mesh_name = p.mesh_name;
        let tc_acc = p
            .prim
            .get(&Semantic::TexCoords(info.tex_coord()))
            .ok_or_else(|| LoadError::Unsupported {
                mesh: mesh_name.to_string(),
                reason: "emissive texture without texture coordinates".into(),
            })?;
        let texcoords = read_vec2(self.buffers, &tc_acc, self.limits)?;
        let LoadedImage {
            width,
            height,
            texels,
            decoded,
        } = load_image(
            self.buffers,
            info.texture().source(),
            self.base,
            self.limits,
        )?;
        if decoded != (width, height) {
            self.warnings.push(format!(
                "mesh '{mesh_name}': its {}x{} emissive texture is box-filtered to \
                 {width}x{height} (at most {EMISSIVE_TEXTURE_SIDE} a side)",
                decoded.0, decoded.1
            ));
        }
        Ok(EmissiveTexture {
            width,
            height,
            texels,
            texcoords,
        })
    }

    /// The base-colour texture times `factor`, shared by meshes of one material; `None` when
    /// the material has none, or has one without texture coordinates (noted).
    fn albedo_texture(
        &mut self,
        p: &Primitive,
        factor: Vec3,
    ) -> Result<Option<TexturedAlbedo>, LoadError> {
        let material = p.prim.material();
        let Some(info) = material.pbr_metallic_roughness().base_color_texture() else {
            return Ok(None);
        };
        let Some(acc) = p.prim.get(&Semantic::TexCoords(info.tex_coord())) else {
            let name = format!(
                "{} (mesh '{}')",
                material.name().unwrap_or("unnamed material"),
                p.mesh_name
            );
            if !self.untextured_albedo.contains(&name) {
                self.untextured_albedo.push(name);
            }
            return Ok(None);
        };
        let image = info.texture().source();
        let key = (image.index(), factor.to_array().map(f32::to_bits));
        let texture = match self.albedo_textures.get(&key) {
            Some(t) => Arc::clone(t),
            None => {
                let img = load_image(self.buffers, image, self.base, self.limits)?;
                if img.decoded != (img.width, img.height) {
                    self.warnings.push(format!(
                        "mesh '{}': its {}x{} base-colour texture is box-filtered to {}x{}",
                        p.mesh_name, img.decoded.0, img.decoded.1, img.width, img.height
                    ));
                }
                let t = Arc::new(
                    AlbedoTexture::new(img.width, img.height, img.texels, factor)
                        .map_err(LoadError::Texture)?,
                );
                self.albedo_textures.insert(key, Arc::clone(&t));
                t
            }
        };
        Ok(Some(TexturedAlbedo {
            texture,
            texcoords: read_vec2(self.buffers, &acc, self.limits)?,
        }))
    }

    /// The primitive's opacity under its material's alpha mode (glTF 2.0 section 3.9.4), the
    /// factor's `alpha`; `None` for a mesh masked out (below its cutoff), which casts nothing.
    fn opacity(&mut self, p: &Primitive, alpha: f32) -> Option<f32> {
        let material = p.prim.material();
        let mesh_name = p.mesh_name;
        let material_name = || {
            material.name().map_or_else(
                || format!("#{}", material.index().unwrap_or(0)),
                String::from,
            )
        };
        let textured_alpha = material
            .pbr_metallic_roughness()
            .base_color_texture()
            .is_some();
        match material.alpha_mode() {
            gltf::material::AlphaMode::Blend => {
                if textured_alpha {
                    self.warnings.push(format!(
                        "mesh '{mesh_name}': the alpha of material {}'s base-colour texture is \
                         not read (its opacity is the factor's, {alpha})",
                        material_name()
                    ));
                }
                Some(alpha)
            }
            gltf::material::AlphaMode::Mask => {
                // glTF: fully opaque at or above the cutoff, fully transparent below.
                let cutoff = material.alpha_cutoff().unwrap_or(0.5);
                if textured_alpha {
                    self.warnings.push(format!(
                        "mesh '{mesh_name}': the alpha mask of material {}'s base-colour \
                         texture is not read (the mask is the factor's alpha {alpha} against \
                         the cutoff {cutoff})",
                        material_name()
                    ));
                }
                if alpha < cutoff {
                    self.warnings.push(format!(
                        "mesh '{mesh_name}' is masked out (material {}: alpha {alpha} below \
                         its cutoff {cutoff}) and casts no shadow",
                        material_name()
                    ));
                    return None;
                }
                Some(1.0)
            }
            gltf::material::AlphaMode::Opaque => Some(1.0),
        }
    }
}

/// The roots of a file without scenes: every node no node names as a child (glTF 2.0,
/// "Scenes": without a scene, the nodes' hierarchy is still theirs).
///
/// # Errors
/// [`LoadError::Gltf`] when every node is some node's child (the hierarchy is a cycle).
fn parentless(doc: &gltf::Document) -> Result<Vec<gltf::Node<'_>>, LoadError> {
    let mut child = vec![false; doc.nodes().len()];
    for c in doc.nodes().flat_map(|n| n.children()) {
        if let Some(flag) = child.get_mut(c.index()) {
            *flag = true;
        }
    }
    let roots: Vec<gltf::Node> = doc.nodes().filter(|n| !child[n.index()]).collect();
    if roots.is_empty() && doc.nodes().len() > 0 {
        return Err(LoadError::Gltf(
            "the file has no scene and every node is some node's child: the node hierarchy \
             has a cycle"
                .into(),
        ));
    }
    Ok(roots)
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

/// Triangles from a primitive's indices under its topology (glTF 2.0 section 3.7.2.1);
/// points and lines have no surface and are refused.
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
