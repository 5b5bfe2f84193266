//! Scenes (from arrays, built in, or loaded from glTF or OBJ), their lights and cameras.

use std::path::Path;
use std::sync::Arc;

use glam::Vec3;
use pyo3::prelude::*;
use pyo3::types::PyList;

use shadow_core::mesh::PerTriangle;
use shadow_core::prelude::*;
use shadow_core::scene::{DegeneratePolicy, Scene as _};
use shadow_io::{LoadLimits, SceneSetup, load_scene};

use crate::arrays::{floats, triangles, vec3, vec3s};
use crate::errors::{invalid, load_error};
use crate::light::Light as PyLight;

/// A triangle scene: the occluders and the surfaces receivers lie on.
///
/// Build one with ``Scene.from_arrays`` or ``Scene.from_meshes``, or take a built-in or
/// loaded scene's (``builtin``, ``load``).
#[pyclass(frozen, module = "soft_shadows")]
pub struct Scene {
    /// The validated scene, shared with every estimate.
    pub inner: Arc<TriangleScene>,
}

/// One mesh's arrays, from Python.
struct MeshArrays<'py> {
    vertices: Bound<'py, PyAny>,
    indices: Bound<'py, PyAny>,
    opacity: Option<Bound<'py, PyAny>>,
    albedo: Option<Bound<'py, PyAny>>,
}

impl MeshArrays<'_> {
    /// The mesh, its arrays checked (`what` names it in errors).
    fn desc(&self, what: &str) -> PyResult<MeshDesc> {
        let v = vec3s(&self.vertices, &format!("{what} vertices"))?;
        if v.shape.len() != 2 {
            return Err(invalid(format!(
                "{what} vertices: shape {:?} is not (N, 3)",
                v.shape
            )));
        }
        let tris = triangles(&self.indices, &format!("{what} indices"))?;
        let mut mesh = MeshDesc::new(v.vec3s()?.to_vec(), tris);
        let m = mesh.triangles.len();
        if let Some(o) = &self.opacity {
            let o = floats(o, &format!("{what} opacity"))?;
            mesh.opacity = match o.shape.as_slice() {
                [] => PerTriangle::All(o.values()?[0]),
                [n] if *n == m => PerTriangle::Each(o.values()?.to_vec()),
                s => {
                    return Err(invalid(format!(
                        "{what} opacity: shape {s:?} is neither () nor ({m},), one per triangle"
                    )));
                }
            };
        }
        if let Some(a) = &self.albedo {
            let a = floats(a, &format!("{what} albedo"))?;
            let values = a.values()?;
            mesh.albedo = match a.shape.as_slice() {
                [3] => PerTriangle::All(Vec3::from_slice(values)),
                [n, 3] if *n == m => {
                    PerTriangle::Each(values.chunks_exact(3).map(Vec3::from_slice).collect())
                }
                s => {
                    return Err(invalid(format!(
                        "{what} albedo: shape {s:?} is neither (3,) nor ({m}, 3)"
                    )));
                }
            };
        }
        Ok(mesh)
    }
}

/// A scene from meshes; zero-area triangles rejected, or dropped and counted.
fn build(meshes: &[MeshArrays], drop_degenerate: bool) -> PyResult<Scene> {
    let policy = if drop_degenerate {
        DegeneratePolicy::Drop
    } else {
        DegeneratePolicy::Reject
    };
    let mut builder = SceneBuilder::new().degenerate_policy(policy);
    for (k, m) in meshes.iter().enumerate() {
        let what = if meshes.len() == 1 {
            "mesh".to_string()
        } else {
            format!("mesh {k}")
        };
        builder
            .push_mesh(m.desc(&what)?)
            .map_err(|e| invalid(format!("{what}: {e}")))?;
    }
    let scene = builder.build().map_err(|e| invalid(e.to_string()))?;
    Ok(Scene {
        inner: Arc::new(scene),
    })
}

#[pymethods]
impl Scene {
    /// A scene of one mesh: ``vertices`` (N, 3) and ``indices`` (M, 3) arrays, optional
    /// ``opacity`` (one value or (M,) in [0, 1]) and diffuse ``albedo`` ((3,) or (M, 3)).
    /// Zero-area triangles are an error unless ``drop_degenerate`` (then counted in
    /// ``dropped_degenerate``).
    #[staticmethod]
    #[pyo3(signature = (vertices, indices, opacity=None, albedo=None, drop_degenerate=false))]
    fn from_arrays<'py>(
        vertices: Bound<'py, PyAny>,
        indices: Bound<'py, PyAny>,
        opacity: Option<Bound<'py, PyAny>>,
        albedo: Option<Bound<'py, PyAny>>,
        drop_degenerate: bool,
    ) -> PyResult<Scene> {
        let mesh = MeshArrays {
            vertices,
            indices,
            opacity,
            albedo,
        };
        build(&[mesh], drop_degenerate)
    }

    /// A scene of several meshes, each a tuple ``(vertices, indices)`` or ``(vertices,
    /// indices, opacity)`` or ``(vertices, indices, opacity, albedo)``; closedness (which some
    /// techniques need) is judged per mesh.
    #[staticmethod]
    #[pyo3(signature = (meshes, drop_degenerate=false))]
    fn from_meshes(meshes: &Bound<'_, PyList>, drop_degenerate: bool) -> PyResult<Scene> {
        let mut all = Vec::with_capacity(meshes.len());
        for (k, item) in meshes.iter().enumerate() {
            let parts: Vec<Bound<'_, PyAny>> = item
                .extract()
                .map_err(|_| invalid(format!("mesh {k}: not a tuple of arrays")))?;
            let mut parts = parts.into_iter();
            let (Some(vertices), Some(indices)) = (parts.next(), parts.next()) else {
                return Err(invalid(format!(
                    "mesh {k}: needs (vertices, indices[, opacity[, albedo]])"
                )));
            };
            let opacity = parts.next().filter(|o| !o.is_none());
            let albedo = parts.next().filter(|a| !a.is_none());
            if parts.next().is_some() {
                return Err(invalid(format!("mesh {k}: more than four arrays")));
            }
            all.push(MeshArrays {
                vertices,
                indices,
                opacity,
                albedo,
            });
        }
        build(&all, drop_degenerate)
    }

    /// Number of triangles.
    #[getter]
    fn triangle_count(&self) -> usize {
        self.inner.triangle_count()
    }

    /// Zero-area triangles dropped (``drop_degenerate``).
    #[getter]
    fn dropped_degenerate(&self) -> usize {
        self.inner.dropped_degenerate()
    }

    /// The bounding box as ``(min, max)`` tuples.
    #[getter]
    fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        let b = self.inner.bounds();
        (b.min.to_array(), b.max.to_array())
    }

    /// Whether some triangle is semi-opaque (opacity below 1).
    #[getter]
    fn has_semi_opaque(&self) -> bool {
        self.inner.has_semi_opaque()
    }

    fn __repr__(&self) -> String {
        format!("Scene({} triangles)", self.inner.triangle_count())
    }
}

/// A pinhole camera (+Y up by default), for receivers rendered by the built-in rasterizer.
#[pyclass(frozen, module = "soft_shadows")]
pub struct Camera {
    /// The camera.
    pub inner: shadow_core::Camera,
}

#[pymethods]
impl Camera {
    /// A camera at ``eye`` looking at ``target``, ``fov_y`` the vertical field of view in
    /// radians.
    #[staticmethod]
    #[pyo3(signature = (eye, target, up=None, fov_y=0.9))]
    fn look_at(
        eye: &Bound<'_, PyAny>,
        target: &Bound<'_, PyAny>,
        up: Option<&Bound<'_, PyAny>>,
        fov_y: f32,
    ) -> PyResult<Camera> {
        let up = match up {
            Some(u) => vec3(u, "up")?,
            None => Vec3::Y,
        };
        let inner =
            shadow_core::Camera::look_at(vec3(eye, "eye")?, vec3(target, "target")?, up, fov_y)
                .map_err(|e| invalid(format!("camera: {e}")))?;
        Ok(Camera { inner })
    }

    /// The eye position.
    #[getter]
    fn position(&self) -> [f32; 3] {
        self.inner.position().to_array()
    }

    /// The viewing direction.
    #[getter]
    fn forward(&self) -> [f32; 3] {
        self.inner.forward().to_array()
    }

    /// The vertical field of view in radians.
    #[getter]
    fn fov_y(&self) -> f32 {
        self.inner.yfov()
    }
}

/// A built-in or loaded scene: its geometry, lights, camera and the loader's notes.
#[pyclass(frozen, module = "soft_shadows")]
pub struct Setup {
    setup: SceneSetup,
}

#[pymethods]
impl Setup {
    /// The scene's name (built-in name or file stem).
    #[getter]
    fn name(&self) -> &str {
        &self.setup.name
    }

    /// The geometry.
    #[getter]
    fn scene(&self) -> Scene {
        Scene {
            inner: self.setup.scene.clone(),
        }
    }

    /// The lights, in file order (emissive meshes and punctual lights of a glTF file).
    #[getter]
    fn lights(&self) -> Vec<PyLight> {
        self.setup
            .lights
            .iter()
            .map(|l| PyLight { inner: l.clone() })
            .collect()
    }

    /// The file's camera, if it has one.
    #[getter]
    fn camera(&self) -> Option<Camera> {
        self.setup.camera.map(|inner| Camera { inner })
    }

    /// The file's camera, or one looking at the scene's bounds from the front-top (what
    /// ``cargo xtask render`` uses).
    fn camera_or_default(&self) -> Camera {
        Camera {
            inner: self.setup.camera_or_default(),
        }
    }

    /// The camera's aspect ratio (width / height) when the file declares one.
    #[getter]
    fn aspect(&self) -> Option<f32> {
        self.setup.aspect
    }

    /// What the loader ignored or changed, for the user to read.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.setup.warnings.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "Setup({:?}, {} triangles, {} lights)",
            self.setup.name,
            self.setup.scene.triangle_count(),
            self.setup.lights.len()
        )
    }
}

/// The names of the built-in scenes (the corpus scenes are also accepted by ``builtin``).
#[pyfunction]
pub fn builtin_scenes() -> Vec<&'static str> {
    shadow_scenes::BUILTIN_SCENES.to_vec()
}

/// A built-in scene or a corpus scene by name, with its lights and camera: the same scene
/// ``cargo xtask render --scene NAME`` renders.
#[pyfunction]
pub fn builtin(name: &str) -> PyResult<Setup> {
    shadow_scenes::builtin(name)
        .map(|setup| Setup { setup })
        .map_err(|e| invalid(e.to_string()))
}

/// A glTF 2.0 (``.gltf``, ``.glb``) or OBJ file: emissive meshes become area lights (unless
/// ``emissive_as_geometry``), ``KHR_lights_punctual`` lights small spheres and disks. Sizes
/// are checked against the loader's limits before anything is allocated (``LimitError``).
#[pyfunction]
#[pyo3(signature = (path, emissive_as_geometry=false))]
pub fn load(
    py: Python<'_>,
    path: std::path::PathBuf,
    emissive_as_geometry: bool,
) -> PyResult<Setup> {
    let limits = LoadLimits {
        emissive_as_geometry,
        ..LoadLimits::default()
    };
    let shown = path.display().to_string();
    let result = py.detach(|| load_scene(Path::new(&path), &limits));
    result
        .map(|setup| Setup { setup })
        .map_err(|e| load_error(&shown, &e))
}
