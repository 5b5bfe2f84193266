//! The discrete covered-samples representation of DCS section 7.3 (Fig. 8), for planar lights
//! and samplers with a finite number of sample sets (correlated: one; interleaved: `k x k`).
//!
//! For each sample set, in the light plane around the centre `c`:
//! * a **sector table** over `ANGLE_BINS` directions: bit `i` of entry `k` is set when sample
//!   `i` lies at a direction (counter-clockwise from the light's first axis) below the start of
//!   bin `k + 1` (the paper's cube map of "samples from the origin to `v`"). Like the cube
//!   map's texels, the bins are uniform in a pseudo-angle rather than in the angle: the
//!   "diamond angle" `1 - x / (|x| + |y|)` (`3 + x / (|x| + |y|)` below the axis), monotone
//!   in the angle, each bin at most `4 / pi` (1.27) times as wide as a uniform one, and free of
//!   the two `atan2` per edge that uniform bins cost;
//! * a **line table** over a `LINE_GRID x LINE_GRID` grid of the light's square: for the cell
//!   holding the foot `q` of the perpendicular from `c` to a line, the samples beyond the line
//!   (`s . q / |q| > |q|`), evaluated at the cell centre (the paper's 2D texture).
//!
//! The samples an edge covers are then `v1 & !v0 & line`, with `v0`, `v1` the sector entries of
//! the projected end points in counter-clockwise order (a union where the sector wraps past
//! angle 0). Samples whose angle or line cell is shared with the edge are classified at the
//! bin's resolution, which is the representation's error; the exact mode
//! (`coverage::EdgeTest`) has none. Three lookups and two bit operations replace a loop
//! over the samples.

use glam::{DVec2, DVec3, UVec2};
use shadow_core::light::{AreaLight, LightGeometry};
use shadow_core::sampling::{LightSampler, SamplingStrategy};
use shadow_core::technique::{TechniqueError, UnsupportedReason};

use crate::stages::coverage::{EdgeTest, RelativeSamples};
use crate::stages::edges::SceneEdge;
use crate::stages::light_shape::LightShape;

/// Angular resolution of the sector table.
pub const ANGLE_BINS: usize = 4096;
/// Side of the line table's grid.
pub const LINE_GRID: usize = 256;

/// How the samples an edge covers are found (section 7.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CoveredSamples {
    /// A segment-triangle test per sample: exact.
    Exact,
    /// The sector and line tables of Fig. 8: a few lookups per edge, discretisation error at
    /// the bins' resolution.
    Discrete,
    /// The same tables, holding for each line cell the samples surely beyond and surely before
    /// every line whose foot lies in the cell: the tables classify every sample they can decide,
    /// and only the samples in the end points' angle bins or in an undecided line cell take the
    /// exact test. Exact like [`CoveredSamples::Exact`].
    ///
    /// In a pixel with at least 6 wedge pairs the sector part comes from the pixel's angular
    /// index (the sector table of its own samples, `crate::accel::angular`): a pair whose sector holds
    /// at most 12 candidates tests them exactly, one with more looks its line up in the line
    /// table, which settles the candidates in the sector's inner buckets surely beyond the line
    /// and drops those surely before it. On `bunny` at 512x512 this runs in 0.23 s against
    /// 0.36 s when every pair looked both tables up (`docs/benchmarks.md`).
    Refined,
}

/// One sample set's tables.
#[derive(Debug, Clone)]
struct SetTables {
    sector: Vec<u64>,
    /// Per cell: samples beyond the line through the cell centre ([`CoveredSamples::Discrete`]),
    /// or samples beyond every line with its foot in the cell ([`CoveredSamples::Refined`]).
    line: Vec<u64>,
    /// Per cell, refined tables only: samples not surely before every such line.
    maybe: Vec<u64>,
}

/// Side of the line-table grid of the refined tables (undecided cells cost exact tests, not
/// errors, so a coarser grid suffices and builds faster).
pub const REFINED_LINE_GRID: usize = 128;

/// The tables of every sample set of a sampler, for one planar light.
#[derive(Debug, Clone)]
pub struct DiscreteTables {
    words: usize,
    tile: u32,
    center: DVec3,
    normal: DVec3,
    t1: DVec3,
    t2: DVec3,
    half: f64,
    grid: usize,
    refined: bool,
    sets: Vec<SetTables>,
}

impl DiscreteTables {
    /// Builds the tables of every sample set of `sampler` on `light`.
    ///
    /// # Errors
    /// [`TechniqueError::Unsupported`] for per-pixel sample sets (stratified, decorrelated) and
    /// for non-planar lights.
    pub(crate) fn build(
        sampler: &LightSampler,
        light: &dyn AreaLight,
        shape: &LightShape,
        refined: bool,
        technique: &str,
    ) -> Result<Self, TechniqueError> {
        let unsupported = |reason: &str| {
            TechniqueError::unsupported(technique, UnsupportedReason::Configuration(reason.into()))
        };
        let tile = match sampler.strategy() {
            SamplingStrategy::Correlated => 1,
            SamplingStrategy::Interleaved { tile } => tile,
            _ => {
                return Err(unsupported(
                    "discrete covered-sample tables need a finite number of sample sets \
                     (correlated or interleaved sampling)",
                ));
            }
        };
        let (normal, t1) = match light.geometry() {
            LightGeometry::Rectangle { normal, half_u, .. } => (normal, half_u.normalize()),
            LightGeometry::Disk { normal, .. } | LightGeometry::Polygon { normal, .. } => {
                (normal, shadow_core::geometry::orthonormal_basis(normal).0)
            }
            _ => {
                return Err(unsupported(
                    "discrete covered-sample tables are defined on a planar light",
                ));
            }
        };
        let (normal, t1) = (normal.as_dvec3(), t1.as_dvec3());
        let t2 = normal.cross(t1);
        let center = shape.center.as_dvec3();
        let half = shape.radius as f64 * 1.0001;
        let n = sampler.count() as usize;
        let words = n.div_ceil(64);
        let grid = if refined {
            REFINED_LINE_GRID
        } else {
            LINE_GRID
        };
        let mut units = Vec::new();
        let sets = (0..tile * tile)
            .map(|k| {
                sampler.unit_samples(UVec2::new(k % tile, k / tile), &mut units);
                let pts: Vec<DVec2> = units
                    .iter()
                    .map(|u| {
                        let d = light.sample(*u).position.as_dvec3() - center;
                        DVec2::new(d.dot(t1), d.dot(t2))
                    })
                    .collect();
                let mut sector = vec![0u64; ANGLE_BINS * words];
                for (i, s) in pts.iter().enumerate() {
                    let b = angle_bin(*s);
                    // Below the start of bin k + 1 for every k >= b.
                    for k in b..ANGLE_BINS {
                        sector[k * words + i / 64] |= 1 << (i % 64);
                    }
                }
                let mut line = vec![0u64; grid * grid * words];
                let mut maybe = vec![0u64; if refined { grid * grid * words } else { 0 }];
                let cellw = 2.0 * half / grid as f64;
                for gy in 0..grid {
                    for gx in 0..grid {
                        let lo = DVec2::new(-half + gx as f64 * cellw, -half + gy as f64 * cellw);
                        let hi = lo + DVec2::splat(cellw);
                        let cell = (gy * grid + gx) * words;
                        if !refined {
                            let q = (lo + hi) * 0.5;
                            let r = q.length();
                            for (i, s) in pts.iter().enumerate() {
                                if r == 0.0 || s.dot(q) / r > r {
                                    line[cell + i / 64] |= 1 << (i % 64);
                                }
                            }
                            continue;
                        }
                        // s is beyond the line with foot q when s.q - |q|^2 > 0: concave in q,
                        // so its minimum over the cell is at a corner; its maximum is at most
                        // the corners' largest s.q minus the cell's least |q|^2.
                        let corners = [lo, DVec2::new(hi.x, lo.y), hi, DVec2::new(lo.x, hi.y)];
                        let near = DVec2::ZERO.clamp(lo, hi);
                        let least = near.length_squared();
                        for (i, s) in pts.iter().enumerate() {
                            let f = corners.map(|q| s.dot(q) - q.length_squared());
                            let g = corners.map(|q| s.dot(q));
                            let fmin = f.iter().copied().fold(f64::INFINITY, f64::min);
                            let gmax = g.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                            // Margins of a relative 1e-9 keep rounding on the undecided side.
                            let eps = 1e-9 * half * half;
                            if fmin > eps {
                                line[cell + i / 64] |= 1 << (i % 64);
                            }
                            if gmax - least >= -eps {
                                maybe[cell + i / 64] |= 1 << (i % 64);
                            }
                        }
                    }
                }
                SetTables {
                    sector,
                    line,
                    maybe,
                }
            })
            .collect();
        Ok(Self {
            words,
            tile,
            center,
            normal,
            t1,
            t2,
            half,
            grid,
            refined,
            sets,
        })
    }

    /// The light-plane coordinates of the projections of the edge `a b` from `p` (all three
    /// relative to the light centre), with the foot of the perpendicular from the centre to
    /// their line; `None` where the tables cannot answer: an end point outside the slab
    /// between `p`'s parallel plane and the light plane, or a line through (or within rounding
    /// of) the centre.
    fn project_edge(&self, p: DVec3, a: DVec3, b: DVec3) -> Option<Projected> {
        let h = -p.dot(self.normal);
        let (ha, hb) = ((a - p).dot(self.normal), (b - p).dot(self.normal));
        // Both end points strictly between p's parallel plane and the light plane.
        let inside = |x: f64| (h > 0.0 && x > 0.0 && x < h) || (h < 0.0 && x < 0.0 && x > h);
        if !(inside(ha) && inside(hb)) {
            return None;
        }
        let project = |x: DVec3, hx: f64| {
            let y = p + (x - p) * (h / hx);
            DVec2::new(y.dot(self.t1), y.dot(self.t2))
        };
        let (a2, b2) = (project(a, ha), project(b, hb));
        let d = b2 - a2;
        let cross = a2.perp_dot(b2);
        let len = d.length();
        if !(len > 0.0) || (cross / len).abs() < 1e-9 * self.half {
            return None;
        }
        let foot = a2 - d * (a2.dot(d) / (len * len));
        Some(Projected {
            a: a2,
            b: b2,
            cross,
            foot,
        })
    }

    /// The first word of the line-table cell holding `foot`; `None` when the foot lies outside
    /// the light's square, whose line leaves every sample on the centre's side (the square
    /// holds the light's bounding circle around its centre).
    fn cell(&self, foot: DVec2) -> Option<usize> {
        let grid = self.grid;
        let g = |v: f64| (((v + self.half) / (2.0 * self.half)) * grid as f64).floor();
        let (gx, gy) = (g(foot.x), g(foot.y));
        (gx >= 0.0 && gy >= 0.0 && gx < grid as f64 && gy < grid as f64)
            .then(|| (gy as usize * grid + gx as usize) * self.words)
    }

    /// The sample set of a pixel.
    fn set(&self, pixel: UVec2) -> &SetTables {
        &self.sets[((pixel.y % self.tile) * self.tile + pixel.x % self.tile) as usize]
    }

    /// The refined tables' answer for the line of the edge `a b` seen from `p` (all three
    /// relative to the light centre), for pixel `pixel`'s sample set.
    pub(crate) fn refined_line(&self, pixel: UVec2, p: DVec3, a: DVec3, b: DVec3) -> LineMasks<'_> {
        debug_assert!(self.refined);
        let Some(pr) = self.project_edge(p, a, b) else {
            return LineMasks::Unknown;
        };
        let Some(cell) = self.cell(pr.foot) else {
            return LineMasks::NoneBeyond;
        };
        let set = self.set(pixel);
        let w = self.words;
        LineMasks::Cell {
            beyond: &set.line[cell..cell + w],
            maybe: &set.maybe[cell..cell + w],
        }
    }

    /// The covered samples of `edge` seen from `p` (pixel `pixel`'s set), restricted to
    /// `allowed`; falls back to the exact `test` where the tables cannot answer (the edge's
    /// projection passes through the centre, or the edge leaves the slab between `p` and the
    /// light plane).
    #[expect(
        clippy::too_many_arguments,
        reason = "the table lookup reads the pixel, its test, origin, edge, samples and two masks together in the per-pair hot path"
    )]
    pub(crate) fn mask(
        &self,
        pixel: UVec2,
        test: &EdgeTest,
        p: DVec3,
        edge: &SceneEdge,
        relative: &RelativeSamples,
        allowed: &[u64],
        mask: &mut [u64],
    ) -> bool {
        let c = self.center;
        let Some(Projected {
            a: a2,
            b: b2,
            cross,
            foot,
        }) = self.project_edge(p - c, edge.a - c, edge.b - c)
        else {
            return test.mask(relative, allowed, mask);
        };
        let set = self.set(pixel);
        let w = self.words;
        let cell = self.cell(foot);
        let Some(line) = cell.map(|cell| &set.line[cell..cell + w]) else {
            // The line misses the light's square: no sample lies beyond it.
            mask.fill(0);
            return false;
        };
        // Counter-clockwise order of the end points seen from the centre.
        let (first, second) = if cross > 0.0 { (a2, b2) } else { (b2, a2) };
        let (k0, k1) = (angle_bin(first), angle_bin(second));
        let s0 = &set.sector[k0 * w..k0 * w + w];
        let s1 = &set.sector[k1 * w..k1 * w + w];
        if self.refined {
            let maybe = cell.map(|cell| &set.maybe[cell..cell + w]).unwrap_or(line);
            let upto = |k: usize, j: usize| -> u64 {
                if k == 0 {
                    0
                } else {
                    set.sector[(k - 1) * w + j]
                }
            };
            // upto(k): samples in bins below k.
            // Up to 1024 samples on the stack; more on the heap.
            let (mut stack, mut heap) = ([0u64; 16], Vec::new());
            let uncertain: &mut [u64] = if w <= stack.len() {
                &mut stack[..w]
            } else {
                heap.resize(w, 0);
                &mut heap
            };
            let mut any_uncertain = 0u64;
            for j in 0..w {
                let inner = if k0 < k1 {
                    upto(k1, j) & !upto(k0 + 1, j)
                } else if k0 > k1 {
                    !upto(k0 + 1, j) | upto(k1, j)
                } else {
                    0
                };
                let border = (upto(k0 + 1, j) & !upto(k0, j)) | (upto(k1 + 1, j) & !upto(k1, j));
                let sure = inner & line[j];
                mask[j] = sure & allowed[j];
                uncertain[j] = (inner | border) & maybe[j] & !sure & allowed[j];
                any_uncertain |= uncertain[j];
            }
            if any_uncertain != 0 {
                test.add_covered(relative, uncertain, mask);
            }
            return mask.iter().any(|m| *m != 0);
        }
        let mut any = 0u64;
        for j in 0..w {
            let sector = if k0 <= k1 {
                s1[j] & !s0[j]
            } else {
                s1[j] | !s0[j]
            };
            mask[j] = sector & line[j] & allowed[j];
            any |= mask[j];
        }
        any != 0
    }
}

/// An edge projected from a view sample onto the light plane, in the tables' coordinates.
struct Projected {
    a: DVec2,
    b: DVec2,
    /// `a x b`: positive when `a` comes first counter-clockwise around the centre.
    cross: f64,
    /// The foot of the perpendicular from the centre to the line `a b`.
    foot: DVec2,
}

/// What the refined line table says about the samples beyond an edge's projected line.
pub(crate) enum LineMasks<'a> {
    /// The table cannot answer (see [`DiscreteTables::mask`]): every candidate takes the
    /// exact test.
    Unknown,
    /// The line leaves the light's square: no sample is beyond it.
    NoneBeyond,
    /// The cell of the line's foot: the samples surely beyond the line, and those not surely
    /// before it.
    Cell { beyond: &'a [u64], maybe: &'a [u64] },
}

/// Angle bin of a direction (counter-clockwise from the first axis), uniform in the diamond
/// angle in `[0, 4)` (the double-precision form of the angular index's pseudo-angle); the
/// zero vector falls in bin 0.
fn angle_bin(v: DVec2) -> usize {
    let r = v.x.abs() + v.y.abs();
    if !(r > 0.0) {
        return 0;
    }
    let t = v.x / r;
    let a = if v.y >= 0.0 { 1.0 - t } else { 3.0 + t };
    ((a / 4.0 * ANGLE_BINS as f64) as usize).min(ANGLE_BINS - 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stages::coverage::RelativeSamples;
    use glam::Vec3;
    use shadow_core::light::{Radiance, RectLight};
    use shadow_core::sampling::{hash_words, unit_float};

    /// The refined tables give exactly the exact test's covered samples; the paper's tables
    /// alone differ on a small share of samples near the projected edges.
    #[test]
    fn refined_tables_equal_the_exact_test_and_plain_tables_are_close() {
        let light = RectLight::facing(
            Vec3::new(0.2, 3.0, -0.1),
            Vec3::NEG_Y,
            1.6,
            1.0,
            Radiance::constant(Vec3::ONE).unwrap(),
        )
        .unwrap();
        let shape = LightShape::new(&light, "test").unwrap();
        let sampler = LightSampler::new(SamplingStrategy::Interleaved { tile: 2 }, 64, 9).unwrap();
        let refined = DiscreteTables::build(&sampler, &light, &shape, true, "t").unwrap();
        let plain = DiscreteTables::build(&sampler, &light, &shape, false, "t").unwrap();
        let c = shape.center.as_dvec3();
        let (mut units, mut total, mut plain_wrong, mut covered) = (Vec::new(), 0, 0, 0);
        let mut rel = RelativeSamples::default();
        for k in 0..400u64 {
            let r = |i: u64| unit_float(hash_words(&[k, i])) as f64;
            let p = DVec3::new(r(0) * 4.0 - 2.0, 0.0, r(1) * 4.0 - 2.0);
            let mid = DVec3::new(r(2) * 2.0 - 1.0, 0.5 + r(3) * 2.0, r(4) * 2.0 - 1.0);
            let dir = DVec3::new(r(5) - 0.5, (r(6) - 0.5) * 0.3, r(7) - 0.5) * r(8);
            let edge = SceneEdge {
                a: mid - dir,
                b: mid + dir,
                faces: Vec::new(),
                always: true,
            };
            let pixel = UVec2::new(k as u32 % 2, (k as u32 / 2) % 2);
            sampler.unit_samples(pixel, &mut units);
            let pos: Vec<Vec3> = units.iter().map(|u| light.sample(*u).position).collect();
            rel.set(p.as_vec3(), &pos);
            let Some(test) = EdgeTest::new(p, c, edge.a, edge.b) else {
                continue;
            };
            let allowed = [u64::MAX];
            let (mut exact, mut fine, mut coarse) = ([0u64], [0u64], [0u64]);
            test.mask(&rel, &allowed, &mut exact);
            refined.mask(pixel, &test, p, &edge, &rel, &allowed, &mut fine);
            plain.mask(pixel, &test, p, &edge, &rel, &allowed, &mut coarse);
            assert_eq!(fine, exact, "case {k}");
            total += 64;
            covered += exact[0].count_ones();
            plain_wrong += (coarse[0] ^ exact[0]).count_ones();
        }
        assert!(covered > 200, "{covered}");
        assert!(
            plain_wrong as f64 <= 0.01 * total as f64,
            "{plain_wrong} of {total}"
        );
    }
}
