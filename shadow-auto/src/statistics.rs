//! The statistics `shadow-auto` records, as types ([`shadow_core::stats`]): what a test or a
//! report names, and the names they carry in `stats.json`.

shadow_core::statistics! {
    Counter:
    /// Counters of `shadow-auto`.
    pub enum AutoCounter {
        /// Preparations whose probe was DCS (1) rather than rays (0).
        AutoProbeDcs => "auto-probe-dcs",
        /// Pixels of the probe view.
        AutoProbePixels => "auto-probe-pixels",
        /// Estimates whose chosen technique reused the probe's preparation.
        AutoProbePreparationReused => "auto-probe-preparation-reused",
        /// Configurations the chooser weighed.
        AutoCandidates => "auto-candidates",
    }
}

shadow_core::statistics! {
    PhaseName:
    /// Phases of `shadow-auto`.
    pub enum AutoPhase {
        /// Preparing the probe technique.
        AutoProbePrepare => "auto-probe-prepare",
        /// Running the probe.
        AutoProbe => "auto-probe",
        /// Preparing the chosen configuration.
        AutoChosenPrepare => "auto-chosen-prepare",
    }
}
