//! The core stress cases, run against every registered preset at a small size.

use shadow_conformance::stress::{input_cases, known_limitation, technique_cases};
use shadow_presets::registry;

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
    let presets = registry();
    // Two scenes of the corpus of real meshes, one under each light shape; `cargo xtask
    // stress` runs more.
    let corpus = [
        "corpus-stanford-bunny-disk-whole",
        "corpus-fandisk-rect-quarter",
    ]
    .map(String::from);
    for p in &presets {
        for r in technique_cases(p, 48, 36, &corpus) {
            if let Some(reason) = known_limitation(p, &r.case) {
                assert!(
                    !r.held,
                    "{} now holds {}: remove it from the preset's known_limitations ({reason})",
                    r.technique, r.case
                );
                limitations_seen += 1;
                println!(
                    "{:<24} {:<10} known limitation: {reason} ({})",
                    r.case, r.technique, r.detail
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
    let declared: usize = presets.iter().map(|p| p.known_limitations.len()).sum();
    assert_eq!(
        limitations_seen, declared,
        "every declared limitation is a stress case"
    );
    assert!(failed.is_empty(), "{failed:#?}");
}
