//! The cost and error models of the `auto` chooser, their fit and their predictions.
//!
//! **Features** of a scene and view ([`Features`]) are deterministic for a seed: the triangle
//! count, the valid pixels, and what the probe pass (two independent 16-sample stratified sets
//! per pixel, on a low-resolution copy of the view, evaluated by DCS or by the reference on the
//! same samples, [`super::probe`]) finds: the share of pixels in shadow (some sample occluded),
//! the share in penumbra, and the mean variance
//! `v16` of a 16-sample estimate, which is the image MSE of the 16-sample reference. The probe
//! stands for the light's solid angle and the penumbra's extent at once: both enter the
//! pixels' variance.
//!
//! **Error** of a configuration against an independent many-sample reference:
//! * sample counts and the biased map-based methods: `k sqrt(v16)` (for stratified sampling
//!   with edges across the light `k` is about `(N / 16)^-3/4`; for a biased method `k` says
//!   how its error tracks the penumbra);
//! * the adaptive reference: `k target`.
//!
//! `k` is a high quantile ([`AutoModel::error_quantile`]) of the ratio measured over the
//! fitting scenes, so the prediction errs on the safe side.
//!
//! **Cost** in seconds on the fitting machine: `theta . [triangles, pixels, sampled pixels,
//! penumbra pixels, silhouette edges x penumbra pixels, sampled pixels x v16^(2/3)]` with
//! `theta >= 0` ("sampled" pixels are those the reference traces, [`Features::sampled_share`]), fitted by non-negative least squares
//! on relative errors (every subset of the
//! terms the configuration's work can depend on, [`Config::cost_mask`], the best feasible one
//! kept). Each probe's own cost is fitted the same way on the scenes it looked at (the
//! reference's on the first four terms, DCS's with the silhouette term too); at run time the
//! ratio of the probe's measured time to its
//! predicted time scales every prediction to the machine at hand. The ratio is common to all
//! candidates, so under an error budget the choice does not depend on it: it is deterministic.

use serde::{Deserialize, Serialize};
use shadow_core::prelude::*;
use shadow_ref::AdaptiveReference;
use shadow_ref::adaptive::{DEFAULT_BATCH, DEFAULT_CAP};

use super::probe::ProbeKind;

/// The committed model, written by `cargo xtask budgets --write-model`.
pub const COMMITTED_MODEL: &str = include_str!("../auto-model.json");

/// Builds a named configuration with `seed`: with `Some(n)`, the same technique as the named
/// one at `n` samples (`ref-64` at 256 samples is `ref-256`); with `None`, the named one
/// itself (`pcss`). The chooser composes techniques of several crates and names them as the
/// workspace's registry does; `shadow-presets`' `build` is that registry's catalogue.
///
/// # Errors
/// [`TechniqueError::InvalidInput`] for a name the catalogue does not know, a sample count it
/// refuses, or a configuration that takes no sample count.
pub type Catalogue = fn(
    name: &str,
    samples: Option<u32>,
    seed: u64,
) -> Result<Box<dyn ShadowTechnique>, TechniqueError>;

/// One configuration the chooser can pick.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "family", rename_all = "kebab-case")]
pub enum Config {
    /// The uniform stratified reference at `samples` samples.
    Ref {
        /// Samples per pixel.
        samples: u32,
    },
    /// Depth complexity sampling at `samples` samples.
    Dcs {
        /// Samples per pixel.
        samples: u32,
    },
    /// The adaptive reference toward image RMSE `target`.
    RefAdaptive {
        /// Target image RMSE.
        target: f32,
    },
    /// A registered preset with no sample count to set (`pcss`, `ssm-adaptive`, ...).
    Preset {
        /// The preset's name.
        name: String,
    },
}

impl Config {
    /// The cost terms ([`COST_TERMS`], as a bit mask) the configuration's cost may depend on:
    /// triangles, pixels, sampled and penumbra pixels for all; the silhouette term for DCS
    /// alone (its wedges); the `v16` term for the adaptive reference alone (its counts follow
    /// the variance). A term a configuration's work cannot depend on is never fitted, so a
    /// correlation between scenes cannot stand in for a cost.
    pub fn cost_mask(&self) -> u32 {
        const BASE: u32 = 0b1111;
        match self {
            Config::Dcs { .. } => BASE | 1 << 4,
            Config::RefAdaptive { .. } => BASE | 1 << 5,
            Config::Ref { .. } | Config::Preset { .. } => BASE,
        }
    }

    /// Whether the configuration's error on semi-opaque occluders is only sampling noise. DCS
    /// sums opacities (a saturating count of layers, DCS section 3) where the exact answer is
    /// the product of transmittances: its error there has a floor that no sample count lowers
    /// and no probe of the sampling variance predicts, so `auto` leaves it out on such scenes.
    pub fn exact_with_semi_opacity(&self) -> bool {
        !matches!(self, Config::Dcs { .. })
    }

    /// The configuration's name, as the registry would spell it (`ref-64`, `dcs-256`,
    /// `ref-adaptive-0.003`, `pcss`).
    pub fn name(&self) -> String {
        match self {
            Config::Ref { samples } => format!("ref-{samples}"),
            Config::Dcs { samples } => format!("dcs-{samples}"),
            Config::RefAdaptive { target } => format!("ref-adaptive-{target}"),
            Config::Preset { name } => name.clone(),
        }
    }

    /// Builds the technique with `seed`, the named configurations through `catalogue`.
    ///
    /// # Errors
    /// [`TechniqueError::InvalidInput`] for a count, target or name the catalogue refuses.
    pub fn build(
        &self,
        seed: u64,
        catalogue: Catalogue,
    ) -> Result<Box<dyn ShadowTechnique>, TechniqueError> {
        match self {
            Config::Ref { samples } => catalogue("ref-64", Some(*samples), seed),
            Config::Dcs { samples } => catalogue("dcs-16", Some(*samples), seed),
            Config::RefAdaptive { target } => Ok(Box::new(
                AdaptiveReference::new(*target, DEFAULT_BATCH, DEFAULT_CAP, seed)?
                    .named(&self.name()),
            )),
            Config::Preset { name } => catalogue(name, None, seed),
        }
    }
}

/// What a configuration's error is proportional to.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum ErrorModel {
    /// `k sqrt(v16)`.
    Probe {
        /// The factor.
        k: f64,
    },
    /// `k target` (the adaptive reference).
    Target {
        /// The factor.
        k: f64,
    },
}

/// The number of cost terms: triangles, pixels, sampled pixels, penumbra pixels, silhouette
/// edges times penumbra pixels (DCS's wedge-sample pairs), sampled pixels times `v16^(2/3)`
/// (the adaptive reference's samples at a fixed target: `n ~ (v16 / target^2)^(2/3)` under the
/// `n^-3/2` error model).
pub const COST_TERMS: usize = 6;

/// A configuration with its fitted models.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Candidate {
    /// What to build.
    pub config: Config,
    /// Its error model.
    pub error: ErrorModel,
    /// Seconds per unit of each cost term ([`COST_TERMS`]) on the fitting machine.
    pub cost: [f64; COST_TERMS],
    /// Fitting scenes it ran on.
    pub scenes: usize,
}

/// Scene and view features the models read (see the module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Features {
    /// Triangles of the scene.
    pub triangles: usize,
    /// Edges that are silhouettes from the light's centre (two faces on either side of it, or
    /// a boundary): DCS's penumbra wedges.
    pub silhouettes: usize,
    /// The scene has semi-opaque occluders.
    pub semi_opaque: bool,
    /// Valid pixels of the view.
    pub pixels: usize,
    /// Share of the probe's pixels the reference traces: those in shadow (some sample of the
    /// two sets occluded or below the horizon: umbra and penumbra) under a light whose
    /// bounding quad gives the reference a beam that proves the others lit, else all of them.
    pub sampled_share: f64,
    /// Share of the probe's pixels in penumbra.
    pub penumbra_share: f64,
    /// Mean variance of a 16-sample estimate over the probe's pixels.
    pub v16: f64,
    /// Valid pixels of the probe's low-resolution view.
    pub probe_pixels: usize,
    /// Measured seconds of the probe (its preparation and its pass), on this machine.
    pub probe_seconds: f64,
    /// Which technique the probe ran.
    #[serde(default)]
    pub probe: ProbeKind,
}

impl Features {
    /// The cost terms of the full view.
    pub fn terms(&self) -> [f64; COST_TERMS] {
        self.terms_at(self.pixels)
    }

    /// The cost terms of the probe's own work.
    pub fn probe_terms(&self) -> [f64; COST_TERMS] {
        self.terms_at(self.probe_pixels)
    }

    fn terms_at(&self, pixels: usize) -> [f64; COST_TERMS] {
        let p = pixels as f64;
        [
            self.triangles as f64,
            p,
            p * self.sampled_share,
            p * self.penumbra_share,
            p * self.penumbra_share * self.silhouettes as f64,
            p * self.sampled_share * self.v16.powf(2.0 / 3.0),
        ]
    }
}

/// One measured run for the fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Observation {
    /// The scene's name.
    pub scene: String,
    /// Its features.
    pub features: Features,
    /// The configuration run.
    pub config: Config,
    /// RMSE against the independent reference.
    pub rmse: f64,
    /// Seconds, preparation and estimate (median of repeats).
    pub seconds: f64,
}

/// The chooser's models: every candidate, the probe's cost, and where they were fitted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AutoModel {
    /// How, when and where the model was fitted.
    pub fitted: serde_json::Value,
    /// The most pixels of the probe's low-resolution view.
    pub probe_pixels: u32,
    /// The quantile of the measured error ratios each `k` is.
    pub error_quantile: f64,
    /// The reference probe's cost, as a candidate's.
    pub probe_cost: [f64; COST_TERMS],
    /// The DCS probe's cost, as a candidate's.
    #[serde(default)]
    pub dcs_probe_cost: [f64; COST_TERMS],
    /// The configurations.
    pub candidates: Vec<Candidate>,
}

/// One candidate's prediction on a scene.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Prediction {
    /// The configuration's name.
    pub name: String,
    /// Predicted RMSE.
    pub rmse: f64,
    /// Predicted seconds on this machine.
    pub seconds: f64,
}

impl AutoModel {
    /// The model committed beside this crate.
    ///
    /// # Errors
    /// A message when the file does not parse (a build with a broken model file).
    pub fn committed() -> Result<Self, String> {
        serde_json::from_str(COMMITTED_MODEL).map_err(|e| format!("auto-model.json: {e}"))
    }

    /// Fits a model from `observations` (several scenes per configuration), `probes` the
    /// probe's measured (features, seconds) on the same scenes.
    pub fn fit(
        observations: &[Observation],
        probes: &[Features],
        probe_pixels: u32,
        error_quantile: f64,
        fitted: serde_json::Value,
    ) -> Self {
        let mut configs: Vec<Config> = Vec::new();
        for o in observations {
            if !configs.contains(&o.config) {
                configs.push(o.config.clone());
            }
        }
        let candidates = configs
            .into_iter()
            .map(|config| {
                let runs: Vec<&Observation> =
                    observations.iter().filter(|o| o.config == config).collect();
                let ratios: Vec<f64> = runs
                    .iter()
                    .filter_map(|o| {
                        let basis = match config {
                            Config::RefAdaptive { target } => f64::from(target),
                            _ => o.features.v16.sqrt(),
                        };
                        (basis > 0.0).then(|| o.rmse / basis)
                    })
                    .collect();
                let k = quantile(ratios, error_quantile).unwrap_or(1.0);
                let error = match config {
                    Config::RefAdaptive { .. } => ErrorModel::Target { k },
                    _ => ErrorModel::Probe { k },
                };
                let rows: Vec<([f64; COST_TERMS], f64)> = runs
                    .iter()
                    .map(|o| (o.features.terms(), o.seconds))
                    .collect();
                Candidate {
                    cost: nnls_relative(&rows, config.cost_mask()),
                    error,
                    scenes: runs.len(),
                    config,
                }
            })
            .collect();
        let probe_rows = |kind: ProbeKind| -> Vec<([f64; COST_TERMS], f64)> {
            probes
                .iter()
                .filter(|f| f.probe == kind)
                .map(|f| (f.probe_terms(), f.probe_seconds))
                .collect()
        };
        Self {
            fitted,
            probe_pixels,
            error_quantile,
            // The adaptive reference's first pass: BVH, beams, 32 samples.
            probe_cost: nnls_relative(&probe_rows(ProbeKind::Reference), PROBE_COST_MASK),
            // DCS's preparation (edges, silhouettes, wedges) and two 16-sample passes.
            dcs_probe_cost: nnls_relative(&probe_rows(ProbeKind::Dcs), DCS_PROBE_COST_MASK),
            candidates,
        }
    }

    /// How much slower this machine is than the fitting one, from the probe's measured and
    /// modelled times (1 when the model has no probe cost).
    pub fn speed_ratio(&self, f: &Features) -> f64 {
        let cost = match f.probe {
            ProbeKind::Reference => &self.probe_cost,
            ProbeKind::Dcs => &self.dcs_probe_cost,
        };
        let modelled = dot(cost, &f.probe_terms());
        if modelled > 0.0 && f.probe_seconds > 0.0 {
            f.probe_seconds / modelled
        } else {
            1.0
        }
    }

    /// Predicted error and time of `c` on features `f` (time scaled by `speed`).
    pub fn predict(&self, c: &Candidate, f: &Features, speed: f64) -> Prediction {
        let rmse = match (c.error, &c.config) {
            (ErrorModel::Target { k }, Config::RefAdaptive { target }) => k * f64::from(*target),
            (ErrorModel::Target { k }, _) | (ErrorModel::Probe { k }, _) => k * f.v16.sqrt(),
        };
        Prediction {
            name: c.config.name(),
            rmse,
            seconds: dot(&c.cost, &f.terms()) * speed,
        }
    }
}

fn dot(a: &[f64; COST_TERMS], b: &[f64; COST_TERMS]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The `q` quantile (nearest rank) of `v`; `None` when empty.
pub fn quantile(mut v: Vec<f64>, q: f64) -> Option<f64> {
    v.retain(|x| x.is_finite());
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let i = ((q.clamp(0.0, 1.0) * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1;
    Some(v[i])
}

/// The cost terms the reference probe's own time may depend on (see [`Config::cost_mask`]).
pub const PROBE_COST_MASK: u32 = 0b1111;

/// The cost terms the DCS probe's own time may depend on: DCS's (see [`Config::cost_mask`]).
pub const DCS_PROBE_COST_MASK: u32 = 0b1_1111;

/// Non-negative least squares on relative errors: `theta >= 0` minimising
/// `sum ((theta . x - t) / t)^2` over the terms in `allowed` (a bit mask), by trying every
/// subset of them and keeping the feasible solution of least residual.
pub fn nnls_relative(rows: &[([f64; COST_TERMS], f64)], allowed: u32) -> [f64; COST_TERMS] {
    let rows: Vec<([f64; COST_TERMS], f64)> = rows
        .iter()
        .filter(|(_, t)| *t > 0.0 && t.is_finite())
        .map(|(x, t)| (x.map(|v| v / t), 1.0))
        .collect();
    let mut best = ([0.0; COST_TERMS], f64::INFINITY);
    for mask in (1u32..(1 << COST_TERMS)).filter(|m| m & !allowed == 0) {
        let idx: Vec<usize> = (0..COST_TERMS).filter(|i| mask & (1 << i) != 0).collect();
        if idx.len() > rows.len() {
            continue;
        }
        let Some(sol) = least_squares(&rows, &idx) else {
            continue;
        };
        if sol.iter().any(|&v| !(v >= 0.0)) {
            continue;
        }
        let mut theta = [0.0; COST_TERMS];
        for (j, &i) in idx.iter().enumerate() {
            theta[i] = sol[j];
        }
        let res: f64 = rows.iter().map(|(x, t)| (dot(&theta, x) - t).powi(2)).sum();
        if res < best.1 {
            best = (theta, res);
        }
    }
    best.0
}

/// Least squares on the columns `idx` by the normal equations (Gaussian elimination with
/// partial pivoting); `None` when singular.
fn least_squares(rows: &[([f64; COST_TERMS], f64)], idx: &[usize]) -> Option<Vec<f64>> {
    let n = idx.len();
    // Columns are scaled to unit norm first: triangles and pixels differ by orders of magnitude.
    let scale: Vec<f64> = idx
        .iter()
        .map(|&i| rows.iter().map(|(x, _)| x[i] * x[i]).sum::<f64>().sqrt())
        .collect();
    if scale.iter().any(|&s| !(s > 0.0)) {
        return None;
    }
    let mut a = vec![vec![0.0; n + 1]; n];
    for (x, t) in rows {
        for r in 0..n {
            let xr = x[idx[r]] / scale[r];
            for c in 0..n {
                a[r][c] += xr * x[idx[c]] / scale[c];
            }
            a[r][n] += xr * t;
        }
    }
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() < 1e-12 {
            return None;
        }
        a.swap(col, piv);
        for r in 0..n {
            if r != col {
                let f = a[r][col] / a[col][col];
                for c in col..=n {
                    a[r][c] -= f * a[col][c];
                }
            }
        }
    }
    Some((0..n).map(|r| a[r][n] / a[r][r] / scale[r]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nnls_recovers_a_non_negative_cost() {
        let theta = [1e-7, 2e-6, 0.0, 5e-5, 0.0, 3e-4];
        let rows: Vec<([f64; COST_TERMS], f64)> = [
            [1e3, 1e4, 2e3, 1e2, 1e5, 20.0],
            [1e5, 1e4, 5e3, 3e3, 3e7, 90.0],
            [1e4, 2e4, 1e4, 4e2, 1e6, 30.0],
            [5e4, 5e3, 1e3, 1e3, 4e6, 5.0],
            [2e3, 1.2e4, 9e3, 2e3, 2e5, 70.0],
            [3e4, 8e3, 4e3, 9e2, 5e6, 11.0],
            [7e3, 3e3, 2e3, 6e2, 8e5, 42.0],
        ]
        .iter()
        .map(|x| (*x, dot(&theta, x)))
        .collect();
        let fit = nnls_relative(&rows, (1 << COST_TERMS) - 1);
        for (x, t) in &rows {
            assert!((dot(&fit, x) - t).abs() < 1e-6 * t, "{fit:?}");
        }
        assert!(fit.iter().all(|&v| v >= 0.0));
        // Terms outside the mask stay at zero.
        let masked = nnls_relative(&rows, 0b1011);
        assert_eq!((masked[2], masked[4], masked[5]), (0.0, 0.0, 0.0));
    }

    #[test]
    fn quantiles_take_the_nearest_rank() {
        let v = vec![4.0, 1.0, 3.0, 2.0, f64::NAN];
        assert_eq!(quantile(v.clone(), 0.0), Some(1.0));
        assert_eq!(quantile(v.clone(), 0.5), Some(2.0));
        assert_eq!(quantile(v.clone(), 0.8), Some(4.0));
        assert_eq!(quantile(v, 1.0), Some(4.0));
        assert_eq!(quantile(Vec::new(), 0.5), None);
    }
}
