// The occupied tiles of a caster's texel box (`occupancy.wgsl`), in the super-tiles of
// SUPER x SUPER tiles that cluster culling kept for it (`tiles.wgsl`). Every module that
// includes this declares `occupancy`.

const SUPER: u32 = 4u;

// A caster's tiles: the columns and rows of its box in tiles, its first super-tile's column
// and row and the box's width in super-tiles, the bits of the super-tiles kept (row-major over
// the box's super-tiles), or `all` when every one is kept.
struct Span {
    x0: u32,
    x1: u32,
    y0: u32,
    y1: u32,
    sx0: u32,
    sy0: u32,
    across: u32,
    mask: vec2<u32>,
    all: bool,
}

// The span of a non-empty texel box, every super-tile kept.
fn span_of(bbox: vec4<i32>) -> Span {
    var s: Span;
    s.x0 = u32(bbox.x / TILE);
    s.x1 = u32(bbox.z / TILE);
    s.y0 = u32(bbox.y / TILE);
    s.y1 = u32(bbox.w / TILE);
    s.sx0 = s.x0 / SUPER;
    s.sy0 = s.y0 / SUPER;
    s.across = s.x1 / SUPER - s.sx0 + 1u;
    s.mask = vec2<u32>(0xffffffffu);
    s.all = true;
    return s;
}

// Occupied tiles of row y in columns x0..=x1.
fn row_count(y: u32, x0: u32, x1: u32) -> u32 {
    let row = y * (tiles_per_side() + 1u);
    return occupancy[row + x1 + 1u] - occupancy[row + x0];
}

// Whether super-tile column sx of tile row y is kept.
fn span_keeps(s: Span, y: u32, sx: u32) -> bool {
    let bit = (y / SUPER - s.sy0) * s.across + sx - s.sx0;
    return s.all || ((s.mask[bit / 32u] >> (bit % 32u)) & 1u) != 0u;
}

// Occupied tiles of row y of the span, in its kept super-tiles.
fn span_row_count(s: Span, y: u32) -> u32 {
    if s.all {
        return row_count(y, s.x0, s.x1);
    }
    var c = 0u;
    for (var sx = s.sx0; sx <= s.x1 / SUPER; sx++) {
        if span_keeps(s, y, sx) {
            c += row_count(y, max(s.x0, sx * SUPER), min(s.x1, sx * SUPER + SUPER - 1u));
        }
    }
    return c;
}

// The column of the j-th occupied tile (j < `span_row_count`) of row y of the span.
fn span_row_tile(s: Span, y: u32, j: u32) -> u32 {
    let side = tiles_per_side();
    let columns = side * (side + 1u) + y * side;
    var k = j;
    var first = s.x0;
    if !s.all {
        for (var sx = s.sx0; sx <= s.x1 / SUPER; sx++) {
            if span_keeps(s, y, sx) {
                first = max(s.x0, sx * SUPER);
                let c = row_count(y, first, min(s.x1, sx * SUPER + SUPER - 1u));
                if k < c {
                    break;
                }
                k -= c;
            }
        }
    }
    return occupancy[columns + occupancy[y * (side + 1u) + first] + k];
}
