//! The levels of the wedge search above the tiles: blocks, clusters and squares of pixels, and
//! the wedges each keeps.

use super::*;

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
pub(super) fn grid(cols: (u32, u32), rows: (u32, u32), side: u32) -> impl Iterator<Item = Rect> {
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
pub(super) type ViewBox = Option<(Vec3, Vec3)>;

/// The box around some boxes.
pub(super) fn union_of<'a>(boxes: impl IntoIterator<Item = &'a ViewBox>) -> ViewBox {
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
pub(super) const LIST_CHUNK: usize = 1024;

/// Side of a cluster of squares, in pixels: the level between blocks and squares.
pub(super) const CLUSTER: u32 = 2 * SQUARE;

/// A block's squares grouped by clusters of [`CLUSTER`] x [`CLUSTER`] pixels: a wedge a block
/// keeps meets few of its squares, so the clusters are tested first and then only the squares
/// of the clusters kept, each cluster's (at most four) squares one quad of the square boxes.
pub(super) struct Clusters {
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
