//! # shadow-conformance: the registry and the conformance runner
//!
//! One set of checks, run against every registered technique preset on every built-in scene
//! its capabilities support (DESIGN section 6): values in [0, 1], no NaN, no false shadow where
//! the reference is fully lit, error within the preset's declared budgets, determinism for a
//! seed, and error falling as samples grow. Each comparison uses the same view samples as the
//! reference, and the same light samples when the technique is sample-based.
//!
//! The registry is the union of the technique crates' `presets()`: adding a preset there adds it
//! to the test suite (`shadow-tests`) and to `cargo xtask conformance`, with no new code. This
//! crate is a library both use; the tests themselves live in `shadow-tests`.
//!
//! ```
//! use shadow_conformance::conformance::{Outcome, SceneContext, SuiteConfig, run_case};
//!
//! let cfg = SuiteConfig { width: 32, height: 24, ref_samples: 256, extra_checks: false, ..SuiteConfig::default() };
//! let ctx = SceneContext::new(shadow_core::scenes::builtin("quad-over-plane").unwrap(), cfg).unwrap();
//! let preset = shadow_conformance::preset("ref-64").unwrap();
//! match run_case(&preset, &ctx) {
//!     Outcome::Ran(report) => assert!(report.metrics.rmse < 0.05),
//!     other => panic!("{other:?}"),
//! }
//! ```

#![deny(missing_docs)]

pub mod auto;
pub mod closed_form;
pub mod conformance;
pub mod stress;

use shadow_core::preset::Preset;

/// Every registered preset, from every technique crate.
pub fn registry() -> Vec<Preset> {
    let mut all = Vec::new();
    all.extend(shadow_ref::presets());
    all.extend(shadow_dcs::presets());
    all.extend(shadow_ssm::presets());
    all.extend(shadow_afsm::presets());
    all.extend(auto::presets());
    all
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
