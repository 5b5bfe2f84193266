//! The plane lookup table of section 4.2: for a plane described by two angles (the polar and
//! azimuthal angles of its normal in the light's frame) and a distance (from the light's
//! centre, in units of the light's bounding radius), the bitmask of the light samples on its
//! positive side. The occlusion pass ANDs the masks of a triangle's planes instead of testing
//! every sample. The table is sized relative to the sample count (the paper uses 128^3 for 128
//! samples; here `theta` and `delta` get `clamp(N / 2, 16, 64)` bins and `phi` twice that),
//! and its discretisation error against the exact test is measured by the `afsm-128-lut`
//! preset against the same-samples reference.

use glam::Vec3;
use rayon::prelude::*;

use crate::params::LightBounds;

/// A built table.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneLut {
    /// Bins in theta, phi, delta.
    pub bins: [u32; 3],
    /// Words per entry (`ceil(N / 32)`).
    pub words: u32,
    /// Entries, `words` per cell, cells in (theta, phi, delta) row-major order.
    pub data: Vec<u32>,
}

/// Bins for `n` samples.
pub fn bins_for(n: u32) -> [u32; 3] {
    let t = (n / 2).clamp(16, 64);
    [t, 2 * t, t]
}

/// The normal and distance at the centre of cell `(it, ip, id)`.
fn cell_plane(bins: [u32; 3], b: &LightBounds, it: u32, ip: u32, id: u32) -> (Vec3, f32) {
    let theta = (it as f32 + 0.5) * std::f32::consts::PI / bins[0] as f32;
    let phi = -std::f32::consts::PI + (ip as f32 + 0.5) * std::f32::consts::TAU / bins[1] as f32;
    let delta = -1.0 + (id as f32 + 0.5) * 2.0 / bins[2] as f32;
    let m = theta.sin() * phi.cos() * b.axes[0]
        + theta.sin() * phi.sin() * b.axes[1]
        + theta.cos() * b.normal;
    (m, delta)
}

impl PlaneLut {
    /// Builds the table of `samples` (world positions on the light bounded by `b`).
    pub fn build(b: &LightBounds, samples: &[Vec3]) -> Self {
        let bins = bins_for(samples.len() as u32);
        let words = (samples.len() as u32).div_ceil(32);
        let r = b.bound.max(f32::MIN_POSITIVE);
        let rel: Vec<Vec3> = samples.iter().map(|y| (*y - b.center) / r).collect();
        let cells = (bins[0] * bins[1] * bins[2]) as usize;
        let mut data = vec![0u32; cells * words as usize];
        data.par_chunks_mut(words as usize * bins[2] as usize)
            .enumerate()
            .for_each(|(row, out)| {
                let (it, ip) = (row as u32 / bins[1], row as u32 % bins[1]);
                for id in 0..bins[2] {
                    let (m, delta) = cell_plane(bins, b, it, ip, id);
                    let e = &mut out[(id * words) as usize..((id + 1) * words) as usize];
                    for (k, y) in rel.iter().enumerate() {
                        if m.dot(*y) >= delta {
                            e[k / 32] |= 1 << (k % 32);
                        }
                    }
                }
            });
        Self { bins, words, data }
    }

    /// The cell of the oriented plane `{y : m . (y - base) >= 0}` (`lut_cell` in
    /// `occlude.wgsl`).
    pub fn cell(&self, b: &LightBounds, m: Vec3, base: Vec3) -> usize {
        let mh = m.normalize();
        let theta = mh.dot(b.normal).clamp(-1.0, 1.0).acos();
        let phi = mh.dot(b.axes[1]).atan2(mh.dot(b.axes[0]));
        let delta = mh.dot(base - b.center) / b.bound.max(f32::MIN_POSITIVE);
        let [nt, np, nd] = self.bins;
        let it = ((theta / std::f32::consts::PI * nt as f32) as u32).min(nt - 1);
        let ip =
            (((phi + std::f32::consts::PI) / std::f32::consts::TAU * np as f32) as u32).min(np - 1);
        let id = ((delta + 1.0) * 0.5 * nd as f32).clamp(0.0, (nd - 1) as f32) as u32;
        ((it * np + ip) * nd + id) as usize
    }

    /// The mask of the plane `{y : m . (y - base) >= 0}`.
    pub fn mask(&self, b: &LightBounds, m: Vec3, base: Vec3) -> &[u32] {
        let c = self.cell(b, m, base) * self.words as usize;
        &self.data[c..c + self.words as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shadow_core::light::{AreaLight, Radiance, RectLight};
    use shadow_core::sampling::{LightSampler, SamplingStrategy};

    /// Against the exact side test over random planes that cut the light: the share of wrong
    /// bits is small and falls as the table grows with N.
    #[test]
    fn lookup_agrees_with_the_exact_side_test() {
        let light = RectLight::new(
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 0.5),
            Radiance::constant(Vec3::ONE).unwrap(),
        )
        .unwrap();
        let b = LightBounds::new(&light, false);
        let mut errors = Vec::new();
        for n in [32u32, 128] {
            let sampler = LightSampler::new(SamplingStrategy::Correlated, n, 3).unwrap();
            let mut u = Vec::new();
            sampler.unit_samples(glam::UVec2::ZERO, &mut u);
            let ys: Vec<Vec3> = u.iter().map(|u| light.sample(*u).position).collect();
            let lut = PlaneLut::build(&b, &ys);
            let (mut wrong, mut total) = (0u32, 0u32);
            let mut h = 12345u64;
            for _ in 0..2000 {
                let mut r = || {
                    h = shadow_core::sampling::mix64(h);
                    shadow_core::sampling::unit_float(h) * 2.0 - 1.0
                };
                let m = Vec3::new(r(), r(), r());
                let base = light.center() + Vec3::new(r() * 0.5, 0.0, r() * 0.5);
                if m.length() < 0.1 {
                    continue;
                }
                let mask = lut.mask(&b, m, base);
                for (k, y) in ys.iter().enumerate() {
                    let exact = m.dot(*y - base) >= 0.0;
                    let got = mask[k / 32] >> (k % 32) & 1 == 1;
                    wrong += (exact != got) as u32;
                    total += 1;
                }
            }
            errors.push(wrong as f64 / total as f64);
        }
        assert!(errors[0] < 0.06 && errors[1] < 0.03, "{errors:?}");
        assert!(errors[1] < errors[0], "{errors:?}");
    }
}
