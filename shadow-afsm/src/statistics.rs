//! The statistics `shadow-afsm` records, as types ([`shadow_core::stats`]): what a test or a
//! report names, and the names they carry in `stats.json`.

shadow_core::statistics! {
    Counter:
    /// Counters of `shadow-afsm`.
    pub enum AfsmCounter {
        /// Tiles numbered for the occlusion pass.
        TilesNumbered => "tiles-numbered",
        /// Closed meshes that separate the eye from the light.
        ClosedMeshesBetweenEyeAndLight => "closed-meshes-between-eye-and-light",
        /// Receivers put into the light-space lists.
        ReceiversListed => "receivers-listed",
        /// Receivers facing away from the light, not listed.
        ReceiversFacingAway => "receivers-facing-away",
        /// Batches of receivers.
        ReceiverBatches => "receiver-batches",
        /// Batches of casters.
        CasterBatches => "caster-batches",
        /// Potential silhouette edges of the stencil.
        SilhouetteEdges => "silhouette-edges",
        /// Light-space texels whose list holds a receiver.
        ListsOccupied => "lists-occupied",
        /// Texels visited by the occlusion pass.
        TexelsVisited => "texels-visited",
        /// Caster-receiver pairs tested.
        PairsTested => "pairs-tested",
        /// Pairs whose caster hides no sample.
        PairsEmpty => "pairs-empty",
        /// Pairs whose caster hides every sample.
        PairsFull => "pairs-full",
        /// Pairs tested sample by sample.
        PairsPerSample => "pairs-per-sample",
        /// Pairs of a receiver with its own triangle, skipped.
        PairsOwnTriangle => "pairs-own-triangle",
        /// Pairs tested against one sample.
        PairsOneSample => "pairs-one-sample",
        /// Tiles cluster culling removed.
        TilesCulled => "tiles-culled",
        /// Texels culled by depth bounds.
        TexelsCulledByDepth => "texels-culled-by-depth",
        /// Pairs skipped because the receiver was already in umbra.
        PairsAfterUmbra => "pairs-after-umbra",
        /// Tiles with no receiver.
        TilesEmpty => "tiles-empty",
        /// Texels whose every view sample was already hidden.
        TexelsHidden => "texels-hidden",
        /// Tiles whose every view sample was already hidden.
        TilesHidden => "tiles-hidden",
        /// Texels outside a caster's region.
        TexelsCulledByRegion => "texels-culled-by-region",
        /// Texels outside a caster's shadow volume.
        TexelsCulledByVolume => "texels-culled-by-volume",
        /// Super-tiles cluster culling removed.
        SuperTilesCulled => "super-tiles-culled",
        /// Casters culled before the occlusion pass.
        CastersCulled => "casters-culled",
    }
}

shadow_core::statistics! {
    Gauge:
    /// Gauges of `shadow-afsm`.
    pub enum AfsmGauge {
        /// Longest light-space list.
        ListLengthMax => "list-length-max",
        /// Side of the light-space map, in texels.
        MapSide => "map-side",
    }
}

shadow_core::statistics! {
    PhaseName:
    /// Phases of `shadow-afsm`.
    pub enum AfsmPhase {
        /// Preparing the scene and light on the device.
        Prepare => "prepare",
        /// Gathering the receivers.
        Receivers => "receivers",
        /// Grouping the receivers into batches and fitting each batch's frame.
        Frame => "frame",
        /// The light-space regions of the casters.
        GpuInfluence => "gpu-influence",
        /// Marking texels whose view samples are all hidden.
        GpuHidden => "gpu-hidden",
        /// Numbering and pairing tiles.
        GpuTiles => "gpu-tiles",
        /// The silhouette stencil.
        GpuStencil => "gpu-stencil",
        /// The occlusion pass.
        GpuOcclude => "gpu-occlude",
        /// Uploading a batch of receivers.
        GpuUpload => "gpu-upload",
        /// Building the light-space lists.
        GpuLists => "gpu-lists",
        /// Resolving per-sample visibility to V(p).
        GpuResolve => "gpu-resolve",
        /// Reading the results back.
        GpuReadback => "gpu-readback",
    }
}
