//! Light samples bucketed by position on a planar light, so the exact test of section 4.2
//! visits only the samples a triangle can hide.
//!
//! A light sample hidden from view sample `o` by a triangle lies inside the pyramid from `o`
//! through the triangle. On the light's plane, that pyramid is the triangle projected from `o`,
//! whenever all three vertices project forward. Only the buckets under the projection's
//! bounding box (padded against rounding) can hold hidden samples, so the others are skipped
//! without changing a bit. This matters under many thin occluders (`grass`: a blade hides a
//! sliver of the light from each view sample). Sphere lights have no plane and keep the full
//! loop, as do pairs whose projection is unbounded.
//!
//! Layout per sample set, as `occlude.wgsl` reads it: `g * g + 1` bucket offsets (row-major
//! buckets, offsets into this set's index list), then the set's `N` sample indices sorted by
//! bucket.

use glam::{Vec2, Vec3};

use crate::params::{KIND_DISK, KIND_POINTS, LightBounds};

/// Samples per set bucketed on a `g` x `g` grid in the light's plane.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleGrid {
    /// Buckets per side.
    pub g: u32,
    /// Grid origin in the light's (u, v) coordinates about its centre.
    pub origin: Vec2,
    /// Buckets per unit along u and v.
    pub scale: Vec2,
    /// Per set: `g * g + 1` offsets, then `N` sample indices.
    pub data: Vec<u32>,
}

impl SampleGrid {
    /// Fewest samples per set for which the technique uses a grid: below, the plain loop over
    /// every sample is as fast on llvmpipe (measured on bunny and grass; `docs/benchmarks.md`).
    pub const MIN_SAMPLES: u32 = 128;

    /// Buckets per side for `n` samples: about four samples per bucket, at most 32 x 32.
    pub fn side_for(n: u32) -> u32 {
        ((n as f32).sqrt() / 2.0).round().clamp(1.0, 32.0) as u32
    }

    /// The grid of `sets` (each of `n` positions) on a planar light; `None` for sphere and
    /// point lights, which have no plane.
    pub fn build(bounds: &LightBounds, sets: &[Vec<Vec3>], n: u32) -> Option<Self> {
        if bounds.kind != KIND_POINTS && bounds.kind != KIND_DISK {
            return None;
        }
        let [u, v] = bounds.axes;
        let local = |p: Vec3| Vec2::new((p - bounds.center).dot(u), (p - bounds.center).dot(v));
        // The light's extent in its plane: its outline, or the disk's square.
        let (mut lo, mut hi) = if bounds.kind == KIND_DISK {
            (Vec2::splat(-bounds.radius), Vec2::splat(bounds.radius))
        } else {
            bounds.outline.iter().fold(
                (Vec2::splat(f32::MAX), Vec2::splat(f32::MIN)),
                |(lo, hi), p| (lo.min(local(*p)), hi.max(local(*p))),
            )
        };
        for s in sets.iter().flatten() {
            lo = lo.min(local(*s));
            hi = hi.max(local(*s));
        }
        let g = Self::side_for(n);
        let scale = Vec2::splat(g as f32) / (hi - lo);
        if !scale.is_finite() {
            // A light without extent: nothing to bucket.
            return None;
        }
        let cell = |p: Vec3| {
            let t = ((local(p) - lo) * scale).floor();
            let m = (g - 1) as f32;
            (t.y.clamp(0.0, m) as u32) * g + t.x.clamp(0.0, m) as u32
        };
        let cells = (g * g) as usize;
        let mut data = Vec::with_capacity(sets.len() * (cells + 1 + n as usize));
        for set in sets {
            let ids: Vec<u32> = set.iter().map(|p| cell(*p)).collect();
            let mut start = vec![0u32; cells + 1];
            for &c in &ids {
                start[c as usize + 1] += 1;
            }
            for c in 0..cells {
                start[c + 1] += start[c];
            }
            let mut next = start.clone();
            let mut order = vec![0u32; set.len()];
            for (k, &c) in ids.iter().enumerate() {
                order[next[c as usize] as usize] = k as u32;
                next[c as usize] += 1;
            }
            data.extend_from_slice(&start);
            data.extend_from_slice(&order);
        }
        Some(Self {
            g,
            origin: lo,
            scale,
            data,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shadow_core::light::{Radiance, RectLight};
    use shadow_core::prelude::*;

    /// Every sample sits once in the bucket its position falls in, and every bucket's samples
    /// lie inside the bucket (so a box of buckets covers every sample in the box).
    #[test]
    fn every_sample_is_in_the_bucket_of_its_position() {
        let light = RectLight::facing(
            Vec3::new(0.3, 2.0, -0.1),
            Vec3::NEG_Y,
            1.2,
            0.7,
            Radiance::constant(Vec3::ONE).unwrap(),
        )
        .unwrap();
        let bounds = LightBounds::new(&light, false);
        let sampler = LightSampler::new(SamplingStrategy::Correlated, 64, 3).unwrap();
        let mut s = Vec::new();
        sampler.light_samples(&light, glam::UVec2::ZERO, &mut s);
        let set: Vec<Vec3> = s.iter().map(|x| x.position).collect();
        let grid = SampleGrid::build(&bounds, std::slice::from_ref(&set), 64).unwrap();
        assert_eq!(grid.g, 4);
        let cells = (grid.g * grid.g) as usize;
        let (start, order) = grid.data.split_at(cells + 1);
        let mut seen = [false; 64];
        for c in 0..cells {
            for &k in &order[start[c] as usize..start[c + 1] as usize] {
                assert!(!seen[k as usize]);
                seen[k as usize] = true;
                let [u, v] = bounds.axes;
                let q = set[k as usize] - bounds.center;
                let t = (Vec2::new(q.dot(u), q.dot(v)) - grid.origin) * grid.scale;
                let (bx, by) = ((c as u32 % grid.g) as f32, (c as u32 / grid.g) as f32);
                assert!(t.x >= bx - 1e-4 && t.x <= bx + 1.0 + 1e-4, "{t} in {c}");
                assert!(t.y >= by - 1e-4 && t.y <= by + 1.0 + 1e-4, "{t} in {c}");
            }
        }
        assert!(seen.iter().all(|&x| x));
    }
}
