// Sections 3.2, 3.3 and 4.2: the (caster, view sample) pairs of a range of casters, numbered
// across tiles by the running sum of each tile's pair count (`tile_pairs.wgsl`), are dealt out
// `pairs_per_invocation()` consecutive ones to each invocation: every invocation finds its
// first pair's tile by a binary search, walks the tile's overlapping texels (their mask comes
// from `tile_pairs`) to the pair's list entry, then steps through its pairs, searching again
// when it passes the end of a tile. Lanes are never idle for want of pairs in a tile, and no
// invocation's work grows with a region's size or a list's length.
//
// A light sample y is hidden from view sample o by the triangle when y lies inside the three
// planes through o and each edge, and beyond the triangle's supporting plane. For closed
// meshes only triangles with o in front of them count, so that y must see the triangle's back
// (light back-facing casters, section 3.3: no bias); for open meshes either side counts.
//
// Restrict computations (section 4.3): each plane is first classified against the whole light;
// a plane with the whole light inside is dropped, one with the light outside ends the pair, so
// per-sample work happens only for the planes that cut the light, i.e. where an edge of the
// triangle is a silhouette seen from o for part of the light. Pairs whose every plane is
// dropped (umbra from this triangle) set the whole mask at once.
//
// Per-sample tests are exact (plane against sample; on planar lights only the samples bucketed
// under the triangle's projection onto the light, see `sample_grid.rs`), or, in LUT mode, the
// 3D lookup table of section 4.2 returns the samples behind each plane from its two angles and
// distance, and the masks of the planes are ANDed. Off the silhouette stencil one sample
// stands for all. Opaque casters combine with atomic OR; semi-opaque ones add their optical
// depth to each hidden sample's sum (saturating).

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(4) var<storage, read> pair_offsets: array<u32>;
@group(0) @binding(5) var<storage, read> casters: array<Caster>;
@group(0) @binding(6) var<storage, read> receivers: array<Receiver>;
@group(0) @binding(7) var<storage, read> lists: array<u32>;
@group(0) @binding(8) var<storage, read> samples: array<vec4<f32>>;
@group(0) @binding(9) var<storage, read_write> masks: array<atomic<u32>>;
@group(0) @binding(10) var<storage, read_write> stats: array<atomic<u32>>;
// The plane table in LUT mode; in exact mode, the light samples bucketed on the light's plane
// (`sample_grid.rs`): per set, g * g + 1 bucket offsets, then the sample indices.
@group(0) @binding(11) var<storage, read> lut: array<u32>;
@group(0) @binding(12) var<storage, read> flags: array<u32>;
@group(0) @binding(13) var<storage, read_write> depths: array<atomic<u32>>;
// The map's occupied tiles (`occupancy.wgsl`), for `tile_of`.
@group(0) @binding(14) var<storage, read> occupancy: array<u32>;
// The super-tiles kept per caster of the range (`tiles.wgsl`), for `tile_of`.
@group(0) @binding(15) var<storage, read> caster_masks: array<u32>;

// The pair outcomes of the workgroup.
var<workgroup> outcomes: array<atomic<u32>, 6>;

// LUT cell of the oriented plane {y : dot(m, y - base) >= 0}.
fn lut_cell(m: vec3<f32>, base: vec3<f32>) -> u32 {
    let mh = normalize(m);
    let mu = dot(mh, P.light_u.xyz);
    let mv = dot(mh, P.light_v.xyz);
    let mn = dot(mh, P.light_n.xyz);
    let theta = acos(clamp(mn, -1.0, 1.0));
    let phi = atan2(mv, mu);
    let delta = dot(mh, base - P.center.xyz) / P.light_u.w;
    let nt = P.lut.x;
    let np = P.lut.y;
    let nd = P.lut.z;
    let it = min(u32(theta / 3.14159265 * f32(nt)), nt - 1u);
    let ip = min(u32((phi + 3.14159265) / 6.2831853 * f32(np)), np - 1u);
    let id = u32(clamp((delta + 1.0) * 0.5 * f32(nd), 0.0, f32(nd - 1u)));
    return (it * np + ip) * nd + id;
}

// Whether light sample y lies inside the four oriented planes (strictly for the supporting
// plane q = 0); a plane dropped by the whole-light classification is (0, -1), always inside.
// Branch-free: no loop over the live planes, so every invocation runs the same code.
fn inside4(y: vec3<f32>, ms: ptr<function, array<vec3<f32>, 4>>,
           bs: ptr<function, array<f32, 4>>) -> bool {
    let f0 = dot((*ms)[0], y) - (*bs)[0];
    let f1 = dot((*ms)[1], y) - (*bs)[1];
    let f2 = dot((*ms)[2], y) - (*bs)[2];
    let f3 = dot((*ms)[3], y) - (*bs)[3];
    return f0 > 0.0 && min(min(f1, f2), f3) >= 0.0;
}

// Hides the samples of word wd set in `bits` from receiver i behind a caster of optical depth
// `depth`: opaque casters OR the bits into the mask; semi-opaque ones add their optical depth
// to each sample's sum (section 6's transparency, exact per sample), saturating at OPAQUE.
fn hide(i: u32, wd: u32, bits: u32, depth: u32) {
    if depth == OPAQUE {
        atomicOr(&masks[i * P.dims.w + wd], bits);
        return;
    }
    var b = bits;
    while b != 0u {
        let slot = i * P.dims.z + wd * 32u + firstTrailingBit(b);
        b &= b - 1u;
        let old = atomicAdd(&depths[slot], depth);
        if old > OPAQUE - depth {
            atomicMax(&depths[slot], OPAQUE);
        }
    }
}

// Hides all N samples of receiver i.
fn hide_all(i: u32, depth: u32) {
    let n_samples = P.dims.z;
    for (var wd = 0u; wd < P.dims.w; wd++) {
        let rest = n_samples - wd * 32u;
        hide(i, wd, select((1u << rest) - 1u, 0xffffffffu, rest >= 32u), depth);
    }
}

// Whether every light sample of receiver i is already hidden by an opaque caster: later
// casters cannot change its answer (the mask only gains bits, and a hidden sample's optical
// depth is never read).
fn hidden_everywhere(i: u32) -> bool {
    let n_samples = P.dims.z;
    for (var wd = 0u; wd < P.dims.w; wd++) {
        let rest = n_samples - wd * 32u;
        let full = select((1u << rest) - 1u, 0xffffffffu, rest >= 32u);
        if atomicLoad(&masks[i * P.dims.w + wd]) != full {
            return false;
        }
    }
    return true;
}

// Tests receiver `i` against caster `t` and ORs the occluded samples into its mask; `one`
// when the receiver's texel is off the silhouette stencil (one sample stands for all). Returns
// 0 for the receiver's own triangle, 1 for an empty pair, 2 for a full one, 3 for per-sample
// work, 4 for a one-sample test, 5 for a receiver already hidden everywhere (its per-sample
// work skipped; how many depends on the order pairs run in).
fn occlude_pair(t: u32, i: u32, one: bool) -> u32 {
    let tri = casters[t];
    let a = tri.a;
    let b = tri.b;
    let c = tri.c;
    let r = receivers[i];
    if r.triangle == tri.id {
        return 0u;
    }
    if hidden_everywhere(i) {
        return 5u;
    }
    let nt = cross(b - a, c - a);
    let o = r.origin;
    let so = dot(nt, o - a);
    if so == 0.0 || (tri.closed == 1u && so < 0.0) {
        return 1u;
    }
    // Oriented planes: inside means dot(m, y) >= base (strict for the supporting plane).
    var ms: array<vec3<f32>, 4>;
    var bs: array<f32, 4>;
    let m0 = select(nt, -nt, so > 0.0);
    ms[0] = m0;
    bs[0] = dot(m0, a);
    let e1 = cross(a - o, b - o);
    let e2 = cross(b - o, c - o);
    let e3 = cross(c - o, a - o);
    let sigma = select(-1.0, 1.0, dot(e1, c - o) > 0.0);
    ms[1] = sigma * e1;
    ms[2] = sigma * e2;
    ms[3] = sigma * e3;
    bs[1] = dot(ms[1], o);
    bs[2] = dot(ms[2], o);
    bs[3] = dot(ms[3], o);
    var live: array<u32, 4>;
    var cuts: array<bool, 4>;
    var na = 0u;
    var empty = false;
    for (var p = 0u; p < 4u; p++) {
        let rg = light_range(ms[p]) - bs[p];
        // Outside: the whole light is behind the plane; inside: the whole light in front.
        let outside = select(rg.y < 0.0, rg.y <= 0.0, p == 0u);
        let inside = select(rg.x >= 0.0, rg.x > 0.0, p == 0u);
        empty = empty || outside;
        cuts[p] = !inside;
        if !inside {
            live[na] = p;
            na++;
        }
    }
    if empty {
        return 1u;
    }
    // The exact test's planes: those that do not cut the light always hold.
    var tm = ms;
    var tb = bs;
    for (var p = 0u; p < 4u; p++) {
        if !cuts[p] {
            tm[p] = vec3<f32>(0.0);
            tb[p] = -1.0;
        }
    }
    let n_samples = P.dims.z;
    let words = P.dims.w;
    let depth = tri.optical_depth;
    if na == 0u {
        hide_all(i, depth);
        return 2u;
    }
    let first = r.set_index * n_samples;
    if one {
        if inside4(samples[first].xyz, &tm, &tb) {
            hide_all(i, depth);
        }
        return 4u;
    }
    if P.kind.w == 1u {
        var cells: array<u32, 4>;
        for (var q = 0u; q < na; q++) {
            let p = live[q];
            // The table stores dot(m, y - base) >= 0; the supporting plane's strict inequality
            // differs only on the plane itself.
            cells[q] = lut_cell(ms[p], select(o, a, p == 0u));
        }
        for (var wd = 0u; wd < words; wd++) {
            var bits = 0xffffffffu;
            for (var q = 0u; q < na; q++) {
                bits &= lut[cells[q] * words + wd];
            }
            if bits != 0u {
                hide(i, wd, bits, depth);
            }
        }
        return 3u;
    }
    // Exact test. On a planar light, only the buckets under the bounding box of the triangle
    // projected from o onto the light's plane can hold hidden samples (`sample_grid.rs`).
    let g = P.options.z;
    var bounded = g > 0u;
    var box = vec4<u32>(0u);
    if bounded {
        let n = P.light_n.xyz;
        let num = dot(P.center.xyz - o, n);
        var lo = vec2<f32>(3.4e38);
        var hi = vec2<f32>(-3.4e38);
        let verts = array<vec3<f32>, 3>(a, b, c);
        for (var k = 0u; k < 3u; k++) {
            let den = dot(verts[k] - o, n);
            // A vertex that does not project forward leaves the projection unbounded.
            bounded = bounded && num * den > 0.0;
            let q = o + (num / den) * (verts[k] - o) - P.center.xyz;
            let uv = vec2<f32>(dot(q, P.light_u.xyz), dot(q, P.light_v.xyz));
            lo = min(lo, uv);
            hi = max(hi, uv);
        }
        // Padded by 1e-4 of the light's size against rounding.
        let pad = 1e-4 * P.light_u.w;
        let t0 = floor((lo - pad - P.grid.xy) * P.grid.zw);
        let t1 = floor((hi + pad - P.grid.xy) * P.grid.zw);
        let m = f32(g - 1u);
        if bounded && (any(t1 < vec2<f32>(0.0)) || any(t0 > vec2<f32>(m))) {
            // The projection misses every sample: nothing to hide.
            return 3u;
        }
        box = vec4<u32>(vec2<u32>(clamp(t0, vec2<f32>(0.0), vec2<f32>(m))),
                        vec2<u32>(clamp(t1, vec2<f32>(0.0), vec2<f32>(m))));
        // Over half the buckets, the plain loop over every sample is cheaper.
        bounded = bounded && 2u * (box.z - box.x + 1u) * (box.w - box.y + 1u) <= g * g;
    }
    if bounded {
        var hidden: array<u32, 32>;
        let cells = g * g;
        let base = r.set_index * (cells + 1u + n_samples);
        for (var by = box.y; by <= box.w; by++) {
            let row = base + by * g;
            for (var j = lut[row + box.x]; j < lut[row + box.z + 1u]; j++) {
                let k = lut[base + cells + 1u + j];
                if inside4(samples[first + k].xyz, &tm, &tb) {
                    hidden[k / 32u] |= 1u << (k % 32u);
                }
            }
        }
        for (var wd = 0u; wd < words; wd++) {
            if hidden[wd] != 0u {
                hide(i, wd, hidden[wd], depth);
            }
        }
        return 3u;
    }
    for (var wd = 0u; wd < words; wd++) {
        var bits = 0u;
        let k0 = wd * 32u;
        let k1 = min(k0 + 32u, n_samples);
        for (var kk = k0; kk < k1; kk++) {
            if inside4(samples[first + kk].xyz, &tm, &tb) {
                bits |= 1u << (kk - k0);
            }
        }
        if bits != 0u {
            hide(i, wd, bits, depth);
        }
    }
    return 3u;
}

// Consecutive pairs per invocation: enough to pay for the searches, few enough that the
// per-sample loops of one invocation stay well inside software rasterisers' iteration limits.
fn pairs_per_invocation() -> u32 {
    return clamp(64u / P.dims.w, 1u, 8u);
}

// A position in the pair numbering: the tile, its texel mask not yet walked past, the current
// texel's index and list length, the entry in that list, and the pair number where the tile
// ends.
struct Cursor {
    tile: Tile,
    slot: u32,
    mask: vec2<u32>,
    texel: u32,
    len: u32,
    entry: u32,
    end: u32,
}

// Moves the cursor to the next overlapping texel of its tile (its mask must not be empty).
fn next_texel(cur: ptr<function, Cursor>) {
    let word = select(1u, 0u, (*cur).mask.x != 0u);
    let k = 32u * word + firstTrailingBit((*cur).mask[word]);
    (*cur).mask[word] &= (*cur).mask[word] - 1u;
    (*cur).texel = tile_texel_index((*cur).tile, k);
    (*cur).len = offsets[(*cur).texel + 1u] - offsets[(*cur).texel];
    (*cur).entry = 0u;
}

// The cursor at pair `e` of the range.
fn seek(e: u32) -> Cursor {
    var lo = 0u;
    var hi = P.work.z;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if pair_offsets[mid] <= e {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    var cur: Cursor;
    cur.tile = tile_of(lo);
    cur.slot = lo;
    cur.mask = vec2<u32>(pair_offsets[P.work.z + 1u + 2u * lo],
                         pair_offsets[P.work.z + 2u + 2u * lo]);
    cur.end = pair_offsets[lo + 1u];
    var local = e - pair_offsets[lo];
    // At most 64 texels: the entry lies in the first texel whose list outlasts `local`.
    next_texel(&cur);
    for (var k = 0u; k < 64u && local >= cur.len; k++) {
        local -= cur.len;
        next_texel(&cur);
    }
    cur.entry = local;
    return cur;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>,
        @builtin(local_invocation_index) li: u32) {
    let per = pairs_per_invocation();
    let first = linear_index(g, n) * per;
    var counts = array<u32, 6>(0u, 0u, 0u, 0u, 0u, 0u);
    if first < P.work.w {
        let last = min(first + per, P.work.w);
        var cur = seek(first);
        for (var e = first; e < last; e++) {
            if e == cur.end {
                cur = seek(e);
            } else if cur.entry == cur.len {
                next_texel(&cur);
            }
            let i = lists[offsets[cur.texel] + cur.entry];
            cur.entry++;
            let one = P.options.x == 1u && flags[cur.texel] == 0u;
            counts[occlude_pair(cur.tile.caster, i, one)]++;
        }
    }
    for (var k = 0u; k < 6u; k++) {
        if counts[k] != 0u {
            atomicAdd(&outcomes[k], counts[k]);
        }
    }
    workgroupBarrier();
    // Tallies by outcome (empty, full, per-sample, own triangle, one sample, already hidden),
    // once per workgroup.
    if li == 0u {
        add64(2u, atomicLoad(&outcomes[1]));
        add64(3u, atomicLoad(&outcomes[2]));
        add64(4u, atomicLoad(&outcomes[3]));
        add64(5u, atomicLoad(&outcomes[0]));
        add64(6u, atomicLoad(&outcomes[4]));
        add64(11u, atomicLoad(&outcomes[5]));
    }
}
