//! Receivers: points with normals, a camera's view through the built-in rasterizer, or a
//! renderer's G-buffer (DESIGN section 3, "Receivers"), snapped onto the scene.

use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use shadow_core::prelude::*;
use shadow_core::raster::NO_TRIANGLE;
use shadow_core::receivers::{GBuffer, Snapping};
use shadow_core::view_samples::FREE_RECEIVER;

use crate::arrays::{Floats, leading, mask, to_array, vec3s, vec3s_to_array};
use crate::errors::{invalid, raster_error, receiver_error};
use crate::scene::{Camera, Scene};

/// The points V is estimated at, with their normals, laid out as the caller gave them: shape
/// ``(n,)`` for points, ``(height, width)`` for a camera or G-buffer. Results come back in the
/// same shape.
#[pyclass(frozen, module = "soft_shadows")]
pub struct Receivers {
    /// The receivers as every technique takes them.
    pub view: Arc<ViewSamples>,
    /// The caller's layout.
    pub shape: Vec<usize>,
}

/// The snapping tolerance: the caller's, or the scene's default.
fn snapping(scene: &Scene, tolerance: Option<f32>) -> PyResult<Snapping> {
    match tolerance {
        None => Ok(Snapping::for_scene(scene.inner.as_ref())),
        Some(t) if t.is_finite() && t > 0.0 => Ok(Snapping { tolerance: t }),
        Some(t) => Err(invalid(format!(
            "tolerance: {t} is not a positive finite distance"
        ))),
    }
}

/// `n` as a `u32` image side, or an error naming `what`.
fn side(n: usize, what: &str) -> PyResult<u32> {
    u32::try_from(n).map_err(|_| invalid(format!("{what}: {n} is too large")))
}

#[pymethods]
impl Receivers {
    /// Receivers at ``points`` (n, 3) facing ``normals`` (n, 3): lightmap texels, a path
    /// tracer's hit points, vertices. Each is snapped onto the surface it lies on within
    /// ``tolerance`` along its normal (default 1e-4 of the scene's diagonal); one that matches
    /// no surface is moved off its point by the tolerance and counted in ``unmatched``. They
    /// carry no camera: techniques that work in a camera's image refuse them.
    #[staticmethod]
    #[pyo3(signature = (scene, points, normals, tolerance=None))]
    fn from_points(
        py: Python<'_>,
        scene: &Scene,
        points: &Bound<'_, PyAny>,
        normals: &Bound<'_, PyAny>,
        tolerance: Option<f32>,
    ) -> PyResult<Receivers> {
        let p = vec3s(points, "points")?;
        let n = vec3s(normals, "normals")?;
        for (f, what) in [(&p, "points"), (&n, "normals")] {
            if f.shape.len() != 2 {
                return Err(invalid(format!(
                    "{what}: shape {:?} is not (n, 3)",
                    f.shape
                )));
            }
        }
        let snap = snapping(scene, tolerance)?;
        let (ps, ns) = (p.vec3s()?, n.vec3s()?);
        let s = scene.inner.clone();
        let view = py
            .detach(|| ViewSamples::from_points(s.as_ref(), ps, ns, snap))
            .map_err(|e| receiver_error(&e))?;
        Ok(Receivers {
            shape: vec![ps.len()],
            view: Arc::new(view),
        })
    }

    /// The view of ``camera`` at ``width`` × ``height`` through the built-in rasterizer (the
    /// receivers ``cargo xtask render`` uses).
    #[staticmethod]
    fn from_camera(
        py: Python<'_>,
        scene: &Scene,
        camera: &Camera,
        width: u32,
        height: u32,
    ) -> PyResult<Receivers> {
        let s = scene.inner.clone();
        let c = camera.inner;
        let view = py
            .detach(|| ViewSamples::render(s.as_ref(), &c, width, height))
            .map_err(|e| raster_error(&e))?;
        Ok(Receivers {
            shape: vec![height as usize, width as usize],
            view: Arc::new(view),
        })
    }

    /// A renderer's G-buffer: ``positions`` and geometric ``normals`` (H, W, 3), optional
    /// ``valid`` (H, W) bool mask, ``shading_normals`` and diffuse ``albedo`` (H, W, 3), and the
    /// ``camera`` it was rendered with (techniques that work in the camera's image need it).
    /// Snapped onto the scene as ``from_points``.
    #[staticmethod]
    #[pyo3(signature = (scene, positions, normals, valid=None, camera=None, shading_normals=None, albedo=None, tolerance=None))]
    #[allow(clippy::too_many_arguments)]
    fn from_gbuffer<'py>(
        py: Python<'py>,
        scene: &Scene,
        positions: &Bound<'py, PyAny>,
        normals: &Bound<'py, PyAny>,
        valid: Option<&Bound<'py, PyAny>>,
        camera: Option<&Camera>,
        shading_normals: Option<&Bound<'py, PyAny>>,
        albedo: Option<&Bound<'py, PyAny>>,
        tolerance: Option<f32>,
    ) -> PyResult<Receivers> {
        let p = vec3s(positions, "positions")?;
        let shape = leading(&p);
        let [h, w] = shape.as_slice() else {
            return Err(invalid(format!(
                "positions: shape {:?} is not (H, W, 3)",
                p.shape
            )));
        };
        let (width, height) = (side(*w, "width")?, side(*h, "height")?);
        let same = |obj: &Bound<'py, PyAny>, what: &str| -> PyResult<Floats<'py>> {
            let f = vec3s(obj, what)?;
            if f.shape != p.shape {
                return Err(invalid(format!(
                    "{what}: shape {:?} is not the positions' {:?}",
                    f.shape, p.shape
                )));
            }
            Ok(f)
        };
        let n = same(normals, "normals")?;
        let shading = shading_normals
            .map(|s| same(s, "shading_normals"))
            .transpose()?;
        let albedo = albedo.map(|a| same(a, "albedo")).transpose()?;
        let valid = valid.map(|v| mask(v, "valid", &shape)).transpose()?;
        let snap = snapping(scene, tolerance)?;
        let g = GBuffer {
            width,
            height,
            positions: p.vec3s()?,
            geometric_normals: n.vec3s()?,
            shading_normals: shading.as_ref().map(|s| s.vec3s()).transpose()?,
            albedo: albedo.as_ref().map(|a| a.vec3s()).transpose()?,
            valid: valid.as_deref(),
            camera: camera.map(|c| c.inner.raster_view(width, height)),
        };
        let s = scene.inner.clone();
        let view = py
            .detach(|| ViewSamples::from_gbuffer(s.as_ref(), &g, snap))
            .map_err(|e| receiver_error(&e))?;
        Ok(Receivers {
            shape,
            view: Arc::new(view),
        })
    }

    /// The layout results come back in: ``(n,)`` or ``(height, width)``.
    #[getter]
    fn shape(&self) -> Vec<usize> {
        self.shape.clone()
    }

    /// Receivers that hold a surface.
    #[getter]
    fn valid_count(&self) -> usize {
        self.view.valid_count()
    }

    /// Receivers that matched no surface within the tolerance (moved off their point).
    #[getter]
    fn unmatched(&self) -> u64 {
        self.view.unmatched_receivers()
    }

    /// Whether the receivers carry a perspective camera.
    #[getter]
    fn has_camera(&self) -> bool {
        self.view.eye().is_some()
    }

    /// The receivers as arrays in their shape: ``position``, ``geometric_normal``,
    /// ``shading_normal`` (…, 3) float32, ``depth`` float32, ``triangle`` int64 (-1 where none:
    /// background or unmatched) and ``valid`` bool. From a camera this is the G-buffer.
    fn arrays<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let v = &self.view;
        let d = PyDict::new(py);
        d.set_item("position", vec3s_to_array(py, v.positions(), &self.shape)?)?;
        d.set_item(
            "geometric_normal",
            vec3s_to_array(py, v.geometric_normals(), &self.shape)?,
        )?;
        d.set_item(
            "shading_normal",
            vec3s_to_array(py, v.shading_normals(), &self.shape)?,
        )?;
        d.set_item("depth", to_array(py, v.depths().to_vec(), &self.shape)?)?;
        let triangles: Vec<i64> = v
            .triangles()
            .iter()
            .map(|&t| {
                if t == NO_TRIANGLE || t == FREE_RECEIVER {
                    -1
                } else {
                    i64::from(t)
                }
            })
            .collect();
        d.set_item("triangle", to_array(py, triangles, &self.shape)?)?;
        d.set_item("valid", to_array(py, v.valid_mask(), &self.shape)?)?;
        Ok(d)
    }

    fn __len__(&self) -> usize {
        self.view.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Receivers(shape {:?}, {} valid, {} unmatched)",
            self.shape,
            self.view.valid_count(),
            self.view.unmatched_receivers()
        )
    }
}
