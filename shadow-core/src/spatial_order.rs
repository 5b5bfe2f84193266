//! Receivers without a camera in a spatially coherent layout ([`SpatialOrder`]), for the
//! techniques that rely on image neighbours or tiles (issue 67): the adaptive reference pools
//! its variance over neighbours, the reference's beam culling and the shadow maps' tiles want
//! receivers close in space next to each other. The layout keeps each receiver's light sample
//! set (drawn per pixel, [`crate::view_samples::ViewSample::pixel`]), so a technique gives the
//! same answer in either order, and [`SpatialOrder::restore`] gives the estimate back in the
//! caller's order.

use glam::{UVec2, Vec3};
use rayon::prelude::*;

use crate::raster::NO_TRIANGLE;
use crate::technique::{Estimate, TechniqueError};
use crate::view_samples::ViewSamples;
use crate::visibility::PerSampleVisibility;

/// Receivers without a camera laid out for a technique that relies on image neighbours (the
/// adaptive reference pools its variance over 3 x 3 pixels): sorted along a 3D Morton curve
/// of their positions and placed along the Hilbert curve of a square grid, so that receivers
/// close in space are close in the grid. [`SpatialOrder::restore`] gives the estimate back in the
/// caller's order.
#[derive(Debug, Clone)]
pub struct SpatialOrder {
    /// The receivers in their new layout (no camera, background where the grid is padding).
    pub view: ViewSamples,
    /// For each pixel of [`SpatialOrder::view`], the caller's receiver it holds.
    source: Vec<Option<usize>>,
    /// The pixels of [`SpatialOrder::view`] that hold receivers, in the order of the curve.
    curve: Vec<usize>,
}

impl ViewSamples {
    /// These receivers in a spatially coherent layout ([`SpatialOrder`]).
    pub fn spatially_ordered(&self) -> SpatialOrder {
        let valid: Vec<usize> = (0..self.len()).filter(|&i| self.is_valid(i)).collect();
        let (lo, hi) = valid.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), &i| (lo.min(self.position[i]), hi.max(self.position[i])),
        );
        let scale = (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE));
        let mut keyed: Vec<(u64, usize)> = valid
            .iter()
            .map(|&i| {
                let q = ((self.position[i] - lo) / scale * 2_097_151.0).as_uvec3();
                (morton3(q.x, q.y, q.z), i)
            })
            .collect();
        keyed.sort_unstable();
        // The smallest power-of-two square that holds them.
        let m = keyed.len().max(1);
        let mut side = 1usize;
        while side * side < m {
            side *= 2;
        }
        let (width, height) = (side, side);
        let n = width * height;
        let mut source = vec![None; n];
        let mut curve = Vec::with_capacity(keyed.len());
        for (k, &(_, i)) in keyed.iter().enumerate() {
            let (x, y) = hilbert_decode(side as u64, k as u64);
            let cell = y as usize * width + x as usize;
            source[cell] = Some(i);
            curve.push(cell);
        }
        let pick = |f: &dyn Fn(usize) -> Vec3, empty: Vec3| -> Vec<Vec3> {
            source.iter().map(|s| s.map_or(empty, f)).collect()
        };
        let view = ViewSamples {
            width: width as u32,
            height: height as u32,
            camera_position: Vec3::ZERO,
            view: None,
            position: pick(&|i| self.position[i], Vec3::ZERO),
            geometric_normal: pick(&|i| self.geometric_normal[i], Vec3::ZERO),
            shading_normal: pick(&|i| self.shading_normal[i], Vec3::ZERO),
            triangle: source
                .iter()
                .map(|s| s.map_or(NO_TRIANGLE, |i| self.triangle[i]))
                .collect(),
            depth: source
                .iter()
                .map(|s| s.map_or(f32::INFINITY, |i| self.depth[i]))
                .collect(),
            albedo: self.albedo.as_ref().map(|a| {
                source
                    .iter()
                    .map(|s| s.map_or(Vec3::ZERO, |i| a[i]))
                    .collect()
            }),
            unmatched: self.unmatched,
            sample_pixels: Some(
                source
                    .iter()
                    .map(|s| s.map_or(UVec2::ZERO, |i| self.sample_pixel(i)))
                    .collect(),
            ),
        };
        SpatialOrder {
            view,
            source,
            curve,
        }
    }
}

impl SpatialOrder {
    /// For every pixel of [`SpatialOrder::view`] that holds a receiver, up to `K` other pixels
    /// holding the receivers nearest it in space among the `window` on either side along the
    /// 3D curve, on surfaces facing the same way (normals within 90 degrees); empty for
    /// padding. What a technique takes for "neighbouring pixels" where there is no image.
    pub fn neighbours<const K: usize>(&self, window: usize) -> Vec<Vec<u32>> {
        let v = &self.view;
        let mut out = vec![Vec::new(); self.source.len()];
        let lists: Vec<(usize, Vec<u32>)> = (0..self.curve.len())
            .into_par_iter()
            .map(|j| {
                let cell = self.curve[j];
                let (p, n) = (v.position[cell], v.geometric_normal[cell]);
                let lo = j.saturating_sub(window);
                let hi = (j + window + 1).min(self.curve.len());
                let mut near: Vec<(f32, u32)> = (lo..hi)
                    .filter(|&k| k != j)
                    .map(|k| self.curve[k])
                    .filter(|&c| v.geometric_normal[c].dot(n) > 0.0)
                    .map(|c| ((v.position[c] - p).length_squared(), c as u32))
                    .collect();
                near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                (cell, near.into_iter().take(K).map(|(_, c)| c).collect())
            })
            .collect();
        for (cell, list) in lists {
            out[cell] = list;
        }
        out
    }

    /// `est`, computed on [`SpatialOrder::view`], in the layout of `caller` (the view this
    /// order was made from): visibility, classes, per-sample visibility (each receiver kept its
    /// light samples) and direct light move back to the caller's receivers; statistics and the
    /// decision are kept.
    ///
    /// # Errors
    /// [`TechniqueError::InvalidInput`] for an estimate that is not of this order's size.
    pub fn restore(&self, caller: &ViewSamples, est: Estimate) -> Result<Estimate, TechniqueError> {
        use crate::visibility::{Coefficients, VisibilityBuffer, VisibilityImage};
        let v = &est.visibility;
        if v.len() != self.source.len() {
            return Err(TechniqueError::InvalidInput(
                "an estimate restored from a spatial order must be of its size".into(),
            ));
        }
        let mut out = if v.is_rgb() {
            VisibilityImage::rgb_buffer(caller)
        } else {
            VisibilityImage::scalar(caller)
        };
        let mut classes = v
            .class(0)
            .map(|_| vec![crate::visibility::PixelClass::Skipped; caller.len()]);
        let mut direct = est.direct.as_ref().map(|_| vec![Vec3::ZERO; caller.len()]);
        let mut per_sample = v.per_sample().map(|p| match p {
            PerSampleVisibility::Bits { samples, .. } => {
                PerSampleVisibility::bits(caller.len(), *samples)
            }
            PerSampleVisibility::Counters { samples, .. } => PerSampleVisibility::Counters {
                samples: *samples,
                counts: vec![0; caller.len() * *samples as usize],
            },
        });
        for (k, s) in self.source.iter().enumerate() {
            let Some(i) = *s else { continue };
            match out.coefficients() {
                Coefficients::Scalar(_) => out.scalars_mut()[i] = v.value(k),
                Coefficients::Rgb(_) => out.rgbs_mut()[i] = v.rgb(k),
            }
            if let (Some(c), Some(class)) = (classes.as_mut(), v.class(k)) {
                c[i] = class;
            }
            if let (Some(d), Some(from)) = (direct.as_mut(), est.direct.as_ref()) {
                d[i] = from[k];
            }
            if let (Some(to), Some(from)) = (per_sample.as_mut(), v.per_sample()) {
                move_samples(from, k, to, i);
            }
        }
        if let Some(c) = classes {
            out.set_classes(c)?;
        }
        if let Some(p) = per_sample {
            out.set_per_sample(p)?;
        }
        Ok(Estimate {
            visibility: out,
            direct,
            stats: est.stats,
            decision: est.decision,
        })
    }
}

/// Copies pixel `k`'s per-sample values of `from` to pixel `i` of `to` (same kind and count).
fn move_samples(from: &PerSampleVisibility, k: usize, to: &mut PerSampleVisibility, i: usize) {
    match (from, to) {
        (
            PerSampleVisibility::Bits { samples, words },
            PerSampleVisibility::Bits { words: out, .. },
        ) => {
            let wpp = samples.div_ceil(64) as usize;
            out[i * wpp..(i + 1) * wpp].copy_from_slice(&words[k * wpp..(k + 1) * wpp]);
        }
        (
            PerSampleVisibility::Counters { samples, counts },
            PerSampleVisibility::Counters { counts: out, .. },
        ) => {
            let n = *samples as usize;
            out[i * n..(i + 1) * n].copy_from_slice(&counts[k * n..(k + 1) * n]);
        }
        _ => {}
    }
}

/// Runs `pass` on `view`'s receivers laid out in a spatial order when they have no camera (a
/// caller's points: a technique's tiles and beams then hold receivers close in space), and
/// gives the estimate back in the caller's order; on a camera's image, runs `pass` on it as it
/// is. Each receiver keeps its light samples, so the answer is the same either way.
///
/// # Errors
/// As `pass`.
pub fn in_spatial_order(
    view: &ViewSamples,
    pass: impl FnOnce(&ViewSamples) -> Result<Estimate, TechniqueError>,
) -> Result<Estimate, TechniqueError> {
    if view.raster_view().is_some() || view.valid_count() == 0 {
        return pass(view);
    }
    let order = view.spatially_ordered();
    let est = pass(&order.view)?;
    order.restore(view, est)
}

/// The cell of a `side x side` grid (`side` a power of two) at distance `k` along its Hilbert
/// curve: consecutive distances are neighbouring cells, and every run of `4^j` aligned
/// distances fills a square.
fn hilbert_decode(side: u64, k: u64) -> (u32, u32) {
    let (mut x, mut y, mut t) = (0u64, 0u64, k);
    let mut s = 1u64;
    while s < side {
        let rx = 1 & (t / 2);
        let ry = 1 & (t ^ rx);
        if ry == 0 {
            if rx == 1 {
                x = s - 1 - x;
                y = s - 1 - y;
            }
            std::mem::swap(&mut x, &mut y);
        }
        x += s * rx;
        y += s * ry;
        t /= 4;
        s *= 2;
    }
    (x as u32, y as u32)
}

/// The 3D Morton code of three 21-bit coordinates.
fn morton3(x: u32, y: u32, z: u32) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut v = u64::from(v) & 0x1f_ffff;
        v = (v | v << 32) & 0x1f_0000_0000_ffff;
        v = (v | v << 16) & 0x1f_0000_ff00_00ff;
        v = (v | v << 8) & 0x100f_00f0_0f00_f00f;
        v = (v | v << 4) & 0x10c3_0c30_c30c_30c3;
        (v | v << 2) & 0x1249_2492_4924_9249
    }
    spread(x) | spread(y) << 1 | spread(z) << 2
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::receivers::Snapping;
    use crate::scene::{MeshDesc, SceneBuilder};
    use crate::technique::Stats;
    use crate::visibility::{VisibilityBuffer, VisibilityImage};

    /// A pass whose every answer depends on the receiver alone: V from its pixel and position,
    /// per-sample bits from its pixel, direct light its position.
    fn per_receiver_pass(v: &ViewSamples) -> Result<Estimate, TechniqueError> {
        let mut vis = VisibilityImage::scalar(v);
        let mut bits = PerSampleVisibility::bits(v.len(), 70);
        let mut direct = vec![Vec3::ZERO; v.len()];
        for i in 0..v.len() {
            let Some(s) = v.get(i) else { continue };
            vis.scalars_mut()[i] = ((s.pixel.x * 7 + s.pixel.y) % 11) as f32 / 10.0;
            if let PerSampleVisibility::Bits { words, .. } = &mut bits {
                words[i * 2] = u64::from(s.pixel.x) * 0x9E37;
                words[i * 2 + 1] = u64::from(s.pixel.y) + 1;
            }
            direct[i] = s.position;
        }
        vis.set_per_sample(bits)?;
        let mut est = Estimate::new(vis, Stats::default());
        est.direct = Some(direct);
        Ok(est)
    }

    #[test]
    fn a_pass_in_spatial_order_answers_every_receiver_as_in_the_callers_order() {
        let floor = MeshDesc::new(
            vec![
                Vec3::new(-1.0, 0.0, -1.0),
                Vec3::new(1.0, 0.0, -1.0),
                Vec3::new(1.0, 0.0, 1.0),
                Vec3::new(-1.0, 0.0, 1.0),
            ],
            vec![[0, 2, 1], [0, 3, 2]],
        );
        let mut b = SceneBuilder::new();
        b.push_mesh(floor).unwrap();
        let scene = b.build().unwrap();
        // 37 points on the floor in a scrambled order.
        let positions: Vec<Vec3> = (0..37u32)
            .map(|k| {
                let j = (k * 17) % 37;
                Vec3::new(j as f32 / 20.0 - 0.9, 0.0, (j % 6) as f32 / 4.0 - 0.6)
            })
            .collect();
        let normals = vec![Vec3::Y; positions.len()];
        let view =
            ViewSamples::from_points(&scene, &positions, &normals, Snapping::for_scene(&scene))
                .unwrap();
        let order = view.spatially_ordered();
        assert!(order.view.len() >= view.len() && order.view.width() > 1);
        let direct = per_receiver_pass(&view).unwrap();
        let ordered = in_spatial_order(&view, per_receiver_pass).unwrap();
        assert_eq!(
            ordered.visibility.coefficients(),
            direct.visibility.coefficients()
        );
        assert_eq!(
            ordered.visibility.per_sample(),
            direct.visibility.per_sample()
        );
        assert_eq!(ordered.direct, direct.direct);
        assert_eq!(ordered.visibility.len(), view.len());
    }

    #[test]
    fn morton_codes_interleave_their_coordinates() {
        assert_eq!(morton3(1, 0, 0), 1);
        assert_eq!(morton3(0, 1, 0), 2);
        assert_eq!(morton3(0, 0, 1), 4);
        assert_eq!(morton3(3, 0, 0), 0b1001);
        assert_eq!(morton3(0x1f_ffff, 0x1f_ffff, 0x1f_ffff), (1 << 63) - 1);
    }

    #[test]
    fn the_hilbert_curve_visits_every_cell_once_through_neighbours() {
        let side = 32u64;
        let mut seen = vec![false; (side * side) as usize];
        let mut last = None;
        for k in 0..side * side {
            let (x, y) = hilbert_decode(side, k);
            assert!(u64::from(x) < side && u64::from(y) < side);
            let cell = (u64::from(y) * side + u64::from(x)) as usize;
            assert!(!seen[cell], "cell ({x}, {y}) visited twice");
            seen[cell] = true;
            if let Some((px, py)) = last {
                let step =
                    i64::from(x).abs_diff(i64::from(px)) + i64::from(y).abs_diff(i64::from(py));
                assert_eq!(
                    step, 1,
                    "distance {k} jumps from ({px}, {py}) to ({x}, {y})"
                );
            }
            last = Some((x, y));
        }
    }
}
