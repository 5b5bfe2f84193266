// Load balancing of the occlusion work (section 4.3's restricted computations, spread evenly):
// each caster's influence region is covered by the map's 8 x 8 texel tiles it touches, tiles
// hold the pairs of the listed view samples in their texels that overlap the region, and a few
// consecutive pairs of the range's numbering are the unit of work. Every invocation thus does a
// bounded amount of work however large a region or long a list is. (Software rasterisers such as llvmpipe also end every loop of an invocation
// after 65535 iterations in all, so unbounded per-invocation loops would silently drop work.)
//
// Tiles are numbered per range of casters by the running sum of their counts (`tile_offsets`).

@group(0) @binding(1) var<storage, read> regions: array<Region>;
@group(0) @binding(2) var<storage, read> tile_offsets: array<u32>;
@group(0) @binding(3) var<storage, read> offsets: array<u32>;

struct Tile {
    // Caster index in the batch.
    caster: u32,
    // The map's tile (a cluster of view samples): its index and first texel.
    index: u32,
    origin: vec2<i32>,
    // The first and the last texel of the region's box.
    first: vec2<i32>,
    last: vec2<i32>,
}

// Tile `u` of the current range: the last caster whose first tile is at or before `u`.
fn tile_of(u: u32) -> Tile {
    var lo = 0u;
    var hi = P.work.y;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if tile_offsets[mid] <= u {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let t = P.work.x + lo;
    let bbox = regions[t].bbox;
    // The j-th occupied tile of the box in its kept super-tiles, row by row (`occupied.wgsl`;
    // every module that tiles declares `occupancy` and `caster_masks`, written by `tiles`).
    var sp = span_of(bbox);
    let m = vec3<u32>(caster_masks[3u * lo], caster_masks[3u * lo + 1u], caster_masks[3u * lo + 2u]);
    sp.mask = m.xy;
    sp.all = m.z == 1u;
    var j = u - tile_offsets[lo];
    var y = sp.y0;
    for (var r = 0u; r < tiles_per_side(); r++) {
        let c = span_row_count(sp, y);
        if j < c {
            break;
        }
        j -= c;
        y++;
    }
    let x = span_row_tile(sp, y, j);
    return Tile(t, y * tiles_per_side() + x, TILE * vec2<i32>(i32(x), i32(y)), bbox.xy, bbox.zw);
}

// The bits (row-major, two words) of a tile's texels inside the region's box.
fn box_bits(tl: Tile) -> vec2<u32> {
    let lo = clamp(tl.first - tl.origin, vec2<i32>(0), vec2<i32>(TILE));
    let hi = clamp(tl.last - tl.origin + 1, vec2<i32>(0), vec2<i32>(TILE));
    if any(hi <= lo) {
        return vec2<u32>(0u);
    }
    // One row's bits (columns lo.x to hi.x - 1), then that row repeated over rows lo.y to
    // hi.y - 1.
    let row = ((1u << u32(hi.x - lo.x)) - 1u) << u32(lo.x);
    var bits = vec2<u32>(0u);
    for (var y = lo.y; y < hi.y; y++) {
        let k = u32(y) * u32(TILE);
        bits[k / 32u] |= row << (k % 32u);
    }
    return bits;
}

// Conservative rasterisation (section 3.2): texel (tx, ty) overlaps the hull of caster t.
fn texel_overlaps(t: u32, tx: i32, ty: i32) -> bool {
    let info = regions[t].info;
    if info.y != 0u || info.x < 3u {
        return true;
    }
    // Separating axes: the hull's edges (the box is tested by the tiling).
    let lo = vec2<f32>(f32(tx), f32(ty)) - vec2<f32>(1e-3);
    let hi = lo + vec2<f32>(1.0 + 2e-3);
    let h = info.x;
    var inside = true;
    for (var k = 0u; k < h; k++) {
        let a = regions[t].pts[k];
        let b = regions[t].pts[(k + 1u) % h];
        let e = b - a;
        // Inward normal of a counter-clockwise hull is (-e.y, e.x); the texel is outside when
        // its corner farthest along that normal is still outside.
        let nrm = vec2<f32>(-e.y, e.x);
        let corner = vec2<f32>(select(lo.x, hi.x, nrm.x > 0.0), select(lo.y, hi.y, nrm.y > 0.0));
        inside = inside && dot(nrm, corner - a) >= 0.0;
    }
    return inside;
}

// The map index of texel `k` (0..64, row-major) of a tile (outside the region's box, or past
// the map's edge, when the tile overhangs the box).
fn tile_texel_index(tl: Tile, k: u32) -> u32 {
    let tx = tl.origin.x + i32(k % u32(TILE));
    let ty = tl.origin.y + i32(k / u32(TILE));
    return u32(ty) * P.dims.x + u32(tx);
}

// Texel `k` (0..64, row-major) of a tile: its index and the length of its list, 0 when it lies
// outside the region's box (the hull is not tested).
fn tile_texel_list(tl: Tile, k: u32) -> vec2<u32> {
    let tx = tl.origin.x + i32(k % u32(TILE));
    let ty = tl.origin.y + i32(k / u32(TILE));
    if tx < tl.first.x || ty < tl.first.y || tx > tl.last.x || ty > tl.last.y {
        return vec2<u32>(0u);
    }
    let texel = tile_texel_index(tl, k);
    return vec2<u32>(texel, offsets[texel + 1u] - offsets[texel]);
}

// Whether texel `k` of a tile overlaps the caster's hull (conservative rasterisation).
fn tile_texel_in_hull(tl: Tile, k: u32) -> bool {
    return texel_overlaps(tl.caster, tl.origin.x + i32(k % u32(TILE)),
                          tl.origin.y + i32(k / u32(TILE)));
}

// Texel `k` (0..64, row-major) of a tile: its index and the length of its list, 0 when it lies
// outside the region's box or hull (empty lists are skipped, section 4.3).
fn tile_texel(tl: Tile, k: u32) -> vec2<u32> {
    let tt = tile_texel_list(tl, k);
    if tt.y == 0u || !tile_texel_in_hull(tl, k) {
        return vec2<u32>(tt.x, 0u);
    }
    return tt;
}
