//! The core stress cases, run against every registered preset at a small size.

use shadow_tests::registry;
use shadow_tests::stress::{input_cases, technique_cases};

#[test]
fn bad_input_gives_typed_errors() {
    let results = input_cases();
    assert!(results.len() >= 8);
    let failed: Vec<_> = results.iter().filter(|r| !r.held).collect();
    assert!(failed.is_empty(), "{failed:#?}");
}

#[test]
fn every_preset_holds_the_stress_cases() {
    let mut failed = Vec::new();
    for p in registry() {
        for r in technique_cases(&p, 48, 36) {
            println!(
                "{:<24} {:<10} {} {}",
                r.case,
                r.technique,
                if r.held { "held" } else { "FAILED" },
                r.detail
            );
            if !r.held {
                failed.push(r);
            }
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}
