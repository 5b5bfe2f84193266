//! The statistics `shadow-dcs` records, as types ([`shadow_core::stats`]): what a test or a
//! report names, and the names they carry in `stats.json`.

shadow_core::statistics! {
    Counter:
    /// Counters of `shadow-dcs`.
    pub enum DcsCounter {
        /// Penumbra wedges of the frame's silhouette edges.
        Wedges => "wedges",
        /// Frames whose integration constants did not need shadow volumes (every pixel traced).
        ShadowVolumesSkipped => "shadow-volumes-skipped",
        /// Shadow-volume quads rasterized for the integration constants.
        ShadowVolumeQuads => "shadow-volume-quads",
        /// Receivers without a camera whose integration constant was counted along their own segment to the light centre.
        ReceiverConstantSegments => "receiver-constant-segments",
        /// Edges of the scene's meshes.
        Edges => "edges",
        /// Edges on the silhouette seen from the light.
        SilhouetteEdges => "silhouette-edges",
        /// Triangles the light may pass through (and their neighbours), tested against each
        /// sample's segment instead of by wedges (a light in or set into a closed mesh).
        ExplicitTriangles => "explicit-triangles",
        /// Preparations that reused another light's or technique's edges and silhouettes.
        PreparationShared => "preparation-shared",
        /// Estimates that reused a frame another estimate built.
        FrameShared => "frame-shared",
        /// Pixels facing away from the light, not estimated.
        PixelsFacingAway => "pixels-facing-away",
        /// Pixels no wedge covers: the integration constant alone.
        PixelsConstantOnly => "pixels-constant-only",
        /// Pixels whose samples were counted one by one.
        PixelsPerSample => "pixels-per-sample",
        /// Edge-against-sample tests.
        EdgeTests => "edge-tests",
        /// Counter updates of covered samples.
        CoveredUpdates => "covered-updates",
        /// Packed counters widened after an overflow.
        CounterEscalations => "counter-escalations",
        /// Pixels counted with plain counters after packed ones overflowed.
        PlainCounterFallbacks => "plain-counter-fallbacks",
        /// Samples whose depth complexity came out negative (clamped and counted).
        NegativeDepthComplexity => "negative-depth-complexity",
        /// Samples exactly on an edge, broken by the tie rule.
        EdgeTies => "edge-ties",
        /// Pixels scanned over all wedges.
        WedgePixelsScanned => "wedge-pixels-scanned",
        /// Wedge pixels weighted exactly.
        WedgeExactWeights => "wedge-exact-weights",
        /// Wedges binned to blocks.
        BinBlockWedges => "bin-block-wedges",
        /// Squares of the frame traced with rays instead of counted.
        SquaresTraced => "squares-traced",
        /// The square planner's predicted depth-complexity work, in ray units.
        PredictedDcsRays => "predicted-dcs-rays",
        /// The planner's predicted shadow-volume work, in ray units.
        PredictedShadowVolumeRays => "predicted-shadow-volume-rays",
        /// The planner's predicted rays for tracing instead.
        PredictedTracedRays => "predicted-traced-rays",
        /// The planner's predicted BVH build, in ray units.
        PredictedBvhRays => "predicted-bvh-rays",
        /// Pixels traced with rays.
        PixelsTraced => "pixels-traced",
        /// Occlusion rays traced.
        OcclusionRays => "occlusion-rays",
        /// Wedges binned to squares.
        BinSquareWedges => "bin-square-wedges",
        /// Wedges binned to tiles.
        BinTileWedges => "bin-tile-wedges",
        /// Wedge-pixel pairs processed.
        WedgePairs => "wedge-pairs",
        /// Wedge-pixel pairs whose edge misses the light, skipped.
        WedgePairsOffLight => "wedge-pairs-off-light",
        /// Wedge-pixel pairs whose sector holds no sample, skipped.
        WedgePairsEmptySector => "wedge-pairs-empty-sector",
        /// Line cells refined near an edge.
        RefinedLineCells => "refined-line-cells",
        /// Pixels that used a sample set shared with their tile.
        PixelsSharedSampleSets => "pixels-shared-sample-sets",
        /// Shared sample sets built.
        SharedSampleSetsBuilt => "shared-sample-sets-built",
    }
}

shadow_core::statistics! {
    Gauge:
    /// Gauges of `shadow-dcs`.
    pub enum DcsGauge {
        /// Largest integration constant.
        MaxIntegrationConstant => "max-integration-constant",
        /// Counter width chosen, in bits.
        CounterBits => "counter-bits",
    }
}

shadow_core::statistics! {
    PhaseName:
    /// Phases of `shadow-dcs`.
    pub enum DcsPhase {
        /// Planning which squares are counted and which traced.
        SquarePlan => "square-plan",
        /// The integration constants from shadow volumes.
        ShadowVolumes => "shadow-volumes",
        /// The integration constants of receivers without a camera, one segment each.
        ReceiverConstants => "receiver-constants",
        /// Gathering the scene's edges.
        Edges => "edges",
        /// Finding the silhouette edges.
        Silhouettes => "silhouettes",
        /// Building the discrete sample tables.
        DiscreteTables => "discrete-tables",
        /// Building the penumbra wedges.
        Wedges => "wedges",
        /// Counting depth complexity over the wedges.
        DepthComplexity => "depth-complexity",
    }
}
