//! The core stress cases, run against every registered preset at a small size.

use shadow_tests::registry;
use shadow_tests::stress::{KNOWN_LIMITATIONS, input_cases, known_limitation, technique_cases};

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
    let mut limitations_seen = 0;
    for p in registry() {
        for r in technique_cases(&p, 48, 36) {
            if let Some(reason) = known_limitation(&r.technique, &r.case) {
                assert!(
                    !r.held,
                    "{} now holds {}: remove it from KNOWN_LIMITATIONS ({reason})",
                    r.technique, r.case
                );
                limitations_seen += 1;
                println!(
                    "{:<24} {:<10} known limitation: {reason}",
                    r.case, r.technique
                );
                continue;
            }
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
    assert_eq!(limitations_seen, KNOWN_LIMITATIONS.len());
    assert!(failed.is_empty(), "{failed:#?}");
}
