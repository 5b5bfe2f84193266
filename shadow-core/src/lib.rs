//! # shadow-core
//!
//! The shared vocabulary of the soft-shadow workspace: everything a technique, the ray-traced
//! reference and the conformance suite agree on, and nothing heavy.
//!
//! * [`scene`]: the [`Scene`] trait and the validated [`TriangleScene`]; [`topology`]: edge
//!   adjacency and closedness (DCS section 4.1, AFSM section 3.3).
//! * [`light`]: the [`AreaLight`] trait with rectangle, disk, polygon, sphere and point lights,
//!   constant or textured radiance.
//! * [`sampling`]: per-pixel light sample sets with the strategies of DCS section 5.
//! * [`camera`], [`raster`] and [`view_samples`]: the camera, a CPU depth rasterizer (camera
//!   G-buffers now, shadow maps and depth peeling for the SSM family) and the shared view samples.
//! * [`visibility`] and [`technique`]: visibility buffers and the object-safe
//!   [`ShadowTechnique`] trait with its [`Stats`] and [`TechniqueError`].
//! * [`direct`]: direct illumination from per-sample visibility (DCS eq. 6).
//! * [`metrics`]: RMSE, penumbra RMSE, bias, max error, share over 0.1, per-sample agreement.
//! * [`preset`]: named technique configurations with their error budgets.
//! * [`load`], [`scenes`] and [`procedural`]: glTF and OBJ loading, built-in scenes.
//! * [`image_io`]: EXR and PNG output.
//! * `gpu` (feature `gpu`): wgpu device creation with a software fallback, upload, readback
//!   and naga validation of WGSL, for GPU techniques.
//!
//! The visibility coefficient is `V(p) = (1/|L|) * integral of v(p, y) dA(y)` over the light
//! (DCS eq. 1): the unweighted fraction of the light's area visible from `p`, where `y` below
//! `p`'s tangent plane counts as occluded, and a receiver behind a planar light (which emits
//! from its front side only) gets none of it.
//!
//! ```
//! use shadow_core::prelude::*;
//!
//! let setup = shadow_core::scenes::builtin("quad-over-plane").unwrap();
//! let camera = setup.camera_or_default();
//! let view = ViewSamples::render(setup.scene.as_ref(), &camera, 32, 24).unwrap();
//! assert!(view.valid_count() > 0);
//! let sampler = LightSampler::new(SamplingStrategy::Stratified, 16, 7).unwrap();
//! let mut samples = Vec::new();
//! sampler.light_samples(setup.lights[0].as_ref(), glam::UVec2::new(3, 4), &mut samples);
//! assert_eq!(samples.len(), 16);
//! ```

#![deny(missing_docs)]

pub mod albedo;
pub mod camera;
pub mod corpus;
pub mod direct;
pub mod geometry;
#[cfg(feature = "gpu")]
pub mod gpu;
#[cfg(feature = "gpu")]
mod gpu_timestamps;
pub mod image_io;
pub mod irradiance;
pub mod light;
pub mod load;
pub mod metrics;
pub mod offset;
pub mod preset;
pub mod procedural;
pub mod raster;
mod rounding;
pub mod sampling;
pub mod scene;
pub mod scenes;
pub mod technique;
pub mod topology;
pub mod triangulate;
pub mod view_samples;
pub mod visibility;

pub use camera::Camera;
pub use light::{AreaLight, Light, LightSample};
pub use scene::{Scene, TriangleScene};
pub use technique::{
    Outputs, PreparedShadows, ShadowTechnique, Stats, TechniqueError, UnsupportedReason,
};
pub use view_samples::ViewSamples;
pub use visibility::{VisibilityBuffer, VisibilityImage};

/// The types most users need.
pub mod prelude {
    pub use crate::camera::Camera;
    pub use crate::light::{
        AreaLight, DiskLight, Light, LightKind, LightSample, PointLight, PolygonLight, Radiance,
        RectLight, SphereLight,
    };
    pub use crate::load::SceneSetup;
    pub use crate::metrics::{Metrics, compare};
    pub use crate::preset::{Budget, Preset};
    pub use crate::sampling::{LightSampler, SamplingStrategy};
    pub use crate::scene::{MeshDesc, Scene, SceneBuilder, TriangleScene};
    pub use crate::technique::{
        Capabilities, Estimate, Outputs, PreparedShadows, Processor, SceneRef, ShadowTechnique,
        Stats, TechniqueError, UnsupportedReason,
    };
    pub use crate::view_samples::ViewSamples;
    pub use crate::visibility::{
        PerSampleVisibility, PixelClass, VisibilityBuffer, VisibilityImage,
    };
}
