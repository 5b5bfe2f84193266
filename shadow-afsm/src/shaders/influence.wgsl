// Section 4.1: each caster triangle's influence region in the shadow map. For every vertex v
// and every point y bounding the light (rectangle corners, polygon outline, the octagon around
// a disk; for spheres the hexagon around the light's silhouette circle seen from v), the line
// from y through v meets the far plane (the farthest listed view sample) at f; the convex
// hull of the projections of the vertices and of every f bounds the texels whose view samples
// the triangle can shadow. A point light gives the triangle's own projection (section 3).
// Conservative back-face culling for closed meshes (section 4.3, [ED07]): a triangle whose
// supporting plane has the whole light on its front side is never a light back-facing caster.
// The root of the view-sample cluster hierarchy: with cluster culling on, a caster whose
// penumbra volume (`volume.wgsl`) misses the box of every ray origin of the batch shadows
// none of them and gets no region (tally 18: casters culled), so `tiles.wgsl` numbers no tile
// for it.

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> casters: array<Caster>;
@group(0) @binding(2) var<storage, read_write> regions: array<Region>;
@group(0) @binding(3) var<storage, read> volumes: array<Volume>;
// The box of the batch's ray origins: lower corner, then upper corner.
@group(0) @binding(4) var<storage, read> batch_box: array<vec4<f32>, 2>;
@group(0) @binding(5) var<storage, read_write> stats: array<atomic<u32>>;

fn cross2(o: vec2<f32>, a: vec2<f32>, b: vec2<f32>) -> f32 {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

fn whole_map(t: u32) {
    let s = i32(P.dims.x) - 1;
    regions[t].bbox = vec4<i32>(0, 0, s, s);
    regions[t].info = vec4<u32>(0u, 1u, 0u, 0u);
}

fn culled(t: u32) {
    regions[t].bbox = vec4<i32>(0, 0, -1, -1);
    regions[t].info = vec4<u32>(0u, 0u, 0u, 0u);
}

fn lex_less(a: vec2<f32>, b: vec2<f32>) -> bool {
    return a.x < b.x || (a.x == b.x && a.y < b.y);
}

// Merges the ring pts[off .. off + cnt) (a convex polygon in cyclic order, cnt <= 8) into the
// sorted points out[0 .. s) and returns the new count. From the ring's lexicographic minimum,
// the forward and the backward walks to its maximum are both sorted: merging them sorts the
// ring in O(cnt), and one pass from the back merges it into `out`.
fn merge_ring(pts: ptr<function, array<vec2<f32>, 28>>, off: u32, cnt: u32,
              out: ptr<function, array<vec2<f32>, 28>>, s: u32) -> u32 {
    if cnt == 0u {
        return s;
    }
    var lo = 0u;
    var hi = 0u;
    for (var j = 1u; j < cnt; j++) {
        let p = (*pts)[off + j];
        if lex_less(p, (*pts)[off + lo]) {
            lo = j;
        }
        if lex_less((*pts)[off + hi], p) {
            hi = j;
        }
    }
    var run: array<vec2<f32>, 8>;
    var r = 0u;
    if lo == hi {
        // Every point equal (or one point): any order is sorted.
        for (var j = 0u; j < cnt; j++) {
            run[j] = (*pts)[off + j];
        }
        r = cnt;
    } else {
        run[0] = (*pts)[off + lo];
        r = 1u;
        var a = (lo + 1u) % cnt;
        var b = (lo + cnt - 1u) % cnt;
        while a != hi || b != hi {
            let take_a = a != hi && (b == hi || !lex_less((*pts)[off + b], (*pts)[off + a]));
            if take_a {
                run[r] = (*pts)[off + a];
                a = (a + 1u) % cnt;
            } else {
                run[r] = (*pts)[off + b];
                b = (b + cnt - 1u) % cnt;
            }
            r++;
        }
        run[r] = (*pts)[off + hi];
        r++;
    }
    var i = i32(s) - 1;
    var j = i32(r) - 1;
    var w = i32(s + r) - 1;
    while j >= 0 {
        if i >= 0 && lex_less(run[j], (*out)[i]) {
            (*out)[w] = (*out)[i];
            i--;
        } else {
            (*out)[w] = run[j];
            j--;
        }
        w--;
    }
    return s + r;
}

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let t = linear_index(g, n);
    if t >= P.kind.x {
        return;
    }
    let tri = casters[t];
    if P.options.w == 1u {
        var vol = volumes[t];
        if box_outside(&vol, batch_box[0].xyz, batch_box[1].xyz) {
            culled(t);
            add64(18u, 1u);
            return;
        }
    }
    var v = array<vec3<f32>, 3>(tri.a, tri.b, tri.c);
    let nt = cross(v[1] - v[0], v[2] - v[0]);
    let closed = tri.closed == 1u;
    let r = light_range(nt) - dot(nt, v[0]);
    if closed && r.x > 0.0 {
        culled(t);
        return;
    }
    let zfar = P.axis_d.w;
    let d = P.axis_d.xyz;
    let c = P.center.xyz;
    var zmin = 3.4e38;
    var zmax = -3.4e38;
    for (var k = 0u; k < 3u; k++) {
        zmin = min(zmin, dot(v[k] - c, d));
        zmax = max(zmax, dot(v[k] - c, d));
    }
    if zmin > zfar {
        // Beyond every listed view sample: it shadows none of them.
        culled(t);
        return;
    }
    // Wholly before the light's nearest point along the frustum axis (behind the light for
    // this frustum, as for a cube face's frustum facing away from it): a segment from a view
    // sample (in front of the light's centre) to the light never reaches it.
    let light_near = (light_range(d) - dot(d, c)).x;
    if zmax < light_near - 1e-5 * zfar {
        culled(t);
        return;
    }
    // Group 0: the vertices' projections (three points are always in cyclic order). Group
    // k + 1: the light's bounding points seen through vertex k, in the cyclic order of the
    // light's outline (a central projection keeps a convex polygon convex and in order).
    var pts: array<vec2<f32>, 28>;
    var m = 3u;
    var ny = 0u;
    for (var k = 0u; k < 3u; k++) {
        let vk = v[k];
        let zv = dot(vk - c, d);
        if zv <= 1e-6 * zfar {
            whole_map(t);
            return;
        }
        pts[k] = to_texel(project(vk).xy);
        // The points bounding the light as seen through this vertex.
        var ys: array<vec3<f32>, 8>;
        let found = light_points(vk, &ys);
        if found < 0 {
            whole_map(t);
            return;
        }
        ny = u32(found);
        for (var j = 0u; j < ny; j++) {
            let zy = dot(ys[j] - c, d);
            if zv - zy <= 1e-6 * zfar {
                whole_map(t);
                return;
            }
            let s = (zfar - zv) / (zv - zy);
            let f = vk + s * (vk - ys[j]);
            let q = f - c;
            pts[m] = to_texel(vec2<f32>(dot(q, P.axis_u.xyz), dot(q, P.axis_v.xyz)) / zfar);
            m++;
        }
    }
    // Bounding box, then the convex hull (a monotone chain over the points sorted in O(n)).
    var lo = pts[0];
    var hi = pts[0];
    for (var k = 1u; k < m; k++) {
        lo = min(lo, pts[k]);
        hi = max(hi, pts[k]);
    }
    let side = f32(P.dims.x);
    let eps = 1e-3;
    if hi.x < -eps || hi.y < -eps || lo.x > side + eps || lo.y > side + eps {
        culled(t);
        return;
    }
    let s1 = i32(P.dims.x) - 1;
    regions[t].bbox = vec4<i32>(
        clamp(i32(floor(lo.x - eps)), 0, s1),
        clamp(i32(floor(lo.y - eps)), 0, s1),
        clamp(i32(floor(hi.x + eps)), 0, s1),
        clamp(i32(floor(hi.y + eps)), 0, s1));
    // Sorted by x, then y, in O(n) (section 4.1): each group's cyclic order splits at its
    // lexicographic extremes into two sorted chains, merged into the sorted points so far. The
    // insertion sort that follows costs one comparison per point when the merge is sorted, and
    // repairs the order where rounding made a group not quite convex.
    var sorted: array<vec2<f32>, 28>;
    var count = merge_ring(&pts, 0u, 3u, &sorted, 0u);
    for (var k = 0u; k < 3u; k++) {
        count = merge_ring(&pts, 3u + k * ny, ny, &sorted, count);
    }
    for (var i = 1u; i < m; i++) {
        let p = sorted[i];
        var j = i;
        while j > 0u && lex_less(p, sorted[j - 1u]) {
            sorted[j] = sorted[j - 1u];
            j--;
        }
        sorted[j] = p;
    }
    var hull: array<vec2<f32>, 29>;
    var h = 0u;
    for (var i = 0u; i < m; i++) {
        while h >= 2u && cross2(hull[h - 2u], hull[h - 1u], sorted[i]) <= 0.0 {
            h--;
        }
        hull[h] = sorted[i];
        h++;
    }
    let lower = h + 1u;
    for (var ii = 1u; ii < m; ii++) {
        let i = m - 1u - ii;
        while h >= lower && cross2(hull[h - 2u], hull[h - 1u], sorted[i]) <= 0.0 {
            h--;
        }
        hull[h] = sorted[i];
        h++;
    }
    if h > 1u {
        h--;
    }
    if h < 3u {
        // Degenerate (a triangle seen edge-on from a point light): the box alone.
        regions[t].info = vec4<u32>(0u, 2u, 0u, 0u);
        return;
    }
    for (var k = 0u; k < h; k++) {
        regions[t].pts[k] = hull[k];
    }
    regions[t].info = vec4<u32>(h, 0u, 0u, 0u);
}
