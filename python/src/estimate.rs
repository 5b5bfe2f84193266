//! Techniques and estimates: every registered preset by name, V per light with per-sample
//! visibility, direct light and statistics, and the light samples a sample-based technique
//! evaluates.

use glam::UVec2;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use shadow_core::lights::{LightEstimate, LightsEstimate, PreparedLights};
use shadow_core::prelude::*;

use crate::arrays::{to_array, vec3s_to_array};
use crate::errors::{invalid, technique_error};
use crate::light::Light as PyLight;
use crate::receivers::Receivers;
use crate::scene::Scene;

/// `value` as a Python object through JSON (statistics, decisions, capabilities).
fn to_python<'py>(py: Python<'py>, value: &impl serde::Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| invalid(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// Every registered preset: a list of dicts with ``name``, ``description``, ``family``,
/// ``samples`` (light samples per receiver, ``None`` for techniques that declare none),
/// ``settable_samples`` (whether ``estimate(..., samples=N)`` applies) and the technique's
/// capabilities: ``lights`` (kinds), ``semi_opaque``, ``textured_lights``,
/// ``needs_closed_meshes``, ``sample_based``, ``processor`` (``cpu`` or ``gpu``) and
/// ``needs_camera``.
#[pyfunction]
pub fn techniques(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let list = PyList::empty(py);
    for p in shadow_presets::registry() {
        let t = (p.make)(1);
        let c = t.capabilities();
        let d = PyDict::new(py);
        d.set_item("name", p.name)?;
        d.set_item("description", p.description)?;
        d.set_item("family", shadow_presets::family_of(p.name))?;
        d.set_item("samples", t.light_sampler().map(|s| s.count()))?;
        d.set_item("settable_samples", p.with_samples.is_some())?;
        let kinds: Vec<String> = c
            .lights
            .iter()
            .map(|k| format!("{k:?}").to_lowercase())
            .collect();
        d.set_item("lights", kinds)?;
        d.set_item("semi_opaque", c.semi_opaque)?;
        d.set_item("textured_lights", c.textured_lights)?;
        d.set_item("needs_closed_meshes", c.needs_closed_meshes)?;
        d.set_item("sample_based", c.sample_based)?;
        d.set_item(
            "processor",
            match c.processor {
                Processor::Cpu => "cpu",
                Processor::Gpu => "gpu",
            },
        )?;
        d.set_item("needs_camera", c.needs_camera)?;
        list.append(d)?;
    }
    Ok(list)
}

/// `lights` as a list: one ``Light`` or a sequence of them.
fn light_list(lights: &Bound<'_, PyAny>) -> PyResult<Vec<shadow_core::Light>> {
    if let Ok(one) = lights.cast::<PyLight>() {
        return Ok(vec![one.get().inner.clone()]);
    }
    let mut out = Vec::new();
    for (k, item) in lights
        .try_iter()
        .map_err(|_| invalid("lights: not a Light nor a sequence of Lights"))?
        .enumerate()
    {
        let item = item?;
        let l = item
            .cast::<PyLight>()
            .map_err(|_| invalid(format!("lights[{k}]: not a Light")))?;
        out.push(l.get().inner.clone());
    }
    Ok(out)
}

/// One light's V, with what was asked for, in the receivers' shape.
#[pyclass(frozen, module = "soft_shadows")]
pub struct LightResult {
    /// The light's index in the list given.
    #[pyo3(get)]
    index: usize,
    /// The technique that shadowed it (the fallback's name where the technique refused it).
    #[pyo3(get)]
    technique: String,
    /// Why the technique refused this light, when the fallback traced it.
    #[pyo3(get)]
    fallback_reason: Option<String>,
    /// True when the light reaches no receiver (V zero, no work done).
    #[pyo3(get)]
    skipped: bool,
    /// V: float32 in the receivers' shape, with a trailing axis of 3 for a textured light
    /// (radiance-weighted, DCS eq. 2); 0 where a receiver is not valid.
    #[pyo3(get)]
    visibility: Py<PyAny>,
    /// Per-sample visibility (``per_sample=True``): bool, the receivers' shape plus one axis
    /// of samples; ``None`` otherwise.
    #[pyo3(get)]
    per_sample: Option<Py<PyAny>>,
    /// This light's direct light (``direct=True``): float32 RGB, the receivers' shape plus 3.
    #[pyo3(get)]
    direct: Option<Py<PyAny>>,
    /// The estimate's phases, counters and gauges.
    #[pyo3(get)]
    stats: Py<PyAny>,
    /// What an adaptive technique (``auto``) chose and why; ``None`` for the others.
    #[pyo3(get)]
    decision: Option<Py<PyAny>>,
}

/// Every light's V, the summed direct light and the statistics of one estimate.
#[pyclass(frozen, module = "soft_shadows")]
pub struct Frame {
    /// One result per light, in the order given.
    #[pyo3(get)]
    lights: Vec<Py<LightResult>>,
    /// Direct light summed over the lights (``direct=True``): float32 RGB in the receivers'
    /// shape plus 3.
    #[pyo3(get)]
    direct: Option<Py<PyAny>>,
    /// Every light's estimate statistics merged.
    #[pyo3(get)]
    stats: Py<PyAny>,
    /// The preparation's statistics (every light's).
    #[pyo3(get)]
    preparation: Py<PyAny>,
    /// Which receivers hold a surface: bool in the receivers' shape.
    #[pyo3(get)]
    valid: Py<PyAny>,
    /// The technique's name.
    #[pyo3(get)]
    technique: String,
}

#[pymethods]
impl Frame {
    /// V of the only light; with several lights, read ``lights[k].visibility``.
    #[getter]
    fn visibility(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        match self.lights.as_slice() {
            [one] => Ok(one.get().visibility.clone_ref(py)),
            many => Err(invalid(format!(
                "{} lights were shadowed: read lights[k].visibility",
                many.len()
            ))),
        }
    }

    fn __repr__(&self) -> String {
        format!("Frame({}, {} lights)", self.technique, self.lights.len())
    }
}

/// V of one light's estimate in `shape` (plus 3 for RGB).
fn visibility_array<'py>(
    py: Python<'py>,
    v: &VisibilityImage,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    if v.is_rgb() {
        let rgb: Vec<glam::Vec3> = (0..v.len()).map(|i| v.rgb(i)).collect();
        vec3s_to_array(py, &rgb, shape)
    } else {
        to_array(py, (0..v.len()).map(|i| v.value(i)).collect(), shape)
    }
}

/// Per-sample visibility as bool in `shape` plus the samples.
fn per_sample_array<'py>(
    py: Python<'py>,
    ps: &PerSampleVisibility,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let n = ps.samples();
    let bits: Vec<bool> = (0..ps.pixels())
        .flat_map(|i| (0..n).map(move |k| ps.visible(i, k)))
        .collect();
    let mut s = shape.to_vec();
    s.push(n as usize);
    to_array(py, bits, &s)
}

/// One light's result as Python objects.
fn light_result(
    py: Python<'_>,
    e: &LightEstimate,
    shape: &[usize],
    per_sample: bool,
) -> PyResult<LightResult> {
    let est = &e.estimate;
    let ps = match (per_sample, est.visibility.per_sample()) {
        (true, Some(ps)) => Some(per_sample_array(py, ps, shape)?.unbind()),
        _ => None,
    };
    Ok(LightResult {
        index: e.index,
        technique: e.technique.clone(),
        fallback_reason: e.fallback.as_ref().map(ToString::to_string),
        skipped: e.skipped,
        visibility: visibility_array(py, &est.visibility, shape)?.unbind(),
        per_sample: ps,
        direct: est
            .direct
            .as_ref()
            .map(|d| vec3s_to_array(py, d, shape).map(Bound::unbind))
            .transpose()?,
        stats: to_python(py, &est.stats)?.unbind(),
        decision: est
            .decision
            .as_ref()
            .map(|d| to_python(py, &d.to_json()).map(Bound::unbind))
            .transpose()?,
    })
}

/// The frame as Python objects.
fn frame(
    py: Python<'_>,
    technique: &str,
    prepared: &PreparedLights,
    est: &LightsEstimate,
    receivers: &Receivers,
    per_sample: bool,
) -> PyResult<Frame> {
    let shape = &receivers.shape;
    let lights = est
        .lights
        .iter()
        .map(|e| Py::new(py, light_result(py, e, shape, per_sample)?))
        .collect::<PyResult<Vec<_>>>()?;
    Ok(Frame {
        lights,
        direct: est
            .direct
            .as_ref()
            .map(|d| vec3s_to_array(py, d, shape).map(Bound::unbind))
            .transpose()?,
        stats: to_python(py, &est.stats)?.unbind(),
        preparation: to_python(py, prepared.preparation())?.unbind(),
        valid: to_array(py, receivers.view.valid_mask(), shape)?.unbind(),
        technique: technique.to_string(),
    })
}

/// V of ``receivers`` for each of ``lights`` (one ``Light`` or a list) in ``scene`` by the
/// preset ``technique`` (``techniques()`` lists them; a family name such as ``ref``, ``dcs``
/// or ``afsm`` with ``samples`` sets the count), seeded by ``seed``: the same numbers as the
/// Rust call and ``cargo xtask render``. ``per_sample`` adds per-sample visibility,
/// ``direct`` direct light (DCS eq. 6, sample-based techniques); ``fallback`` names a preset
/// that shadows the lights the technique refuses. ``progress(done, total)`` is called after
/// each light (and once before the first); an exception it raises stops the estimate and is
/// raised here. The GIL is released while the technique runs; Ctrl-C stops it between lights.
#[pyfunction]
#[pyo3(signature = (technique, scene, lights, receivers, *, samples=None, seed=1, per_sample=false, direct=false, fallback=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn estimate(
    py: Python<'_>,
    technique: &str,
    scene: &Scene,
    lights: &Bound<'_, PyAny>,
    receivers: &Receivers,
    samples: Option<u32>,
    seed: u64,
    per_sample: bool,
    direct: bool,
    fallback: Option<&str>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Frame> {
    let t =
        shadow_presets::resolve(technique, samples, seed).map_err(|e| technique_error(py, &e))?;
    let fb = fallback
        .map(|f| shadow_presets::resolve(f, None, seed))
        .transpose()
        .map_err(|e| technique_error(py, &e))?;
    let lights = light_list(lights)?;
    let outputs = Outputs {
        per_sample: per_sample || (direct && t.light_sampler().is_some()),
        direct,
    };
    let scene_ref: SceneRef = scene.inner.clone();
    let view = receivers.view.clone();
    let prepared = py
        .detach(|| PreparedLights::prepare(t.as_ref(), fb.as_deref(), scene_ref, &lights))
        .map_err(|e| technique_error(py, &e))?;
    if let Some(cb) = &progress {
        cb.call1(py, (0, lights.len()))?;
    }
    let mut interrupted: Option<PyErr> = None;
    let result = py.detach(|| {
        let mut hook = |done: usize, total: usize| {
            Python::attach(|py| {
                py.check_signals()?;
                if let Some(cb) = &progress {
                    cb.call1(py, (done, total))?;
                }
                Ok(())
            })
            .map_err(|e: PyErr| {
                interrupted = Some(e);
                TechniqueError::InvalidInput("stopped by the progress callback".into())
            })
        };
        prepared.estimate_with_progress(&view, outputs, &mut hook)
    });
    if let Some(e) = interrupted {
        return Err(e);
    }
    let est = result.map_err(|e| technique_error(py, &e))?;
    frame(py, t.name(), &prepared, &est, receivers, per_sample)
}

/// The light samples ``technique`` evaluates for each receiver: float32 positions on
/// ``light`` in the receivers' shape plus (samples, 3), the points the per-sample visibility
/// of ``estimate`` refers to, in the same order (to trace them with another renderer).
#[pyfunction]
#[pyo3(signature = (technique, light, receivers, *, samples=None, seed=1))]
pub fn sample_points<'py>(
    py: Python<'py>,
    technique: &str,
    light: &PyLight,
    receivers: &Receivers,
    samples: Option<u32>,
    seed: u64,
) -> PyResult<Bound<'py, PyAny>> {
    let t =
        shadow_presets::resolve(technique, samples, seed).map_err(|e| technique_error(py, &e))?;
    let sampler = t.light_sampler().ok_or_else(|| {
        invalid(format!(
            "{}: the technique declares no light samples",
            t.name()
        ))
    })?;
    let view = &receivers.view;
    let width = view.width().max(1);
    let l = light.inner.as_ref();
    let positions = py.detach(|| {
        let mut out = Vec::with_capacity(view.len() * sampler.count() as usize);
        let mut buf = Vec::new();
        for i in 0..view.len() as u32 {
            sampler.light_samples(l, UVec2::new(i % width, i / width), &mut buf);
            out.extend(buf.iter().map(|s| s.position));
        }
        out
    });
    let mut shape = receivers.shape.clone();
    shape.push(sampler.count() as usize);
    vec3s_to_array(py, &positions, &shape)
}
