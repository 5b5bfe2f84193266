//! One square's scan: its tiles, the wedges that reach each tile, the view samples inside
//! each wedge with their weights, and the (pixel, edge) pairs they make.

use super::*;

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
pub(super) struct ScanTile {
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

/// The (tile, wedge) candidates of square `rect` among `wedges` (silhouette indices): the
/// pairs whose boxes meet, which [`square_pairs`] then evaluates on the tile's view samples
/// (its `tile_wedges` count), found by the box tests alone: all of them for lists of up to
/// `most` wedges, else an evenly spaced sample of `most` scaled to the whole list. The hybrid's
/// cost predictor (`technique::rays`): a square's DCS work follows it.
pub(crate) fn square_tile_wedges(
    input: &ScanInput,
    wedges: &[u32],
    rect: Rect,
    most: usize,
    scratch: &mut SquareScratch,
) -> f64 {
    if wedges.is_empty() {
        return 0.0;
    }
    let tiles = &mut scratch.tiles;
    tiles.set(input, rect);
    let step = wedges.len().div_ceil(most.max(1));
    let (met, tested) = wedges
        .iter()
        .step_by(step)
        .fold((0u64, 0u64), |(met, tested), &wi| {
            let mask = tiles.boxes.test(&input.wedges[wi as usize], input.slack);
            (met + u64::from(mask.count_ones()), tested + 1)
        });
    met as f64 * wedges.len() as f64 / tested as f64
}

/// The pairs of square `rect` from the wedges its box keeps (`wedges`, silhouette indices in
/// order), wedge by wedge: its box test against the square's tiles, then on the view samples of
/// each tile it keeps (fold planes, bounding planes, then the weight, exact where the
/// single-precision signs are uncertain), with the light-plane test set up while the wedge is
/// at hand. Each wedge's data is read once per square: tile by tile, with a list of wedges per
/// tile, a wedge came back once per tile it met, after the other wedges had evicted it; wedge
/// by wedge trades a few instructions for fewer cache misses.
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
