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
//! * **View samples** of a tile ([`crate::lanes`]): a surviving wedge's fold planes, bounding
//!   planes and weight `k_e(p)` on every view sample at once; each view sample inside the
//!   planes with a non-zero weight makes a (pixel, edge) pair. Only the bounding planes that
//!   may cut the tile's box are evaluated on its view samples ([`ScanWedge::cut_planes`]): on
//!   `bunny` that cut `dcs-64` from 1982 M to 1918 M instructions.
//!
//! A box keeps a wedge when none of the wedge's bounding planes ([`crate::wedges::wedge_planes`])
//! has the whole box on its negative side, and the edge may be a silhouette from some point of
//! the box (its two face planes, with a slack). A test loads one wedge's planes and evaluates
//! each at the boxes' corners farthest along its normal (and, for the face planes, the nearest
//! ones too), four boxes at a time, the bounds in packed vectors. Boxes are padded by their own
//! rounding, so that no test rejects a view sample that the exact test on the lanes would
//! keep.

use glam::{BVec4A, DVec3, Vec3, Vec4};
use rayon::prelude::*;

use crate::centred::FastWeight;
use crate::centred::{CentredEdge, CentredPlane};
use crate::edges::SceneEdge;
use crate::lanes::{
    LANES, LaneMask, QUADS, TILE_H, TILE_W, TileLanes, TileQuads, lanes_of, rect_lanes,
};
use crate::planar::{PlanarEdge, PlanarTest};
use crate::wedges::{Pair, Wedge};

/// Side of a block, in pixels (a multiple of [`SQUARE`]). 128 rather than 64 since the box
/// tests got cheaper (`bunny` `dcs-64`: 2176 M -> 2158 M instructions; 32: 2459 M).
pub(crate) const BLOCK: u32 = 128;

/// Side of a square, in pixels (a multiple of [`TILE_W`] and [`TILE_H`]).
pub(crate) const SQUARE: u32 = 16;

/// Bounding planes per wedge in the box tests: more are dropped (any subset of a wedge's
/// bounding planes bounds it). Eight fill two groups of four ([`PlaneGroup`]). The built-in
/// scenes' wedges have 4 to 9 planes (`bunny`: 2,410 with 4, 25,620 with 6, 3 with 8, 2 with
/// 9; `quad-over-plane` and `overlapping-occluders` 8 or 9); with 8 rather than 10 the tile
/// candidates, pairs and covered updates are the same on every built-in scene, and a wedge
/// took 448 bytes instead of 512 while it was one record (`bunny` `dcs-64`: 1784 M -> 1770 M
/// instructions, simulated last-level misses 2,516 k -> 2,207 k, wall time 5% lower); its
/// box-test record ([`ScanWedge`]) now takes 192.
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
/// planes, then the groups of bounding planes, up to eight planes in three lines (192 bytes).
/// Left to the compiler, the fields were reordered (the tile data first, the count after the
/// weight), and a box test touched five lines of 656 bytes; in declaration order `bunny`'s
/// simulated last-level misses fell by 10% (3,029 k to 2,729 k), with no change in wall time
/// measured. The bounding planes are kept once, four to a group in structure-of-arrays form,
/// which both the box tests (one plane at a time) and [`ScanWedge::cut_planes`] (a group at a
/// time) read. With a second copy in plane-by-plane form a wedge took 704 bytes; one copy took
/// it to 512 and `bunny` `dcs-64` from 0.138 s to 0.118 s on two threads (`scripts/dcs_ab.sh`,
/// 8 rounds; 0.262 s to 0.219 s on one), for the same instructions (1786 M -> 1784 M) and 4%
/// fewer simulated L1 misses: smaller records are what a square's wedges keep in the caches.
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
/// densely packed 192-byte records rather than 448-byte ones: `bunny` `dcs-64` 1758 M -> 1763 M
/// instructions, and in wall time 0.1237 s -> 0.1208 s on two threads (8 A/B rounds), 0.236 s
/// -> 0.225 s on one (mean of 8 alternating runs).
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

/// Up to [`BOXES`] boxes of light-centred view samples in packed form (lower and upper bounds
/// along each axis, four boxes to a vector), padded by the rounding of the tests.
///
/// A plane's largest value over a box is at the corner farthest along its normal: per axis the
/// upper bound where the normal's component is not negative, else the lower one. The plane
/// picks those bounds once for all the boxes, so a (plane, four boxes) test is three products
/// and three sums, as a plane on four view samples is.
#[derive(Debug, Clone, Default)]
pub(crate) struct Boxes {
    /// Per axis, the upper bounds (`[k][0]`) and the lower ones (`[k][1]`), four boxes to a
    /// vector (fixed arrays: a plane's pick of bounds is then one pointer per axis, indexed by
    /// the sign bit of the normal's component, and indices below [`Boxes::quads`] need no
    /// check).
    bounds: [[[Vec4; BOXES / 4]; 2]; 3],
    /// Vectors in use.
    quads: usize,
    /// The boxes that exist (one bit each).
    valid: u64,
}

impl Boxes {
    /// Sets the boxes (`None`: a box without view samples, which no test keeps).
    pub fn set(&mut self, boxes: impl IntoIterator<Item = Option<(Vec3, Vec3)>>) {
        self.valid = 0;
        self.quads = 0;
        for (i, b) in boxes.into_iter().enumerate() {
            assert!(i < BOXES, "at most {BOXES} boxes");
            let (q, lane) = (i / 4, i % 4);
            if lane == 0 {
                // A new vector of four boxes, none yet.
                for v in self.bounds.iter_mut().flatten() {
                    v[q] = Vec4::ZERO;
                }
                self.quads = q + 1;
            }
            if let Some((lo, hi)) = b {
                // Padded around the centre by far more than the rounding of the bounds below
                // and of a plane evaluated at a corner.
                let m = (lo + hi) * 0.5;
                let h = (hi - lo) * 0.5;
                let h = h + (m.abs() + h) * BOX_PAD;
                let (lo, hi) = (m - h, m + h);
                for k in 0..3 {
                    self.bounds[k][0][q][lane] = hi[k];
                    self.bounds[k][1][q][lane] = lo[k];
                }
                self.valid |= 1 << i;
            }
        }
    }

    /// Per axis, the bounds at the boxes' corners farthest along `n` (the plane's largest
    /// values) and at the nearest ones (its smallest).
    #[inline(always)]
    fn corners(&self, [x, y, z, _]: [f32; 4]) -> Corners<'_> {
        // The sign bit picks the bounds without a comparison (a zero or NaN component may
        // take either: its products are zero or NaN at both).
        let pick = |k: usize, c: f32| {
            let neg = (c.to_bits() >> 31) as usize;
            (&self.bounds[k][neg], &self.bounds[k][neg ^ 1])
        };
        let ((fx, nx), (fy, ny), (fz, nz)) = (pick(0, x), pick(1, y), pick(2, z));
        ([fx, fy, fz], [nx, ny, nz])
    }

    /// [`Boxes::test`] on the quads of boxes in `quads` (one bit per quad) alone; the other
    /// boxes are not kept.
    pub fn test_quads(&self, w: &ScanWedge, slack: f32, quads: u64) -> u64 {
        let n = self.quads.min(BOXES / 4);
        let mut live = [0usize; BOXES / 4];
        let mut count = 0;
        for q in bits_of(quads & ((1 << n) - 1)) {
            live[count] = q;
            count += 1;
        }
        let live = &live[..count];
        let mut reject = [BVec4A::splat(false); BOXES / 4];
        each_plane(&w.planes, w.used as usize, |p| {
            let ([x, y, z], _) = self.corners(p);
            let s = p.map(Vec4::splat);
            for (r, &q) in reject.iter_mut().zip(live) {
                *r |= eval(s, x[q], y[q], z[q]).cmplt(Vec4::ZERO);
            }
        });
        let fold = FoldTest::new(self, w, slack);
        let mut mask = 0u64;
        for (r, &q) in reject.iter().zip(live) {
            mask |= fold.kept(*r, q) << (4 * q);
        }
        mask & self.valid
    }

    /// The boxes (one bit each) that may hold a view sample of wedge `w`: no bounding plane has
    /// the whole box on its negative side, and the fold planes do not both surely differ in
    /// sign over it (a NaN keeps the box). `slack` is the fold test's slack.
    #[inline]
    pub fn test(&self, w: &ScanWedge, slack: f32) -> u64 {
        // Up to 16 boxes (a square's tiles, a block's clusters): four vectors, unrolled, the
        // rejections in registers; the unused vectors' boxes are not valid.
        if self.quads <= SMALL_QUADS {
            self.test_quads_up_to::<SMALL_QUADS>(w, slack, SMALL_QUADS)
        } else {
            self.test_quads_up_to::<{ BOXES / 4 }>(w, slack, self.quads)
        }
    }

    /// [`Boxes::test`] on the first `quads` vectors (at most `Q`).
    #[inline(always)]
    fn test_quads_up_to<const Q: usize>(&self, w: &ScanWedge, slack: f32, quads: usize) -> u64 {
        let quads = quads.min(Q);
        let mut reject = [BVec4A::splat(false); Q];
        each_plane(&w.planes, w.used as usize, |p| {
            let ([x, y, z], _) = self.corners(p);
            let n = p.map(Vec4::splat);
            for q in 0..quads {
                reject[q] |= eval(n, x[q], y[q], z[q]).cmplt(Vec4::ZERO);
            }
        });
        let fold = FoldTest::new(self, w, slack);
        let mut mask = 0u64;
        for (q, r) in reject[..quads].iter().enumerate() {
            mask |= fold.kept(*r, q) << (4 * q);
        }
        mask & self.valid
    }
}

/// Vectors of boxes that [`Boxes::test`] tests unrolled.
const SMALL_QUADS: usize = 4;

/// Per axis, one bound array of a [`Boxes`] for the farthest corners, then for the nearest.
type Corners<'a> = ([&'a [Vec4; BOXES / 4]; 3], [&'a [Vec4; BOXES / 4]; 3]);

/// A plane's four coefficients, each in all lanes.
#[inline(always)]
fn splat(p: Vec4) -> [Vec4; 4] {
    p.to_array().map(Vec4::splat)
}

/// The plane `[nx, ny, nz, d]` (splatted) at the points `(x, y, z)`, four at a time.
#[inline(always)]
fn eval([nx, ny, nz, d]: [Vec4; 4], x: Vec4, y: Vec4, z: Vec4) -> Vec4 {
    nx * x + ny * y + nz * z + d
}

/// The fold part of a box test: a wedge's two face planes at the boxes' farthest and nearest
/// corners.
struct FoldTest<'a> {
    planes: [[Vec4; 4]; 2],
    far: [[&'a [Vec4; BOXES / 4]; 3]; 2],
    near: [[&'a [Vec4; BOXES / 4]; 3]; 2],
    slack: Vec4,
}

impl<'a> FoldTest<'a> {
    #[inline(always)]
    fn new(boxes: &'a Boxes, w: &ScanWedge, slack: f32) -> Self {
        let [f1, f2] = w.fold;
        let ((far1, near1), (far2, near2)) =
            (boxes.corners(f1.to_array()), boxes.corners(f2.to_array()));
        Self {
            planes: [splat(f1), splat(f2)],
            far: [far1, far2],
            near: [near1, near2],
            slack: Vec4::splat(slack),
        }
    }

    /// The boxes of quad `q` kept (one bit each), given the bounding planes' rejections.
    #[inline(always)]
    fn kept(&self, reject: BVec4A, q: usize) -> u64 {
        // Four boxes the planes reject (most of them: a wedge meets few of a grid's cells)
        // need no fold test.
        if reject.all() {
            return 0;
        }
        let value =
            |k: usize, c: &[&[Vec4; BOXES / 4]; 3]| eval(self.planes[k], c[0][q], c[1][q], c[2][q]);
        let s = self.slack;
        // Surely no silhouette: the fold planes surely differ in sign over the whole box.
        let not_both_positive = value(0, &self.far[0]).cmple(-s) | value(1, &self.far[1]).cmple(-s);
        let not_both_negative = value(0, &self.near[0]).cmpge(s) | value(1, &self.near[1]).cmpge(s);
        let out = reject | (not_both_positive & not_both_negative);
        u64::from(!out.bitmask() & 0xf)
    }
}

/// The set bits of a mask, in order.
#[inline]
pub(crate) fn bits_of(mut m: u64) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (m != 0).then(|| {
            let j = m.trailing_zeros() as usize;
            m &= m - 1;
            j
        })
    })
}

/// A rectangle of pixels, inclusive bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Rect {
    pub cols: (u32, u32),
    pub rows: (u32, u32),
}

impl Rect {
    /// Number of pixels.
    pub fn len(&self) -> usize {
        ((self.cols.1 - self.cols.0 + 1) * (self.rows.1 - self.rows.0 + 1)) as usize
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.cols.1 - self.cols.0 + 1
    }

    /// The image indices of the pixels, row by row.
    pub fn pixels(&self, image_width: u32) -> impl Iterator<Item = usize> + use<> {
        let (c, r, w) = (self.cols, self.rows, image_width as usize);
        (r.0..=r.1).flat_map(move |y| (c.0..=c.1).map(move |x| y as usize * w + x as usize))
    }
}

/// The rectangles of side `side` covering `cols` x `rows`, row by row.
fn grid(cols: (u32, u32), rows: (u32, u32), side: u32) -> impl Iterator<Item = Rect> {
    (rows.0..=rows.1).step_by(side as usize).flat_map(move |y| {
        (cols.0..=cols.1).step_by(side as usize).map(move |x| Rect {
            cols: (x, (x + side - 1).min(cols.1)),
            rows: (y, (y + side - 1).min(rows.1)),
        })
    })
}

/// The blocks of an image, each with its squares.
pub(crate) fn blocks(width: u32, height: u32) -> Vec<(Rect, Vec<Rect>)> {
    if width == 0 || height == 0 {
        return Vec::new();
    }
    grid((0, width - 1), (0, height - 1), BLOCK)
        .map(|b| (b, grid(b.cols, b.rows, SQUARE).collect()))
        .collect()
}

/// The first level of the hierarchy for a frame: which blocks' boxes keep each wedge.
pub(crate) struct BlockWedges {
    /// Per wedge, one mask word per group of [`BOXES`] blocks.
    masks: Vec<u64>,
    groups: usize,
    /// Per block, its squares' boxes (the view samples are read once for all levels above
    /// the tiles).
    square_boxes: Vec<Vec<ViewBox>>,
}

/// The box of some view samples, `None` when there are none.
type ViewBox = Option<(Vec3, Vec3)>;

/// The box around some boxes.
fn union_of<'a>(boxes: impl IntoIterator<Item = &'a ViewBox>) -> ViewBox {
    boxes
        .into_iter()
        .flatten()
        .copied()
        .reduce(|(lo, hi), (l, h)| (lo.min(l), hi.max(h)))
}

impl BlockWedges {
    /// Every wedge against the boxes of `blocks`, [`BOXES`] blocks per test, in parallel.
    pub fn new(input: &ScanInput, blocks: &[(Rect, Vec<Rect>)]) -> Self {
        let square_boxes: Vec<Vec<ViewBox>> = blocks
            .par_iter()
            .map(|(_, squares)| {
                squares
                    .iter()
                    .map(|r| rect_box(*r, input.width, input.centred, input.active))
                    .collect()
            })
            .collect();
        let groups: Vec<Boxes> = square_boxes
            .chunks(BOXES)
            .map(|g| {
                let mut b = Boxes::default();
                b.set(g.iter().map(union_of));
                b
            })
            .collect();
        let masks = input
            .wedges
            .par_iter()
            .flat_map_iter(|w| groups.iter().map(move |g| g.test(w, input.slack)))
            .collect();
        Self {
            masks,
            groups: groups.len(),
            square_boxes,
        }
    }

    /// The second level for block `block` (with squares `squares`): the wedges its box keeps
    /// against the boxes of its clusters of [`CLUSTER`] x [`CLUSTER`] pixels, then those a
    /// cluster keeps against its squares' boxes. Returns each square's wedges (silhouette
    /// indices in order) and the number of wedges the block kept.
    ///
    /// The block's wedges are tested [`LIST_CHUNK`] at a time in parallel and the chunks'
    /// lists joined in order: a block holding much of the penumbra keeps thousands of wedges,
    /// and testing them on one thread left the other idle at the end of the frame.
    pub fn square_lists(
        &self,
        input: &ScanInput,
        block: usize,
        squares: &[Rect],
    ) -> (Vec<Vec<u32>>, usize) {
        let (g, bit) = (block / BOXES, block % BOXES);
        let clusters = Clusters::new(squares, &self.square_boxes[block]);
        let kept: Vec<u32> = (0..input.wedges.len() as u32)
            .filter(|&wi| self.masks[wi as usize * self.groups + g] >> bit & 1 == 1)
            .collect();
        let chunk_lists = |chunk: &[u32]| {
            let mut lists: Vec<Vec<u32>> = vec![Vec::new(); squares.len()];
            for &wi in chunk {
                let w = &input.wedges[wi as usize];
                let live = clusters.boxes.test(w, input.slack);
                if live == 0 {
                    continue;
                }
                for slot in bits_of(clusters.squares.test_quads(w, input.slack, live)) {
                    lists[clusters.slots[slot]].push(wi);
                }
            }
            lists
        };
        if kept.len() <= LIST_CHUNK {
            return (chunk_lists(&kept), kept.len());
        }
        let parts: Vec<Vec<Vec<u32>>> = kept.par_chunks(LIST_CHUNK).map(chunk_lists).collect();
        let mut lists: Vec<Vec<u32>> = (0..squares.len())
            .map(|s| Vec::with_capacity(parts.iter().map(|p| p[s].len()).sum()))
            .collect();
        for part in &parts {
            for (l, p) in lists.iter_mut().zip(part) {
                l.extend_from_slice(p);
            }
        }
        (lists, kept.len())
    }
}

/// Wedges per parallel task of [`BlockWedges::square_lists`].
const LIST_CHUNK: usize = 1024;

/// Side of a cluster of squares, in pixels: the level between blocks and squares.
const CLUSTER: u32 = 2 * SQUARE;

/// A block's squares grouped by clusters of [`CLUSTER`] x [`CLUSTER`] pixels: a wedge a block
/// keeps meets few of its squares, so the clusters are tested first and then only the squares
/// of the clusters kept, each cluster's (at most four) squares one quad of the square boxes.
struct Clusters {
    /// The clusters' boxes.
    boxes: Boxes,
    /// The squares' boxes, cluster by cluster, four slots per cluster.
    squares: Boxes,
    /// The square (index into the block's squares) of each slot; unused slots have no box.
    slots: Vec<usize>,
}

impl Clusters {
    /// The clusters of `squares`, whose boxes are `boxes`.
    fn new(squares: &[Rect], boxes: &[ViewBox]) -> Self {
        let Some(first) = squares.first() else {
            return Self {
                boxes: Boxes::default(),
                squares: Boxes::default(),
                slots: Vec::new(),
            };
        };
        let (x0, y0) = (first.cols.0, first.rows.0);
        let right = squares.iter().map(|r| r.cols.1).max().unwrap_or(x0);
        let across = (right - x0) / CLUSTER + 1;
        let mut slots = Vec::new();
        for (s, r) in squares.iter().enumerate() {
            let (cx, cy) = ((r.cols.0 - x0) / CLUSTER, (r.rows.0 - y0) / CLUSTER);
            let (sx, sy) = ((r.cols.0 - x0) / SQUARE % 2, (r.rows.0 - y0) / SQUARE % 2);
            let slot = ((cy * across + cx) * 4 + sy * 2 + sx) as usize;
            if slots.len() <= slot {
                slots.resize(slot + 1, usize::MAX);
            }
            slots[slot] = s;
        }
        slots.resize(slots.len().next_multiple_of(4), usize::MAX);
        // Each slot's box (unused slots have none).
        let slot_boxes: Vec<ViewBox> = slots
            .iter()
            .map(|&s| boxes.get(s).copied().flatten())
            .collect();
        let mut cluster_boxes = Boxes::default();
        cluster_boxes.set(slot_boxes.chunks(4).map(union_of));
        let mut sq = Boxes::default();
        sq.set(slot_boxes);
        Self {
            boxes: cluster_boxes,
            squares: sq,
            slots,
        }
    }
}

/// The box of the active light-centred view samples of `rect`, `None` when it has none.
pub(crate) fn rect_box(
    rect: Rect,
    width: u32,
    centred: &[Vec3],
    active: &[bool],
) -> Option<(Vec3, Vec3)> {
    let mut b: Option<(Vec3, Vec3)> = None;
    for i in rect.pixels(width) {
        if active[i] {
            let p = centred[i];
            b = Some(match b {
                Some((lo, hi)) => (lo.min(p), hi.max(p)),
                None => (p, p),
            });
        }
    }
    b
}

/// The (pixel, edge, weight) pairs of a square, one list per pixel that the scan appends to
/// directly (buffers kept from square to square). Pixels are numbered tile by tile (row by row
/// of tiles), then lane by lane within a tile.
#[derive(Debug, Default)]
pub(crate) struct SquarePairs {
    rect: Option<Rect>,
    /// Tiles per row of tiles.
    across: usize,
    /// Pixels of the square (tiles times lanes, padding included).
    pixels: usize,
    /// Each pixel's pairs for the 3D test, in wedge order (empty lists for pixels that take
    /// the light-plane test).
    entries: Vec<Vec<Pair>>,
    /// Each pixel's pairs for the light-plane test, in wedge order, each test carrying its
    /// pair's weight (empty lists for pixels that take the 3D test).
    tests: Vec<Vec<PlanarTest>>,
    /// Number of pairs.
    len: usize,
    /// What the scan did.
    pub counts: ScanCounts,
}

/// Work counters of the wedge scan.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct ScanCounts {
    /// Pairs dropped on the tie of the light-plane test's orientation.
    pub ties: u64,
    /// View samples whose weight took the exact form.
    pub exact_weights: u64,
    /// View samples tested against a wedge's planes and weight.
    pub scanned: u64,
    /// (tile, wedge) candidates evaluated on the tile's view samples.
    pub tile_wedges: u64,
    /// Wedges kept by the squares' boxes.
    pub square_wedges: u64,
}

impl ScanCounts {
    /// Adds `o`'s counts.
    pub fn add(&mut self, o: &ScanCounts) {
        self.ties += o.ties;
        self.exact_weights += o.exact_weights;
        self.scanned += o.scanned;
        self.tile_wedges += o.tile_wedges;
        self.square_wedges += o.square_wedges;
    }
}

impl SquarePairs {
    /// The square's pixels inside the image: `(j, x, y)` with `j` the pixel's number.
    pub fn pixels(&self) -> impl Iterator<Item = (usize, u32, u32)> + '_ {
        let r = self.rect.expect("pairs of a square");
        let across = self.across;
        (0..self.pixels).filter_map(move |j| {
            let (t, lane) = (j / LANES, j % LANES);
            let x = r.cols.0 + (t % across) as u32 * TILE_W + (lane as u32 % TILE_W);
            let y = r.rows.0 + (t / across) as u32 * TILE_H + (lane as u32 / TILE_W);
            (x <= r.cols.1 && y <= r.rows.1).then_some((j, x, y))
        })
    }

    /// The pairs of pixel number `j`: for the 3D test, and for the light-plane test (one of
    /// the two is empty).
    pub fn of(&self, j: usize) -> (&[Pair], &[PlanarTest]) {
        (&self.entries[j], &self.tests[j])
    }

    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Empties the lists for a square of `pixels` pixels.
    fn reset(&mut self, pixels: usize) {
        self.pixels = pixels;
        self.len = 0;
        let n = self.entries.len().max(pixels);
        self.entries.resize_with(n, Vec::new);
        self.tests.resize_with(n, Vec::new);
        self.entries.iter_mut().for_each(Vec::clear);
        self.tests.iter_mut().for_each(Vec::clear);
    }
}

/// A square's tiles (the hierarchy's third level): their view samples and what the wedges'
/// tests read of each tile, in one record per tile.
#[derive(Default)]
pub(crate) struct SquareTiles {
    rect: Option<Rect>,
    boxes: Boxes,
    /// Tiles per row of tiles.
    pub across: usize,
    /// Each tile's view samples.
    pub lanes: Vec<TileLanes>,
    /// Each tile's box.
    bounds: Vec<ViewBox>,
    /// Each tile's test data.
    tiles: Vec<ScanTile>,
}

/// What a wedge's test on a tile's view samples reads: the view samples as packed quads, the
/// tile's box, each lane's image index, the lanes that take the light-plane test, and the
/// number of active lanes.
#[derive(Clone, Copy)]
struct ScanTile {
    quads: TileQuads,
    extent: TileExtent,
    pixels: [usize; LANES],
    planar_lanes: LaneMask,
    /// Active view samples (this target has no population count instruction: counted once
    /// per tile, not once per wedge).
    active: u32,
}

impl SquareTiles {
    /// The tiles of square `rect`.
    pub fn set(&mut self, input: &ScanInput, rect: Rect) {
        self.rect = Some(rect);
        self.across = rect_lanes(
            input.width,
            rect.cols,
            rect.rows,
            input.centred,
            input.active,
            &mut self.lanes,
        );
        self.bounds.clear();
        self.bounds.extend(self.lanes.iter().map(TileLanes::bounds));
        self.boxes.set(self.bounds.iter().copied());
        // Each lane's image index from its tile's first.
        let w = input.width as usize;
        let offsets: [usize; LANES] =
            std::array::from_fn(|j| j / TILE_W as usize * w + j % TILE_W as usize);
        self.tiles.clear();
        for (t, (tile, bounds)) in self.lanes.iter().zip(&self.bounds).enumerate() {
            let (x, y) = self.origin(t);
            let pixels = offsets.map(|o| y as usize * w + x as usize + o);
            let planar_lanes = match input.planar {
                Some((_, marked)) => lanes_of(tile.active)
                    .filter(|&j| marked[pixels[j]])
                    .fold(0, |m, j| m | 1 << j),
                None => 0,
            };
            self.tiles.push(ScanTile {
                quads: tile.quads(),
                extent: TileExtent::new(*bounds),
                pixels,
                planar_lanes,
                active: tile.active.count_ones(),
            });
        }
    }

    /// The image column and row of tile `t`'s first view sample.
    pub fn origin(&self, t: usize) -> (u32, u32) {
        let r = self.rect.expect("tiles of a square");
        (
            r.cols.0 + (t % self.across) as u32 * TILE_W,
            r.rows.0 + (t / self.across) as u32 * TILE_H,
        )
    }
}

/// The weights of wedge `wi` at the view samples of a tile (`tile`, `quads`, its box
/// `extent`, the image index of each lane in `pixels`): the fold planes (where the edge may be
/// a silhouette), then the bounding planes that may cut the tile's box on the view samples
/// left, then the weights where any is inside, exact where the single-precision signs are
/// uncertain. Returns the lanes with a non-zero weight (one bit each) and the weights, which
/// only the lanes of that mask may read (the others hold whatever the lane form gave them).
#[inline]
pub(crate) fn tile_weights(
    input: &ScanInput,
    wi: u32,
    tile: &TileLanes,
    quads: &TileQuads,
    extent: &TileExtent,
    pixels: &[usize; LANES],
    counts: &mut ScanCounts,
) -> (LaneMask, [i32; LANES]) {
    let wedge = &input.wedges[wi as usize];
    // Where the edge cannot be a silhouette of the view sample (its face planes surely differ
    // in sign there), the weight is zero: those view samples take neither the weight nor the
    // planes, and most tiles a wedge's box test keeps have none left.
    let (fold, values) = wedge.fold_lanes(quads, input.slack);
    let fold = fold & tile.active;
    if fold == 0 {
        return (0, [0; LANES]);
    }
    // Where the edge may be a silhouette its weight is rarely zero (on `bunny`, at no view
    // sample the fold test keeps), so the planes come first and the weights are taken only
    // for tiles with a view sample inside.
    let inside = wedge.inside(quads, fold, wedge.cut_planes(extent));
    if inside == 0 {
        return (0, [0; LANES]);
    }
    let weight = &input.lanes[wi as usize].weight;
    let faces = wedge.folded.then_some(&values);
    // The certain lanes' weights come whole from the lane form, every lane converted at once
    // (branch-free: a loop over the lanes not zero cost more, one mispredicted exit per
    // call); the uncertain ones (a few in a thousand on `bunny`) take the exact weight one
    // by one.
    let (mut ks, mut nonzero, exact) =
        match weight.as_ref().and_then(|f| f.weight_lanes(quads, faces)) {
            Some(f) => (
                std::array::from_fn(|j| f.k(j)),
                inside & f.certain & f.nonzero,
                inside & !f.certain,
            ),
            None => ([0i32; LANES], 0, inside),
        };
    for j in lanes_of(exact) {
        counts.exact_weights += 1;
        let e = &input.edges[wedge.edge as usize];
        let Some(k) = e.sweep_weight(input.origins[pixels[j]].as_dvec3(), input.c, false) else {
            continue;
        };
        if k != 0 {
            ks[j] = k.clamp(i32::MIN as i64, i32::MAX as i64) as i32;
            nonzero |= 1 << j;
        }
    }
    (nonzero, ks)
}

/// The light-plane test of wedge `wi` (`pe`, its edge in light-plane form) from view sample
/// `i` (`pc`, its light-centred position, taken from the tile's lanes rather than the image so
/// that a pair reads no more of the frame; `l1` at least `|pc|_1`): `None` on the tie of the
/// orientation.
#[inline]
pub(crate) fn planar_test(
    input: &ScanInput,
    pe: &PlanarEdge,
    wi: u32,
    i: usize,
    pc: Vec3,
    l1: f32,
) -> Option<PlanarTest> {
    let exact = || {
        let centred_edges = input.planar.map_or(&[][..], |(e, _)| e);
        let pc = input.origins[i].as_dvec3() - input.c;
        centred_edges[wi as usize].orientation(pc)
    };
    pe.test(pc, l1, exact)
}

/// Per-thread buffers of the square scan.
#[derive(Default)]
pub(crate) struct SquareScratch {
    tiles: SquareTiles,
}

/// What the wedge scan reads of a frame.
pub(crate) struct ScanInput<'a> {
    pub edges: &'a [SceneEdge],
    pub wedges: &'a [ScanWedge],
    /// The same wedges' data for the view samples' pass.
    pub lanes: &'a [WedgeLanes],
    /// The light centre.
    pub c: DVec3,
    pub width: u32,
    pub origins: &'a [Vec3],
    pub centred: &'a [Vec3],
    pub active: &'a [bool],
    /// Slack of the fold test.
    pub slack: f32,
    /// With the light-plane form of the covered-sample test: the silhouette edges around the
    /// light centre (for its orientation ties) and the pixels that take it (the others take
    /// the 3D test).
    pub planar: Option<(&'a [CentredEdge], &'a [bool])>,
}

/// The pairs of square `rect` from the wedges its box keeps (`wedges`, silhouette indices in
/// order), wedge by wedge: its box test against the square's tiles, then on the view samples of
/// each tile it keeps (fold planes, bounding planes, then the weight, exact where the
/// single-precision signs are uncertain), with the light-plane test set up while the wedge is
/// at hand. Each wedge's data is read once per square: tile by tile, with a list of wedges per
/// tile, a wedge came back once per tile it met, after the other wedges had evicted it. On
/// `bunny` (`scripts/dcs_instructions.sh --cache bunny dcs-64`) wedge by wedge took the
/// simulated L1 data misses from 10.27 M to 9.21 M and `dcs-64` from 0.158 s to 0.146 s on two
/// threads, for 2% more instructions (1746 M -> 1786 M).
pub(crate) fn square_pairs(
    input: &ScanInput,
    wedges: &[u32],
    rect: Rect,
    out: &mut SquarePairs,
    scratch: &mut SquareScratch,
) {
    out.rect = Some(rect);
    out.counts = ScanCounts::default();
    let SquareScratch { tiles } = scratch;
    tiles.set(input, rect);
    out.across = tiles.across;
    out.reset(tiles.lanes.len() * LANES);
    let mut ties = 0;
    let mut len = 0;
    let counts = &mut out.counts;
    counts.square_wedges += wedges.len() as u64;
    for &wi in wedges {
        let wedge = &input.wedges[wi as usize];
        let mask = tiles.boxes.test(wedge, input.slack);
        for t in bits_of(mask) {
            let (tile, scan) = (&tiles.lanes[t], &tiles.tiles[t]);
            // Counted here rather than by the mask's population count, which this target
            // computes in software.
            counts.tile_wedges += 1;
            counts.scanned += u64::from(scan.active);
            let entries = &mut out.entries[t * LANES..(t + 1) * LANES];
            let tests = &mut out.tests[t * LANES..(t + 1) * LANES];
            let (pairs, ks) = tile_weights(
                input,
                wi,
                tile,
                &scan.quads,
                &scan.extent,
                &scan.pixels,
                counts,
            );
            if pairs == 0 {
                continue;
            }
            // Read here, not per wedge: a wedge whose tiles give no pair leaves its lanes'
            // record untouched. The light-plane form is copied out once for the tile's pairs,
            // so that its rows stay in registers across them (read pair by pair, they were
            // loaded again for each).
            let pe = input.lanes[wi as usize].planar;
            let planar = if pe.is_some() {
                pairs & scan.planar_lanes
            } else {
                0
            };
            for j in lanes_of(pairs & !planar) {
                entries[j].push(Pair { edge: wi, k: ks[j] });
                len += 1;
            }
            if let (Some(pe), true) = (pe, planar != 0) {
                for j in lanes_of(planar) {
                    let pc = Vec3::new(tile.x[j], tile.y[j], tile.z[j]);
                    match planar_test(input, &pe, wi, scan.pixels[j], pc, tile.l1[j]) {
                        Some(mut t) => {
                            t.k = ks[j];
                            tests[j].push(t);
                            len += 1;
                        }
                        None => ties += 1,
                    }
                }
            }
        }
    }
    out.counts.ties += ties;
    out.len = len;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edges::{Silhouettes, scene_edges, silhouettes};
    use crate::light_shape::LightShape;
    use crate::wedges::{FOLD_SLACK, wedges};
    use shadow_core::offset::RayOffset;
    use shadow_core::prelude::*;

    /// The box test keeps the same boxes whether it runs unrolled (up to 16 boxes) or over
    /// all 64, and as [`Boxes::test_quads`] on every vector: the wedges of `bunny` against
    /// boxes around its view samples, some of them empty.
    #[test]
    fn box_tests_agree_unrolled_and_not() {
        let setup = shadow_core::scenes::builtin("bunny").unwrap();
        let scene = setup.scene.as_ref();
        let (w, h) = (64, 48);
        let view = ViewSamples::render(scene, &setup.camera_or_default(), w, h).unwrap();
        let light = setup.lights[0].as_ref();
        let shape = LightShape::new(light, "test").unwrap();
        let (edges, _) = scene_edges(scene, shape.center);
        let sil = silhouettes(&edges, &shape, Silhouettes::Accurate);
        let scan: Vec<ScanWedge> = wedges(&edges, &sil, &shape)
            .iter()
            .map(|w| ScanWedge::new(w, None).0)
            .collect();
        let c = shape.center.as_dvec3();
        let n = view.len();
        let mut centred = vec![Vec3::ZERO; n];
        let mut active = vec![false; n];
        for i in 0..n {
            if let Some(s) = view.get(i) {
                centred[i] = (s.position.as_dvec3() - c).as_vec3();
                active[i] = true;
            }
        }
        // Boxes of 4 x 4 pixels over the whole image: 192, shuffled (so that every vector
        // holds some the wedges meet), taken 16 and 64 at a time.
        let grid_boxes: Vec<ViewBox> = grid((0, w - 1), (0, h - 1), 4)
            .map(|r| rect_box(r, w, &centred, &active))
            .collect();
        let boxes: Vec<ViewBox> = (0..grid_boxes.len())
            .map(|i| grid_boxes[i * 37 % grid_boxes.len()])
            .collect();
        assert!(boxes.iter().any(Option::is_none), "some boxes are empty");
        let slack = 1e-6;
        let (mut kept, mut compared) = (0u32, 0u32);
        for big in boxes.chunks(BOXES) {
            let mut all = Boxes::default();
            all.set(big.iter().copied());
            for (g, small) in big.chunks(16).enumerate() {
                let mut few = Boxes::default();
                few.set(small.iter().copied());
                for sw in scan.iter().step_by(7) {
                    let want = few.test(sw, slack);
                    let got = all.test(sw, slack) >> (16 * g) & 0xffff;
                    assert_eq!(got, want);
                    assert_eq!(few.test_quads(sw, slack, 0xf), want);
                    kept += want.count_ones();
                    compared += 1;
                }
            }
        }
        assert!(
            compared > 1000 && kept > 100,
            "{kept} kept in {compared} tests"
        );
    }

    /// Uniform values in `[0, 1)` from a linear congruential sequence started at `seed`.
    fn uniform(mut seed: u64) -> impl FnMut() -> f32 {
        move || {
            seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
            (seed >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// A plane that [`ScanWedge::cut_planes`] leaves out is positive at every view sample of
    /// the tile, far from the origin and with planes through a view sample (value zero up to
    /// rounding); planes well clear of the box are left out.
    #[test]
    fn planes_left_out_of_a_tile_reject_none_of_its_view_samples() {
        let mut rand = uniform(0x9e37_79b9_7f4a_7c15u64);
        let (mut left_out, mut kept) = (0, 0);
        for round in 0..400 {
            let scale = [1e-3f32, 1.0, 1e3][round % 3];
            let centre = Vec3::new(rand(), rand(), rand()) * 2.0 * scale - scale;
            let extent = Vec3::new(rand(), rand(), rand()) * 0.01 * scale;
            let mut tile = TileLanes::at(centre);
            for j in 0..LANES {
                let p = centre + (Vec3::new(rand(), rand(), rand()) * 2.0 - 1.0) * extent;
                (tile.x[j], tile.y[j], tile.z[j]) = (p.x, p.y, p.z);
                tile.l1[j] = p.abs().element_sum();
            }
            tile.active = LaneMask::MAX;
            let quads = tile.quads();
            let mut planes = [OPEN; BOX_PLANES];
            for (k, plane) in planes.iter_mut().enumerate() {
                let n = (Vec3::new(rand(), rand(), rand()) * 2.0 - 1.0).normalize_or(Vec3::X);
                // Through a view sample, or at some distance from one (either side).
                let j = k % LANES;
                let at = n.dot(Vec3::new(tile.x[j], tile.y[j], tile.z[j]));
                let shift = if k % 3 == 0 {
                    0.0
                } else {
                    (rand() * 2.0 - 1.0) * extent.length() * 3.0
                };
                *plane = n.extend(-at + shift);
            }
            let w = ScanWedge {
                planes: std::array::from_fn(|g| PlaneGroup::new(&planes, g)),
                fold: [OPEN, OPEN],
                folded: false,
                used: BOX_PLANES as u32,
                edge: 0,
            };
            let bounds = tile.bounds();
            let cut = w.cut_planes(&TileExtent::new(bounds));
            for k in 0..BOX_PLANES {
                if cut >> k & 1 == 1 {
                    kept += 1;
                    continue;
                }
                left_out += 1;
                assert_eq!(
                    w.inside(&quads, tile.active, 1 << k),
                    tile.active,
                    "round {round}, plane {k}: {:?} over {bounds:?}",
                    planes[k]
                );
                assert!(k % 3 != 0, "a plane through a view sample is always tested");
            }
        }
        assert!(
            left_out > 500 && kept > 1000,
            "{left_out} left out, {kept} kept"
        );
    }

    /// A box test keeps exactly the boxes that reach the positive side of a plane (up to the
    /// boxes' padding): the plane's largest value over a box, at the corner its normal's signs
    /// pick, against the largest of the eight corners in double precision. Normal components of
    /// `0.0` and `-0.0` (whose sign bit picks the other bound) are among the planes. Fails when
    /// the pick takes the nearest corner instead of the farthest.
    #[test]
    fn box_tests_keep_the_boxes_a_plane_reaches() {
        let mut rand = uniform(0x2545_f491_4f6c_dd1du64);
        let (mut kept, mut rejected) = (0, 0);
        for round in 0..300 {
            let boxes: Vec<ViewBox> = (0..16)
                .map(|_| {
                    let c = Vec3::new(rand(), rand(), rand()) * 2.0 - 1.0;
                    let h = Vec3::new(rand(), rand(), rand()) * 0.3;
                    Some((c - h, c + h))
                })
                .collect();
            let mut b = Boxes::default();
            b.set(boxes.iter().copied());
            let mut n = Vec3::new(rand(), rand(), rand()) * 2.0 - 1.0;
            // Some components exactly zero, of either sign.
            for k in 0..3 {
                match (round + k) % 5 {
                    0 => n[k] = 0.0,
                    1 => n[k] = -0.0,
                    _ => {}
                }
            }
            let plane = n.extend(rand() * 2.0 - 1.0);
            let mut planes = [OPEN; BOX_PLANES];
            planes[0] = plane;
            let w = ScanWedge {
                planes: std::array::from_fn(|g| PlaneGroup::new(&planes, g)),
                fold: [OPEN, OPEN],
                folded: false,
                used: 1,
                edge: 0,
            };
            let mask = b.test(&w, 0.0);
            for (i, bx) in boxes.iter().enumerate() {
                let (lo, hi) = bx.unwrap();
                let largest = (0..8)
                    .map(|c| {
                        let pick = |k: usize| if c >> k & 1 == 1 { hi[k] } else { lo[k] };
                        let x = DVec3::new(pick(0).into(), pick(1).into(), pick(2).into());
                        plane.truncate().as_dvec3().dot(x) + f64::from(plane.w)
                    })
                    .fold(f64::NEG_INFINITY, f64::max);
                let keeps = mask >> i & 1 == 1;
                if largest >= 0.0 {
                    assert!(keeps, "round {round}, box {i}: {bx:?} reaches {plane:?}");
                    kept += 1;
                } else if largest < -1e-4 {
                    assert!(!keeps, "round {round}, box {i}: {bx:?} misses {plane:?}");
                    rejected += 1;
                }
            }
        }
        assert!(
            kept > 500 && rejected > 500,
            "{kept} kept, {rejected} rejected"
        );
    }

    /// The box hierarchy finds exactly the (pixel, wedge, weight) pairs of a brute-force scan
    /// of every view sample against every wedge (inside the bounding planes, non-zero exact
    /// weight): no box test drops a pair.
    #[test]
    fn the_hierarchy_finds_every_pair_of_the_brute_force_scan() {
        for (name, w, h) in [("bunny", 40, 30), ("overlapping-occluders", 70, 52)] {
            let setup = shadow_core::scenes::builtin(name).unwrap();
            let scene = setup.scene.as_ref();
            let view = ViewSamples::render(scene, &setup.camera_or_default(), w, h).unwrap();
            let light = setup.lights[0].as_ref();
            let shape = LightShape::new(light, "test").unwrap();
            let (edges, _) = scene_edges(scene, shape.center);
            let sil = silhouettes(&edges, &shape, Silhouettes::Accurate);
            let ws = wedges(&edges, &sil, &shape);
            let (scan, lanes): (Vec<ScanWedge>, Vec<WedgeLanes>) =
                ws.iter().map(|w| ScanWedge::new(w, None)).unzip();
            // The weights take the fold test's values wherever the wedge has fold planes
            // (most of `bunny`'s; `overlapping-occluders`' open quads have none).
            let folded = scan.iter().filter(|s| s.folded).count();
            assert_eq!(folded, ws.iter().filter(|w| w.fold.is_some()).count());
            assert!(
                name != "bunny" || folded * 10 > scan.len() * 9,
                "{name}: {folded} of {}",
                scan.len()
            );
            let extent = scene.bounds().union(light.bounds()).diagonal();
            let offset = RayOffset::for_extent(extent);
            let c = shape.center.as_dvec3();
            let n = view.len();
            let (mut origins, mut centred, mut active) =
                (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n], vec![false; n]);
            for i in 0..n {
                if let Some(s) = view.get(i) {
                    origins[i] = offset.offset(s.position, s.geometric_normal);
                    centred[i] = (origins[i].as_dvec3() - c).as_vec3();
                    active[i] = true;
                }
            }
            let input = ScanInput {
                edges: &edges,
                wedges: &scan,
                lanes: &lanes,
                c,
                width: w,
                origins: &origins,
                centred: &centred,
                active: &active,
                slack: (FOLD_SLACK * extent as f64) as f32,
                planar: None,
            };
            let blocks = blocks(w, h);
            let levels = BlockWedges::new(&input, &blocks);
            let mut found = Vec::new();
            let mut chunked = false;
            let (mut pairs, mut scratch) = (SquarePairs::default(), SquareScratch::default());
            for (bi, (_, squares)) in blocks.iter().enumerate() {
                let (lists, kept) = levels.square_lists(&input, bi, squares);
                // `bunny` keeps wedges enough for several parallel chunks, joined in order.
                chunked |= kept > LIST_CHUNK;
                for (r, list) in squares.iter().zip(&lists) {
                    assert!(
                        list.is_sorted_by(|a, b| a < b),
                        "a square's wedges in order"
                    );
                    square_pairs(&input, list, *r, &mut pairs, &mut scratch);
                    for (j, x, y) in pairs.pixels() {
                        let i = (y * w + x) as usize;
                        found.extend(pairs.of(j).0.iter().map(|p| (i, p.edge, p.k)));
                    }
                }
            }
            // Brute force: every active view sample against every wedge.
            let mut want = Vec::new();
            for i in 0..n {
                if !active[i] {
                    continue;
                }
                let q = TileLanes::at(centred[i]).quads();
                for (wi, sw) in scan.iter().enumerate() {
                    if sw.inside(&q, 1, (1 << sw.used) - 1) == 0 {
                        continue;
                    }
                    let e = &edges[sw.edge as usize];
                    match e.sweep_weight(origins[i].as_dvec3(), c, false) {
                        Some(k) if k != 0 => want.push((i, wi as u32, k as i32)),
                        _ => {}
                    }
                }
            }
            found.sort_unstable();
            want.sort_unstable();
            assert!(want.len() > 500, "{name}: {} pairs", want.len());
            assert_eq!(found, want, "{name}");
            assert!(
                chunked || name != "bunny",
                "bunny's block in parallel chunks"
            );
        }
    }
}
