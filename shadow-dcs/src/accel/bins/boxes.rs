//! The box tests of the wedge search: up to [`BOXES`] boxes of view samples against one wedge's
//! bounding and fold planes at once.

use super::*;

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
pub(super) const SMALL_QUADS: usize = 4;

/// Per axis, one bound array of a [`Boxes`] for the farthest corners, then for the nearest.
pub(super) type Corners<'a> = ([&'a [Vec4; BOXES / 4]; 3], [&'a [Vec4; BOXES / 4]; 3]);

/// A plane's four coefficients, each in all lanes.
#[inline(always)]
pub(super) fn splat(p: Vec4) -> [Vec4; 4] {
    p.to_array().map(Vec4::splat)
}

/// The plane `[nx, ny, nz, d]` (splatted) at the points `(x, y, z)`, four at a time.
#[inline(always)]
pub(super) fn eval([nx, ny, nz, d]: [Vec4; 4], x: Vec4, y: Vec4, z: Vec4) -> Vec4 {
    nx * x + ny * y + nz * z + d
}

/// The fold part of a box test: a wedge's two face planes at the boxes' farthest and nearest
/// corners.
pub(super) struct FoldTest<'a> {
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
