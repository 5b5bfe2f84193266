//! The reference as the shadow rays of other techniques ([`shadow_core::rays`]): a hybrid
//! technique (DCS's `dcs-*-hybrid`) is handed [`BvhRays`] by whoever builds it, so the
//! technique crate itself never depends on this one.

use shadow_core::light::{Light, LightSample};
use shadow_core::rays::{PreparedRays, RayScratch, ShadowRays};
use shadow_core::sampling::LightSampler;
use shadow_core::technique::{SceneRef, TechniqueError};
use shadow_core::view_samples::ViewSample;

use crate::reference::{PixelScratch, PreparedReference, Reference};

/// Shadow rays through the reference's BVH, evaluated exactly as the reference evaluates the
/// same light samples ([`PreparedReference::pixel_visibility`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct BvhRays;

impl ShadowRays for BvhRays {
    fn name(&self) -> &str {
        "ref-bvh"
    }

    fn prepare_rays(
        &self,
        scene: SceneRef,
        light: Light,
        sampler: &LightSampler,
    ) -> Result<Box<dyn PreparedRays>, TechniqueError> {
        let prepared = Reference::same_samples(sampler.clone()).prepare_reference(scene, light)?;
        Ok(Box::new(prepared))
    }
}

impl PreparedRays for PreparedReference {
    fn scratch(&self) -> RayScratch {
        RayScratch::new(PixelScratch::default())
    }

    fn pixel_visibility<'a>(
        &self,
        s: &ViewSample,
        samples: &[LightSample],
        scratch: &'a mut RayScratch,
    ) -> (&'a [f32], u64) {
        if scratch.get_mut::<PixelScratch>().is_none() {
            // Another implementation's scratch: replaced, never a panic.
            *scratch = PreparedRays::scratch(self);
        }
        let buffers = scratch
            .get_mut::<PixelScratch>()
            .expect("replaced by a PixelScratch above");
        PreparedReference::pixel_visibility(self, s, samples, buffers)
    }
}
