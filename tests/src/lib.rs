//! # shadow-tests: the conformance suite
//!
//! The tests every registered technique preset must pass (DESIGN section 6), run by
//! `cargo test`: `tests/conformance.rs` holds one named test per (preset, scene) case and per
//! preset against the closed form, `tests/stress.rs` the numerical-stability and bad-input
//! cases. The registry and the runner they call are the library `shadow-conformance`, which
//! `cargo xtask` uses too.
//!
//! This crate's own library holds nothing but the README's code, compiled and run as doctests.

#![deny(missing_docs)]

/// The README's code blocks, compiled and run as doctests so that the README stays true.
#[cfg(doctest)]
#[doc = include_str!("../../README.md")]
pub struct ReadmeDoctests;
