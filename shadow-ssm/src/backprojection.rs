//! Back-projection of shadow-map samples onto the light (GBP06, as BCS06 section 2 summarises
//! it, eq. 1): each occluding texel is a small quadrilateral parallel to the light at its depth;
//! seen from the receiver it covers a rectangle of the light's plane, clipped to the light, and
//! the occluded fraction is the sum of the clipped areas over the light's area.
//!
//! * Kernel: GBP07's converged kernel from the min/max pyramid; a receiver with nothing in
//!   front of it there is lit without back-projection; one whose kernel (with a texel's
//!   border) lies wholly in front is umbra (GBP06: the gap-filled samples then cover the
//!   light). Every other receiver is integrated and classified from the result.
//! * Gap filling (GBP06): each occluding sample's rectangle is extended to meet the rectangles
//!   of its right and upper occluding neighbours, closing the gaps between adjacent samples
//!   seen from the receiver (and adding overlap: the over-estimation GBP07 section 4 removes).
//! * At most `max_nspp` samples per receiver: beyond, the kernel is read with a uniform stride
//!   and each sample's size is scaled by the stride (BCS06 section 5).
//! * Depth peeling (BCS06 section 4): the layers of a multi-layer map with the midpoint test
//!   for self-shadowing. The paper keeps one layer per texel (the deepest that covers part of
//!   the light) and sums the rectangles (eq. 1); the deeper layers' rectangles, magnified more,
//!   overlap, and a sum counts each overlap twice: three layers came out darker and less
//!   accurate than one on 7 of 10 scenes (`docs/history/ssm-peeling-2026-12-07.md`). With
//!   [`Backprojection::union`] every occluding layer adds its rectangle and the occluded part
//!   of the light is their union ([`crate::rect_union`]), so a deeper layer only adds occlusion
//!   where the layers in front of it leave light (overlaps are the problem the paper leaves
//!   open, section 3).

use glam::DVec2;

use crate::light_domain::{Covered, LightDomain};
use crate::rect_union::{UnionScratch, disjoint_strips};
use crate::shadow_map::ShadowMap;

/// Settings of one back-projection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Backprojection {
    /// Largest number of samples read per receiver.
    pub max_nspp: u32,
    /// Extend samples to their occluding neighbours (GBP06).
    pub gap_filling: bool,
    /// Depth peeling (BCS06 section 4): the map's layers are read deepest first, a layer
    /// occludes when its midpoint with the next layer (capped at this many world units beyond
    /// it, Fig. 5b) is in front of the receiver, and the first layer whose back-projection
    /// covers part of the light is used; a layer must also pass the caller's depth test
    /// (against the receiver's tangent plane), since a sample in that plane cannot hide light
    /// above the horizon. `None` reads layer 0 with the caller's depth test alone.
    pub peeling_max_bias: Option<f32>,
    /// Take the union of the samples' rectangles over the light ([`crate::rect_union`]) instead
    /// of their sum (BCS06 eq. 1, which counts an overlap twice). With peeling, every layer that
    /// passes the tests adds its rectangle, so a deeper layer only adds occlusion where the
    /// layers in front of it leave light. Gap filling then extends each texel's deepest
    /// rectangle toward its neighbours'.
    pub union: bool,
}

impl Backprojection {
    /// The occluded fraction of the light seen from a receiver at texel coordinates `(x, y)`,
    /// depth `z`, through a kernel of `width` texels; `occludes(depth, ix, iy)` is the biased
    /// depth test of a texel. Returns the occluded part of the light (area and, for a textured
    /// light, radiance; overlaps may exceed the light) and the samples read.
    #[expect(
        clippy::too_many_arguments,
        reason = "one occlusion test reads the map sample, the receiver and its kernel together"
    )]
    pub fn occluded(
        &self,
        sm: &ShadowMap,
        light: &LightDomain,
        x: f64,
        y: f64,
        z: f32,
        width: f64,
        occludes: &impl Fn(f32, i64, i64) -> bool,
    ) -> (Covered, u64) {
        let (l, _, _, t, _, _) = sm.view.extents();
        let (l, t, tpu, z) = (l as f64, t as f64, sm.texels_per_unit, z as f64);
        // The receiver in view space (unit-depth coordinates times depth).
        let p = DVec2::new(l + x / tpu, t - y / tpu) * z;
        let count = (width.ceil().max(1.0) as u64).pow(2);
        let step = ((count as f64 / self.max_nspp.max(1) as f64).sqrt().ceil() as i64).max(1);
        let half = width * 0.5;
        let (x0, y0) = ((x - half).floor() as i64, (y - half).floor() as i64);
        let (x1, y1) = ((x + half).floor() as i64, (y + half).floor() as i64);
        // The light-plane rectangle a texel back-projects to, if it occludes.
        let project = |ix: i64, iy: i64, zs: f32| -> Option<(DVec2, DVec2)> {
            let zs = zs as f64;
            let scale = z / (z - zs);
            if !(scale > 0.0) || !scale.is_finite() {
                return None;
            }
            let q = DVec2::new(l + (ix as f64 + 0.5) / tpu, t - (iy as f64 + 0.5) / tpu) * zs;
            let c = p + (q - p) * scale;
            // Texel size at depth zs (times the stride), back-projected.
            let h = 0.5 * step as f64 * zs / tpu * scale;
            Some((c - DVec2::splat(h), c + DVec2::splat(h)))
        };
        // The light-plane rectangles of texel (ix, iy) into `out`: its layer's when `first`
        // (BCS06: the deepest whose back-projection covers part of the light); else, with
        // `union` and peeling, every occluding layer's, since a union counts what they share
        // once.
        let rects = |ix: i64, iy: i64, first: bool, out: &mut Vec<(DVec2, DVec2)>| {
            match self.peeling_max_bias {
                None => {
                    let zs = sm.at(ix, iy);
                    if occludes(zs, ix, iy)
                        && let Some(r) = project(ix, iy, zs)
                    {
                        out.push(r);
                    }
                }
                Some(cap) => {
                    let zf = z as f32;
                    for k in (0..sm.layers).rev() {
                        let d = sm.layer_at(ix, iy, k);
                        if !d.is_finite() {
                            continue;
                        }
                        let next = sm.layer_at(ix, iy, k + 1);
                        let mid = if next.is_finite() {
                            (0.5 * (d + next)).min(d + cap)
                        } else {
                            d + cap
                        };
                        // The midpoint decides self-shadowing; a layer on or behind the receiver's
                        // tangent plane (the caller's test) cannot hide light above its horizon.
                        if !(mid < zf) || !occludes(d, ix, iy) {
                            continue;
                        }
                        if let Some((lo, hi)) = project(ix, iy, d)
                            && light.clipped_area(lo, hi) > 0.0
                        {
                            out.push((lo, hi));
                            if first || !self.union {
                                return;
                            }
                        }
                    }
                }
            }
        };
        let mut neighbour = Vec::with_capacity(1);
        let mut first = |ix: i64, iy: i64| -> Option<(DVec2, DVec2)> {
            neighbour.clear();
            rects(ix, iy, true, &mut neighbour);
            neighbour.first().copied()
        };
        let mut sum = Covered::default();
        let mut read = 0u64;
        let mut found: Vec<(DVec2, DVec2)> = Vec::new();
        let mut iy = y0;
        while iy <= y1 {
            let mut ix = x0;
            while ix <= x1 {
                read += 1;
                let start = found.len();
                rects(ix, iy, false, &mut found);
                if self.gap_filling && found.len() > start {
                    // Screen x grows with view x; screen y grows against view y.
                    let hi = &mut found[start].1;
                    if let Some((nlo, _)) = first(ix + step, iy) {
                        hi.x = hi.x.max(nlo.x);
                    }
                    if let Some((nlo, _)) = first(ix, iy - step) {
                        hi.y = hi.y.max(nlo.y);
                    }
                }
                if !self.union {
                    for (lo, hi) in found.drain(..) {
                        sum += light.rect(lo, hi);
                    }
                }
                ix += step;
            }
            iy += step;
        }
        if self.union {
            disjoint_strips(&found, &mut UnionScratch::default(), |x0, x1, ys| {
                sum += light.strip(x0, x1, ys);
            });
        }
        (sum, read)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    /// BCS06 eq. 1 by hand: an 8 x 8 map over unit-depth [-1, 1]^2 (4 texels per unit), one
    /// occluding texel at depth 1 straight between a receiver at depth 2 and a unit square
    /// light: its quad, 1/4 wide at depth 1, back-projects with scale z / (z - z_s) = 2 to a
    /// 1/2 x 1/2 square centred on the light, a quarter of it.
    #[test]
    fn one_sample_back_projects_as_eq1_says() {
        let mut depth = vec![f32::INFINITY; 64];
        depth[4 * 8 + 4] = 1.0;
        let sm = ShadowMap::unit_square(8, depth);
        let light = LightDomain::new(&[
            Vec2::new(-0.5, -0.5),
            Vec2::new(0.5, -0.5),
            Vec2::new(0.5, 0.5),
            Vec2::new(-0.5, 0.5),
        ]);
        let occludes = |d: f32, _: i64, _: i64| d < 2.0;
        for gap_filling in [false, true] {
            let bp = Backprojection {
                max_nspp: 64,
                gap_filling,
                peeling_max_bias: None,
                union: false,
            };
            let (c, read) = bp.occluded(&sm, &light, 4.5, 4.5, 2.0, 8.0, &occludes);
            let f = c.area / light.area();
            assert!((f - 0.25).abs() < 1e-12, "{f}");
            assert!(read >= 64);
        }
        // With a stride of 2 the sample stands for 2 x 2 texels: a full-width square.
        let bp = Backprojection {
            max_nspp: 16,
            gap_filling: false,
            peeling_max_bias: None,
            union: false,
        };
        let f = bp
            .occluded(&sm, &light, 4.5, 4.5, 2.0, 8.0, &occludes)
            .0
            .area
            / light.area();
        assert!((f - 1.0).abs() < 1e-12, "{f}");
    }
}
