//! Scene loading: glTF 2.0 (`.gltf` and `.glb`, embedded or external buffers, with
//! `KHR_materials_emissive_strength` and `KHR_lights_punctual`, [`punctual`]) and Wavefront OBJ,
//! into a validated [`SceneSetup`].
//!
//! Every size a file declares is checked against [`LoadLimits`] and against the bytes actually
//! present before anything is allocated, so malformed or hostile files give a [`LoadError`],
//! never a panic or an unbounded allocation.

mod emissive;
mod gltf_accessors;
mod gltf_loader;
mod gltf_nodes;
mod gltf_pose;
mod obj;
pub mod punctual;
mod texture;
mod uri;

pub use emissive::light_from_emissive_mesh;
pub use gltf_loader::{glb_bytes, load_gltf, load_gltf_slice};
pub use obj::{load_obj, load_obj_slice, read_obj_mesh};
pub use texture::EMISSIVE_TEXTURE_SIDE;

use std::path::Path;
use std::sync::Arc;

use thiserror::Error;

use shadow_core::camera::{Camera, CameraError};
use shadow_core::light::{Light, LightError};
use shadow_core::lightmap::UvLayout;
use shadow_core::scene::{SceneError, TriangleScene};

/// Upper bounds on what a file may make the loader allocate, and the one choice a loader makes
/// about a file's content (what an emissive mesh is).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LoadLimits {
    /// Largest file read, in bytes.
    pub max_file_bytes: u64,
    /// Largest single buffer, in bytes.
    pub max_buffer_bytes: u64,
    /// Largest vertex count over the whole scene, instances flattened (each instance is a copy:
    /// about 400 bytes a triangle once the reference or DCS has prepared it, so the default,
    /// 2^24, keeps a scene of two triangles a vertex near 13 GB).
    pub max_vertices: u64,
    /// Largest texture, in pixels.
    pub max_image_pixels: u64,
    /// Load emissive meshes as ordinary geometry (occluders and receivers with their base
    /// colour) instead of as lights; a file left with no light then gets the default light.
    pub emissive_as_geometry: bool,
}

impl Default for LoadLimits {
    fn default() -> Self {
        Self {
            max_file_bytes: 2 << 30,
            max_buffer_bytes: 2 << 30,
            max_vertices: 1 << 24,
            max_image_pixels: 1 << 26,
            emissive_as_geometry: false,
        }
    }
}

/// Why a file could not be loaded.
#[derive(Debug, Error)]
pub enum LoadError {
    /// The file could not be read.
    #[error("reading {path}: {source}")]
    Io {
        /// Path.
        path: String,
        /// Cause.
        source: std::io::Error,
    },
    /// The glTF document is malformed.
    #[error("malformed glTF: {0}")]
    Gltf(String),
    /// The OBJ file is malformed.
    #[error("malformed OBJ: {0}")]
    Obj(String),
    /// A declared size exceeds a limit or the data present (`what` names the quantity and its
    /// unit).
    #[error("{what} is {size}, above the limit of {limit}")]
    Limit {
        /// What was too large.
        what: String,
        /// Declared size.
        size: u64,
        /// The limit or the bytes present.
        limit: u64,
    },
    /// A buffer or image the file refers to is missing.
    #[error("missing data: {0}")]
    Missing(String),
    /// An accessor is out of bounds or of an unexpected type.
    #[error("bad accessor: {0}")]
    Accessor(String),
    /// The geometry failed validation.
    #[error("invalid scene: {0}")]
    Scene(#[from] SceneError),
    /// An emissive mesh makes an invalid light.
    #[error("mesh `{mesh}` makes an invalid light: {source}")]
    Light {
        /// Mesh name.
        mesh: String,
        /// Cause.
        source: LightError,
    },
    /// The file uses something the loader does not turn into a scene.
    #[error("unsupported: mesh `{mesh}`: {reason}")]
    Unsupported {
        /// Mesh (or element) name.
        mesh: String,
        /// Why.
        reason: String,
    },
    /// The camera is invalid.
    #[error("invalid camera: {0}")]
    Camera(#[from] CameraError),
    /// A texture could not be decoded.
    #[error("texture: {0}")]
    Texture(String),
}

/// A loaded or built-in scene: geometry, lights and (when the file has one) a camera.
#[derive(Debug, Clone)]
pub struct SceneSetup {
    /// Name (file stem or built-in name).
    pub name: String,
    /// The occluders and receivers.
    pub scene: Arc<TriangleScene>,
    /// Area lights (emissive meshes), in file order.
    pub lights: Vec<Light>,
    /// The first camera, if any.
    pub camera: Option<Camera>,
    /// The camera's declared aspect ratio (width / height), if any.
    pub aspect: Option<f32>,
    /// Things the loader ignored (e.g. an orthographic camera), for the user to see.
    pub warnings: Vec<String>,
    /// The file's `KHR_lights_punctual` lights; each has an area light in `lights`.
    pub punctual: Vec<punctual::PunctualLight>,
    /// The texture layouts (`TEXCOORD_0`) of the meshes that have one, in file order: what
    /// `bake --mesh NAME` shadows the texels of.
    pub layouts: Vec<UvLayout>,
}

impl SceneSetup {
    /// Gives every point and spot light of the file radius `radius` (their area lights are
    /// rebuilt; directional lights keep their angular size).
    ///
    /// # Errors
    /// [`LoadError::Light`] for a radius that makes no valid light.
    pub fn set_punctual_radius(&mut self, radius: f32) -> Result<(), LoadError> {
        use shadow_core::scene::Scene;
        let b = self.scene.bounds();
        for p in &mut self.punctual {
            if p.kind != punctual::PunctualKind::Directional {
                let (light, _) = p.area_light(radius, b.center(), b.diagonal())?;
                self.lights[p.light_index] = light;
                p.radius = radius;
            }
        }
        Ok(())
    }

    /// The texture layout of the mesh named `name`.
    ///
    /// # Errors
    /// A message naming the meshes that have a layout.
    pub fn layout(&self, name: &str) -> Result<&UvLayout, String> {
        self.layouts.iter().find(|l| l.name == name).ok_or_else(|| {
            let names: Vec<&str> = self.layouts.iter().map(|l| l.name.as_str()).collect();
            format!(
                "`{}` has no mesh `{name}` with texture coordinates (TEXCOORD_0); {}",
                self.name,
                if names.is_empty() {
                    "no mesh has them".to_string()
                } else {
                    format!("meshes with them: {}", names.join(", "))
                }
            )
        })
    }

    /// The height of an image `width` pixels wide: from the camera's declared aspect ratio
    /// (width / height), else three quarters of the width; at least one pixel.
    ///
    /// # Errors
    /// A message naming the aspect ratio when it gives a height over `max_pixels / width`
    /// (an image no renderer could hold).
    pub fn image_height(&self, width: u32, max_pixels: u64) -> Result<u32, String> {
        let h = match self.aspect {
            Some(r) if r > 0.0 && r.is_finite() => (f64::from(width) / f64::from(r)).round(),
            _ => (f64::from(width) * 3.0 / 4.0).floor(),
        };
        let limit = max_pixels / u64::from(width.max(1));
        if !(h <= limit as f64) {
            return Err(format!(
                "the camera's aspect ratio {} gives an image {width} wide and {h} high, over \
                 the {max_pixels}-pixel limit: give the height",
                self.aspect.unwrap_or(0.0)
            ));
        }
        Ok((h as u32).max(1))
    }

    /// The file's camera, or one looking at the scene's bounds from the front-top.
    pub fn camera_or_default(&self) -> Camera {
        use shadow_core::scene::Scene;
        self.camera.unwrap_or_else(|| {
            let b = self.scene.bounds();
            let c = b.center();
            let r = 0.5 * b.diagonal().max(1e-6);
            let eye = c + glam::Vec3::new(0.0, 0.8, 1.6).normalize() * (2.2 * r);
            Camera::look_at(eye, c, glam::Vec3::Y, 0.9)
                .or_else(|_| Camera::look_at(c + glam::Vec3::Z, c, glam::Vec3::Y, 0.9))
                .expect("a camera one unit in front of a finite point is valid")
        })
    }
}

/// Adds the warning a loader gives when it dropped zero-area triangles (the corpus builds its
/// scenes with the same words).
pub fn dropped_warning(scene: &TriangleScene, warnings: &mut Vec<String>) {
    if scene.dropped_degenerate() > 0 {
        warnings.push(format!(
            "{} zero-area triangles dropped",
            scene.dropped_degenerate()
        ));
    }
}

/// Loads a scene file by extension (`.gltf`, `.glb`, `.obj`).
///
/// # Errors
/// [`LoadError`] for unreadable, malformed or unsupported files.
pub fn load_scene(path: &Path, limits: &LoadLimits) -> Result<SceneSetup, LoadError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or_default()
        .to_ascii_lowercase();
    match ext.as_str() {
        "gltf" | "glb" => load_gltf(path, limits),
        "obj" => load_obj(path, limits),
        other => Err(LoadError::Unsupported {
            mesh: path.display().to_string(),
            reason: format!("unknown extension `{other}` (expected gltf, glb or obj)"),
        }),
    }
}

/// Reads a whole file after checking its size against `limit`.
pub(crate) fn read_limited(path: &Path, limit: u64) -> Result<Vec<u8>, LoadError> {
    let io = |source| LoadError::Io {
        path: path.display().to_string(),
        source,
    };
    let len = std::fs::metadata(path).map_err(io)?.len();
    if len > limit {
        return Err(LoadError::Limit {
            what: format!("the size of {} in bytes", path.display()),
            size: len,
            limit,
        });
    }
    std::fs::read(path).map_err(io)
}
