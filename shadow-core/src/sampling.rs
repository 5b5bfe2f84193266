//! Light sample sets per pixel, with the strategies of DCS section 5 (Fig. 5): correlated (one
//! set for all pixels), decorrelated (the set rotated per pixel, a Cranley-Patterson toroidal
//! shift), stratified (a fresh jittered set per pixel) and interleaved (k x k tiles of sets,
//! Keller and Heidrich 2001).
//!
//! Samples come from a counter-based hash of `(seed, pixel, sample, dimension)`, not from a
//! sequential generator, so a pixel's samples do not depend on the order or the thread that
//! asks for them, and a GPU can reproduce them from the same integers.

use glam::{UVec2, Vec2};
use serde::Serialize;
use thiserror::Error;

use crate::light::{AreaLight, LightSample};

/// Largest sample count a sampler accepts.
pub const MAX_SAMPLES: u32 = 1 << 16;

/// How sample sets vary from pixel to pixel (DCS section 5, Fig. 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum SamplingStrategy {
    /// One jittered stratified set shared by every pixel: banding, no noise.
    Correlated,
    /// The shared set shifted by a random offset per pixel (toroidal rotation): noise, no banding.
    Decorrelated,
    /// An independent jittered stratified set per pixel.
    Stratified,
    /// `tile x tile` independent stratified sets repeated over the image.
    Interleaved {
        /// Tile side `k` (1 to 64).
        tile: u32,
    },
}

/// Why a sampler could not be built.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum SamplingError {
    /// The sample count is 0 or above [`MAX_SAMPLES`].
    #[error("sample count {0} is outside 1..={MAX_SAMPLES}")]
    Count(u32),
    /// The interleaving tile is 0 or above 64.
    #[error("interleaving tile {0} is outside 1..=64")]
    Tile(u32),
}

/// SplitMix64 finaliser: a bijective 64-bit mixer.
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Hash of several words, order-sensitive.
pub fn hash_words(words: &[u64]) -> u64 {
    words.iter().fold(0x9e37_79b9_7f4a_7c15u64, |h, &w| {
        mix64(h ^ mix64(w.wrapping_add(h)))
    })
}

/// A float in `[0, 1)` from the top 24 bits of a hash.
pub fn unit_float(h: u64) -> f32 {
    // Through `i32`: the 24 bits convert exactly either way, and the baseline x86-64 has a
    // single instruction for a signed conversion but a sequence for an unsigned 64-bit one.
    (h >> 40) as i32 as f32 * (1.0 / 16_777_216.0)
}

/// `x.min(ONE_MINUS)` for the non-NaN values of a jittered sample, as one `minss` (the NaN
/// handling of `f32::min` costs three more instructions per coordinate).
#[inline(always)]
fn below_one(x: f32) -> f32 {
    if x < ONE_MINUS { x } else { ONE_MINUS }
}

const ONE_MINUS: f32 = 1.0 - 1.0 / 16_777_216.0;

/// A seeded, reproducible source of per-pixel light sample sets.
#[derive(Debug, Clone, PartialEq)]
pub struct LightSampler {
    strategy: SamplingStrategy,
    count: u32,
    seed: u64,
    grid: UVec2,
    /// Shared sets: one for correlated/decorrelated, `tile^2` for interleaved.
    sets: Vec<Vec<Vec2>>,
    /// Each cell's hash key, `mix64(k ^ CELL_SALT)`: the part of a jittered sample's hash that
    /// does not depend on the set, computed once rather than per pixel.
    cell_keys: Vec<u64>,
    /// Each cell's corner `(k % grid.x, k / grid.x)` in cell units.
    cell_corners: Vec<Vec2>,
}

/// Salt of the cell index in a jittered sample's hash.
const CELL_SALT: u64 = 0x6a09_e667_f3bc_c909;

impl LightSampler {
    /// A sampler drawing `count` samples per pixel.
    ///
    /// # Errors
    /// [`SamplingError`] for a count outside `1..=MAX_SAMPLES` or a bad tile size.
    pub fn new(strategy: SamplingStrategy, count: u32, seed: u64) -> Result<Self, SamplingError> {
        if count == 0 || count > MAX_SAMPLES {
            return Err(SamplingError::Count(count));
        }
        let grid = strata(count);
        let mut s = Self {
            strategy,
            count,
            seed,
            grid,
            sets: Vec::new(),
            cell_keys: (0..u64::from(count))
                .map(|k| mix64(k ^ CELL_SALT))
                .collect(),
            cell_corners: (0..count)
                .map(|k| Vec2::new((k % grid.x) as f32, (k / grid.x) as f32))
                .collect(),
        };
        s.sets = match strategy {
            SamplingStrategy::Correlated | SamplingStrategy::Decorrelated => {
                vec![s.jittered_set(&[seed, 0x5e7])]
            }
            SamplingStrategy::Stratified => Vec::new(),
            SamplingStrategy::Interleaved { tile } => {
                if tile == 0 || tile > 64 {
                    return Err(SamplingError::Tile(tile));
                }
                (0..tile * tile)
                    .map(|k| s.jittered_set(&[seed, 0x11, k as u64]))
                    .collect()
            }
        };
        Ok(s)
    }

    /// The strategy.
    pub fn strategy(&self) -> SamplingStrategy {
        self.strategy
    }
    /// Samples per pixel.
    pub fn count(&self) -> u32 {
        self.count
    }
    /// The seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }
    /// The stratification grid (`x * y = count`).
    pub fn grid(&self) -> UVec2 {
        self.grid
    }

    /// A jittered set: one uniform point in each cell of the grid, cells in row-major order.
    fn jittered_set(&self, key: &[u64]) -> Vec<Vec2> {
        let mut out = Vec::with_capacity(self.count as usize);
        self.jittered_into(hash_words(key), &mut out);
        out
    }

    /// Appends the jittered set of `base` (a hash of the set's key) to `out`: sample `k` is
    /// cell `(k % grid.x, k / grid.x)` jittered by `mix64(base ^ cell_keys[k])`.
    fn jittered_into(&self, base: u64, out: &mut Vec<Vec2>) {
        let g = self.grid.as_vec2();
        if self.grid.x.is_power_of_two() && self.grid.y.is_power_of_two() {
            // Dividing by a power of two and multiplying by its reciprocal round alike.
            let inv = g.recip();
            self.jitter_cells(base, out, |c| c * inv);
        } else {
            self.jitter_cells(base, out, |c| c / g);
        }
    }

    /// [`LightSampler::jittered_into`] with the division by the grid given as `scale`; one
    /// pass over the cells' keys and corners, which `extend` writes without a capacity check
    /// per sample.
    #[inline(always)]
    fn jitter_cells(&self, base: u64, out: &mut Vec<Vec2>, scale: impl Fn(Vec2) -> Vec2) {
        out.extend(
            self.cell_keys
                .iter()
                .zip(&self.cell_corners)
                .map(|(key, corner)| {
                    let h = mix64(base ^ key);
                    let s = scale(*corner + Vec2::new(unit_float(h), unit_float(mix64(h))));
                    Vec2::new(below_one(s.x), below_one(s.y))
                }),
        );
    }

    /// The shared set whose samples pixel `pixel` takes unchanged: set 0 under correlated
    /// sampling, the set of the pixel's place in its tile under interleaved sampling; `None`
    /// where each pixel has samples of its own (decorrelated and stratified sampling). Pixels
    /// with the same shared set have the same [`LightSampler::unit_samples`], so a technique
    /// may keep whatever it derives from them alone.
    pub fn shared_set(&self, pixel: UVec2) -> Option<usize> {
        match self.strategy {
            SamplingStrategy::Correlated => Some(0),
            SamplingStrategy::Interleaved { tile } => {
                Some(((pixel.y % tile) * tile + pixel.x % tile) as usize)
            }
            SamplingStrategy::Decorrelated | SamplingStrategy::Stratified => None,
        }
    }

    /// The unit-square samples of pixel `pixel` (x, y), written into `out` (cleared first).
    pub fn unit_samples(&self, pixel: UVec2, out: &mut Vec<Vec2>) {
        out.clear();
        match self.strategy {
            SamplingStrategy::Correlated => out.extend_from_slice(&self.sets[0]),
            SamplingStrategy::Decorrelated => {
                let h = hash_words(&[self.seed, 0xdec, pixel.x as u64, pixel.y as u64]);
                let shift = Vec2::new(unit_float(h), unit_float(mix64(h)));
                out.extend(self.sets[0].iter().map(|u| {
                    let s = *u + shift;
                    (s - s.floor()).min(Vec2::splat(ONE_MINUS))
                }));
            }
            SamplingStrategy::Stratified => self.jittered_into(
                hash_words(&[self.seed, 0x57, pixel.x as u64, pixel.y as u64]),
                out,
            ),
            SamplingStrategy::Interleaved { .. } => {
                let k = self.shared_set(pixel).unwrap_or(0);
                out.extend_from_slice(&self.sets[k]);
            }
        }
    }

    /// The light samples of pixel `pixel`, written into `out` (cleared first).
    pub fn light_samples(&self, light: &dyn AreaLight, pixel: UVec2, out: &mut Vec<LightSample>) {
        let mut u = Vec::with_capacity(self.count as usize);
        self.unit_samples(pixel, &mut u);
        out.clear();
        light.sample_into(&u, out);
    }
}

/// Grid `(x, y)` with `x * y = count` and `x` the largest divisor not above `sqrt(count)`.
fn strata(count: u32) -> UVec2 {
    let mut x = (count as f64).sqrt().floor() as u32;
    while x > 1 && !count.is_multiple_of(x) {
        x -= 1;
    }
    let x = x.max(1);
    UVec2::new(count / x, x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strata_multiply_to_count() {
        for n in [1, 2, 7, 16, 64, 128, 1000, 1024, 4096] {
            let g = strata(n);
            assert_eq!(g.x * g.y, n);
            assert!(g.x >= g.y);
        }
        assert_eq!(strata(1024), UVec2::new(32, 32));
        assert_eq!(strata(128), UVec2::new(16, 8));
    }

    /// Sample `k` of a stratified pixel is the point of cell `(k % x, k / x)` jittered by the
    /// hash of the pixel's key and `k` (the per-cell key table only caches part of it).
    #[test]
    fn stratified_samples_follow_the_per_sample_hash() {
        for n in [1, 7, 12, 64, 128, 1000] {
            let s = LightSampler::new(SamplingStrategy::Stratified, n, 9).unwrap();
            let g = s.grid();
            let mut out = Vec::new();
            for pixel in [UVec2::new(0, 0), UVec2::new(17, 3)] {
                s.unit_samples(pixel, &mut out);
                assert_eq!(out.len(), n as usize);
                let base = hash_words(&[9, 0x57, u64::from(pixel.x), u64::from(pixel.y)]);
                for (k, u) in out.iter().enumerate() {
                    let h = mix64(base ^ mix64(k as u64 ^ 0x6a09_e667_f3bc_c909));
                    let (cx, cy) = (k as u32 % g.x, k as u32 / g.x);
                    let want = Vec2::new(
                        ((cx as f32 + unit_float(h)) / g.x as f32).min(ONE_MINUS),
                        ((cy as f32 + unit_float(mix64(h))) / g.y as f32).min(ONE_MINUS),
                    );
                    assert_eq!(*u, want, "n {n} pixel {pixel} sample {k}");
                }
            }
        }
    }

    /// Pixels with the same shared set get the same samples, pixels with different ones do
    /// not, and only correlated and interleaved sampling share sets.
    #[test]
    fn pixels_of_one_shared_set_have_the_same_samples() {
        let pixels: Vec<UVec2> = (0..7)
            .flat_map(|y| (0..9).map(move |x| UVec2::new(x, y)))
            .collect();
        let samples = |s: &LightSampler, p: UVec2| {
            let mut out = Vec::new();
            s.unit_samples(p, &mut out);
            out
        };
        for strategy in [
            SamplingStrategy::Correlated,
            SamplingStrategy::Interleaved { tile: 3 },
            SamplingStrategy::Interleaved { tile: 1 },
        ] {
            let s = LightSampler::new(strategy, 16, 5).unwrap();
            let sets: std::collections::BTreeSet<usize> =
                pixels.iter().map(|p| s.shared_set(*p).unwrap()).collect();
            let want = match strategy {
                SamplingStrategy::Interleaved { tile } => (tile * tile) as usize,
                _ => 1,
            };
            assert_eq!(sets.len(), want, "{strategy:?}");
            assert!(sets.iter().all(|k| *k < want));
            for a in &pixels {
                for b in &pixels {
                    let same = s.shared_set(*a) == s.shared_set(*b);
                    assert_eq!(
                        samples(&s, *a) == samples(&s, *b),
                        same,
                        "{strategy:?} {a} {b}"
                    );
                }
            }
        }
        for strategy in [SamplingStrategy::Decorrelated, SamplingStrategy::Stratified] {
            let s = LightSampler::new(strategy, 16, 5).unwrap();
            assert!(pixels.iter().all(|p| s.shared_set(*p).is_none()));
        }
    }

    #[test]
    fn bad_parameters_are_errors() {
        assert_eq!(
            LightSampler::new(SamplingStrategy::Stratified, 0, 1),
            Err(SamplingError::Count(0))
        );
        assert!(LightSampler::new(SamplingStrategy::Stratified, MAX_SAMPLES + 1, 1).is_err());
        assert_eq!(
            LightSampler::new(SamplingStrategy::Interleaved { tile: 0 }, 4, 1),
            Err(SamplingError::Tile(0))
        );
    }
}
