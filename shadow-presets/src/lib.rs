//! # shadow-presets: every technique's named configurations and their budgets
//!
//! A preset is a name, a constructor and the error budgets the configuration promises per
//! scene (DESIGN section 6). The technique crates know nothing of presets, scenes or budgets:
//! this crate names their configurations ([`reference`](mod@reference), [`dcs`], [`ssm`], [`afsm`],
//! [`auto`]), holds their measured error tables ([`budgets`]), and [`registry`] is the union
//! the conformance suite, the test suite and xtask iterate, so adding a preset here adds it
//! everywhere with no other code.
//!
//! ```
//! let p = shadow_presets::preset("dcs-64").unwrap();
//! let technique = (p.make)(1);
//! assert_eq!(technique.name(), "dcs-64");
//! assert!((p.budget)("bunny").is_some());
//! assert!(shadow_presets::preset("no-such-preset").is_err());
//! ```

#![deny(missing_docs)]

pub mod afsm;
pub mod auto;
pub mod budgets;
pub mod dcs;
pub mod reference;
pub mod ssm;

use serde::Serialize;

use shadow_core::technique::{ShadowTechnique, TechniqueError};

/// Every registered preset, from every technique crate.
pub fn registry() -> Vec<Preset> {
    let mut all = Vec::new();
    all.extend(reference::presets());
    all.extend(dcs::presets());
    all.extend(ssm::presets());
    all.extend(afsm::presets());
    all.extend(auto::presets());
    all
}

/// The preset called `name` with `seed`, at `samples` samples when given (the preset's
/// [`Preset::with_samples`]): the catalogue `shadow-auto` builds its candidates from
/// (`shadow_auto::Catalogue`).
///
/// # Errors
/// [`TechniqueError::InvalidInput`] for an unknown name, a preset without a sample count, or a
/// count the technique refuses.
pub fn build(
    name: &str,
    samples: Option<u32>,
    seed: u64,
) -> Result<Box<dyn ShadowTechnique>, TechniqueError> {
    let p = preset(name).map_err(TechniqueError::InvalidInput)?;
    match samples {
        None => Ok((p.make)(seed)),
        Some(n) => {
            let with = p.with_samples.ok_or_else(|| {
                TechniqueError::InvalidInput(format!("preset {name} has no sample count"))
            })?;
            with(n, seed)
        }
    }
}

/// The family of a preset name: what comes before its first `-` (`dcs-64` is a `dcs`).
pub fn family_of(name: &str) -> &str {
    name.split('-').next().unwrap_or(name)
}

/// A preset by name, or a family by name (`ref`, `dcs`, `afsm`: the family's preset whose
/// sample count can be set), with `seed` and optionally another sample count: what the
/// command line's `--technique` and the Python package's `technique` accept.
///
/// # Errors
/// [`TechniqueError::InvalidInput`] for an unknown name (listing the valid ones), a fixed
/// sample count (naming the family to use instead), or a count the technique refuses.
pub fn resolve(
    name: &str,
    samples: Option<u32>,
    seed: u64,
) -> Result<Box<dyn ShadowTechnique>, TechniqueError> {
    let all = registry();
    let settable = |family: &str| {
        all.iter()
            .find(|p| family_of(p.name) == family && p.with_samples.is_some())
            .copied()
    };
    let p = match preset(name) {
        Ok(p) => p,
        Err(unknown) => settable(name).ok_or(TechniqueError::InvalidInput(unknown))?,
    };
    match samples {
        None => Ok((p.make)(seed)),
        Some(n) => match p.with_samples {
            Some(f) => f(n, seed).map_err(|e| {
                TechniqueError::InvalidInput(format!("technique `{name}` at {n} samples: {e}"))
            }),
            None => Err(TechniqueError::InvalidInput(
                match settable(family_of(p.name)) {
                    Some(_) => format!(
                        "technique `{name}` has a fixed sample count; use its family: `{}` \
                         with {n} samples",
                        family_of(p.name)
                    ),
                    None => format!("technique `{name}` has no sample count to set"),
                },
            )),
        },
    }
}

/// The preset called `name`.
///
/// # Errors
/// A message listing the valid names.
pub fn preset(name: &str) -> Result<Preset, String> {
    let all = registry();
    all.iter().find(|p| p.name == name).copied().ok_or_else(|| {
        format!(
            "unknown technique `{name}`; valid names: {}",
            all.iter().map(|p| p.name).collect::<Vec<_>>().join(", ")
        )
    })
}

/// Largest errors a preset promises on one scene, against the reference on the same view
/// samples (DESIGN section 6). A tighter measured value is good news, a looser one a failure.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Budget {
    /// Root mean square error.
    pub rmse: f64,
    /// RMSE over penumbra pixels.
    pub penumbra_rmse: f64,
    /// Absolute mean signed error.
    pub bias: f64,
    /// Largest absolute error.
    pub max_abs: f64,
    /// Share of pixels off by more than 0.1.
    pub share_over_0_1: f64,
    /// Share of pixels the reference calls fully lit that the technique darkens by more than
    /// 0.1 (false shadow).
    pub false_shadow: f64,
    /// Least per-sample agreement with the same-samples reference (sample-based techniques).
    pub min_sample_agreement: Option<f64>,
}

impl Budget {
    /// A budget from errors measured by the conformance suite (`rmse`, `penumbra_rmse`, `bias`,
    /// `max_abs`, `share_over_0_1`), with the suite's documented margins: 25% on RMSE, penumbra
    /// RMSE and max error (max capped at 1), |bias| doubled with a floor of 0.002, the share
    /// over 0.1 plus 25% and 0.002, and false shadow at most 0.2% of pixels. Measurements are
    /// deterministic for a seed, so the margins only absorb platform differences in `libm`.
    pub fn from_measured(m: [f64; 5]) -> Self {
        let [rmse, pen, bias, max, share] = m;
        Self {
            rmse: rmse * 1.25,
            penumbra_rmse: pen * 1.25,
            bias: (bias.abs() * 2.0).max(0.002),
            max_abs: (max * 1.25).min(1.0),
            share_over_0_1: share * 1.25 + 0.002,
            false_shadow: 0.002,
            min_sample_agreement: None,
        }
    }

    /// Looks `scene` up in a table of measured errors (see [`Budget::from_measured`] and
    /// [`table_row`]).
    pub fn lookup(table: &[(&str, [f64; 5])], scene: &str) -> Option<Self> {
        table_row(table, scene).map(|m| Self::from_measured(*m))
    }

    /// A budget with the same bound on RMSE-like terms and no per-sample requirement.
    pub const fn uniform(rmse: f64, max_abs: f64, share: f64) -> Self {
        Self {
            rmse,
            penumbra_rmse: rmse * 2.0,
            bias: rmse,
            max_abs,
            share_over_0_1: share,
            false_shadow: share,
            min_sample_agreement: None,
        }
    }
}

/// The name of the one row a measured table holds for the whole corpus of real meshes
/// ([`shadow_scenes::corpus`]): each measure is its largest over the corpus scenes
/// (`scripts/measure_budgets.py --corpus` folds them). A budget there is the promise a preset
/// makes on a real mesh it was never tuned to, the same on all 44 scenes, so one row covers
/// them; the built-in scenes keep a row each.
pub const CORPUS_ROW: &str = "corpus";

/// The row of `scene` in a per-scene table: its own row, or for a corpus scene without one the
/// [`CORPUS_ROW`].
pub fn table_row<'a, T>(table: &'a [(&str, T)], scene: &str) -> Option<&'a T> {
    let find = |name: &str| table.iter().find(|(s, _)| *s == name).map(|(_, v)| v);
    find(scene).or_else(|| {
        shadow_scenes::corpus::is_corpus_scene(scene)
            .then(|| find(CORPUS_ROW))
            .flatten()
    })
}

/// Builds a technique with a given sample count and seed; a count outside the technique's
/// range is an error, never a panic.
pub type WithSamples =
    fn(samples: u32, seed: u64) -> Result<Box<dyn ShadowTechnique>, TechniqueError>;

/// A named, constructible technique configuration with its budgets.
#[derive(Clone, Copy)]
pub struct Preset {
    /// Unique name, e.g. `ref-64` or `dcs-64`.
    pub name: &'static str,
    /// One line for listings.
    pub description: &'static str,
    /// Builds a fresh technique with the preset's parameters and `seed`.
    pub make: fn(seed: u64) -> Box<dyn ShadowTechnique>,
    /// The budget for a built-in scene, or `None` when the preset makes no promise there.
    pub budget: fn(scene: &str) -> Option<Budget>,
    /// For sample-based presets: the same technique with another sample count, used by the
    /// convergence check (error must fall as samples grow).
    pub with_samples: Option<WithSamples>,
    /// Stress cases (by name, see `shadow-conformance`'s stress cases) the preset fails by design, each
    /// with the reason: the suite asserts they still fail, so a limitation is shown rather than
    /// hidden, and is removed here when it no longer holds.
    pub known_limitations: &'static [(&'static str, &'static str)],
}

impl std::fmt::Debug for Preset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Preset")
            .field("name", &self.name)
            .finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolve_takes_presets_and_families_with_a_count() {
        let r = resolve("ref", Some(16), 1).unwrap();
        assert_eq!(r.light_sampler().map(|s| s.count()), Some(16));
        assert_eq!(resolve("dcs-64", None, 1).unwrap().name(), "dcs-64");
        let msg = |e: TechniqueError| match e {
            TechniqueError::InvalidInput(m) => m,
            e => panic!("not invalid input: {e}"),
        };
        let fixed = msg(resolve("dcs-64", Some(32), 1).err().unwrap());
        assert!(fixed.contains("use its family: `dcs`"), "{fixed}");
        let unknown = msg(resolve("nope", None, 1).err().unwrap());
        assert!(unknown.contains("valid names: ref"), "{unknown}");
        assert_eq!(family_of("ssm-contours"), "ssm");
    }

    const TABLE: &[(&str, [f64; 5])] = &[
        ("bunny", [0.01, 0.02, 0.0, 0.1, 0.001]),
        (CORPUS_ROW, [0.03, 0.05, 0.001, 0.5, 0.01]),
    ];

    #[test]
    fn a_scene_takes_its_own_row_and_a_corpus_scene_the_corpus_row() {
        assert_eq!(table_row(TABLE, "bunny"), Some(&TABLE[0].1));
        assert_eq!(
            table_row(TABLE, "corpus-teapot-disk-whole"),
            Some(&TABLE[1].1)
        );
        // Neither a built-in scene without a row nor a name that only looks like the corpus's.
        assert_eq!(table_row(TABLE, "grass"), None);
        assert_eq!(table_row(TABLE, "corpus-unknown-disk-whole"), None);
        assert_eq!(table_row(&TABLE[..1], "corpus-teapot-disk-whole"), None);
        let b = Budget::lookup(TABLE, "corpus-cow-rect-quarter").unwrap();
        assert_eq!(b, Budget::from_measured(TABLE[1].1));
    }

    #[test]
    fn named_scenes_are_the_built_in_ones_and_the_corpus() {
        assert!(shadow_scenes::is_named_scene("bunny"));
        assert!(shadow_scenes::is_named_scene("corpus-fandisk-rect-quarter"));
        assert!(!shadow_scenes::is_named_scene("corpus"));
        assert!(!shadow_scenes::is_named_scene("my-scene.gltf"));
    }
}
