// Per (caster, tile): first cluster culling, then the texels that overlap the caster's region
// and hold a list (tally 0, texels visited; their 64-bit mask is stored after the pair counts,
// at T + 1 + 2u, so the occlusion pass does not redo the overlap tests) and the pairs they hold
// (`pair_counts`, summed into tally 1 over every range and tally 8 over this one).
//
// Cluster culling (the view-sample clusters of Sintorn et al. 2014, here the map's tiles): a
// tile's view samples all lie at or before its farthest one's depth `zt` from the light's
// centre (`count.wgsl`). A segment from one of them to the light stays between the light's
// depth and `zt`, so only the part of the caster at depth `zt` or less can hide anything from
// them, and it hides the light only from points inside its influence region drawn at depth
// `zt` instead of at the far plane (section 4.1's construction: the region grows
// monotonically with depth). A tile beyond which the caster lies, or outside that smaller
// region, gets no pairs (tally 9: tiles culled; tiles with no view sample, tally 12, get none
// either). Within a surviving tile, texels whose view samples all lie before the caster are
// skipped (tally 10), as are texels outside the region drawn at their own farthest depth
// (tally 15). These tests are conservative: they drop only pairs the occlusion test would find
// empty. Texels (tally 13) and whole tiles (tally 14) whose every view sample is already hidden
// from every light sample by earlier ranges of casters (`hidden.wgsl`) are skipped as well:
// their answer cannot change.
//
// Before that, the caster's supporting plane is tested against the tile's box of ray origins
// and the light: when both lie strictly on one side, no segment between them crosses the
// caster (a wall or a floor of a room around the light casts on none of its receivers), and
// a closed mesh's caster with every origin behind it casts on none (section 3.3).
// The box of the tile's origins, and within the tile each texel's part of the light's frustum
// between its nearest and farthest view samples, are tested against the caster's penumbra
// volume (`volume.rs`: planes that every point the caster shadows from some light point lies
// inside of). A box or a frustum piece outside one plane holds no view sample the caster can
// shadow (tiles: tally 9; texels: tally 16). The map's border texels, which also hold the view
// samples clamped into the map, are left to the other tests.
// `P.options.w` = 0 turns cluster culling and the skipping of hidden texels and tiles off (for
// the tests that compare both).

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(4) var<storage, read_write> pair_counts: array<u32>;
@group(0) @binding(5) var<storage, read_write> stats: array<atomic<u32>>;
@group(0) @binding(6) var<storage, read> casters: array<Caster>;
@group(0) @binding(7) var<storage, read> tile_depth: array<u32>;
@group(0) @binding(8) var<storage, read> texel_depth: array<u32>;
@group(0) @binding(9) var<storage, read> tile_box: array<u32>;
// Per texel, its view samples already hidden from every light sample (`hidden.wgsl`).
@group(0) @binding(10) var<storage, read> texel_hidden: array<u32>;
// Per tile, its view samples and those of them already hidden (`count.wgsl`, `hidden.wgsl`).
@group(0) @binding(11) var<storage, read> tile_count: array<u32>;
@group(0) @binding(12) var<storage, read> tile_hidden: array<u32>;
// Per caster, its penumbra volume; per texel and per tile, its nearest view sample's depth
// (`count.wgsl`).
@group(0) @binding(13) var<storage, read> volumes: array<Volume>;
@group(0) @binding(14) var<storage, read> texel_near: array<u32>;
@group(0) @binding(15) var<storage, read> tile_near: array<u32>;
// Per tile, its texels that hold a view sample (`count.wgsl`).
@group(0) @binding(18) var<storage, read> texel_bits: array<u32>;
// The map's occupied tiles (`occupancy.wgsl`), for `tile_of`.
@group(0) @binding(16) var<storage, read> occupancy: array<u32>;
// The super-tiles kept per caster of the range (`tiles.wgsl`), for `tile_of`.
@group(0) @binding(17) var<storage, read> caster_masks: array<u32>;

// Depth of a point from the light's centre along the frustum axis.
fn depth_of(p: vec3<f32>) -> f32 {
    return dot(p - P.center.xyz, P.axis_d.xyz);
}

// The depth of the light's farthest point.
fn light_far() -> f32 {
    return (light_range(P.axis_d.xyz) - dot(P.axis_d.xyz, P.center.xyz)).y;
}

// The depth before which view samples are safe from caster t: its nearest depth less a margin
// for rounding, or none when the caster reaches before the light's far side (segments run
// from a view sample to the light, so they reach that deep whatever the sample's depth).
fn near_depth(t: u32) -> f32 {
    let tri = casters[t];
    let z = min(min(depth_of(tri.a), depth_of(tri.b)), depth_of(tri.c));
    return select(z, -3.4e38, z <= light_far()) - 1e-5 * P.axis_d.w;
}

// Whether the caster's supporting plane has the tile's ray origins and the light strictly on
// one side, or (closed meshes) every origin behind it.
fn plane_separates(tl: Tile) -> bool {
    let tri = casters[tl.caster];
    let b = 6u * tl.index;
    let lo = vec3<f32>(from_key(~tile_box[b]), from_key(~tile_box[b + 1u]),
                       from_key(~tile_box[b + 2u]));
    let hi = vec3<f32>(from_key(tile_box[b + 3u]), from_key(tile_box[b + 4u]),
                       from_key(tile_box[b + 5u]));
    let nt = cross(tri.b - tri.a, tri.c - tri.a);
    let base = dot(nt, tri.a);
    let centre = dot(nt, 0.5 * (lo + hi)) - base;
    let reach = dot(abs(nt), 0.5 * (hi - lo));
    let light = light_range(nt) - base;
    let eps = 1e-5 * length(nt) * P.axis_d.w;
    let front = min(centre - reach, light.x) > eps;
    let back = max(centre + reach, light.y) < -eps;
    return front || back || (tri.closed == 1u && centre + reach < -eps);
}

// A caster's influence region as a function of depth: each of its points (the clipped
// caster's vertices p, and for each of them the points f(z) where the lines from the light's
// bounding points y through p reach depth z) has texel coordinates a + b / z (for f:
// a = k, b = (p - c).u - z_p k with k = (p - y).u / (z_p - z_y), then scaled to texels), valid
// for z at or beyond `deepest`, the clipped caster's deepest point. Its hull at depth z (here
// bounded by its box) holds the projections of every view sample at depth z or less that
// the caster can shadow.
struct DepthRegion {
    n: u32,
    a: array<vec2<f32>, 36>,
    b: array<vec2<f32>, 36>,
    deepest: f32,
}

// The box (lo.xy, hi.xy) in texels of the region at depth z.
fn region_box(r: ptr<function, DepthRegion>, z: f32) -> vec4<f32> {
    var lo = vec2<f32>(3.4e38);
    var hi = vec2<f32>(-3.4e38);
    let w = 1.0 / z;
    for (var k = 0u; k < (*r).n; k++) {
        let q = (*r).a[k] + (*r).b[k] * w;
        lo = min(lo, q);
        hi = max(hi, q);
    }
    return vec4<f32>(lo, hi);
}

// Whether a box of texels lies apart from the `size` x `size` texels from `origin`, with a pad
// for rounding. View samples project into their own texel, but are clamped into the map at its
// edges, so the map's edges are open.
fn box_apart(box: vec4<f32>, origin: vec2<i32>, size: i32) -> bool {
    let side = i32(P.dims.x);
    let pad = 0.02 + 1e-5 * f32(side);
    let t0 = vec2<f32>(origin) - pad;
    let t1 = vec2<f32>(origin + vec2<i32>(size)) + pad;
    let open_lo = origin <= vec2<i32>(0);
    let open_hi = origin + vec2<i32>(size) >= vec2<i32>(side);
    return any((box.zw < t0) & !open_lo) || any((box.xy > t1) & !open_hi);
}

// Cluster culling of caster t against tile `tl`, whose view samples lie at depth `zt` or less:
// 0 when the caster cannot shadow any of them, 1 when it may and no region bounds it (a point
// at or behind the light's depth), 2 when it may and `r` holds its region for the texel tests.
fn cluster_region(tl: Tile, zt: f32, r: ptr<function, DepthRegion>) -> u32 {
    if plane_separates(tl) {
        return 0u;
    }
    let tri = casters[tl.caster];
    let zfar = P.axis_d.w;
    if near_depth(tl.caster) > zt {
        return 0u;
    }
    // The construction below needs the whole light before the view samples.
    if light_far() + 1e-5 * zfar >= zt {
        return 1u;
    }
    // The caster clipped to depth <= zt (a triangle gives at most four points).
    var v = array<vec3<f32>, 3>(tri.a, tri.b, tri.c);
    var poly: array<vec3<f32>, 4>;
    var np = 0u;
    for (var k = 0u; k < 3u; k++) {
        let p = v[k];
        let q = v[(k + 1u) % 3u];
        let zp = depth_of(p);
        let zq = depth_of(q);
        if zp <= zt {
            poly[np] = p;
            np++;
        }
        if (zp <= zt) != (zq <= zt) {
            poly[np] = p + (q - p) * ((zt - zp) / (zq - zp));
            np++;
        }
    }
    // Section 4.1's points, as functions of depth.
    let c = P.center.xyz;
    let scale = P.map.zw;
    (*r).n = 0u;
    (*r).deepest = 0.0;
    for (var k = 0u; k < np; k++) {
        let p = poly[k];
        let zp = min(depth_of(p), zt);
        if zp <= 1e-6 * zfar {
            return 1u;
        }
        (*r).deepest = max((*r).deepest, zp);
        let pc = vec2<f32>(dot(p - c, P.axis_u.xyz), dot(p - c, P.axis_v.xyz));
        (*r).a[(*r).n] = to_texel(pc / zp);
        (*r).b[(*r).n] = vec2<f32>(0.0);
        (*r).n++;
        var ys: array<vec3<f32>, 8>;
        let found = light_points(p, &ys);
        if found < 0 {
            return 1u;
        }
        for (var j = 0u; j < u32(found); j++) {
            let zy = depth_of(ys[j]);
            if zp - zy <= 1e-6 * zfar {
                return 1u;
            }
            let py = p - ys[j];
            let k2 = vec2<f32>(dot(py, P.axis_u.xyz), dot(py, P.axis_v.xyz)) / (zp - zy);
            (*r).a[(*r).n] = to_texel(k2);
            (*r).b[(*r).n] = (pc - zp * k2) * scale;
            (*r).n++;
        }
    }
    if box_apart(region_box(r, zt), tl.origin, TILE) {
        return 0u;
    }
    return 2u;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let u = linear_index(g, n);
    if u >= P.work.z {
        return;
    }
    let tl = tile_of(u);
    let zt = bitcast<f32>(tile_depth[tl.index]);
    // The counts and masks start at zero.
    if tile_depth[tl.index] == 0u {
        add64(12u, 1u);
        return;
    }
    let culling = P.options.w == 1u;
    if culling && tile_hidden[tl.index] >= tile_count[tl.index] {
        add64(14u, 1u);
        return;
    }
    var region: DepthRegion;
    var bounded = false;
    var vol = volumes[tl.caster];
    var fp = frame_planes(&vol);
    // Tiles off the map's border hold only view samples inside their own texels' frusta.
    let side = i32(P.dims.x);
    let inner_tile = all(tl.origin > vec2<i32>(0)) && all(tl.origin + TILE < vec2<i32>(side));
    if culling {
        let b = 6u * tl.index;
        let lo = vec3<f32>(from_key(~tile_box[b]), from_key(~tile_box[b + 1u]),
                           from_key(~tile_box[b + 2u]));
        let hi = vec3<f32>(from_key(tile_box[b + 3u]), from_key(tile_box[b + 4u]),
                           from_key(tile_box[b + 5u]));
        var verdict = 0u;
        if inner_tile {
            let z0 = bitcast<f32>(~tile_near[tl.index]);
            let piece = piece_outside(&fp, tl.origin, vec2<f32>(f32(TILE)), z0, zt);
            verdict = select(1u, 0u, piece || box_outside(&vol, lo, hi));
        } else if !box_outside(&vol, lo, hi) {
            verdict = cluster_region(tl, zt, &region);
        }
        if verdict == 0u {
            add64(9u, 1u);
            return;
        }
        bounded = verdict == 2u;
    }
    let near = select(-3.4e38, near_depth(tl.caster), culling);
    var visited = 0u;
    var pairs = 0u;
    var skipped = 0u;
    var outside = 0u;
    var hidden = 0u;
    var apart = 0u;
    var mask = vec2<u32>(0u);
    // The cheap tests first, the hull (section 3.2's conservative rasterisation) last, over
    // the tile's texels that hold a view sample within the region's box.
    var live = vec2<u32>(texel_bits[2u * tl.index], texel_bits[2u * tl.index + 1u]) & box_bits(tl);
    for (var j = 0u; j < 64u && any(live != vec2<u32>(0u)); j++) {
        let word = select(1u, 0u, live.x != 0u);
        let k = 32u * word + firstTrailingBit(live[word]);
        live[word] &= live[word] - 1u;
        let tt = tile_texel_list(tl, k);
        if tt.y > 0u {
            if culling && texel_hidden[tt.x] >= tt.y {
                hidden++;
                continue;
            }
            let zx = bitcast<f32>(texel_depth[tt.x]);
            if zx < near {
                skipped++;
                continue;
            }
            let texel = tl.origin + vec2<i32>(i32(k % u32(TILE)), i32(k / u32(TILE)));
            let inner = all(texel > vec2<i32>(0)) && all(texel < vec2<i32>(side - 1));
            if culling && inner {
                // The texel's frustum piece against the penumbra volume: tighter than the
                // region and its hull, which it replaces.
                let z0 = bitcast<f32>(~texel_near[tt.x]);
                if piece_outside(&fp, texel, vec2<f32>(1.0), z0, zx) {
                    apart++;
                    continue;
                }
            } else {
                // The region at the texel's own depth (or the caster's deepest, if deeper).
                let at = max(zx, region.deepest);
                if bounded && box_apart(region_box(&region, at), texel, 1) {
                    outside++;
                    continue;
                }
                if !tile_texel_in_hull(tl, k) {
                    continue;
                }
            }
            visited++;
            pairs += tt.y;
            mask[k / 32u] |= 1u << (k % 32u);
        }
    }
    pair_counts[u] = pairs;
    pair_counts[P.work.z + 1u + 2u * u] = mask.x;
    pair_counts[P.work.z + 2u + 2u * u] = mask.y;
    add64(0u, visited);
    add64(1u, pairs);
    add64(8u, pairs);
    add64(10u, skipped);
    add64(13u, hidden);
    add64(15u, outside);
    add64(16u, apart);
}
