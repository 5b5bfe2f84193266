//! The statistics every crate declares (`shadow_core::stats`): within a kind each name is the
//! name of one statistic, so `stats.json` never merges two meanings under one key; a technique
//! never redeclares a name core records for it; device time is a phase's field.

use std::collections::BTreeMap;

use shadow_core::stats::{CoreCounter, CorePhase, Counter, Gauge, PhaseName};

/// Every name of a kind, by the enum that declares it.
fn names<T: Copy>(all: &[T], name: fn(T) -> &'static str) -> Vec<&'static str> {
    all.iter().map(|&t| name(t)).collect()
}

fn assert_distinct(kind: &str, by_enum: &[(&str, Vec<&'static str>)]) {
    for (e, names) in by_enum {
        let mut seen = BTreeMap::new();
        for n in names {
            assert!(
                seen.insert(*n, ()).is_none(),
                "{kind} {e}: `{n}` declared twice"
            );
        }
    }
}

#[test]
fn each_kind_declares_each_name_once_and_techniques_leave_core_names_to_core() {
    let counters: Vec<(&str, Vec<&'static str>)> = vec![
        ("CoreCounter", names(CoreCounter::ALL, Counter::name)),
        (
            "RefCounter",
            names(shadow_ref::RefCounter::ALL, Counter::name),
        ),
        (
            "DcsCounter",
            names(shadow_dcs::DcsCounter::ALL, Counter::name),
        ),
        (
            "SsmCounter",
            names(shadow_ssm::SsmCounter::ALL, Counter::name),
        ),
        (
            "AfsmCounter",
            names(shadow_afsm::AfsmCounter::ALL, Counter::name),
        ),
        (
            "AutoCounter",
            names(shadow_auto::AutoCounter::ALL, Counter::name),
        ),
    ];
    let gauges: Vec<(&str, Vec<&'static str>)> = vec![
        ("RefGauge", names(shadow_ref::RefGauge::ALL, Gauge::name)),
        ("DcsGauge", names(shadow_dcs::DcsGauge::ALL, Gauge::name)),
        ("AfsmGauge", names(shadow_afsm::AfsmGauge::ALL, Gauge::name)),
    ];
    let phases: Vec<(&str, Vec<&'static str>)> = vec![
        ("CorePhase", names(CorePhase::ALL, PhaseName::name)),
        (
            "RefPhase",
            names(shadow_ref::RefPhase::ALL, PhaseName::name),
        ),
        (
            "DcsPhase",
            names(shadow_dcs::DcsPhase::ALL, PhaseName::name),
        ),
        (
            "SsmPhase",
            names(shadow_ssm::SsmPhase::ALL, PhaseName::name),
        ),
        (
            "AfsmPhase",
            names(shadow_afsm::AfsmPhase::ALL, PhaseName::name),
        ),
        (
            "AutoPhase",
            names(shadow_auto::AutoPhase::ALL, PhaseName::name),
        ),
    ];
    for (kind, list) in [
        ("counter", &counters),
        ("gauge", &gauges),
        ("phase", &phases),
    ] {
        assert_distinct(kind, list);
        let core = &list[0];
        for (e, names) in list.iter().skip(1) {
            if !core.0.starts_with("Core") {
                continue;
            }
            for n in names {
                assert!(!core.1.contains(n), "{e} redeclares core's {kind} `{n}`");
            }
        }
    }
    // A counter and a gauge never share a name: `stats.json` readers look both up by name.
    for (_, c) in &counters {
        for (e, g) in &gauges {
            for n in g {
                assert!(!c.contains(n), "{e}: `{n}` is both a counter and a gauge");
            }
        }
    }
    // Every name is the kebab-case `stats.json` has always used.
    for (_, list) in counters.iter().chain(&gauges).chain(&phases) {
        for n in list {
            assert!(
                !n.is_empty()
                    && n.chars()
                        .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'),
                "`{n}` is not kebab-case"
            );
        }
    }
}
