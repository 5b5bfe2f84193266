//! Accurate visibility from occluder contours (GBP07 section 4).
//!
//! * **Smooth contour detection** (section 4.1, Figs. 3 and 4): each 2x2 block of shadow-map
//!   samples around the kernel gives a four-bit mask of occluding samples; the mask indexes
//!   [`RULES`], which holds the number of edges (0, 1 or 2) and the first edge's end points,
//!   each as the sample holding it (whose depth it takes) and the neighbour it moves towards.
//!   An end point lies on the segment from its holder to that neighbour at
//!   `holder + (neighbour - holder) (1 - t) / 2`: with `t = 0` the contour joins the samples'
//!   borders, with `t = 1` the occluders' centres and with `t = -1` the background samples'
//!   centres. The second edge of the two-edge masks is the first by central symmetry (indices
//!   plus 2). Edges are oriented so that the occluder lies on their left in texel coordinates
//!   (x right, y down), which is their right in the light's plane.
//! * **Radial area integration** (section 4.2, Fig. 5a): the edges are back-projected from the
//!   receiver onto the light's plane and integrated radially from the light's centre
//!   ([`LightDomain::edge`]), starting from the full light when the centre is hidden and from
//!   nothing otherwise.
//! * **Initialisation** (Fig. 5b): the centre is hidden when the receiver's projection `p'` lies
//!   inside the contour of its four nearest samples (the edges of that block, tested with the
//!   sign of 2D cross products), not by the plain shadow-map test, so the hard shadow matches the
//!   contours exactly.
//!
//! The same procedure runs on any level of the min/max pyramid (section 5.1), whose samples
//! stand for `2^k x 2^k` texels.

use glam::DVec2;

use crate::light_domain::{Covered, LightDomain};
use crate::shadow_map::InversePlane;

/// One rule of the table: the number of edges and the first edge's end points, each as
/// `(holder, neighbour)` sample indices of the block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rule {
    /// Number of edges (0, 1 or 2).
    pub edges: u8,
    /// Start of the first edge.
    pub start: (u8, u8),
    /// End of the first edge.
    pub end: (u8, u8),
}

/// Sample offsets from the block's centre, in texels, counter-clockwise on screen (texel y
/// grows downwards): 0 top-left, 1 top-right, 2 bottom-right, 3 bottom-left. Bit `k` of a mask
/// is sample `k`.
pub const SAMPLE_OFFSETS: [(f64, f64); 4] = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)];

/// Doubled [`SAMPLE_OFFSETS`], for exact integer orientation tests.
const OFFSETS2: [(i32, i32); 4] = [(-1, -1), (1, -1), (1, 1), (-1, 1)];

const fn occludes(mask: u8, k: usize) -> bool {
    (mask >> k) & 1 == 1
}

/// Orients `(s, e)` so that sample `o` lies on the left (positive cross product) at `t = 0`.
/// Twice the midpoint of the segment between two samples, in doubled offsets.
const fn mid(p: (u8, u8)) -> (i32, i32) {
    let (a, b) = (OFFSETS2[p.0 as usize], OFFSETS2[p.1 as usize]);
    (a.0 + b.0, a.1 + b.1)
}

const fn orient(s: (u8, u8), e: (u8, u8), o: usize) -> ((u8, u8), (u8, u8)) {
    let (ps, pe) = (mid(s), mid(e));
    let po = (2 * OFFSETS2[o].0, 2 * OFFSETS2[o].1);
    let cross = (pe.0 - ps.0) * (po.1 - ps.1) - (pe.1 - ps.1) * (po.0 - ps.0);
    if cross > 0 { (s, e) } else { (e, s) }
}

const fn rule(mask: u8) -> Rule {
    let none = Rule {
        edges: 0,
        start: (0, 0),
        end: (0, 0),
    };
    if mask == 0 || mask == 0xF {
        return none;
    }
    // Two occluders facing each other across the block: two edges, each cutting off one.
    if mask == 0b0101 || mask == 0b1010 {
        let s = if mask == 0b0101 { 0 } else { 1 };
        let (a, b) = orient(
            (s as u8, ((s + 3) % 4) as u8),
            (s as u8, ((s + 1) % 4) as u8),
            s,
        );
        return Rule {
            edges: 2,
            start: a,
            end: b,
        };
    }
    // One contiguous run of occluders: the two sides of the block it crosses.
    let mut ends = [(0u8, 0u8); 2];
    let mut n = 0;
    let mut holder = 0;
    let mut k = 0;
    while k < 4 {
        let j = (k + 1) % 4;
        if occludes(mask, k) != occludes(mask, j) {
            ends[n] = if occludes(mask, k) {
                (k as u8, j as u8)
            } else {
                (j as u8, k as u8)
            };
            holder = ends[n].0 as usize;
            n += 1;
        }
        k += 1;
    }
    let (a, b) = orient(ends[0], ends[1], holder);
    Rule {
        edges: 1,
        start: a,
        end: b,
    }
}

const fn rules() -> [Rule; 16] {
    let mut out = [rule(0); 16];
    let mut m = 0;
    while m < 16 {
        out[m] = rule(m as u8);
        m += 1;
    }
    out
}

/// The 16-case edge detection table (GBP07 section 4.1), indexed by the occluding mask.
pub const RULES: [Rule; 16] = rules();

/// An edge end point: offset from the block's centre (texels) and its holder sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EndPoint {
    /// Offset from the block's centre.
    pub offset: DVec2,
    /// Index of the sample whose depth the point takes.
    pub holder: u8,
}

fn end_point((holder, toward): (u8, u8), t: f64) -> EndPoint {
    let (h, n) = (
        SAMPLE_OFFSETS[holder as usize],
        SAMPLE_OFFSETS[toward as usize],
    );
    let f = 0.5 * (1.0 - t);
    EndPoint {
        offset: DVec2::new(h.0 + (n.0 - h.0) * f, h.1 + (n.1 - h.1) * f),
        holder,
    }
}

/// The oriented edges of a block with occluding `mask` for contour parameter `t` (zero-length
/// edges, which `t = 1` makes of single corners, are dropped).
pub fn block_edges(mask: u8, t: f64) -> impl Iterator<Item = (EndPoint, EndPoint)> {
    let r = RULES[mask as usize & 0xF];
    let rot = |p: (u8, u8)| ((p.0 + 2) % 4, (p.1 + 2) % 4);
    let first = (end_point(r.start, t), end_point(r.end, t));
    let second = (end_point(rot(r.start), t), end_point(rot(r.end), t));
    [first, second]
        .into_iter()
        .take(r.edges as usize)
        .filter(|(a, b)| a.offset != b.offset)
}

/// True when `p` (offset from the block's centre) lies inside the contour of the block: the
/// hard-shadow test consistent with the contours (GBP07 Fig. 5b).
pub fn inside(mask: u8, t: f64, p: DVec2) -> bool {
    match mask & 0xF {
        0 => false,
        0xF => true,
        m => block_edges(m, t).any(|(a, b)| (b.offset - a.offset).perp_dot(p - a.offset) > 0.0),
    }
}

/// A level of the shadow map's min/max pyramid as contour detection reads it.
#[derive(Debug, Clone, Copy)]
pub struct MapLevel<'a> {
    /// Side in samples.
    pub side: usize,
    /// Depths (row-major; min depths above level 0).
    pub depth: &'a [f32],
    /// Level-0 texels per sample side (`2^k`).
    pub scale: f64,
}

impl MapLevel<'_> {
    #[inline]
    fn at(&self, i: i64, j: i64) -> f32 {
        let s = self.side as i64;
        if i < 0 || j < 0 || i >= s || j >= s {
            f32::INFINITY
        } else {
            self.depth[j as usize * self.side + i as usize]
        }
    }
}

/// How the shadow map's texel coordinates map to its view plane: left and top at unit depth
/// and texels per unit.
#[derive(Debug, Clone, Copy)]
pub struct MapFrame {
    /// Left edge at unit depth.
    pub left: f64,
    /// Top edge at unit depth.
    pub top: f64,
    /// Texels per unit at unit depth.
    pub texels_per_unit: f64,
}

/// A receiver as contour integration sees it.
#[derive(Debug, Clone, Copy)]
pub struct Receiver {
    /// Level-0 texel coordinates of its projection `p'`.
    pub x: f64,
    /// See `x`.
    pub y: f64,
    /// Linear depth.
    pub z: f32,
    /// Its tangent plane (a sample occludes only in front of it).
    pub plane: InversePlane,
    /// Depth bias beyond the plane.
    pub bias: f32,
}

/// Reusable buffers of one worker.
#[derive(Debug, Default)]
pub struct Scratch {
    states: Vec<u64>,
    poly: Vec<DVec2>,
    clip: Vec<DVec2>,
}

/// Bit `i` set when `depths[i]`, the sample at row position `first + i`, occludes a receiver
/// whose plane has inverse depth `inv0 + step * k` at position `k` (see [`occluded`]): a
/// finite depth in front of the plane by more than `bias`, or any finite depth where the plane
/// is behind the light. At most 64 depths.
///
/// Eight samples at a time in SIMD lanes (`wide`), with the same f32 operations, roundings
/// and comparisons as one at a time (no fused multiply-add), so the bits are the scalar
/// test's: this test over the kernel was most of the filter's time (`perf`, `ssm-adaptive`).
#[inline]
fn occluding_bits(depths: &[f32], first: usize, inv0: f32, step: f32, bias: f32) -> u64 {
    use wide::{f32x8, i32x8};
    debug_assert!(depths.len() <= 64);
    // Positions are below 2^24 (a map side), so `i32` to `f32` is exact, as `usize` to `f32`.
    let test = |d: f32, k: usize| {
        let inv = inv0 + step * (k as i32) as f32;
        d.is_finite() & ((inv <= 0.0) | ((d + bias) * inv < 1.0))
    };
    let (inv0x, stepx, biasx) = (f32x8::splat(inv0), f32x8::splat(step), f32x8::splat(bias));
    let lanes = i32x8::new([0, 1, 2, 3, 4, 5, 6, 7]);
    let mut bits = 0u64;
    let mut chunks = depths.chunks_exact(8);
    let mut at = 0usize;
    for c in &mut chunks {
        let d = f32x8::new(c.try_into().expect("chunks of eight"));
        let k = f32x8::from_i32x8(i32x8::splat((first + at) as i32) + lanes);
        let inv = inv0x + stepx * k;
        let o =
            d.is_finite() & (inv.simd_le(f32x8::ZERO) | ((d + biasx) * inv).simd_lt(f32x8::ONE));
        bits |= u64::from(o.to_bitmask()) << at;
        at += 8;
    }
    for (l, &d) in chunks.remainder().iter().enumerate() {
        bits |= u64::from(test(d, first + at + l)) << (at + l);
    }
    bits
}

/// The part of the light the contours of `level` hide from `r`, within a kernel of `width`
/// level-0 texels centred on `p'`; returns it with the number of edges integrated.
pub fn occluded(
    level: &MapLevel,
    frame: &MapFrame,
    r: &Receiver,
    width: f64,
    t: f64,
    light: &LightDomain,
    scratch: &mut Scratch,
) -> (Covered, u64) {
    let s = level.scale;
    let half_block = 0.5 * (s - 1.0);
    let (xl, yl) = (r.x / s, r.y / s);
    let h = 0.5 * width / s;
    let (i0, i1) = ((xl - h).floor() as i64 - 1, (xl + h).floor() as i64 + 1);
    let (j0, j1) = ((yl - h).floor() as i64 - 1, (yl + h).floor() as i64 + 1);
    let nx = (i1 - i0 + 1) as usize;
    // A sample occludes when it lies in front of the receiver's plane (its nearest point over
    // the sample's block) by more than the bias: with the plane's inverse depth `inv`,
    // `d < 1 / inv - bias`, i.e. `(d + bias) inv < 1`, or any finite depth where the plane is
    // behind the light (`inv <= 0`). The inverse depth is linear in the texel coordinates, so
    // a row is tested branch-free in f32 lanes.
    let plane = &r.plane;
    let slack = (plane.b.abs() + plane.c.abs()) * half_block;
    let bias = r.bias;
    // One bit per sample, rows of `words` u64s.
    let words = nx.div_ceil(64);
    let states = &mut scratch.states;
    states.clear();
    states.resize(words * (j1 - j0 + 1) as usize, 0);
    let side = level.side as i64;
    let (lo, hi) = ((-i0).max(0) as usize, (side - 1 - i0).min(nx as i64 - 1));
    for j in j0.max(0)..=j1.min(side - 1) {
        if hi < lo as i64 {
            break;
        }
        let base = (j - j0) as usize * words;
        let inv0 =
            plane.a + plane.b * (i0 as f64 + 0.5) * s + plane.c * (j as f64 + 0.5) * s + slack;
        let step = (plane.b * s) as f32;
        // Sample k of the row (k >= lo, so i0 + k >= 0) is row[k - lo].
        let row = &level.depth[(j * side + i0 + lo as i64) as usize..];
        // Branch-free in f32 lanes, one word at a time.
        let (inv0, hi) = (inv0 as f32, hi as usize);
        for w in lo / 64..=hi / 64 {
            let (k0, k1) = ((64 * w).max(lo), (64 * w + 63).min(hi));
            // Whole groups of eight where the level's row has the depths past `k1` (their
            // bits are dropped), so that no sample is tested one at a time.
            let n = (k1 - k0 + 1).next_multiple_of(8).min(row.len() - (k0 - lo));
            let keep = u64::MAX >> (63 - (k1 - k0));
            let bits = occluding_bits(&row[k0 - lo..][..n], k0, inv0, step, bias) & keep;
            states[base + w] = bits << (k0 - 64 * w);
        }
    }
    let states = &scratch.states;
    let state = |i: i64, j: i64| {
        let k = (i - i0) as usize;
        states[(j - j0) as usize * words + k / 64] >> (k % 64) & 1 == 1
    };
    let mask_at = |bi: i64, bj: i64| -> u8 {
        state(bi, bj) as u8
            | (state(bi + 1, bj) as u8) << 1
            | (state(bi + 1, bj + 1) as u8) << 2
            | (state(bi, bj + 1) as u8) << 3
    };
    // The receiver in the view plane.
    let z = r.z as f64;
    let p = DVec2::new(
        frame.left + r.x / frame.texels_per_unit,
        frame.top - r.y / frame.texels_per_unit,
    ) * z;
    let back_project = |bi: i64, bj: i64, e: &EndPoint| -> DVec2 {
        let (oi, oj) = SAMPLE_OFFSETS[e.holder as usize];
        let zs =
            (level.at(bi + (oi + 0.5) as i64, bj + (oj + 0.5) as i64) as f64).min(z * (1.0 - 1e-6));
        let x = (bi as f64 + 1.0 + e.offset.x) * s;
        let y = (bj as f64 + 1.0 + e.offset.y) * s;
        let q = DVec2::new(
            frame.left + x / frame.texels_per_unit,
            frame.top - y / frame.texels_per_unit,
        ) * zs;
        p + (q - p) * (z / (z - zs))
    };
    // Initialisation: the light's centre is hidden when p' is inside its block's contour.
    let (bi, bj) = ((xl - 0.5).floor() as i64, (yl - 0.5).floor() as i64);
    let centre = DVec2::new(xl - (bi as f64 + 1.0), yl - (bj as f64 + 1.0));
    let mut sum = if inside(mask_at(bi, bj), t, centre) {
        light.full()
    } else {
        Covered::default()
    };
    let mut edges = 0u64;
    let blocks = nx - 1;
    for bj in j0..j1 {
        let (top, bottom) = (
            &states[(bj - j0) as usize * words..][..words],
            &states[(bj - j0 + 1) as usize * words..][..words],
        );
        for w in 0..words {
            // Bit k: sample k of the row; shifted: sample k + 1. A block is mixed unless its
            // four samples agree.
            let next = |row: &[u64]| row[w] >> 1 | row.get(w + 1).map_or(0, |n| n << 63);
            let (a, a1, b, b1) = (top[w], next(top), bottom[w], next(bottom));
            let mut mixed = (a | a1 | b | b1) & !(a & a1 & b & b1);
            let valid = blocks.saturating_sub(64 * w).min(64);
            if valid < 64 {
                mixed &= (1u64 << valid) - 1;
            }
            while mixed != 0 {
                let k = mixed.trailing_zeros() as i64;
                mixed &= mixed - 1;
                let bi = i0 + 64 * w as i64 + k;
                for (a, b) in block_edges(mask_at(bi, bj), t) {
                    let (pa, pb) = (back_project(bi, bj, &a), back_project(bi, bj, &b));
                    sum += light.edge(pa, pb, &mut scratch.poly, &mut scratch.clip);
                    edges += 1;
                }
            }
        }
    }
    (sum, edges)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec2;

    fn pos(k: u8) -> DVec2 {
        DVec2::new(SAMPLE_OFFSETS[k as usize].0, SAMPLE_OFFSETS[k as usize].1)
    }

    /// All 16 cases: edge counts, end points at t = -1, 0, 1 and orientation (every occluding
    /// sample on the left of every edge it shares a side with, every background sample on the
    /// right).
    #[test]
    fn all_sixteen_contour_cases() {
        for m in 0u8..16 {
            let occluders = m.count_ones();
            let want = match m {
                0 | 15 => 0,
                5 | 10 => 2,
                _ => 1,
            };
            assert_eq!(RULES[m as usize].edges, want, "mask {m:04b}");
            for t in [-1.0, 0.0, 1.0] {
                let edges: Vec<_> = block_edges(m, t).collect();
                // t = 1 collapses the edges around a single occluder (they join its centre).
                // t = -1 collapses the edge around a single background sample.
                let expect = if (t == 1.0 && (occluders == 1 || m == 5 || m == 10))
                    || (t == -1.0 && occluders == 3)
                {
                    0
                } else {
                    want as usize
                };
                assert_eq!(edges.len(), expect, "mask {m:04b} t {t}");
                for (a, b) in &edges {
                    for e in [a, b] {
                        assert!(m >> e.holder & 1 == 1, "holder must occlude");
                        // On the block's border, at the holder (t = 1), the border midpoint
                        // (t = 0) or the background neighbour (t = -1).
                        let h = pos(e.holder);
                        let d = e.offset - h;
                        let step = d.length();
                        assert!((step - 0.5 * (1.0 - t)).abs() < 1e-12, "mask {m:04b} t {t}");
                    }
                    if t != 1.0 {
                        for k in 0u8..4 {
                            let side = (b.offset - a.offset).perp_dot(pos(k) - a.offset);
                            // Samples on the edge's line (t = -1 puts the edge through the
                            // background samples) are neither side.
                            if side.abs() < 1e-12 {
                                continue;
                            }
                            let is_occ = m >> k & 1 == 1;
                            // In the two-edge cases each edge only separates its own corner.
                            let near = [a.holder, (a.holder + 1) % 4, (a.holder + 3) % 4];
                            if (m == 5 || m == 10) && !near.contains(&k) {
                                continue;
                            }
                            assert_eq!(side > 0.0, is_occ, "mask {m:04b} t {t} sample {k}");
                        }
                    }
                }
            }
        }
        // Positions for t = 0, by hand: a lone top-left occluder is cut off by the edge from
        // the middle of the top side to the middle of the left side (occluder on the left in
        // texel coordinates, y down).
        let e: Vec<_> = block_edges(0b0001, 0.0).collect();
        assert_eq!(e[0].0.offset, DVec2::new(0.0, -0.5));
        assert_eq!(e[0].1.offset, DVec2::new(-0.5, 0.0));
        // Two occluders on top: a straight edge along the middle, right to left.
        let e: Vec<_> = block_edges(0b0011, 0.0).collect();
        assert_eq!(e[0].0.offset, DVec2::new(0.5, 0.0));
        assert_eq!(e[0].1.offset, DVec2::new(-0.5, 0.0));
    }

    /// GBP07 Fig. 5b: p' just outside a lone occluder's texel but inside its square is lit by the
    /// contour test at t = 0 near the cut corner, though the plain test calls it shadowed.
    #[test]
    fn contour_consistent_hard_shadow_test() {
        // Lone occluder at the top-left sample: its texel is [-1, 0]^2 around the block centre.
        // A point at (-0.1, -0.1) is in the occluder's texel (the plain test: shadowed) but
        // beyond the cut from (-0.5, 0) to (0, -0.5) (lit); (-0.4, -0.4) is inside.
        assert!(!inside(0b0001, 0.0, DVec2::new(-0.1, -0.1)));
        assert!(inside(0b0001, 0.0, DVec2::new(-0.4, -0.4)));
        // At t = -1 the contour reaches the background centres: the whole corner triangle.
        assert!(inside(0b0001, -1.0, DVec2::new(-0.1, -0.1)));
        assert!(inside(0b1111, 0.0, DVec2::ZERO));
        assert!(!inside(0, 0.0, DVec2::ZERO));
        // Diagonal occluders: both corners are inside, the centre is not.
        assert!(inside(0b0101, 0.0, DVec2::new(-0.4, -0.4)));
        assert!(inside(0b0101, 0.0, DVec2::new(0.4, 0.4)));
        assert!(!inside(0b0101, 0.0, DVec2::ZERO));
    }

    /// A square block of occluding texels between a receiver and a square light, at t = 0: the
    /// contour is the block's outline with each corner cut by half a texel (the corner blocks
    /// hold a lone occluder), so the occluded area is that octagon back-projected and clipped to
    /// the light: exact when it lies inside the light, against a fine grid otherwise.
    /// The eight-lane test gives the one-sample test's bits, for every length up to 64 and
    /// planes in front of, across and behind the light (inverse depths of both signs), with
    /// empty (infinite) texels among the depths.
    #[test]
    fn lane_test_matches_the_scalar_test() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        for case in 0..2000 {
            let n = case % 65;
            let depths: Vec<f32> = (0..n)
                .map(|_| {
                    let u = next();
                    if u < 0.1 { f32::INFINITY } else { 4.0 * next() }
                })
                .collect();
            let first = (next() * 900.0) as usize;
            let (inv0, step, bias) = (next() - 0.3, (next() - 0.5) * 0.01, 0.05 * next());
            let want = depths.iter().enumerate().fold(0u64, |bits, (i, &d)| {
                let inv = inv0 + step * (first + i) as f32;
                let o = d.is_finite() & ((inv <= 0.0) | ((d + bias) * inv < 1.0));
                bits | u64::from(o) << i
            });
            assert_eq!(
                occluding_bits(&depths, first, inv0, step, bias),
                want,
                "case {case}"
            );
        }
    }

    #[test]
    fn occluded_area_of_a_square_occluder() {
        // 64 x 64 texels over unit-depth [-1, 1]^2 (32 texels per unit), occluders at depth 1
        // over texels 28..36 (unit-depth x, y in [-0.125, 0.125]), background at depth 3.
        let side = 64usize;
        let mut depth = vec![3.0f32; side * side];
        for j in 28..36 {
            for i in 28..36 {
                depth[j * side + i] = 1.0;
            }
        }
        let level = MapLevel {
            side,
            depth: &depth,
            scale: 1.0,
        };
        let frame = MapFrame {
            left: -1.0,
            top: 1.0,
            texels_per_unit: 32.0,
        };
        let light = LightDomain::new(&[
            Vec2::new(-0.5, -0.5),
            Vec2::new(0.5, -0.5),
            Vec2::new(0.5, 0.5),
            Vec2::new(-0.5, 0.5),
        ]);
        // A receiver at depth 2 whose plane faces the light (inverse depth 1/2 everywhere).
        let plane = InversePlane {
            a: 0.5,
            b: 0.0,
            c: 0.0,
        };
        let (a, c) = (0.125, 1.0 / 64.0);
        let octagon = [
            DVec2::new(-a + c, -a),
            DVec2::new(a - c, -a),
            DVec2::new(a, -a + c),
            DVec2::new(a, a - c),
            DVec2::new(a - c, a),
            DVec2::new(-a + c, a),
            DVec2::new(-a, a - c),
            DVec2::new(-a, -a + c),
        ];
        let mut scratch = Scratch::default();
        for (x, y, inside_light) in [
            (32.0, 32.0, true),
            (32.2, 31.7, true),
            (35.3, 30.4, true),
            (41.1, 33.6, false),
            (20.2, 20.3, false),
        ] {
            let r = Receiver {
                x,
                y,
                z: 2.0,
                plane,
                bias: 0.01,
            };
            let (got, edges) = occluded(&level, &frame, &r, 64.0, 0.0, &light, &mut scratch);
            // Seen from p at depth 2, a point q at depth 1 maps to p + (q - p) 2 = 2 q - p.
            let p = DVec2::new(-1.0 + x / 32.0, 1.0 - y / 32.0) * 2.0;
            let poly: Vec<DVec2> = octagon.iter().map(|q| *q * 2.0 - p).collect();
            if inside_light {
                let want = crate::light_domain::polygon_area(&poly).abs();
                assert!(
                    (got.area - want).abs() < 1e-9,
                    "({x}, {y}): {} vs {want}",
                    got.area
                );
            } else {
                let n = 1000;
                let mut hits = 0u32;
                for j in 0..n {
                    for i in 0..n {
                        let q = DVec2::new(
                            -0.5 + (i as f64 + 0.5) / n as f64,
                            -0.5 + (j as f64 + 0.5) / n as f64,
                        );
                        hits += (0..8)
                            .all(|k| (poly[(k + 1) % 8] - poly[k]).perp_dot(q - poly[k]) >= 0.0)
                            as u32;
                    }
                }
                let want = hits as f64 / (n * n) as f64;
                assert!(
                    (got.area - want).abs() < 2e-3,
                    "({x}, {y}): {} vs {want}",
                    got.area
                );
            }
            assert!(edges > 0);
        }
    }
}
