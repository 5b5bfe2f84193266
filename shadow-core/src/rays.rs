//! Shadow rays for techniques that trace some of their work: the traits through which a
//! hybrid (DCS's `dcs-*-hybrid`, which traces a frame whose predicted DCS work exceeds its
//! rays) takes rays without depending on the crate that traces them.
//!
//! `shadow-ref` implements [`ShadowRays`] with its BVH; a renderer may hand in its own tracer
//! (Embree, a hardware ray query) instead. The contract is the reference's: `v(p, y)` of the
//! shared definition (DESIGN section 3) on exactly the light samples the caller passes, so a
//! hybrid's answers do not depend on which side of its choice a pixel fell.

use std::any::Any;
use std::fmt;

use crate::light::{Light, LightSample};
use crate::sampling::LightSampler;
use crate::technique::{SceneRef, TechniqueError};
use crate::view_samples::ViewSample;

/// Something that prepares shadow rays for a scene and a light.
pub trait ShadowRays: Send + Sync + fmt::Debug {
    /// A short name for reports (e.g. `ref-bvh`).
    fn name(&self) -> &str;

    /// Prepares rays on `scene` toward `light` (an acceleration structure, typically), for the
    /// light samples of `sampler`.
    ///
    /// # Errors
    /// A [`TechniqueError`] when the scene or light cannot be traced.
    fn prepare_rays(
        &self,
        scene: SceneRef,
        light: Light,
        sampler: &LightSampler,
    ) -> Result<Box<dyn PreparedRays>, TechniqueError>;
}

/// Shadow rays prepared on one scene and light.
pub trait PreparedRays: Send + Sync {
    /// A fresh scratch for [`PreparedRays::pixel_visibility`] (one per thread).
    fn scratch(&self) -> RayScratch;

    /// The visibility `v(s, y)` (1 visible, 0 occluded; a transmittance between for
    /// semi-opaque occluders) of each light sample `y` of `samples` from view sample `s`, in
    /// order, and the rays cast. A sample below the receiver's tangent plane gets 0 without a
    /// ray.
    fn pixel_visibility<'a>(
        &self,
        s: &ViewSample,
        samples: &[LightSample],
        scratch: &'a mut RayScratch,
    ) -> (&'a [f32], u64);
}

/// Per-thread buffers of a [`PreparedRays`], opaque to the caller: made by
/// [`PreparedRays::scratch`] and read back by the same implementation.
pub struct RayScratch(Box<dyn Any + Send>);

impl RayScratch {
    /// Wraps an implementation's buffers.
    pub fn new<T: Any + Send>(buffers: T) -> Self {
        Self(Box::new(buffers))
    }

    /// The implementation's buffers, when they are of type `T`.
    pub fn get_mut<T: Any>(&mut self) -> Option<&mut T> {
        self.0.downcast_mut()
    }
}

impl fmt::Debug for RayScratch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("RayScratch").finish_non_exhaustive()
    }
}
