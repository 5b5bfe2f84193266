//! A per-pixel angular index of the light samples (planar lights), after the sector table of
//! DCS section 7.3 (Fig. 8) but built for each pixel's own samples, so that it serves
//! stratified and decorrelated sampling, and used only to find candidates: the exact test of
//! [`crate::stages::coverage`] still decides every candidate.
//!
//! The samples an edge covers lie in its angular sector around the light centre `c`: one cone
//! between the lines where the planes `(p, c, a)` and `(p, c, b)` cut the light plane
//! (Algorithm 1, lines 4-5), the one [`EdgeTest`] orients its sector normals toward. Each
//! sample is put in one of [`BUCKETS`] buckets by the direction from `c` to it (over a whole
//! turn); prefix masks over the buckets then give, with two loads and two bit operations, every
//! sample whose direction lies in the cone's arc widened by [`MARGIN`]. Most wedge pairs of a
//! finely tessellated mesh have thin sectors holding no sample at all and are dropped without a
//! per-sample test. The technique asks for the candidates of [`BATCH`] tests at a time
//! ([`AngularIndex::candidates_batch`]): each step of the sectors' arithmetic is a loop over
//! the batch, which the compiler turns into packed instructions.

use glam::{Mat4, Vec3, Vec4};

use crate::accel::planar::{PlanarSamples, PlanarTest};
use crate::stages::coverage::EdgeTest;
use crate::stages::light_shape::LightPlane;

/// Angular buckets over a whole turn.
pub(crate) const BUCKETS: usize = 256;

/// The most words of samples per row that [`spread_table`] indexes (256 samples, `dcs-256`);
/// more take rows of any length.
const MAX_SPREAD_WORDS: usize = 4;

/// Pseudo-angle of a whole turn (see [`direction_angle`]).
const TURN: f32 = 4.0;

/// Widening of a sector's arc, in pseudo-angle units (a quarter turn is 1): far above the
/// rounding of the directions, so that no sample the exact test covers is left out.
const MARGIN: f32 = 1e-3;

/// The angular index of one pixel's samples.
#[derive(Debug, Clone, Default)]
pub(crate) struct AngularIndex {
    words: usize,
    u: Vec3,
    v: Vec3,
    /// `prefix[j * words + w]`: the samples of word `w` whose direction lies in a bucket below
    /// `j` (`BUCKETS + 1` entries per word).
    prefix: Vec<u64>,
    /// Each sample's bucket (scratch of `build`).
    buckets: Vec<u32>,
    /// Each bucket's samples, for two to [`MAX_SPREAD_WORDS`] words ([`spread_table`]); all
    /// zero between builds.
    hits: Vec<u64>,
}

/// The direction of `(x, y)` as a monotone pseudo-angle in `[0, 4)` (the "diamond angle": 0
/// along +x, 1 along +y, 2 along -x, 3 along -y); 0 for the zero vector. Branch-free: with
/// `t = x / (|x| + |y|)` it is `1 - t` on the upper half-plane and `3 + t` on the lower one.
#[inline]
fn direction_angle(x: f32, y: f32) -> f32 {
    let r = x.abs() + y.abs();
    let t = x / r;
    let a = if y >= 0.0 { 1.0 - t } else { 3.0 + t };
    // Zero vector (NaN) and the rounding to 4 just below +x both map to 0.
    if (0.0..TURN).contains(&a) { a } else { 0.0 }
}

/// The bucket of a pseudo-angle in `[0, 4)`.
#[inline]
fn bucket(a: f32) -> usize {
    // Through `i32`, which vectorises; NaN and negative values give 0 as through `usize`.
    ((a * (BUCKETS as f32 / TURN)) as i32).clamp(0, BUCKETS as i32 - 1) as usize
}

/// [`direction_angle`] of four directions at once (the same operations lane by lane).
#[inline(always)]
fn direction_angles(x: Vec4, y: Vec4) -> Vec4 {
    let zero = Vec4::ZERO;
    let t = x / (x.abs() + y.abs());
    let a = Vec4::select(y.cmpge(zero), Vec4::ONE - t, Vec4::splat(3.0) + t);
    // Zero vector (NaN) and the rounding to 4 just below +x both map to 0.
    Vec4::select(a.cmpge(zero) & a.cmplt(Vec4::splat(TURN)), a, zero)
}

/// [`bucket`] of four pseudo-angles, without a saturating conversion per lane: the scaled
/// values are clamped to the buckets' range in the vector (`max` with 0 first, which also
/// takes a NaN to 0) and floored there, and a whole number below `2^23` plus `2^23` holds
/// itself in its low mantissa bits. The floor is taken on that biased form: `x + 2^23` rounds
/// `x` (at most 255) to the nearest whole number exactly, and one less where that went above
/// `x` (five operations; `Vec4::floor` on this target's SSE2 takes eleven).
#[inline(always)]
fn buckets(a: Vec4) -> [usize; 4] {
    const WHOLE: f32 = 8_388_608.0;
    let last = (BUCKETS - 1) as f32;
    let x = (a * (BUCKETS as f32 / TURN))
        .max(Vec4::ZERO)
        .min(Vec4::splat(last));
    let rounded = x + Vec4::splat(WHOLE);
    let above = (rounded - Vec4::splat(WHOLE)).cmpgt(x);
    let b = rounded - Vec4::select(above, Vec4::ONE, Vec4::ZERO);
    b.to_array().map(|x| (x.to_bits() & 0x7f_ffff) as usize)
}

/// The one-word prefix table (`prefix`, zeroed, `BUCKETS + 1` words) of the samples in
/// `buckets` (at most 64, each below [`BUCKETS`]): each sample's bit set in the row after its
/// bucket's, then every row OR-ed with all rows before it. A fixed array, so that neither the
/// scatter nor the running OR checks an index (the `min` only lets the compiler drop the
/// check).
fn one_word_table(prefix: &mut [u64], buckets: &[u32]) {
    let table: &mut [u64; BUCKETS + 1] = prefix
        .try_into()
        .expect("the prefix table has BUCKETS + 1 rows");
    for (k, b) in buckets.iter().enumerate() {
        table[(*b as usize).min(BUCKETS - 1) + 1] |= 1 << (k & 63);
    }
    let mut acc = 0;
    for x in table.iter_mut() {
        acc |= *x;
        *x = acc;
    }
}

/// The prefix table of `W` words per row (`prefix`, `(BUCKETS + 1) W` words, every one of
/// them overwritten) of the samples in `buckets` (at most `64 W`, each below [`BUCKETS`]),
/// through `hits` (at least `BUCKETS W` words, zero on entry and on return): each sample's bit
/// set in its bucket's row of `hits`, the running OR of those rows written to `prefix`, then
/// the rows of `hits` set cleared again. Neither table is zeroed whole (a pixel touches few of
/// its rows), and the rows are fixed arrays (no index checks).
fn spread_table<const W: usize>(prefix: &mut [u64], hits: &mut [u64], buckets: &[u32]) {
    let (rows, _) = prefix.as_chunks_mut::<W>();
    let table: &mut [[u64; W]; BUCKETS + 1] = rows
        .try_into()
        .expect("the prefix table has BUCKETS + 1 rows");
    let (h, _) = hits.as_chunks_mut::<W>();
    let h: &mut [[u64; W]; BUCKETS] = (&mut h[..BUCKETS])
        .try_into()
        .expect("the hit table has BUCKETS rows");
    for (w, word) in buckets.chunks(64).enumerate() {
        let w = w.min(W - 1);
        for (k, b) in word.iter().enumerate() {
            h[(*b as usize).min(BUCKETS - 1)][w] |= 1 << (k & 63);
        }
    }
    let mut acc = [0u64; W];
    table[0] = acc;
    for (row, hit) in table[1..].iter_mut().zip(h.iter()) {
        for (a, x) in acc.iter_mut().zip(hit) {
            *a |= *x;
        }
        *row = acc;
    }
    for (w, word) in buckets.chunks(64).enumerate() {
        let w = w.min(W - 1);
        for b in word {
            h[(*b as usize).min(BUCKETS - 1)][w] = 0;
        }
    }
}

/// [`one_word_table`] for any number of words per row (`words`, `prefix` zeroed).
fn prefix_rows(prefix: &mut [u64], words: usize, buckets: &[u32]) {
    for (k, b) in buckets.iter().enumerate() {
        prefix[(*b as usize + 1) * words + k / 64] |= 1 << (k % 64);
    }
    for j in 1..=BUCKETS {
        let (done, rest) = prefix.split_at_mut(j * words);
        for (x, below) in rest[..words].iter_mut().zip(&done[(j - 1) * words..]) {
            *x |= *below;
        }
    }
}

impl AngularIndex {
    /// Indexes the sample `positions` of a pixel on the light `plane` with centre `c`.
    pub fn build(&mut self, plane: &LightPlane, c: Vec3, positions: &[Vec3]) {
        self.u = plane.u;
        self.v = plane.v;
        // The buckets are computed sample by sample in one loop (which vectorises), then
        // scattered.
        self.buckets.clear();
        self.buckets.extend(positions.iter().map(|s| {
            let d = *s - c;
            bucket(direction_angle(d.dot(plane.u), d.dot(plane.v))) as u32
        }));
        self.index_buckets(positions.len());
    }

    /// Indexes a pixel's samples given in the light plane around the centre (the first `n` of
    /// `samples`).
    pub fn build_planar(&mut self, samples: &PlanarSamples, n: usize) {
        self.buckets.clear();
        // Four samples at a time, the rest one by one (the same values).
        let (xs, x_rest) = samples.x[..n].as_chunks::<4>();
        let (ys, y_rest) = samples.y[..n].as_chunks::<4>();
        for (x, y) in xs.iter().zip(ys) {
            let a = direction_angles(Vec4::from(*x), Vec4::from(*y));
            self.buckets.extend(buckets(a).map(|b| b as u32));
        }
        self.buckets.extend(
            x_rest
                .iter()
                .zip(y_rest)
                .map(|(x, y)| bucket(direction_angle(*x, *y)) as u32),
        );
        self.index_buckets(n);
    }

    /// The prefix masks from `self.buckets` (the first `n` samples' buckets).
    fn index_buckets(&mut self, n: usize) {
        let words = n.div_ceil(64);
        self.words = words;
        let len = (BUCKETS + 1) * words;
        let buckets = &self.buckets[..n];
        if (2..=MAX_SPREAD_WORDS).contains(&words) {
            // Every word of the table is written: no zeroing.
            self.prefix.resize(len, 0);
            self.hits.resize(BUCKETS * MAX_SPREAD_WORDS, 0);
            match words {
                2 => spread_table::<2>(&mut self.prefix, &mut self.hits, buckets),
                3 => spread_table::<3>(&mut self.prefix, &mut self.hits, buckets),
                _ => spread_table::<MAX_SPREAD_WORDS>(&mut self.prefix, &mut self.hits, buckets),
            }
            return;
        }
        self.prefix.clear();
        self.prefix.resize(len, 0);
        if words == 1 {
            one_word_table(&mut self.prefix, buckets);
        } else {
            prefix_rows(&mut self.prefix, words, buckets);
        }
    }

    /// The prefix table as `W`-word rows, when the index holds `W` words per row (a fixed
    /// array: [`QuadRanges::words`] then indexes it without a check).
    #[inline]
    pub fn rows<const W: usize>(&self) -> Option<&PrefixRows<W>> {
        let (rows, _) = self.prefix.as_chunks::<W>();
        rows.try_into().ok().filter(|_| self.words == W)
    }

    /// The samples that may lie in sector `j` of `r`, for a pixel with `W` words of samples
    /// (the index's rows taken as fixed arrays: no index arithmetic or checks per word).
    #[cfg(test)]
    pub fn quad_words<const W: usize>(&self, r: &QuadRanges, j: usize) -> [u64; W] {
        r.words(self.rows::<W>().expect("an index of W words"), j)
    }

    /// The samples of `allowed` that may lie in sector `j` of `r` (every sample the exact
    /// test covers is among them), into `out`; returns whether there is any.
    #[inline]
    pub fn quad_candidates(
        &self,
        r: &QuadRanges,
        j: usize,
        allowed: &[u64],
        out: &mut [u64],
    ) -> bool {
        if r.narrow >> j & 1 == 0 {
            out.copy_from_slice(allowed);
            return allowed.iter().any(|x| *x != 0);
        }
        let wraps = r.wraps >> j & 1 == 1;
        if let ([o], [a]) = (&mut *out, allowed) {
            let (below_lo, upto_hi) = (self.prefix[r.lo[j]], self.prefix[r.hi[j] + 1]);
            let range = if wraps {
                upto_hi | !below_lo
            } else {
                upto_hi & !below_lo
            };
            *o = range & a;
            return *o != 0;
        }
        self.buckets_into(r.lo[j] as u32, r.hi[j] as u32, wraps, allowed, out)
    }

    /// Writes to `out` the samples of `allowed` that may lie in the sector of `test` (every
    /// sample the exact test covers is among them); returns whether any is. (The technique
    /// takes its tests a batch at a time, [`AngularIndex::candidates_batch`].)
    #[cfg(test)]
    pub fn candidates(&self, test: &EdgeTest, allowed: &[u64], out: &mut [u64]) -> bool {
        self.candidates_batch(std::slice::from_ref(test), allowed, out, None) != 0
    }

    /// [`AngularIndex::candidates`] of up to [`BATCH`] tests at once, `tests.len() * words`
    /// words into `out`: the sectors' bucket ranges are computed lane by lane over the batch
    /// (the same operations in the same order whatever the lane), which the compiler turns
    /// into vector instructions. Returns the mask of tests with any candidate.
    ///
    /// With `inner`, also the samples of `allowed` whose buckets lie wholly inside each sector
    /// (narrowed by [`MARGIN`] at both ends, so that every one of them is in the exact test's
    /// sector), `tests.len() * words` words: the refined tables of section 7.3 settle those by
    /// their line alone.
    pub fn candidates_batch(
        &self,
        tests: &[EdgeTest],
        allowed: &[u64],
        out: &mut [u64],
        mut inner: Option<&mut [u64]>,
    ) -> u32 {
        debug_assert!(tests.len() <= BATCH);
        let sectors = Normals::of(tests, self.u, self.v).sectors(inner.is_some());
        let w = self.words;
        let mut any = 0u32;
        for (i, s) in sectors.iter().take(tests.len()).enumerate() {
            if self.apply(*s, allowed, &mut out[i * w..(i + 1) * w]) {
                any |= 1 << i;
            }
            if let Some(inner) = inner.as_deref_mut() {
                self.apply_inner(*s, allowed, &mut inner[i * w..(i + 1) * w]);
            }
        }
        any
    }

    /// The samples of `allowed` in the inner buckets of `s` (none when it has none).
    #[inline]
    fn apply_inner(&self, s: Sector, allowed: &[u64], out: &mut [u64]) {
        match s.inner.filter(|_| s.narrow) {
            Some((lo, hi)) => {
                self.buckets_into(lo, hi, lo > hi, allowed, out);
            }
            None => out.fill(0),
        }
    }

    /// The samples of `allowed` in the buckets of `s` (all of `allowed` when the index cannot
    /// narrow the sector).
    #[inline]
    fn apply(&self, s: Sector, allowed: &[u64], out: &mut [u64]) -> bool {
        if !s.narrow {
            out.copy_from_slice(allowed);
            return allowed.iter().any(|w| *w != 0);
        }
        self.buckets_into(s.lo, s.hi, s.wraps, allowed, out)
    }

    /// The samples of `allowed` in the buckets from `lo` to `hi` (round past the last bucket
    /// when `wraps`); returns whether there is any.
    #[inline]
    fn buckets_into(
        &self,
        lo: u32,
        hi: u32,
        wraps: bool,
        allowed: &[u64],
        out: &mut [u64],
    ) -> bool {
        let (bl, bh) = (lo as usize, hi as usize);
        let w = self.words;
        let (below_lo, upto_hi) = (
            &self.prefix[bl * w..bl * w + w],
            &self.prefix[(bh + 1) * w..(bh + 2) * w],
        );
        let mut any = 0u64;
        for j in 0..w {
            let range = if wraps {
                upto_hi[j] | !below_lo[j]
            } else {
                upto_hi[j] & !below_lo[j]
            };
            out[j] = range & allowed[j];
            any |= out[j];
        }
        any != 0
    }
}

/// An index's prefix table with `W` words per row ([`AngularIndex::rows`]).
pub(crate) type PrefixRows<const W: usize> = [[u64; W]; BUCKETS + 1];

/// The bucket ranges of four light-plane sectors (the cone `a . d > 0`, `b . d < 0`), computed
/// as in `Normals::sectors`, four lanes at a time.
pub(crate) struct QuadRanges {
    lo: [usize; 4],
    hi: [usize; 4],
    /// Lanes whose sector the index can narrow.
    narrow: u32,
    /// Lanes whose range runs round past the last bucket.
    wraps: u32,
}

impl QuadRanges {
    /// The ranges of four light-plane tests' sectors.
    #[inline]
    pub fn of_tests(tests: &[PlanarTest; 4]) -> Self {
        // The tests' x coefficients as columns: their rows are `a.x` and `-b.x` of every
        // test; the same for y.
        let c = tests.map(|t| t.coefficients());
        let xs = Mat4::from_cols(c[0].0, c[1].0, c[2].0, c[3].0).transpose();
        let ys = Mat4::from_cols(c[0].1, c[1].1, c[2].1, c[3].1).transpose();
        Self::of(xs.x_axis, ys.x_axis, -xs.y_axis, -ys.y_axis)
    }

    /// The samples of a pixel's index `rows` that may lie in sector `j`. The bucket numbers
    /// are below [`BUCKETS`] by construction ([`buckets`] clamps them); the masks only let the
    /// compiler drop the index checks (two per pair, on the hottest path of `dcs-64`).
    #[inline(always)]
    pub fn words<const W: usize>(&self, rows: &PrefixRows<W>, j: usize) -> [u64; W] {
        if self.narrow >> j & 1 == 0 {
            return [u64::MAX; W];
        }
        const MASK: usize = BUCKETS - 1;
        const _: () = assert!(BUCKETS.is_power_of_two());
        let (below_lo, upto_hi) = (rows[self.lo[j] & MASK], rows[(self.hi[j] & MASK) + 1]);
        let wraps = self.wraps >> j & 1 == 1;
        std::array::from_fn(|w| {
            if wraps {
                upto_hi[w] | !below_lo[w]
            } else {
                upto_hi[w] & !below_lo[w]
            }
        })
    }

    /// The ranges of the cones `a . d > 0`, `b . d < 0` given lane by lane.
    #[inline(always)]
    fn of(ax: Vec4, ay: Vec4, bx: Vec4, by: Vec4) -> Self {
        let zero = Vec4::ZERO;
        let turn = Vec4::splat(TURN);
        let la2 = ax * ax + ay * ay;
        let lb2 = bx * bx + by * by;
        let cross = ax * by - ay * bx;
        let sign = Vec4::select(cross.cmpgt(zero), Vec4::ONE, -Vec4::ONE);
        let ta = direction_angles(ay * sign, -ax * sign);
        let tb = direction_angles(by * sign, -bx * sign);
        let d = tb - ta;
        let ccw = Vec4::select(tb.cmpge(ta), d, d + turn);
        let half = ccw.cmple(Vec4::splat(TURN / 2.0));
        let start = Vec4::select(half, ta, tb);
        let arc = Vec4::select(half, ccw, turn - ccw);
        let lo = start - Vec4::splat(MARGIN);
        let len = arc + Vec4::splat(2.0 * MARGIN);
        let lo = Vec4::select(lo.cmplt(zero), lo + turn, lo);
        let h = lo + len;
        let hi = Vec4::select(h.cmpge(turn), h - turn, h);
        let narrow = la2.cmpgt(zero)
            & lb2.cmpgt(zero)
            & (cross * cross).cmpgt(Vec4::splat(1e-6) * la2 * lb2)
            & len.cmplt(Vec4::splat(TURN / 2.0));
        Self {
            lo: buckets(lo),
            hi: buckets(hi),
            narrow: narrow.bitmask(),
            wraps: lo.cmpgt(hi).bitmask(),
        }
    }
}

/// Tests per [`AngularIndex::candidates_batch`].
pub(crate) const BATCH: usize = 8;

/// A sector as a range of buckets.
#[derive(Debug, Clone, Copy)]
struct Sector {
    /// False when the index cannot narrow the sector (every sample is a candidate).
    narrow: bool,
    /// The range runs from `lo` past the last bucket round to `hi`.
    wraps: bool,
    lo: u32,
    hi: u32,
    /// The buckets wholly inside the sector shrunk by [`MARGIN`] at both ends, from the first
    /// to the last (round past the last bucket when the first is greater); `None` when no
    /// bucket is.
    inner: Option<(u32, u32)>,
}

/// The sector normals of a batch of tests in the light plane, with the squared lengths of the
/// normals they come from, structure of arrays.
struct Normals {
    ax: [f32; BATCH],
    ay: [f32; BATCH],
    bx: [f32; BATCH],
    by: [f32; BATCH],
    ga2: [f32; BATCH],
    gb2: [f32; BATCH],
}

impl Normals {
    const ZERO: Self = Self {
        ax: [0.0; BATCH],
        ay: [0.0; BATCH],
        bx: [0.0; BATCH],
        by: [0.0; BATCH],
        ga2: [0.0; BATCH],
        gb2: [0.0; BATCH],
    };

    /// The sector normals of up to [`BATCH`] tests in the plane of axes `u`, `v` (unused
    /// lanes zero).
    fn of(tests: &[EdgeTest], u: Vec3, v: Vec3) -> Self {
        let mut n = Self::ZERO;
        for (i, t) in tests.iter().enumerate().take(BATCH) {
            let (ga, gb) = t.sector_normals();
            (n.ax[i], n.ay[i], n.ga2[i]) = (ga.dot(u), ga.dot(v), ga.length_squared());
            (n.bx[i], n.by[i], n.gb2[i]) = (gb.dot(u), gb.dot(v), gb.length_squared());
        }
        n
    }
}

impl Normals {
    /// The bucket ranges of the batch's sectors, each step lane by lane over the batch (loops
    /// the compiler vectorises), branch-free; their inner buckets only `with_inner`.
    fn sectors(&self, with_inner: bool) -> [Sector; BATCH] {
        type Lanes = [f32; BATCH];
        let lanes = |f: &dyn Fn(usize) -> f32| -> Lanes { std::array::from_fn(f) };
        // In the light plane, the cone is A . d > 0 and B . d < 0 for d = s - c.
        let (ax, ay, bx, by) = (&self.ax, &self.ay, &self.bx, &self.by);
        let (ga2, gb2) = (&self.ga2, &self.gb2);
        let la2 = lanes(&|i| ax[i] * ax[i] + ay[i] * ay[i]);
        let lb2 = lanes(&|i| bx[i] * bx[i] + by[i] * by[i]);
        let cross = lanes(&|i| ax[i] * by[i] - ay[i] * bx[i]);
        // The cone's sides: along A's line on the side where B . d < 0, along B's line on the
        // side where A . d > 0; perp(A) = (-ay, ax) has B . perp(A) = cross and
        // perp(B) = (-by, bx) has A . perp(B) = -cross.
        let sign = lanes(&|i| if cross[i] > 0.0 { 1.0 } else { -1.0 });
        let ta = lanes(&|i| direction_angle(ay[i] * sign[i], -ax[i] * sign[i]));
        let tb = lanes(&|i| direction_angle(by[i] * sign[i], -bx[i] * sign[i]));
        // The cone is convex: its arc is the shorter one between its sides.
        let ccw = lanes(&|i| {
            let d = tb[i] - ta[i];
            if tb[i] >= ta[i] { d } else { d + TURN }
        });
        let start = lanes(&|i| if ccw[i] <= TURN / 2.0 { ta[i] } else { tb[i] });
        let arc = lanes(&|i| {
            if ccw[i] <= TURN / 2.0 {
                ccw[i]
            } else {
                TURN - ccw[i]
            }
        });
        let lo = lanes(&|i| start[i] - MARGIN);
        let len = lanes(&|i| arc[i] + 2.0 * MARGIN);
        // The inner buckets: those after the bucket of `start + MARGIN` and before that of
        // `start + arc - MARGIN`.
        let wrap = |a: f32| if a >= TURN { a - TURN } else { a };
        let first = lanes(&|i| wrap(start[i] + MARGIN));
        let last = lanes(&|i| wrap(start[i] + arc[i] - MARGIN));
        let inner = |i: usize| -> Option<(u32, u32)> {
            if !with_inner || !(arc[i] > 2.0 * MARGIN) {
                return None;
            }
            let (bf, bl) = (bucket(first[i]), bucket(last[i]));
            let span = (bl + BUCKETS - bf) % BUCKETS;
            (span >= 2).then(|| {
                (
                    ((bf + 1) % BUCKETS) as u32,
                    ((bl + BUCKETS - 1) % BUCKETS) as u32,
                )
            })
        };
        let lo = lanes(&|i| if lo[i] < 0.0 { lo[i] + TURN } else { lo[i] });
        let hi = lanes(&|i| {
            let h = lo[i] + len[i];
            if h >= TURN { h - TURN } else { h }
        });
        std::array::from_fn(|i| Sector {
            // A sector plane (nearly) parallel to the light plane, or two (nearly) parallel
            // lines (an uncertain orientation of the cone's sides), or a sector too wide:
            // leave it to the exact test.
            narrow: (la2[i] > 1e-8 * ga2[i])
                & (lb2[i] > 1e-8 * gb2[i])
                & (cross[i] * cross[i] > 1e-6 * la2[i] * lb2[i])
                & (len[i] < TURN / 2.0),
            wraps: lo[i] > hi[i],
            lo: bucket(lo[i]) as u32,
            hi: bucket(hi[i]) as u32,
            inner: inner(i),
        })
    }
}

#[cfg(test)]
mod tests;
