//! The discrete covered-samples representation of DCS section 7.3 (Fig. 8), for planar lights
//! and samplers with a finite number of sample sets (correlated: one; interleaved: `k x k`).
//!
//! For each sample set, in the light plane around the centre `c`:
//! * a **sector table** over `ANGLE_BINS` directions: bit `i` of entry `k` is set when sample
//!   `i` lies at an angle (from the light's first axis, counter-clockwise) below the start of
//!   bin `k + 1` (the paper's cube map of "samples from the origin to `v`");
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

use std::f64::consts::TAU;

use glam::{DVec2, DVec3, UVec2};
use shadow_core::light::{AreaLight, LightGeometry};
use shadow_core::sampling::{LightSampler, SamplingStrategy};
use shadow_core::technique::TechniqueError;

use crate::coverage::{EdgeTest, RelativeSamples};
use crate::edges::SceneEdge;
use crate::light_shape::LightShape;

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
}

/// One sample set's tables.
#[derive(Debug, Clone)]
struct SetTables {
    sector: Vec<u64>,
    line: Vec<u64>,
}

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
        technique: &str,
    ) -> Result<Self, TechniqueError> {
        let unsupported = |reason: &str| TechniqueError::Unsupported {
            technique: technique.into(),
            reason: reason.into(),
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
                let mut line = vec![0u64; LINE_GRID * LINE_GRID * words];
                for gy in 0..LINE_GRID {
                    for gx in 0..LINE_GRID {
                        let q = DVec2::new(
                            -half + (gx as f64 + 0.5) / LINE_GRID as f64 * 2.0 * half,
                            -half + (gy as f64 + 0.5) / LINE_GRID as f64 * 2.0 * half,
                        );
                        let r = q.length();
                        let cell = (gy * LINE_GRID + gx) * words;
                        for (i, s) in pts.iter().enumerate() {
                            if r == 0.0 || s.dot(q) / r > r {
                                line[cell + i / 64] |= 1 << (i % 64);
                            }
                        }
                    }
                }
                SetTables { sector, line }
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
            sets,
        })
    }

    /// Light-plane coordinates (relative to the centre) of the projection of `x` from `p`.
    fn project(&self, p: DVec3, x: DVec3) -> DVec2 {
        let t = (self.center - p).dot(self.normal) / (x - p).dot(self.normal);
        let y = p + (x - p) * t - self.center;
        DVec2::new(y.dot(self.t1), y.dot(self.t2))
    }

    /// The covered samples of `edge` seen from `p` (pixel `pixel`'s set), restricted to
    /// `allowed`; falls back to the exact `test` where the tables cannot answer (the edge's
    /// projection passes through the centre, or the edge leaves the slab between `p` and the
    /// light plane).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn mask(
        &self,
        pixel: UVec2,
        test: &EdgeTest,
        p: DVec3,
        _c: DVec3,
        edge: &SceneEdge,
        relative: &RelativeSamples,
        allowed: &[u64],
        mask: &mut [u64],
    ) -> bool {
        let h = (self.center - p).dot(self.normal);
        let ha = (edge.a - p).dot(self.normal);
        let hb = (edge.b - p).dot(self.normal);
        // Both end points strictly between p's parallel plane and the light plane.
        let inside = |x: f64| (h > 0.0 && x > 0.0 && x < h) || (h < 0.0 && x < 0.0 && x > h);
        if !(inside(ha) && inside(hb)) {
            return test.mask(relative, allowed, mask);
        }
        let (a2, b2) = (self.project(p, edge.a), self.project(p, edge.b));
        let d = b2 - a2;
        let cross = a2.perp_dot(b2);
        let len = d.length();
        if !(len > 0.0) || (cross / len).abs() < 1e-9 * self.half {
            return test.mask(relative, allowed, mask);
        }
        // Foot of the perpendicular from the centre (origin) to the line.
        let foot = a2 - d * (a2.dot(d) / (len * len));
        let set = &self.sets[((pixel.y % self.tile) * self.tile + pixel.x % self.tile) as usize];
        let w = self.words;
        let g = |v: f64| (((v + self.half) / (2.0 * self.half)) * LINE_GRID as f64).floor();
        let (gx, gy) = (g(foot.x), g(foot.y));
        let line: Option<&[u64]> =
            (gx >= 0.0 && gy >= 0.0 && gx < LINE_GRID as f64 && gy < LINE_GRID as f64).then(|| {
                let cell = (gy as usize * LINE_GRID + gx as usize) * w;
                &set.line[cell..cell + w]
            });
        let Some(line) = line else {
            // The line misses the light's square: no sample lies beyond it.
            mask.fill(0);
            return false;
        };
        // Counter-clockwise order of the end points seen from the centre.
        let (first, second) = if cross > 0.0 { (a2, b2) } else { (b2, a2) };
        let (k0, k1) = (angle_bin(first), angle_bin(second));
        let s0 = &set.sector[k0 * w..k0 * w + w];
        let s1 = &set.sector[k1 * w..k1 * w + w];
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

/// Angle bin of a direction (counter-clockwise from the first axis).
fn angle_bin(v: DVec2) -> usize {
    let a = v.y.atan2(v.x).rem_euclid(TAU);
    ((a / TAU * ANGLE_BINS as f64) as usize).min(ANGLE_BINS - 1)
}
