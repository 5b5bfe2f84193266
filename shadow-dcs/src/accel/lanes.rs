//! The wedge scan (DCS section 4.2) over tiles of view samples in structure-of-arrays form:
//! each tile of [`TILE_W`] columns by [`TILE_H`] rows holds its light-centred view samples
//! as [`LANES`] lanes per coordinate, so that a wedge's plane tests and the signs that decide
//! its weight run on every view sample of the tile at once (the compiler turns the lane loops
//! into vector instructions), as a GPU evaluates a wedge's pixels in parallel.

use glam::{Vec3, Vec4};

/// Columns of a tile.
pub(crate) const TILE_W: u32 = 4;

/// The lanes of a tile as four packed quads per coordinate (lanes `4 q .. 4 q + 4` in quad `q`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct TileQuads {
    pub x: [Vec4; QUADS],
    pub y: [Vec4; QUADS],
    pub z: [Vec4; QUADS],
    pub l1: [Vec4; QUADS],
}

/// Rows of a tile.
pub(crate) const TILE_H: u32 = 4;

/// View samples per tile; lane `j` is column `j % TILE_W`, row `j / TILE_W` of the tile.
pub(crate) const LANES: usize = (TILE_W * TILE_H) as usize;

/// Packed quads of four lanes per tile.
pub(crate) const QUADS: usize = LANES / 4;

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

    /// The lanes as packed quads.
    #[inline]
    pub fn quads(&self) -> TileQuads {
        let q = |a: &Lanes| -> [Vec4; QUADS] {
            let (c, _) = a.as_chunks::<4>();
            std::array::from_fn(|i| Vec4::from(c[i]))
        };
        TileQuads {
            x: q(&self.x),
            y: q(&self.y),
            z: q(&self.z),
            l1: q(&self.l1),
        }
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

/// The tiles of the pixels in columns `cols` and rows `rows` (both starting at a multiple of
/// the tile's side) of an image `width` wide, tile row by tile row, from the light-centred view
/// samples and their activity, into `out`; returns the number of tiles per row.
pub(crate) fn rect_lanes(
    width: u32,
    cols: (u32, u32),
    rows: (u32, u32),
    centred: &[Vec3],
    active: &[bool],
    out: &mut Vec<TileLanes>,
) -> usize {
    debug_assert!(cols.0.is_multiple_of(TILE_W) && rows.0.is_multiple_of(TILE_H));
    let w = width as usize;
    let across = (cols.1 - cols.0 + 1).div_ceil(TILE_W) as usize;
    let down = (rows.1 - rows.0 + 1).div_ceil(TILE_H) as usize;
    out.clear();
    out.resize(across * down, TileLanes::EMPTY);
    for y in rows.0..=rows.1 {
        let yl = (y - rows.0) as usize;
        let (tile_row, row) = (yl / TILE_H as usize, yl % TILE_H as usize);
        for x in cols.0 as usize..=cols.1 as usize {
            let i = y as usize * w + x;
            if !active[i] {
                continue;
            }
            let xl = x - cols.0 as usize;
            let t = &mut out[tile_row * across + xl / TILE_W as usize];
            let j = row * TILE_W as usize + xl % TILE_W as usize;
            let p = centred[i];
            (t.x[j], t.y[j], t.z[j]) = (p.x, p.y, p.z);
            t.l1[j] = p.abs().element_sum();
            t.active |= 1 << j;
        }
    }
    across
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
        assert_eq!(lanes_of(0b1010_0001).collect::<Vec<_>>(), vec![0, 5, 7]);
    }

    #[test]
    fn rect_lanes_place_every_active_sample() {
        let (w, h) = (10u32, 7u32);
        let centred: Vec<Vec3> = (0..w * h)
            .map(|i| Vec3::new(i as f32, -(i as f32), 0.5))
            .collect();
        let active: Vec<bool> = (0..w * h).map(|i| i % 5 != 0).collect();
        let mut tiles = Vec::new();
        let across = rect_lanes(w, (4, 9), (0, h - 1), &centred, &active, &mut tiles);
        assert_eq!((across, tiles.len()), (2, 4));
        let mut seen = 0;
        for (t, tile) in tiles.iter().enumerate() {
            for j in lanes_of(tile.active) {
                let (x, y) = (4 + (t % 2) * 4 + j % 4, (t / 2) * 4 + j / 4);
                let i = y * w as usize + x;
                assert!(active[i]);
                assert_eq!(tile.x[j], centred[i].x);
                assert_eq!(tile.l1[j], centred[i].abs().element_sum());
                seen += 1;
            }
        }
        let want = (0..w * h)
            .filter(|&i| active[i as usize] && i % w >= 4)
            .count();
        assert_eq!(seen, want);
    }
}
