//! # shadow-conformance: the registry and the conformance runner
//!
//! One set of checks, run against every registered technique preset on every built-in scene
//! its capabilities support (DESIGN section 6): values in [0, 1], no NaN, no false shadow where
//! the reference is fully lit, error within the preset's declared budgets, determinism for a
//! seed, and error falling as samples grow. Each comparison uses the same view samples as the
//! reference, and the same light samples when the technique is sample-based.
//!
//! The presets and their budgets are `shadow-presets`' registry: adding a preset there adds it
//! to the test suite (`shadow-tests`) and to `cargo xtask conformance`, with no new code. This
//! crate is a library both use; the tests themselves live in `shadow-tests`.
//!
//! ```
//! use shadow_conformance::conformance::{Outcome, SceneContext, SuiteConfig, run_case};
//!
//! let cfg = SuiteConfig { width: 32, height: 24, ref_samples: 256, extra_checks: false, ..SuiteConfig::default() };
//! let ctx = SceneContext::new(shadow_scenes::builtin("quad-over-plane").unwrap(), cfg).unwrap();
//! let preset = shadow_presets::preset("ref-64").unwrap();
//! match run_case(&preset, &ctx) {
//!     Outcome::Ran(report) => assert!(report.metrics.rmse < 0.05),
//!     other => panic!("{other:?}"),
//! }
//! ```

#![deny(missing_docs)]

pub mod closed_form;
pub mod conformance;
pub mod lights;
pub mod stress;
