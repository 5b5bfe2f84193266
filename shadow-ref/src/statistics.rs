//! The statistics `shadow-ref` records, as types ([`shadow_core::stats`]): what a test or a
//! report names, and the names they carry in `stats.json`.

shadow_core::statistics! {
    Counter:
    /// Counters of `shadow-ref`.
    pub enum RefCounter {
        /// Occlusion rays traced (beam-cleared samples count as rays not traced).
        OcclusionRays => "occlusion-rays",
        /// Rays traced one by one, outside a packet or a beam.
        RaysSingle => "rays-single",
        /// Pixels whose beam to the light met no triangle: every sample visible, no ray traced.
        PixelsBeamClear => "pixels-beam-clear",
        /// Pixels traced against the candidates their beam gathered.
        PixelsBeamCandidates => "pixels-beam-candidates",
        /// Pixels whose beam gathered too many candidates, traced against the whole BVH.
        PixelsBeamFallback => "pixels-beam-fallback",
        /// Pixels lit by the light with no sample above their horizon.
        PixelsLitWithoutSamples => "pixels-lit-without-samples",
        /// Light samples below a receiver's horizon, not traced.
        SamplesBelowHorizon => "samples-below-horizon",
        /// Valid view samples estimated.
        Pixels => "pixels",
        /// Triangles in the BVH.
        Triangles => "triangles",
        /// Preparations that reused a BVH built for another light or technique.
        BvhShared => "bvh-shared",
        /// Light samples the adaptive reference drew over all pixels.
        AdaptiveSamples => "adaptive-samples",
        /// Pixels the adaptive reference stopped at its sample cap.
        PixelsAtCap => "pixels-at-cap",
        /// Pixels the adaptive reference stopped at each count of its progressive schedule (a histogram by count).
        PixelsByProgressiveSamples => "pixels-by-progressive-samples",
        /// Pixels the adaptive reference stopped before any sample (no light above the horizon).
        PixelsWithoutSamples => "pixels-without-samples",
    }
}

shadow_core::statistics! {
    Gauge:
    /// Gauges of `shadow-ref`.
    pub enum RefGauge {
        /// Worker threads of the trace.
        Threads => "threads",
        /// Most samples the adaptive reference drew at one pixel.
        AdaptiveMaxSamplesPerPixel => "adaptive-max-samples-per-pixel",
    }
}

shadow_core::statistics! {
    PhaseName:
    /// Phases of `shadow-ref`.
    pub enum RefPhase {
        /// Building the occlusion BVH.
        BvhBuild => "bvh-build",
        /// Tracing the occlusion rays.
        Trace => "trace",
    }
}
