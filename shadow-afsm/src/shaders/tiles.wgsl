// Tiles per caster of the current range, summed into 64-bit tally 7 so the host can size (or
// split) the range before the tiles are numbered: the map's occupied 8 x 8 tiles
// (`occupancy.wgsl`) within the caster's texel box, in the super-tiles (4 x 4 tiles) that
// cluster culling keeps. The box's tiles without a view sample are never numbered (tally 12:
// tiles empty), nor are those of culled super-tiles (tally 9, with the tiles `tile_pairs`
// culls).
//
// The first level of the view-sample cluster hierarchy (Sintorn et al. 2014): with culling on,
// each super-tile's bounds (the box of its view samples' ray origins and, off the map's
// border, its part of the light frustum between its nearest and farthest view samples,
// `count.wgsl`) are tested against the caster's penumbra volume (`volume.wgsl`); the tiles of
// a super-tile outside it are not numbered (tally 17 counts such super-tiles). A box wider
// than 64 super-tiles keeps them all. The kept super-tiles go to `caster_masks` (two words of
// bits and a word that is 1 when all are kept) for `tile_of`.

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> regions: array<Region>;
@group(0) @binding(2) var<storage, read_write> tile_counts: array<u32>;
@group(0) @binding(3) var<storage, read_write> stats: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read> occupancy: array<u32>;
@group(0) @binding(5) var<storage, read_write> caster_masks: array<u32>;
@group(0) @binding(6) var<storage, read> volumes: array<Volume>;
// Per super-tile: farthest depth, complement of the nearest, then the origin box's six keys
// (`count.wgsl`); 0 as the first word marks none.
@group(0) @binding(7) var<storage, read> super_bounds: array<u32>;

// Whether super-tile (sx, sy) holds no view sample the caster of frame planes `fp` and
// volume `vol` can shadow.
fn super_culled(vol: ptr<function, Volume>, fp: ptr<function, array<vec4<f32>, 12>>, sx: u32,
                sy: u32) -> bool {
    let side = (tiles_per_side() + SUPER - 1u) / SUPER;
    let b = 8u * (sy * side + sx);
    if super_bounds[b] == 0u {
        return true;
    }
    let lo = vec3<f32>(from_key(~super_bounds[b + 2u]), from_key(~super_bounds[b + 3u]),
                       from_key(~super_bounds[b + 4u]));
    let hi = vec3<f32>(from_key(super_bounds[b + 5u]), from_key(super_bounds[b + 6u]),
                       from_key(super_bounds[b + 7u]));
    if box_outside(vol, lo, hi) {
        return true;
    }
    // Its texels, when none lies on the map's border (which holds samples clamped into it).
    let span = i32(SUPER) * TILE;
    let origin = vec2<i32>(i32(sx), i32(sy)) * span;
    let end = min(origin + span, vec2<i32>(i32(P.dims.x)));
    if any(origin <= vec2<i32>(0)) || any(end >= vec2<i32>(i32(P.dims.x))) {
        return false;
    }
    let z0 = bitcast<f32>(~super_bounds[b + 1u]);
    let z1 = bitcast<f32>(super_bounds[b]);
    return piece_outside(fp, origin, vec2<f32>(end - origin), z0, z1);
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let i = linear_index(g, n);
    if i >= P.work.y {
        return;
    }
    let bbox = regions[P.work.x + i].bbox;
    let a = tiles_across(bbox);
    var c = 0u;
    var mask = vec2<u32>(0xffffffffu);
    var all = true;
    if a.x > 0u {
        var sp = span_of(bbox);
        let rows = sp.y1 / SUPER - sp.sy0 + 1u;
        if P.options.w == 1u && sp.across * rows <= 64u {
            var vol = volumes[P.work.x + i];
            var fp = frame_planes(&vol);
            mask = vec2<u32>(0u);
            var culled = 0u;
            for (var r = 0u; r < rows; r++) {
                for (var q = 0u; q < sp.across; q++) {
                    let sx = sp.sx0 + q;
                    let sy = sp.sy0 + r;
                    if super_culled(&vol, &fp, sx, sy) {
                        let bs = 8u * (sy * ((tiles_per_side() + SUPER - 1u) / SUPER) + sx);
                        culled += select(0u, 1u, super_bounds[bs] != 0u);
                    } else {
                        let bit = r * sp.across + q;
                        mask[bit / 32u] |= 1u << (bit % 32u);
                    }
                }
            }
            add64(17u, culled);
            all = false;
            sp.mask = mask;
            sp.all = false;
        }
        var occupied = 0u;
        for (var y = sp.y0; y <= sp.y1; y++) {
            occupied += row_count(y, sp.x0, sp.x1);
            c += span_row_count(sp, y);
        }
        add64(12u, a.x * a.y - occupied);
        // Occupied tiles of culled super-tiles count as culled tiles.
        add64(9u, occupied - c);
    }
    caster_masks[3u * i] = mask.x;
    caster_masks[3u * i + 1u] = mask.y;
    caster_masks[3u * i + 2u] = select(0u, 1u, all);
    tile_counts[i] = c;
    add64(7u, c);
}
