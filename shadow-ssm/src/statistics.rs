//! The statistics `shadow-ssm` records, as types ([`shadow_core::stats`]): what a test or a
//! report names, and the names they carry in `stats.json`.

shadow_core::statistics! {
    Counter:
    /// Counters of `shadow-ssm`.
    pub enum SsmCounter {
        /// Pixels facing away from the light, not estimated.
        PixelsFacingAway => "pixels-facing-away",
        /// Pixels outside the light frustum.
        PixelsOutsideFrustum => "pixels-outside-frustum",
        /// Pixels the min-max pyramid classified fully lit, not filtered.
        PixelsSkippedLit => "pixels-skipped-lit",
        /// Pixels the min-max pyramid classified in umbra, not filtered.
        PixelsSkippedUmbra => "pixels-skipped-umbra",
        /// Pixels filled by pull-push from their neighbours.
        PixelsReconstructed => "pixels-reconstructed",
        /// Pixels whose estimate is fully lit.
        PixelsLit => "pixels-lit",
        /// Pixels whose estimate is in umbra.
        PixelsUmbra => "pixels-umbra",
        /// Pixels whose estimate is in penumbra.
        PixelsPenumbra => "pixels-penumbra",
        /// Texels of the shadow map.
        ShadowMapTexels => "shadow-map-texels",
        /// Contour edges extracted from the shadow map.
        ContourEdges => "contour-edges",
        /// Depth levels the contours were traced at.
        ContourLevels => "contour-levels",
        /// Pixels blended between filtered and reconstructed.
        PixelsBlended => "pixels-blended",
        /// Shadow-map texels read by the filter.
        SamplesRead => "samples-read",
    }
}

shadow_core::statistics! {
    PhaseName:
    /// Phases of `shadow-ssm`.
    pub enum SsmPhase {
        /// Fitting the light's frame to the receivers.
        LightFrame => "light-frame",
        /// Each receiver's horizon.
        Horizon => "horizon",
        /// Rendering the shadow map.
        ShadowMap => "shadow-map",
        /// Building the min-max pyramid.
        MinMaxPyramid => "min-max-pyramid",
        /// Finding the shadow map's discontinuities (contours).
        Discontinuities => "discontinuities",
        /// Filtering every receiver.
        Filter => "filter",
        /// Pull-push reconstruction.
        PullPush => "pull-push",
    }
}
