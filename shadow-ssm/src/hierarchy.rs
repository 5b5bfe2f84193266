//! The hierarchical min/max shadow map (GBP06; GBP07 section 3): like a mipmap, level `k`
//! holds, for each block of `2^k x 2^k` texels, the smallest and largest depth in it (empty
//! texels are infinitely far). It bounds the depths of any kernel with a few lookups, which
//! GBP07 uses to shrink the kernel of eq. 1 until it converges and to classify a receiver as lit,
//! umbra or penumbra before any exact work.

use std::sync::Arc;

use rayon::prelude::*;

use crate::shadow_map::ShadowMap;

/// Min and max depth pyramids.
#[derive(Debug, Clone)]
pub struct MinMaxPyramid {
    /// Per level: side in blocks, min depths, max depths (row-major; the max is empty at level
    /// 0, whose max is its min). Level 0 is the shadow map's own depths, shared.
    levels: Vec<(usize, Arc<Vec<f32>>, Vec<f32>)>,
}

impl MinMaxPyramid {
    /// Builds the pyramid of a shadow map.
    pub fn build(sm: &ShadowMap) -> Self {
        let r = sm.view.width as usize;
        // Level 0 is the map itself, min and max alike: shared, read as both.
        let mut levels = vec![(r, Arc::clone(&sm.depth), Vec::new())];
        while levels.last().is_some_and(|l| l.0 > 1) {
            let (side, lo, hi) = levels.last().expect("non-empty");
            let hi = if hi.is_empty() { lo } else { hi };
            let side = *side;
            let next = side.div_ceil(2);
            let mut nlo = vec![f32::INFINITY; next * next];
            let mut nhi = vec![f32::NEG_INFINITY; next * next];
            // Rows of the next level in parallel, each from its (one or) two rows; a last odd
            // row or column reads its texel twice, which leaves a min or max as it is.
            nlo.par_chunks_mut(next)
                .zip(nhi.par_chunks_mut(next))
                .enumerate()
                .for_each(|(y, (rlo, rhi))| {
                    let rows = [2 * y * side, (2 * y + 1).min(side - 1) * side];
                    // Whole pairs of columns first, in a form the compiler vectorises; a last
                    // odd column reads its texel twice.
                    let pairs = side / 2;
                    let quad = |src: &[f32], f: fn(f32, f32) -> f32, out: &mut [f32]| {
                        let (r0, r1) = (&src[rows[0]..][..2 * pairs], &src[rows[1]..][..2 * pairs]);
                        for ((o, a), b) in out[..pairs]
                            .iter_mut()
                            .zip(r0.chunks_exact(2))
                            .zip(r1.chunks_exact(2))
                        {
                            *o = f(f(a[0], a[1]), f(b[0], b[1]));
                        }
                        for x in pairs..next {
                            let c = (2 * x).min(side - 1);
                            out[x] = f(src[rows[0] + c], src[rows[1] + c]);
                        }
                    };
                    quad(lo, f32::min, rlo);
                    quad(hi, f32::max, rhi);
                });
            levels.push((next, Arc::new(nlo), nhi));
        }
        Self { levels }
    }

    /// Level `k`: side in texels and the min depths (row-major).
    pub fn level(&self, k: usize) -> (usize, &[f32]) {
        let (side, lo, _) = &self.levels[k.min(self.levels.len() - 1)];
        (*side, lo)
    }

    /// The min depth of level `k` filtered bilinearly at level-0 texel coordinates `(x, y)`,
    /// each tap clamped to `cap` (GBP07 section 5.1's continuous occluder depth: `cap` is the
    /// receiver's depth, so texels with no occluder count as no penumbra).
    pub fn filtered_min(&self, k: usize, x: f64, y: f64, cap: f32) -> f32 {
        let (side, lo) = self.level(k);
        let s = (1u64 << k.min(62)) as f64;
        let (fx, fy) = (x / s - 0.5, y / s - 0.5);
        let (ix, iy) = (fx.floor(), fy.floor());
        let (tx, ty) = ((fx - ix) as f32, (fy - iy) as f32);
        let at = |i: f64, j: f64| -> f32 {
            let (i, j) = (i as i64, j as i64);
            if i < 0 || j < 0 || i >= side as i64 || j >= side as i64 {
                cap
            } else {
                lo[j as usize * side + i as usize].min(cap)
            }
        };
        let top = at(ix, iy) * (1.0 - tx) + at(ix + 1.0, iy) * tx;
        let bottom = at(ix, iy + 1.0) * (1.0 - tx) + at(ix + 1.0, iy + 1.0) * tx;
        top * (1.0 - ty) + bottom * ty
    }

    /// Number of levels (level 0 is the shadow map).
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// Bounds `(min, max)` of the depths in the texel rectangle `[x0, x1] x [y0, y1]`
    /// (inclusive, clamped to the map), from the level whose blocks are about the rectangle's
    /// size: at most 3 x 3 blocks are read, and the bounds cover a superset of the rectangle, so
    /// they are conservative. `None` when the rectangle misses the map.
    pub fn bounds(&self, x0: i64, y0: i64, x1: i64, y1: i64) -> Option<(f32, f32)> {
        let r = self.levels[0].0 as i64;
        let (x0, y0, x1, y1) = (x0.max(0), y0.max(0), x1.min(r - 1), y1.min(r - 1));
        if x0 > x1 || y0 > y1 {
            return None;
        }
        let size = (x1 - x0 + 1).max(y1 - y0 + 1) as u64;
        let level = (63 - size.leading_zeros() as usize).min(self.levels.len() - 1);
        let (side, lo, hi) = &self.levels[level];
        let hi = if hi.is_empty() { lo } else { hi };
        let (mut mn, mut mx) = (f32::INFINITY, f32::NEG_INFINITY);
        for by in (y0 >> level)..=(y1 >> level) {
            for bx in (x0 >> level)..=(x1 >> level) {
                let i = by as usize * side + bx as usize;
                mn = mn.min(lo[i]);
                mx = mx.max(hi[i]);
            }
        }
        Some((mn, mx))
    }

    /// The kernel width of GBP07 section 3 for a receiver at texel `(x, y)` and depth `z`: eq. 1
    /// from the map's minimum depth, then repeatedly from the local minimum over the current
    /// kernel (read from the pyramid) until the width stops shrinking. Returns the width in
    /// texels and the local minimum depth (infinite when the kernel holds no texel in front of
    /// the receiver's depth, i.e. nothing can occlude it).
    pub fn converged_kernel(
        &self,
        sm: &ShadowMap,
        light_width: f32,
        x: f64,
        y: f64,
        z: f32,
    ) -> (f64, f32) {
        let mut z_min = sm.min_depth;
        let mut w = sm.kernel_width(light_width, z_min, z);
        for _ in 0..16 {
            if !(z_min < z) {
                return (0.0, f32::INFINITY);
            }
            let h = w * 0.5;
            let Some((local, _)) = self.bounds(
                (x - h).floor() as i64,
                (y - h).floor() as i64,
                (x + h).floor() as i64,
                (y + h).floor() as i64,
            ) else {
                return (0.0, f32::INFINITY);
            };
            if !(local > z_min) {
                break;
            }
            z_min = local;
            let next = sm.kernel_width(light_width, z_min, z);
            if !(next < w) {
                break;
            }
            w = next;
        }
        if !(z_min < z) {
            return (0.0, f32::INFINITY);
        }
        (w, z_min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shadow_core::sampling::{hash_words, unit_float};

    fn random_map(r: u32) -> ShadowMap {
        let depth: Vec<f32> = (0..r * r)
            .map(|i| {
                let h = hash_words(&[7, i as u64]);
                if h.is_multiple_of(11) {
                    f32::INFINITY
                } else {
                    1.0 + unit_float(h) * 9.0
                }
            })
            .collect();
        let mut sm = ShadowMap::unit_square(r, depth);
        sm.min_depth = 1.0;
        sm
    }

    #[test]
    fn pyramid_bounds_hold_the_brute_force_bounds_of_any_rectangle() {
        for r in [1u32, 7, 64, 100] {
            let sm = random_map(r);
            let p = MinMaxPyramid::build(&sm);
            assert_eq!(p.level_count(), (r as f64).log2().ceil() as usize + 1);
            for k in 0..300u64 {
                let f = |i: u64| (unit_float(hash_words(&[k, i])) * r as f32) as i64;
                let (x0, x1) = (f(0).min(f(1)), f(0).max(f(1)));
                let (y0, y1) = (f(2).min(f(3)), f(2).max(f(3)));
                let (mut mn, mut mx) = (f32::INFINITY, f32::NEG_INFINITY);
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        let d = sm.at(x, y);
                        mn = mn.min(d);
                        mx = mx.max(d);
                    }
                }
                let (lo, hi) = p.bounds(x0, y0, x1, y1).unwrap();
                assert!(lo <= mn && hi >= mx, "r {r} rect {x0},{y0}-{x1},{y1}");
                // Whole-map bounds are exact.
                let (lo, hi) = p.bounds(0, 0, r as i64 - 1, r as i64 - 1).unwrap();
                let all_min = sm.depth.iter().copied().fold(f32::INFINITY, f32::min);
                let all_max = sm.depth.iter().copied().fold(f32::NEG_INFINITY, f32::max);
                assert_eq!((lo, hi), (all_min, all_max));
            }
            assert!(p.bounds(-5, -5, -1, -1).is_none());
        }
    }

    #[test]
    fn converged_kernel_shrinks_to_the_local_occluders_and_finds_lit_receivers() {
        // A map at depth 8 everywhere but one occluder texel block at depth 2.
        let r = 64u32;
        let mut sm = random_map(r);
        let depth = Arc::make_mut(&mut sm.depth);
        depth.iter_mut().for_each(|d| *d = 8.0);
        for y in 40..44 {
            for x in 40..44 {
                depth[(y * r + x) as usize] = 2.0;
            }
        }
        sm.min_depth = 2.0;
        let p = MinMaxPyramid::build(&sm);
        // Eq. 1 with light width 0.5, receiver at depth 10: w = 0.5 * 32 * (1/2 - 1/10) = 6.4.
        let (w, zmin) = p.converged_kernel(&sm, 0.5, 41.0, 41.0, 10.0);
        assert!((w - 6.4).abs() < 1e-9 && zmin == 2.0, "{w} {zmin}");
        // Far from the occluder the local minimum is the background at 8: w = 0.5 * 32 * (1/8 -
        // 1/10) = 0.4.
        let (w, zmin) = p.converged_kernel(&sm, 0.5, 10.0, 10.0, 10.0);
        assert!((w - 0.4).abs() < 1e-9 && zmin == 8.0, "{w} {zmin}");
        // A receiver in front of everything is lit: nothing can occlude it.
        let (w, zmin) = p.converged_kernel(&sm, 0.5, 10.0, 10.0, 1.5);
        assert_eq!((w, zmin), (0.0, f32::INFINITY));
    }
}
