//! The wedge scan (DCS section 4.2) over tiles of view samples in structure-of-arrays form:
//! each tile of [`TILE_W`] columns by [`BAND_ROWS`] rows holds its light-centred view samples
//! as [`LANES`] lanes per coordinate, so that a wedge's plane tests and the signs that decide
//! its weight run on every view sample of the tile at once (the compiler turns the lane loops
//! into vector instructions), as a GPU evaluates a wedge's pixels in parallel.

use glam::Vec3;

/// Columns of a tile.
pub(crate) const TILE_W: u32 = 4;

/// Rows of a band (and of a tile): wedge pairs exist for one band at a time, which bounds their
/// memory on scenes of very high depth complexity (`grass`).
pub(crate) const BAND_ROWS: u32 = 4;

/// View samples per tile; lane `j` is column `j % TILE_W`, row `j / TILE_W` of the tile.
pub(crate) const LANES: usize = (TILE_W * BAND_ROWS) as usize;

/// One value per lane.
pub(crate) type Lanes = [f32; LANES];

/// A bit per lane.
pub(crate) type LaneMask = u16;

const _: () = assert!(LANES == LaneMask::BITS as usize);

/// The light-centred view samples of one tile, with `|x|_1` (for error bounds) and the mask
/// of lanes holding an active view sample (inactive lanes hold zeros).
#[derive(Debug, Clone, Copy)]
pub(crate) struct TileLanes {
    pub x: Lanes,
    pub y: Lanes,
    pub z: Lanes,
    pub l1: Lanes,
    pub active: LaneMask,
}

impl TileLanes {
    const EMPTY: Self = Self {
        x: [0.0; LANES],
        y: [0.0; LANES],
        z: [0.0; LANES],
        l1: [0.0; LANES],
        active: 0,
    };

    /// A tile whose first lane alone holds the point `x`.
    #[cfg(test)]
    pub fn at(x: Vec3) -> Self {
        let mut t = Self::EMPTY;
        (t.x[0], t.y[0], t.z[0]) = (x.x, x.y, x.z);
        t.l1[0] = x.abs().element_sum();
        t.active = 1;
        t
    }

    /// The box of the active view samples, `None` when there is none.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut b: Option<(Vec3, Vec3)> = None;
        for j in 0..LANES {
            if self.active >> j & 1 == 1 {
                let p = Vec3::new(self.x[j], self.y[j], self.z[j]);
                b = Some(match b {
                    Some((lo, hi)) => (lo.min(p), hi.max(p)),
                    None => (p, p),
                });
            }
        }
        b
    }
}

/// The tiles of the band of rows `rows` (at most [`BAND_ROWS`]) of an image `width` wide, from
/// the light-centred view samples and their activity.
pub(crate) fn band_lanes(
    width: u32,
    rows: (u32, u32),
    centred: &[Vec3],
    active: &[bool],
) -> Vec<TileLanes> {
    debug_assert!(rows.1 - rows.0 < BAND_ROWS);
    let w = width as usize;
    let mut out = vec![TileLanes::EMPTY; width.div_ceil(TILE_W) as usize];
    for y in rows.0..=rows.1 {
        let row = (y - rows.0) as usize * TILE_W as usize;
        for x in 0..w {
            let i = y as usize * w + x;
            if !active[i] {
                continue;
            }
            let t = &mut out[x / TILE_W as usize];
            let j = row + x % TILE_W as usize;
            let p = centred[i];
            (t.x[j], t.y[j], t.z[j]) = (p.x, p.y, p.z);
            t.l1[j] = p.abs().element_sum();
            t.active |= 1 << j;
        }
    }
    out
}

/// The lanes of columns `c0..=c1` (tile-relative, clamped to the tile) and rows `r0..=r1`.
#[inline]
pub(crate) fn span_mask(c0: u32, c1: u32, r0: u32, r1: u32) -> LaneMask {
    let cols = (((1u32 << (c1 - c0 + 1)) - 1) << c0) as LaneMask;
    let mut m = 0;
    for r in r0..=r1 {
        m |= cols << (r * TILE_W);
    }
    m
}

/// The mask of lanes where every value of `v` is at least zero (NaN fails).
#[inline]
pub(crate) fn non_negative(v: &Lanes) -> LaneMask {
    let mut m = 0;
    for (j, x) in v.iter().enumerate() {
        m |= LaneMask::from(*x >= 0.0) << j;
    }
    m
}

/// The mask of lanes where `|v| > bound` (NaN fails).
#[inline]
pub(crate) fn above_bound(v: &Lanes, bound: &Lanes) -> LaneMask {
    let mut m = 0;
    for j in 0..LANES {
        m |= LaneMask::from(v[j].abs() > bound[j]) << j;
    }
    m
}

/// The lanes of a mask, in order.
#[inline]
pub(crate) fn lanes_of(mut m: LaneMask) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (m != 0).then(|| {
            let j = m.trailing_zeros() as usize;
            m &= m - 1;
            j
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn masks_select_the_right_lanes() {
        assert_eq!(span_mask(0, 3, 0, 3), u16::MAX);
        assert_eq!(span_mask(1, 2, 1, 1), 0b0110_0000);
        assert_eq!(span_mask(3, 3, 0, 3), 0x8888);
        let mut v = [1.0f32; LANES];
        v[3] = -0.5;
        v[7] = f32::NAN;
        assert_eq!(non_negative(&v), !((1 << 3) | (1 << 7)));
        let bound = [0.75f32; LANES];
        assert_eq!(above_bound(&v, &bound), !(1 << 3 | 1 << 7));
        assert_eq!(lanes_of(0b1010_0001).collect::<Vec<_>>(), vec![0, 5, 7]);
    }

    #[test]
    fn band_lanes_place_every_active_sample() {
        let (w, h) = (6u32, 3u32);
        let centred: Vec<Vec3> = (0..w * h)
            .map(|i| Vec3::new(i as f32, -(i as f32), 0.5))
            .collect();
        let active: Vec<bool> = (0..w * h).map(|i| i % 5 != 0).collect();
        let tiles = band_lanes(w, (0, h - 1), &centred, &active);
        assert_eq!(tiles.len(), 2);
        let mut seen = 0;
        for (t, tile) in tiles.iter().enumerate() {
            for j in lanes_of(tile.active) {
                let (x, y) = (t * 4 + j % 4, j / 4);
                let i = y * w as usize + x;
                assert!(active[i]);
                assert_eq!(tile.x[j], centred[i].x);
                assert_eq!(tile.l1[j], centred[i].abs().element_sum());
                seen += 1;
            }
        }
        assert_eq!(seen, active.iter().filter(|a| **a).count());
    }
}
