//! The spatial structure that finds the view samples inside each penumbra wedge (DCS section
//! 4.2, Algorithm 1 line 2, "for all p in w_e"): a hierarchy of boxes over the light-centred view
//! samples, walked from the top with every wedge.
//!
//! * **Blocks** of [`BLOCK`] x [`BLOCK`] pixels: every wedge of the light against the boxes of
//!   up to [`BOXES`] blocks at once; each block lists the wedges its box keeps.
//! * **Clusters** of [`CLUSTER`] x [`CLUSTER`] pixels (2 x 2 squares): each wedge of a block
//!   against the boxes of the block's clusters.
//! * **Squares** of [`SQUARE`] x [`SQUARE`] pixels: each wedge of a block against the boxes of
//!   the squares of the clusters it keeps. A square is also the unit of the per-pixel pass:
//!   its pairs are kept until its pixels are done, which bounds their memory on scenes of very
//!   high depth complexity (`grass`).
//! * **Tiles** of [`TILE_W`] x [`TILE_H`] pixels: each wedge of a square against the boxes of
//!   the square's tiles.
//! * **View samples** of a tile ([`crate::accel::lanes`]): a surviving wedge's fold planes, bounding
//!   planes and weight `k_e(p)` on every view sample at once; each view sample inside the
//!   planes with a non-zero weight makes a (pixel, edge) pair. Only the bounding planes that
//!   may cut the tile's box are evaluated on its view samples ([`ScanWedge::cut_planes`]): a
//!   plane with the whole box on its positive side holds every view sample in it.
//!
//! A box keeps a wedge when none of the wedge's bounding planes ([`crate::stages::wedges::wedge_planes`])
//! has the whole box on its negative side, and the edge may be a silhouette from some point of
//! the box (its two face planes, with a slack). A test loads one wedge's planes and evaluates
//! each at the boxes' corners farthest along its normal (and, for the face planes, the nearest
//! ones too), four boxes at a time, the bounds in packed vectors. Boxes are padded by their own
//! rounding, so that no test rejects a view sample that the exact test on the lanes would
//! keep.

use glam::{BVec4A, DVec3, Vec3, Vec4};
use rayon::prelude::*;

use crate::accel::centred::FastWeight;
use crate::accel::centred::{CentredEdge, CentredPlane};
use crate::accel::centred_wedges::Wedge;
use crate::accel::lanes::{
    LANES, LaneMask, QUADS, TILE_H, TILE_W, TileLanes, TileQuads, lanes_of, rect_lanes,
};
use crate::accel::planar::{PlanarEdge, PlanarTest};
use crate::stages::edges::SceneEdge;
use crate::stages::wedges::Pair;

mod boxes;
mod hierarchy;
mod squares;
#[cfg(test)]
mod tests;

pub(crate) use boxes::*;
pub(crate) use hierarchy::*;
pub(crate) use squares::*;

/// Side of a block, in pixels (a multiple of [`SQUARE`]): large enough that the top level
/// tests few boxes per wedge, small enough that its box stays tight (the sizes tried are in
/// `docs/history/`).
pub(crate) const BLOCK: u32 = 128;

/// Side of a square, in pixels (a multiple of [`TILE_W`] and [`TILE_H`]).
pub(crate) const SQUARE: u32 = 16;

/// Bounding planes per wedge in the box tests: more are dropped (any subset of a wedge's
/// bounding planes bounds it). Eight fill two groups of four ([`PlaneGroup`]). The built-in
/// scenes' wedges have 4 to 9 planes (`bunny`: 2,410 with 4, 25,620 with 6, 3 with 8, 2 with
/// 9; `quad-over-plane` and `overlapping-occluders` 8 or 9); with 8 rather than 10 the tile
/// candidates, pairs and covered updates are the same on every built-in scene, and the
/// box-test record ([`ScanWedge`]) stays at 192 bytes.
const BOX_PLANES: usize = 8;

/// Relative padding of a box, far above the rounding of its centre and of a plane evaluated there.
const BOX_PAD: f32 = 1e-6;

/// Boxes per [`Boxes`] (one bit each in a test's mask).
pub(crate) const BOXES: usize = 64;

/// A plane for box tests: `n.x`, `n.y`, `n.z`, `d`; the tests take the absolute values of `n`
/// themselves. Four floats rather than seven keep a wedge's box-test data (its count, fold
/// planes and bounding planes, at the front of [`ScanWedge`]) within 176 bytes (208 with ten
/// bounding planes, 344 with seven floats each): a box test waits mostly on its first loads of
/// the wedge (`perf`).
type BoxPlane = Vec4;

/// The plane every box passes (`0 . x + 1 >= 0`): unused plane slots.
const OPEN: BoxPlane = Vec4::new(0.0, 0.0, 0.0, 1.0);

/// What the box tests read of one wedge (the scan visits wedges in silhouette order, square by
/// square): its bounding planes and the planes of its edge's two faces (the bounding planes
/// also test view samples). The rest of what the view samples' pass reads is in
/// [`WedgeLanes`].
///
/// Laid out in declaration order (`repr(C)`) on cache-line boundaries: the count, the fold
/// planes, then the groups of bounding planes, up to eight planes in three lines (192 bytes),
/// in declaration order (`repr(C)`) so that a box test touches only those lines. The bounding
/// planes are kept once, four to a group in structure-of-arrays form, which both the box tests
/// (one plane at a time) and [`ScanWedge::cut_planes`] (a group at a time) read: small records
/// are what keeps a square's wedges in the caches.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub(crate) struct ScanWedge {
    /// Bounding planes in use (the rest are open).
    used: u32,
    /// The scene edge.
    edge: u32,
    /// Whether `fold` holds the planes of the edge's faces (which the weight evaluates too)
    /// rather than open planes.
    folded: bool,
    fold: [BoxPlane; 2],
    planes: [PlaneGroup; PLANE_GROUPS],
}

/// What the view samples' pass reads of a wedge besides its [`ScanWedge`]: its weight from
/// plane signs and its edge prepared for the light-plane test (256 bytes). Kept apart from the
/// box-test data, so that the box tests of every level, which most wedges do not pass, read
/// densely packed 192-byte records rather than 448-byte ones.
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub(crate) struct WedgeLanes {
    weight: Option<FastWeight>,
    planar: Option<PlanarEdge>,
}

/// Groups of four planes for [`PLANE_GROUPS`] x 4 plane slots.
const PLANE_GROUPS: usize = BOX_PLANES.div_ceil(4);

/// Relative margin of [`ScanWedge::cut_planes`]: far above the rounding of a plane evaluated at
/// a view sample and of its bound over a tile's box.
const CUT_PAD: f32 = 1e-5;

/// Four bounding planes in structure-of-arrays form: the normals' components and the offsets,
/// one plane per lane; unused slots are open (a zero normal and a positive offset).
#[derive(Debug, Clone, Copy)]
#[repr(C)]
struct PlaneGroup {
    n: [Vec4; 3],
    d: Vec4,
}

impl PlaneGroup {
    /// Slots `4 g` to `4 g + 3` of `planes` (open past its end).
    fn new(planes: &[BoxPlane], g: usize) -> Self {
        let slot = |l: usize| planes.get(4 * g + l).copied().unwrap_or(OPEN);
        let lanes = |k: usize| Vec4::from_array(std::array::from_fn(|l| slot(l)[k]));
        Self {
            n: [lanes(0), lanes(1), lanes(2)],
            d: lanes(3),
        }
    }
}

/// Plane `k` of `groups` as its coefficients `n.x`, `n.y`, `n.z`, `d`, each a scalar.
#[inline(always)]
fn plane_of(groups: &[PlaneGroup; PLANE_GROUPS], k: usize) -> [f32; 4] {
    let (g, l) = (&groups[k / 4], k % 4);
    [g.n[0], g.n[1], g.n[2], g.d].map(|v| v.as_ref()[l])
}

/// Calls `f` with each of the first `used` planes of `groups`, in order, as its coefficients.
#[inline(always)]
fn each_plane(groups: &[PlaneGroup; PLANE_GROUPS], used: usize, mut f: impl FnMut([f32; 4])) {
    for (g, p) in groups.iter().enumerate() {
        let lanes = used.saturating_sub(4 * g).min(4);
        if lanes == 0 {
            break;
        }
        let [x, y, z, d] = [p.n[0], p.n[1], p.n[2], p.d].map(|v| v.to_array());
        for l in 0..lanes {
            f([x[l], y[l], z[l], d[l]]);
        }
    }
}

/// A tile's box for [`ScanWedge::cut_planes`]: its centre and its half extent (widened by
/// the margin [`CUT_PAD`]), each coordinate in all lanes.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct TileExtent {
    centre: [Vec4; 3],
    half: [Vec4; 3],
}

impl TileExtent {
    /// The extent of box `b` (an empty tile: a point at the origin, which no lane uses).
    fn new(b: ViewBox) -> Self {
        let (lo, hi) = b.unwrap_or((Vec3::ZERO, Vec3::ZERO));
        let (c, h) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        let h = h + (c.abs() + h) * CUT_PAD;
        Self {
            centre: c.to_array().map(Vec4::splat),
            half: h.to_array().map(Vec4::splat),
        }
    }
}

impl ScanWedge {
    /// The scan data of wedge `w`: its box-test record and its record for the view samples'
    /// pass, with its edge in light-plane form (`planar`) for planar lights.
    pub fn new(w: &Wedge, planar: Option<PlanarEdge>) -> (Self, WedgeLanes) {
        let plane = |p: &CentredPlane| -> BoxPlane {
            let (n, d) = p.coefficients();
            n.extend(d)
        };
        // No fold planes: both open, which every box passes.
        let fold = match &w.fold {
            Some((a, b)) => [plane(a), plane(b)],
            None => [OPEN, OPEN],
        };
        // The weight may take the fold test's values only where they are its own planes'.
        let folded = match (&w.fold, w.weight.as_ref().and_then(FastWeight::face_planes)) {
            (Some(f), Some(faces)) => {
                f.0.coefficients() == faces.0.coefficients()
                    && f.1.coefficients() == faces.1.coefficients()
            }
            _ => false,
        };
        let planes: Vec<BoxPlane> = w.planes.iter().take(BOX_PLANES).map(plane).collect();
        let scan = Self {
            planes: std::array::from_fn(|g| PlaneGroup::new(&planes, g)),
            used: planes.len() as u32,
            fold,
            folded,
            edge: w.edge,
        };
        let lanes = WedgeLanes {
            weight: w.weight,
            planar,
        };
        (scan, lanes)
    }

    /// The bounding planes (one bit each) that may put a view sample of a tile with extent
    /// `e` on their negative side: the others are positive over the whole box, with a margin
    /// above the rounding of the lanes' tests, and need no test on the lanes.
    #[inline]
    fn cut_planes(&self, e: &TileExtent) -> u32 {
        let mut m = 0u32;
        for (g, p) in self.planes.iter().enumerate() {
            let [nx, ny, nz] = p.n;
            // The offsets lowered by the margin.
            let d_low = p.d - Vec4::splat(CUT_PAD) * p.d.abs();
            let centre = nx * e.centre[0] + ny * e.centre[1] + nz * e.centre[2] + d_low;
            let reach = nx.abs() * e.half[0] + ny.abs() * e.half[1] + nz.abs() * e.half[2];
            // A NaN is cut: the lanes test it.
            m |= (!(centre - reach).cmpgt(Vec4::ZERO).bitmask() & 0xf) << (4 * g);
        }
        m & ((1 << self.used) - 1)
    }

    /// The view samples where the edge may be a silhouette (its two face planes not surely of
    /// different signs, `slack` the fold test's slack; every view sample without fold planes),
    /// and the two planes' values at every lane (as [`CentredPlane::eval_quads`] computes them,
    /// for [`FastWeight::weight_lanes`]).
    #[inline]
    fn fold_lanes(&self, t: &TileQuads, slack: f32) -> (LaneMask, [[Vec4; QUADS]; 2]) {
        let s = Vec4::splat(slack);
        let eval = |p: &BoxPlane| -> [Vec4; QUADS] {
            let [nx, ny, nz, d] = splat(*p);
            std::array::from_fn(|q| nx * t.x[q] + ny * t.y[q] + nz * t.z[q] + d)
        };
        let values = [eval(&self.fold[0]), eval(&self.fold[1])];
        let mut m = 0;
        for q in 0..QUADS {
            let (v1, v2) = (values[0][q], values[1][q]);
            let differ = (v1.cmple(-s) | v2.cmple(-s)) & (v1.cmpge(s) | v2.cmpge(s));
            m |= ((!differ.bitmask() & 0xf) as LaneMask) << (4 * q);
        }
        (m, values)
    }

    /// The view samples of `lanes` that no bounding plane of `planes` (one bit each) puts on
    /// its negative side (a NaN value rejects nothing); stops when no view sample is left.
    #[inline]
    fn inside(&self, t: &TileQuads, lanes: LaneMask, planes: u32) -> LaneMask {
        let mut alive = lanes;
        for k in bits_of(u64::from(planes)) {
            if alive == 0 {
                break;
            }
            let [nx, ny, nz, d] = plane_of(&self.planes, k).map(Vec4::splat);
            for q in 0..QUADS {
                let v = nx * t.x[q] + ny * t.y[q] + nz * t.z[q] + d;
                alive &= !((v.cmplt(Vec4::ZERO).bitmask() as LaneMask) << (4 * q));
            }
        }
        alive
    }
}
