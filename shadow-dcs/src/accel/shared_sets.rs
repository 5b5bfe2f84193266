//! The part of a pixel's sample set-up that depends on its light samples alone, kept once per
//! shared sample set.
//!
//! Under correlated sampling every pixel takes the same set, and under interleaved sampling
//! (DCS section 5, Fig. 5) the pixels at one place of a `k x k` tile do. Their samples' world
//! positions, their coordinates in the light plane around its centre and the angular index
//! built on those ([`crate::accel::angular`]) are then the same for every such pixel: only what
//! depends on the view sample (the horizon mask, the samples relative to it) is computed per
//! pixel. Each thread keeps the sets it has met for the length of one estimate, built the
//! first time a pixel needs them, and lends a set to the pixel's scratch by swapping buffers,
//! so that a pixel of a set already built costs no copy. As in the paper's GPU version, where
//! the section 7.3 tables are computed once per sample set, the work per set is paid once.

use glam::Vec3;

use crate::accel::angular::AngularIndex;
use crate::accel::planar::PlanarSamples;

/// How a pixel's samples are set up: the keys of one shared set's forms are apart, since the
/// forms give the same points up to rounding only.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SetForm {
    /// Light-plane coordinates straight from the unit samples of a rectangle light (no world
    /// positions outside debug builds).
    PlanarRect,
    /// World positions, and light-plane coordinates from them.
    Planar,
    /// World positions alone (the 3D covered-sample test).
    Spatial,
}

impl SetForm {
    const COUNT: usize = 3;

    fn index(self) -> usize {
        match self {
            Self::PlanarRect => 0,
            Self::Planar => 1,
            Self::Spatial => 2,
        }
    }
}

/// A pixel's samples as its pass reads them: world positions (empty in the rectangle form
/// outside debug builds), light-plane coordinates (the light-plane forms) and their angular
/// index (built where the pass may use it).
#[derive(Debug, Clone, Default)]
pub(crate) struct SampleSet {
    pub positions: Vec<Vec3>,
    pub planar: PlanarSamples,
    pub angular: AngularIndex,
}

/// The shared sets one thread has built during an estimate, and which of them its scratch set
/// holds now.
#[derive(Debug, Default)]
pub(crate) struct SharedSets {
    /// Per shared set and form ([`SetForm::COUNT`] slots per set): the set, or, for the set
    /// lent out, the buffers of the scratch set it replaced.
    slots: Vec<Option<SampleSet>>,
    /// The slot whose set the scratch set holds.
    lent: Option<usize>,
}

impl SharedSets {
    /// Puts shared set `set` in form `form` into `scratch` (a swap of buffers), building it
    /// with `build` the first time (`build` fills an empty set and must depend on the set's
    /// samples alone). Returns whether it built the set.
    pub fn lend(
        &mut self,
        set: usize,
        form: SetForm,
        scratch: &mut SampleSet,
        build: impl FnOnce(&mut SampleSet),
    ) -> bool {
        let slot = set * SetForm::COUNT + form.index();
        if self.lent == Some(slot) {
            return false;
        }
        self.restore(scratch);
        if self.slots.len() <= slot {
            self.slots.resize_with(slot + 1, || None);
        }
        let built = self.slots[slot].is_none();
        let kept = self.slots[slot].get_or_insert_with(|| {
            let mut s = SampleSet::default();
            build(&mut s);
            s
        });
        std::mem::swap(scratch, kept);
        self.lent = Some(slot);
        built
    }

    /// Gives the lent set back, so that `scratch` holds the pixel's own buffers again (before
    /// a pixel sets its own samples up in them).
    pub fn restore(&mut self, scratch: &mut SampleSet) {
        if let Some(slot) = self.lent.take()
            && let Some(kept) = self.slots[slot].as_mut()
        {
            std::mem::swap(scratch, kept);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set_of(v: f32) -> impl FnOnce(&mut SampleSet) {
        move |s: &mut SampleSet| s.positions.push(Vec3::splat(v))
    }

    /// A set is built once per set and form, lent without a copy, and a restore hands the
    /// scratch its own buffers back.
    #[test]
    fn sets_are_built_once_and_lent_back_and_forth() {
        let mut shared = SharedSets::default();
        let mut scratch = SampleSet::default();
        scratch.positions.push(Vec3::splat(-1.0));
        assert!(shared.lend(2, SetForm::Planar, &mut scratch, set_of(2.0)));
        assert_eq!(scratch.positions, [Vec3::splat(2.0)]);
        // Lent already: nothing built, nothing swapped.
        assert!(!shared.lend(2, SetForm::Planar, &mut scratch, set_of(9.0)));
        assert_eq!(scratch.positions, [Vec3::splat(2.0)]);
        // Another form of the same set is another set.
        assert!(shared.lend(2, SetForm::Spatial, &mut scratch, set_of(3.0)));
        assert_eq!(scratch.positions, [Vec3::splat(3.0)]);
        // Back to the first: kept, not rebuilt.
        assert!(!shared.lend(2, SetForm::Planar, &mut scratch, set_of(9.0)));
        assert_eq!(scratch.positions, [Vec3::splat(2.0)]);
        assert!(shared.lend(0, SetForm::PlanarRect, &mut scratch, set_of(4.0)));
        assert_eq!(scratch.positions, [Vec3::splat(4.0)]);
        // The pixel's own buffers come back, and the lent set stays kept.
        shared.restore(&mut scratch);
        assert_eq!(scratch.positions, [Vec3::splat(-1.0)]);
        shared.restore(&mut scratch);
        assert_eq!(scratch.positions, [Vec3::splat(-1.0)]);
        assert!(!shared.lend(0, SetForm::PlanarRect, &mut scratch, set_of(9.0)));
        assert_eq!(scratch.positions, [Vec3::splat(4.0)]);
    }
}
