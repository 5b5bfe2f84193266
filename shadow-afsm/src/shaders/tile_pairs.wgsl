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
// either); within a surviving tile, texels whose view samples all lie before the caster are
// skipped (tally 10), as are texels whose every view sample is already hidden from every
// light sample by earlier ranges of casters (tally 13, `hidden.wgsl`; whole tiles, tally 14).
// The tests are
// conservative: they drop only pairs the occlusion test would find empty.
//
// Before that, the caster's supporting plane is tested against the tile's box of ray origins
// and the light: when both lie strictly on one side, no segment between them crosses the
// caster (a wall or a floor of a room around the light casts on none of its receivers), and
// a closed mesh's caster with every origin behind it casts on none (section 3.3).
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

// Whether caster t may hide part of the light from a view sample of tile `tl`, whose view
// samples lie at depth `zt` or less.
fn cluster_may_shadow(tl: Tile, zt: f32) -> bool {
    if plane_separates(tl) {
        return false;
    }
    let tri = casters[tl.caster];
    let zfar = P.axis_d.w;
    if near_depth(tl.caster) > zt {
        return false;
    }
    // The construction below needs the whole light before the view samples.
    if light_far() + 1e-5 * zfar >= zt {
        return true;
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
    // The region at depth zt, bounded by its box in texels (section 4.1's points).
    var lo = vec2<f32>(3.4e38);
    var hi = vec2<f32>(-3.4e38);
    let c = P.center.xyz;
    for (var k = 0u; k < np; k++) {
        let p = poly[k];
        let zp = min(depth_of(p), zt);
        if zp <= 1e-6 * zfar {
            return true;
        }
        let own = to_texel(project(p).xy);
        lo = min(lo, own);
        hi = max(hi, own);
        var ys: array<vec3<f32>, 8>;
        let found = light_points(p, &ys);
        if found < 0 {
            return true;
        }
        for (var j = 0u; j < u32(found); j++) {
            let zy = depth_of(ys[j]);
            if zp - zy <= 1e-6 * zfar {
                return true;
            }
            let f = p + ((zt - zp) / (zp - zy)) * (p - ys[j]) - c;
            let ft = to_texel(vec2<f32>(dot(f, P.axis_u.xyz), dot(f, P.axis_v.xyz)) / zt);
            lo = min(lo, ft);
            hi = max(hi, ft);
        }
    }
    // The tile's view samples project into its texels; at the map's edges, also beyond them
    // (projections are clamped into the map). A small pad covers rounding.
    let side = i32(P.dims.x);
    let pad = 0.02 + 1e-5 * f32(side);
    let t0 = vec2<f32>(tl.origin) - pad;
    let t1 = vec2<f32>(tl.origin + vec2<i32>(TILE)) + pad;
    let open_lo = tl.origin <= vec2<i32>(0);
    let open_hi = tl.origin + vec2<i32>(TILE) >= vec2<i32>(side);
    let apart_lo = (hi < t0) & !open_lo;
    let apart_hi = (lo > t1) & !open_hi;
    return !(any(apart_lo) || any(apart_hi));
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
    if culling && !cluster_may_shadow(tl, zt) {
        add64(9u, 1u);
        return;
    }
    let near = select(-3.4e38, near_depth(tl.caster), culling);
    var visited = 0u;
    var pairs = 0u;
    var skipped = 0u;
    var hidden = 0u;
    var mask = vec2<u32>(0u);
    for (var k = 0u; k < 64u; k++) {
        let tt = tile_texel(tl, k);
        if tt.y > 0u {
            if culling && texel_hidden[tt.x] >= tt.y {
                hidden++;
                continue;
            }
            if bitcast<f32>(texel_depth[tt.x]) < near {
                skipped++;
                continue;
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
}
