//! `auto`'s committed model names only configurations this crate's catalogue builds.

use shadow_auto::AutoModel;

#[test]
fn the_committed_model_parses_and_builds_every_candidate() {
    let m = AutoModel::committed().unwrap();
    assert!(!m.candidates.is_empty());
    for c in &m.candidates {
        c.config.build(1, shadow_presets::build).unwrap();
        assert!(c.cost.iter().all(|v| *v >= 0.0 && v.is_finite()));
    }
}
