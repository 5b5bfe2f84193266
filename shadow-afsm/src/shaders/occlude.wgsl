// Sections 3.2, 3.3 and 4.2: one workgroup per caster triangle walks the texels of its
// influence region (conservative rasterisation: a texel is visited when its square overlaps
// the hull), skips empty lists, and tests every listed view sample against the triangle.
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
// Per-sample tests are exact (plane against sample), or, in LUT mode, the 3D lookup table of
// section 4.2 returns the samples behind each plane from its two angles and distance, and the
// masks of the planes are ANDed. Results combine across triangles with atomic OR.

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> casters: array<Caster>;
@group(0) @binding(2) var<storage, read> regions: array<Region>;
@group(0) @binding(3) var<storage, read> receivers: array<Receiver>;
@group(0) @binding(4) var<storage, read> offsets: array<u32>;
@group(0) @binding(5) var<storage, read> lists: array<u32>;
@group(0) @binding(6) var<storage, read> samples: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> masks: array<atomic<u32>>;
@group(0) @binding(8) var<storage, read_write> stats: array<atomic<u32>>;
@group(0) @binding(9) var<storage, read> lut: array<u32>;

fn add64(slot: u32, v: u32) {
    if v == 0u {
        return;
    }
    let old = atomicAdd(&stats[2u * slot], v);
    if old + v < old {
        atomicAdd(&stats[2u * slot + 1u], 1u);
    }
}

fn texel_overlaps(t: u32, tx: i32, ty: i32) -> bool {
    let info = regions[t].info;
    if info.y != 0u || info.x < 3u {
        return true;
    }
    // Separating axes: the hull's edges (the box was tested by the loop bounds).
    let lo = vec2<f32>(f32(tx), f32(ty)) - vec2<f32>(1e-3);
    let hi = lo + vec2<f32>(1.0 + 2e-3);
    let h = info.x;
    for (var k = 0u; k < h; k++) {
        let a = regions[t].pts[k];
        let b = regions[t].pts[(k + 1u) % h];
        let e = b - a;
        // Inward normal of a counter-clockwise hull is (-e.y, e.x); the texel is outside when
        // its corner farthest along that normal is still outside.
        let nrm = vec2<f32>(-e.y, e.x);
        let corner = vec2<f32>(select(lo.x, hi.x, nrm.x > 0.0), select(lo.y, hi.y, nrm.y > 0.0));
        if dot(nrm, corner - a) < 0.0 {
            return false;
        }
    }
    return true;
}

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

// Tests receiver `i` against caster `t` and ORs the occluded samples into its mask. Returns 0
// for the receiver's own triangle, 1 for an empty pair, 2 for a full one, 3 for per-sample work.
fn occlude_pair(t: u32, i: u32) -> u32 {
    let tri = casters[t];
    let a = tri.a;
    let b = tri.b;
    let c = tri.c;
    let r = receivers[i];
    if r.triangle == tri.id {
        return 0u;
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
    var na = 0u;
    for (var p = 0u; p < 4u; p++) {
        let rg = light_range(ms[p]) - bs[p];
        if p == 0u {
            if rg.y <= 0.0 {
                return 1u;
            }
            if rg.x > 0.0 {
                continue;
            }
        } else {
            if rg.y < 0.0 {
                return 1u;
            }
            if rg.x >= 0.0 {
                continue;
            }
        }
        live[na] = p;
        na++;
    }
    let n_samples = P.dims.z;
    let words = P.dims.w;
    if na == 0u {
        for (var wd = 0u; wd < words; wd++) {
            let rest = n_samples - wd * 32u;
            let bits = select((1u << rest) - 1u, 0xffffffffu, rest >= 32u);
            atomicOr(&masks[i * words + wd], bits);
        }
        return 2u;
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
                atomicOr(&masks[i * words + wd], bits);
            }
        }
        return 3u;
    }
    let first = r.set_index * n_samples;
    for (var wd = 0u; wd < words; wd++) {
        var bits = 0u;
        let k0 = wd * 32u;
        let k1 = min(k0 + 32u, n_samples);
        for (var kk = k0; kk < k1; kk++) {
            let y = samples[first + kk].xyz;
            var inside = true;
            for (var q = 0u; q < na; q++) {
                let p = live[q];
                let f = dot(ms[p], y) - bs[p];
                if (p == 0u && f <= 0.0) || (p != 0u && f < 0.0) {
                    inside = false;
                    break;
                }
            }
            if inside {
                bits |= 1u << (kk - k0);
            }
        }
        if bits != 0u {
            atomicOr(&masks[i * words + wd], bits);
        }
    }
    return 3u;
}

@compute @workgroup_size(64)
fn main(@builtin(local_invocation_id) l: vec3<u32>, @builtin(workgroup_id) w: vec3<u32>,
        @builtin(num_workgroups) nw: vec3<u32>) {
    let t = w.y * nw.x + w.x;
    if t >= P.kind.x {
        return;
    }
    let bbox = regions[t].bbox;
    let bw = bbox.z - bbox.x + 1;
    let bh = bbox.w - bbox.y + 1;
    // Tallies: texels visited, pairs, then by outcome (own, empty, full, per-sample).
    var visited = 0u;
    var outcome = array<u32, 4>(0u, 0u, 0u, 0u);
    if bw > 0 && bh > 0 {
        let side = P.dims.x;
        let area = u32(bw) * u32(bh);
        for (var k = l.x; k < area; k += 64u) {
            let tx = bbox.x + i32(k % u32(bw));
            let ty = bbox.y + i32(k / u32(bw));
            let texel = u32(ty) * side + u32(tx);
            let start = offsets[texel];
            let end = offsets[texel + 1u];
            if start == end || !texel_overlaps(t, tx, ty) {
                continue;
            }
            visited++;
            for (var e = start; e < end; e++) {
                outcome[occlude_pair(t, lists[e])]++;
            }
        }
    }
    // Tallies go straight to the 64-bit global counters (low word, carry into the high word).
    add64(0u, visited);
    add64(1u, outcome[1] + outcome[2] + outcome[3]);
    add64(2u, outcome[1]);
    add64(3u, outcome[2]);
    add64(4u, outcome[3]);
    add64(5u, outcome[0]);
}
