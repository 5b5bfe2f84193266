//! Screen-space multi-resolution (GBP07 section 5.2): where the penumbra is wide on screen,
//! only some pixels are computed and the others are reconstructed by pull-push.
//!
//! * **Selection** (eqs. 4 to 6): the penumbra's object-space size
//!   `s_obj = w_l (z_p - z_occ) / z_occ` (eq. 4), its screen size
//!   `s_scr = η s_obj / z_pe |n . v|` (eq. 5, `η` the camera's pixels per unit at unit depth,
//!   `z_pe` the camera depth), and a pixel is computed when `s_scr < s_min sqrt(P[i % h, j % h])`
//!   (eq. 6). The pattern `P` is an ordered-dither (Bayer) ranking with `P = h^2 / (rank + 1)`,
//!   so a penumbra `s_min` pixels wide is computed everywhere and one `k s_min` wide on about
//!   `1 / k^2` of its pixels; the first entry is infinite so every `h x h` tile keeps one
//!   computed pixel (the largest pixel spacing is `h`).
//! * **Discontinuities**: a thresholded Sobel filter on the camera's depth (relative to the
//!   depth) and normals, plus the border of the background, marks pixels where pull-push must
//!   not interpolate; the marks are widened by twice the largest pixel spacing and marked pixels
//!   are always computed.
//! * **Pull-push** (Gortler et al. 1996): weights 1 for computed pixels and 0 for gaps; the pull
//!   phase halves the resolution summing weights (clamped to 1) and averaging values; the push
//!   phase fills each level's gaps by blending with the bilinearly upsampled coarser level.

/// Relative depth change (Sobel magnitude over 8 times the depth) above which a pixel is on a
/// depth discontinuity.
pub const DEPTH_THRESHOLD: f32 = 0.05;
/// Normal change (Sobel magnitude over 8) above which a pixel is on a normal discontinuity.
pub const NORMAL_THRESHOLD: f32 = 0.25;

/// Screen-space selection settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScreenSpace {
    /// `s_min` of eq. 6: the screen penumbra size (pixels) from which pixels are skipped.
    pub s_min: f32,
    /// Pattern side `h` (a power of two, 2 to 16).
    pub pattern: u32,
}

/// The `h x h` pattern of eq. 6 (row-major): `h^2 / (rank + 1)` with ranks from the recursive
/// Bayer matrix, the rank-0 entry infinite.
pub fn pattern(h: u32) -> Vec<f32> {
    let h = h.clamp(2, 16).next_power_of_two();
    let mut bayer = vec![0u32];
    let mut side = 1;
    while side < h {
        let mut next = vec![0u32; (4 * side * side) as usize];
        for y in 0..side {
            for x in 0..side {
                let b = 4 * bayer[(y * side + x) as usize];
                let n = 2 * side;
                next[(y * n + x) as usize] = b;
                next[(y * n + x + side) as usize] = b + 2;
                next[((y + side) * n + x) as usize] = b + 3;
                next[((y + side) * n + x + side) as usize] = b + 1;
            }
        }
        bayer = next;
        side *= 2;
    }
    bayer
        .iter()
        .map(|&r| {
            if r == 0 {
                f32::INFINITY
            } else {
                (h * h) as f32 / (r + 1) as f32
            }
        })
        .collect()
}

impl ScreenSpace {
    /// Eq. 6: is pixel `(i, j)` with screen penumbra size `s_scr` computed?
    pub fn selected(&self, pattern: &[f32], i: u32, j: u32, s_scr: f32) -> bool {
        let h = self.pattern.clamp(2, 16).next_power_of_two();
        let p = pattern[((j % h) * h + i % h) as usize];
        !(s_scr >= self.s_min * p.sqrt())
    }
}

/// Eqs. 4 and 5: the screen-space penumbra size (pixels) of a receiver at light depth `z_p`
/// with smoothed occluder depth `z_occ`, camera depth `z_pe`, `n . v` the cosine between its
/// normal and the view direction, `eta` the camera's pixels per unit at unit depth.
pub fn penumbra_pixels(
    light_width: f32,
    z_p: f32,
    z_occ: f32,
    z_pe: f32,
    n_dot_v: f32,
    eta: f32,
) -> f32 {
    if !(z_occ > 0.0) || !(z_occ < z_p) || !(z_pe > 0.0) {
        return 0.0;
    }
    let s_obj = light_width * (z_p - z_occ) / z_occ;
    eta * s_obj / z_pe * n_dot_v.abs()
}

/// The discontinuity buffer: Sobel on depth (relative) and normals, the background's border,
/// widened by `radius` pixels (square dilation).
pub fn discontinuities(
    width: usize,
    height: usize,
    valid: &[bool],
    depth: &[f32],
    normals: &[glam::Vec3],
    radius: usize,
) -> Vec<bool> {
    let at = |x: i64, y: i64| -> usize {
        (y.clamp(0, height as i64 - 1) as usize) * width + x.clamp(0, width as i64 - 1) as usize
    };
    const KX: [[f32; 3]; 3] = [[-1.0, 0.0, 1.0], [-2.0, 0.0, 2.0], [-1.0, 0.0, 1.0]];
    let mut edge = vec![false; width * height];
    for y in 0..height as i64 {
        for x in 0..width as i64 {
            let c = at(x, y);
            if !valid[c] {
                continue;
            }
            let (mut gx, mut gy) = (0.0f32, 0.0f32);
            let (mut nx, mut ny) = (glam::Vec3::ZERO, glam::Vec3::ZERO);
            let mut border = false;
            for dy in -1..=1i64 {
                for dx in -1..=1i64 {
                    let k = at(x + dx, y + dy);
                    if !valid[k] {
                        border = true;
                        continue;
                    }
                    let (wx, wy) = (
                        KX[(dy + 1) as usize][(dx + 1) as usize],
                        KX[(dx + 1) as usize][(dy + 1) as usize],
                    );
                    gx += wx * depth[k];
                    gy += wy * depth[k];
                    nx += normals[k] * wx;
                    ny += normals[k] * wy;
                }
            }
            let dz = (gx * gx + gy * gy).sqrt() / (8.0 * depth[c].max(f32::MIN_POSITIVE));
            let dn = (nx.length_squared() + ny.length_squared()).sqrt() / 8.0;
            edge[c] = border || !(dz <= DEPTH_THRESHOLD) || !(dn <= NORMAL_THRESHOLD);
        }
    }
    // Separable square dilation.
    let r = radius as i64;
    let mut rows = vec![false; width * height];
    for y in 0..height {
        for x in 0..width as i64 {
            let lo = (x - r).max(0);
            let hi = (x + r).min(width as i64 - 1);
            rows[y * width + x as usize] = (lo..=hi).any(|k| edge[y * width + k as usize]);
        }
    }
    let mut out = vec![false; width * height];
    for y in 0..height as i64 {
        let lo = (y - r).max(0);
        let hi = (y + r).min(height as i64 - 1);
        for x in 0..width {
            out[y as usize * width + x] = (lo..=hi).any(|k| rows[k as usize * width + x]);
        }
    }
    out
}

/// Pull-push reconstruction of `values` (`channels` floats per pixel) where `weights` is 1 for
/// computed pixels and 0 for gaps; computed pixels keep their values.
pub fn pull_push(
    width: usize,
    height: usize,
    channels: usize,
    values: &mut [f32],
    weights: &[f32],
) {
    struct Level {
        w: usize,
        h: usize,
        v: Vec<f32>,
        wt: Vec<f32>,
    }
    let mut levels = vec![Level {
        w: width,
        h: height,
        v: values.to_vec(),
        wt: weights.iter().map(|w| w.clamp(0.0, 1.0)).collect(),
    }];
    // Pull until one pixel or saturated.
    loop {
        let l = levels.last().expect("non-empty");
        if (l.w == 1 && l.h == 1) || l.wt.iter().all(|w| *w >= 1.0) {
            break;
        }
        let (w, h) = (l.w.div_ceil(2), l.h.div_ceil(2));
        let mut v = vec![0.0f32; w * h * channels];
        let mut wt = vec![0.0f32; w * h];
        for y in 0..l.h {
            for x in 0..l.w {
                let (i, j) = (y * l.w + x, (y / 2) * w + x / 2);
                let a = l.wt[i];
                if a > 0.0 {
                    wt[j] += a;
                    for c in 0..channels {
                        v[j * channels + c] += a * l.v[i * channels + c];
                    }
                }
            }
        }
        for j in 0..w * h {
            if wt[j] > 0.0 {
                for c in 0..channels {
                    v[j * channels + c] /= wt[j];
                }
            }
            wt[j] = wt[j].min(1.0);
        }
        levels.push(Level { w, h, v, wt });
    }
    // Push: each finer level blends its own values with the upsampled coarser one.
    for k in (0..levels.len() - 1).rev() {
        let (fine, coarse) = levels.split_at_mut(k + 1);
        let (f, c) = (&mut fine[k], &coarse[0]);
        for y in 0..f.h {
            for x in 0..f.w {
                let i = y * f.w + x;
                let a = f.wt[i];
                if a >= 1.0 {
                    continue;
                }
                // Bilinear from the coarse level: fine pixel centre in coarse coordinates.
                let cx = ((x as f32 + 0.5) * 0.5 - 0.5).clamp(0.0, (c.w - 1) as f32);
                let cy = ((y as f32 + 0.5) * 0.5 - 0.5).clamp(0.0, (c.h - 1) as f32);
                let (x0, y0) = (cx.floor() as usize, cy.floor() as usize);
                let (x1, y1) = ((x0 + 1).min(c.w - 1), (y0 + 1).min(c.h - 1));
                let (tx, ty) = (cx - x0 as f32, cy - y0 as f32);
                for ch in 0..channels {
                    let g = |xx: usize, yy: usize| c.v[(yy * c.w + xx) * channels + ch];
                    let up = (g(x0, y0) * (1.0 - tx) + g(x1, y0) * tx) * (1.0 - ty)
                        + (g(x0, y1) * (1.0 - tx) + g(x1, y1) * tx) * ty;
                    let v = &mut f.v[i * channels + ch];
                    *v = a * *v + (1.0 - a) * up;
                }
                f.wt[i] = 1.0;
            }
        }
    }
    values.copy_from_slice(&levels[0].v);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pattern_ranks_every_entry_once_and_keeps_one_per_tile() {
        for h in [2u32, 4, 8] {
            let p = pattern(h);
            assert_eq!(p.len(), (h * h) as usize);
            assert_eq!(p.iter().filter(|v| v.is_infinite()).count(), 1);
            let mut finite: Vec<f32> = p.iter().copied().filter(|v| v.is_finite()).collect();
            finite.sort_by(f32::total_cmp);
            for (k, v) in finite.iter().enumerate() {
                // Ranks 1..h^2-1: values h^2 / (rank + 1), each once.
                let rank = (h * h) as usize - 1 - k;
                assert!((v - (h * h) as f32 / (rank + 1) as f32).abs() < 1e-6);
            }
        }
        // Eq. 6: below s_min everything is computed; at 2 s_min about a quarter; far above,
        // one pixel per tile.
        let s = ScreenSpace {
            s_min: 16.0,
            pattern: 4,
        };
        let p = pattern(4);
        let count = |s_scr: f32| {
            (0..4)
                .flat_map(|j| (0..4).map(move |i| (i, j)))
                .filter(|&(i, j)| s.selected(&p, i, j, s_scr))
                .count()
        };
        assert_eq!(count(15.0), 16);
        assert_eq!(count(32.0), 3);
        assert_eq!(count(1000.0), 1);
    }

    /// Pull-push reproduces a smooth field from a dithered subset.
    #[test]
    fn pull_push_reproduces_a_smooth_field() {
        let (w, h) = (64usize, 48usize);
        let f =
            |x: usize, y: usize| 0.5 + 0.4 * ((x as f32) * 0.08).sin() * ((y as f32) * 0.05).cos();
        let p = pattern(4);
        let mut values = vec![0.0f32; w * h];
        let mut weights = vec![0.0f32; w * h];
        for y in 0..h {
            for x in 0..w {
                // One pixel in four kept (eq. 6 at twice s_min).
                if p[(y % 4) * 4 + x % 4] > 4.0 {
                    values[y * w + x] = f(x, y);
                    weights[y * w + x] = 1.0;
                }
            }
        }
        let kept = weights.iter().filter(|w| **w > 0.0).count();
        assert!(kept * 4 <= w * h && kept * 6 >= w * h, "{kept}");
        pull_push(w, h, 1, &mut values, &weights);
        let mut worst = 0.0f32;
        for y in 0..h {
            for x in 0..w {
                worst = worst.max((values[y * w + x] - f(x, y)).abs());
            }
        }
        assert!(worst < 0.05, "{worst}");
    }

    /// With the discontinuity buffer forcing full sampling near a depth step, pull-push does
    /// not blur the shadow across it.
    #[test]
    fn pull_push_does_not_blur_across_a_depth_discontinuity() {
        let (w, h) = (64usize, 32usize);
        // Left half near (depth 1, lit), right half far (depth 3, shadowed).
        let depth: Vec<f32> = (0..w * h)
            .map(|i| if i % w < 32 { 1.0 } else { 3.0 })
            .collect();
        let normals = vec![glam::Vec3::Z; w * h];
        let valid = vec![true; w * h];
        let truth = |x: usize| if x < 32 { 1.0f32 } else { 0.0 };
        let spacing = 4;
        let disc = discontinuities(w, h, &valid, &depth, &normals, 2 * spacing);
        assert!(disc[10 * w + 31] && disc[10 * w + 32] && !disc[10 * w + 5]);
        let p = pattern(4);
        // Sparse everywhere (the widest penumbra), full where `dense` says; the worst error
        // after pull-push.
        let reconstruct = |dense: &dyn Fn(usize) -> bool| -> f32 {
            let mut values = vec![0.0f32; w * h];
            let mut weights = vec![0.0f32; w * h];
            for i in 0..w * h {
                let (x, y) = (i % w, i / w);
                if dense(i) || p[(y % 4) * 4 + x % 4].is_infinite() {
                    values[i] = truth(x);
                    weights[i] = 1.0;
                }
            }
            pull_push(w, h, 1, &mut values, &weights);
            (0..w * h)
                .map(|i| (values[i] - truth(i % w)).abs())
                .fold(0.0f32, f32::max)
        };
        let worst = reconstruct(&|i| disc[i]);
        assert!(worst < 1e-6, "{worst}");
        // Without the discontinuity buffer the step is blurred.
        let worst = reconstruct(&|_| false);
        assert!(worst > 0.2, "{worst}");
    }
}
