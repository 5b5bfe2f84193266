//! Lights: rectangle, disk, polygon and sphere, of constant radiance or textured from an image
//! array.

use std::sync::Arc;

use glam::{Affine2, Vec3};
use pyo3::prelude::*;

use shadow_core::light::{LightError, TexturedRadiance};
use shadow_core::prelude::*;

use crate::arrays::{vec3, vec3s};
use crate::errors::invalid;

/// An area light. Build one with ``Light.rectangle``, ``Light.rectangle_facing``,
/// ``Light.disk``, ``Light.polygon`` or ``Light.sphere``; a planar light emits from its front
/// side (the side its normal points to).
#[pyclass(frozen, module = "soft_shadows")]
pub struct Light {
    /// The light.
    pub inner: shadow_core::Light,
}

/// `radiance` (one value or RGB) and an optional `texture` ((H, W, 3) linear RGB, row 0 at the
/// light's v = 0, scaled by the radiance) as a [`Radiance`].
fn radiance(radiance: &Bound<'_, PyAny>, texture: Option<&Bound<'_, PyAny>>) -> PyResult<Radiance> {
    let rgb = match radiance.extract::<f32>() {
        Ok(v) => Vec3::splat(v),
        Err(_) => vec3(radiance, "radiance")?,
    };
    let Some(texture) = texture else {
        return Radiance::constant(rgb).map_err(light_error);
    };
    let t = vec3s(texture, "texture")?;
    let [h, w, 3] = t.shape.as_slice() else {
        return Err(invalid(format!(
            "texture: shape {:?} is not (H, W, 3)",
            t.shape
        )));
    };
    let (w, h) = (
        u32::try_from(*w).map_err(|_| invalid("texture: too wide"))?,
        u32::try_from(*h).map_err(|_| invalid("texture: too tall"))?,
    );
    TexturedRadiance::new(w, h, t.vec3s()?.to_vec(), rgb, Affine2::IDENTITY)
        .map(Radiance::Textured)
        .map_err(light_error)
}

fn light_error(e: LightError) -> PyErr {
    invalid(format!("light: {e}"))
}

fn wrap<L: AreaLight + 'static>(light: Result<L, LightError>) -> PyResult<Light> {
    Ok(Light {
        inner: Arc::new(light.map_err(light_error)?),
    })
}

#[pymethods]
impl Light {
    /// A rectangle centred at ``center`` spanning ``center ± half_u ± half_v`` (orthogonal
    /// axes), facing ``half_u × half_v``.
    #[staticmethod]
    #[pyo3(signature = (center, half_u, half_v, radiance=None, texture=None))]
    fn rectangle(
        py: Python<'_>,
        center: &Bound<'_, PyAny>,
        half_u: &Bound<'_, PyAny>,
        half_v: &Bound<'_, PyAny>,
        radiance: Option<&Bound<'_, PyAny>>,
        texture: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Light> {
        let r = self::radiance(&or_one(py, radiance), texture)?;
        wrap(RectLight::new(
            vec3(center, "center")?,
            vec3(half_u, "half_u")?,
            vec3(half_v, "half_v")?,
            r,
        ))
    }

    /// A ``width`` × ``height`` rectangle centred at ``center`` facing ``normal``.
    #[staticmethod]
    #[pyo3(signature = (center, normal, width, height, radiance=None, texture=None))]
    fn rectangle_facing(
        py: Python<'_>,
        center: &Bound<'_, PyAny>,
        normal: &Bound<'_, PyAny>,
        width: f32,
        height: f32,
        radiance: Option<&Bound<'_, PyAny>>,
        texture: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Light> {
        let r = self::radiance(&or_one(py, radiance), texture)?;
        wrap(RectLight::facing(
            vec3(center, "center")?,
            vec3(normal, "normal")?,
            width,
            height,
            r,
        ))
    }

    /// A disk of ``radius`` centred at ``center`` facing ``normal``.
    #[staticmethod]
    #[pyo3(signature = (center, normal, radius, radiance=None, texture=None))]
    fn disk(
        py: Python<'_>,
        center: &Bound<'_, PyAny>,
        normal: &Bound<'_, PyAny>,
        radius: f32,
        radiance: Option<&Bound<'_, PyAny>>,
        texture: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Light> {
        let r = self::radiance(&or_one(py, radiance), texture)?;
        wrap(DiskLight::new(
            vec3(center, "center")?,
            vec3(normal, "normal")?,
            radius,
            r,
        ))
    }

    /// A planar polygon from its outline ``vertices`` ((K, 3), K ≥ 3, counter-clockwise seen
    /// from the side it emits to).
    #[staticmethod]
    #[pyo3(signature = (vertices, radiance=None, texture=None))]
    fn polygon(
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        radiance: Option<&Bound<'_, PyAny>>,
        texture: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Light> {
        let v = vec3s(vertices, "vertices")?;
        if v.shape.len() != 2 {
            return Err(invalid(format!(
                "vertices: shape {:?} is not (K, 3)",
                v.shape
            )));
        }
        let r = self::radiance(&or_one(py, radiance), texture)?;
        wrap(PolygonLight::new(v.vec3s()?.to_vec(), r))
    }

    /// A sphere of ``radius`` at ``center``, emitting all around.
    #[staticmethod]
    #[pyo3(signature = (center, radius, radiance=None, texture=None))]
    fn sphere(
        py: Python<'_>,
        center: &Bound<'_, PyAny>,
        radius: f32,
        radiance: Option<&Bound<'_, PyAny>>,
        texture: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Light> {
        let r = self::radiance(&or_one(py, radiance), texture)?;
        wrap(SphereLight::new(vec3(center, "center")?, radius, r))
    }

    /// The light's kind: ``rectangle``, ``disk``, ``polygon``, ``sphere``, ``point`` or
    /// ``mesh``.
    #[getter]
    fn kind(&self) -> String {
        format!("{:?}", self.inner.kind()).to_lowercase()
    }

    /// The emitting area.
    #[getter]
    fn area(&self) -> f32 {
        self.inner.area()
    }

    /// The centre.
    #[getter]
    fn center(&self) -> [f32; 3] {
        self.inner.center().to_array()
    }

    /// Whether the radiance is an image (V is then RGB, DCS eq. 2).
    #[getter]
    fn textured(&self) -> bool {
        self.inner.is_textured()
    }

    fn __repr__(&self) -> String {
        format!(
            "Light({}, area {:.4}, centre {:?})",
            self.kind(),
            self.inner.area(),
            self.inner.center().to_array()
        )
    }
}

/// `radiance`, or 1.0 when not given.
fn or_one<'py>(py: Python<'py>, radiance: Option<&Bound<'py, PyAny>>) -> Bound<'py, PyAny> {
    match radiance {
        Some(r) if !r.is_none() => r.clone(),
        _ => pyo3::types::PyFloat::new(py, 1.0).into_any(),
    }
}
