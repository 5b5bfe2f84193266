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
//! * [`direct`] and [`irradiance`]: direct illumination from per-sample visibility (DCS eq. 6)
//!   and the closed-form unshadowed irradiance of planar lights.
//! * [`lights`]: every light of a scene, V per light and direct light summed.
//! * [`receivers`]: receivers handed in by the caller (a renderer's G-buffer, or points with
//!   normals), snapped onto the scene.
//! * [`spatial_order`]: receivers without a camera laid out coherently for a technique's
//!   tiles and neighbours, and given back in the caller's order.
//! * [`rays`]: the shadow-ray traits a hybrid technique takes its rays through, so that no
//!   technique crate depends on the reference.
//! * `gpu` (feature `gpu`): wgpu device creation with a software fallback, upload, readback
//!   and naga validation of WGSL, for GPU techniques.
//!
//! What is not here lives in crates named for it: loading and image output (`shadow-io`), the
//! built-in scenes and the corpus (`shadow-scenes`), error metrics (`shadow-metrics`), presets
//! and their budgets (`shadow-presets`).
//!
//! The visibility coefficient is `V(p) = (1/|L|) * integral of v(p, y) dA(y)` over the light
//! (DCS eq. 1): the unweighted fraction of the light's area visible from `p`, where `y` below
//! `p`'s tangent plane counts as occluded, and a receiver behind a planar light (which emits
//! from its front side only) gets none of it.
//!
//! ```
//! use glam::{UVec2, Vec3};
//! use shadow_core::prelude::*;
//!
//! // A floor under a square light facing down, seen from above.
//! let floor = MeshDesc::new(
//!     vec![Vec3::new(-2.0, 0.0, -2.0), Vec3::new(2.0, 0.0, -2.0), Vec3::new(2.0, 0.0, 2.0), Vec3::new(-2.0, 0.0, 2.0)],
//!     vec![[0, 2, 1], [0, 3, 2]],
//! );
//! let mut builder = SceneBuilder::new();
//! builder.push_mesh(floor).unwrap();
//! let scene = builder.build().unwrap();
//! let light = RectLight::new(Vec3::Y * 2.0, Vec3::X * 0.5, Vec3::Z * 0.5, Radiance::Constant(Vec3::ONE)).unwrap();
//! let camera = Camera::look_at(Vec3::new(0.0, 3.0, 3.0), Vec3::ZERO, Vec3::Y, 0.9).unwrap();
//! let view = ViewSamples::render(&scene, &camera, 32, 24).unwrap();
//! assert!(view.valid_count() > 0);
//! let sampler = LightSampler::new(SamplingStrategy::Stratified, 16, 7).unwrap();
//! let mut samples = Vec::new();
//! sampler.light_samples(&light, UVec2::new(3, 4), &mut samples);
//! assert_eq!(samples.len(), 16);
//! ```

#![deny(missing_docs)]

pub mod albedo;
pub mod camera;
pub mod clip;
pub mod direct;
pub mod geometry;
#[cfg(feature = "gpu")]
pub mod gpu;
#[cfg(feature = "gpu")]
mod gpu_timestamps;
pub mod irradiance;
pub mod light;
pub mod lightmap;
pub mod lights;
pub mod mesh;
pub mod offset;
pub mod raster;
pub mod rays;
pub mod receivers;
mod rounding;
pub mod sampling;
pub mod scene;
pub mod spatial_order;
pub mod stats;
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
    pub use crate::lights::{LightEstimate, LightsEstimate, PreparedLights};
    pub use crate::sampling::{LightSampler, SamplingStrategy};
    pub use crate::scene::{MeshDesc, Scene, SceneBuilder, TriangleScene};
    pub use crate::technique::{
        Capabilities, Estimate, EstimateDecision, Outputs, PreparedShadows, Processor, SceneRef,
        ShadowTechnique, Stats, TechniqueError, UnsupportedReason,
    };
    pub use crate::view_samples::ViewSamples;
    pub use crate::visibility::{
        PerSampleVisibility, PixelClass, VisibilityBuffer, VisibilityImage,
    };
}
