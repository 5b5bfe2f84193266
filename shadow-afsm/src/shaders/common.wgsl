// Shared definitions of the AFSM compute passes (Sintorn, Eisemann and Assarsson 2008). Every
// module is this file followed by one pass; the Rust side mirrors `Params` in `params.rs`.

struct Params {
    // Light frame (section 4.3): centre, two axes spanning the map plane, the frustum axis
    // (w = far plane distance), and the projected box: x0, y0, texels per unit in x and y.
    center: vec4<f32>,
    axis_u: vec4<f32>,
    axis_v: vec4<f32>,
    axis_d: vec4<f32>,
    map: vec4<f32>,
    // The light: plane normal (planar lights), w = radius (disk, sphere) or bounding radius.
    light_n: vec4<f32>,
    // The light's own in-plane axes (disk octagon, LUT frame); w of light_u = bounding radius.
    light_u: vec4<f32>,
    light_v: vec4<f32>,
    // side, listed receivers, samples per set N, words per receiver W.
    dims: vec4<u32>,
    // caster triangles in this batch, light kind (0 polygon points, 1 disk, 2 sphere, 3 point),
    // number of outline points, LUT mode (1 = lookup table).
    kind: vec4<u32>,
    // LUT bins in theta, phi, delta; 1 when the light is textured.
    lut: vec4<u32>,
    // The occlusion work of one range of casters: first caster, caster count, tiles, pairs.
    work: vec4<u32>,
    // x = 1 when the silhouette stencil restricts per-sample work (section 4.3); y = 1 when
    // semi-opaque casters accumulate per-sample optical depths; z = buckets per side of the
    // sample grid (0: none); w = 1 when cluster culling is on.
    options: vec4<u32>,
    // The sample grid: origin (u, v) and buckets per unit (u, v) in the light's plane.
    grid: vec4<f32>,
    // Up to 8 points bounding the light (rectangle corners, polygon outline or its box).
    outline: array<vec4<f32>, 8>,
}

// Integers live in their own u32 fields (never bit-cast into floats: a small integer's bits are
// a denormal float, which some drivers flush to zero).
struct Receiver {
    // Ray origin (offset off the surface as the reference does) and sample set index.
    origin: vec3<f32>,
    set_index: u32,
    // Surface point and the receiver's own triangle.
    position: vec3<f32>,
    triangle: u32,
    // Geometric normal.
    normal: vec3<f32>,
    pad: u32,
}

struct Caster {
    // Vertices, the triangle id, 1 when its mesh is closed, and the optical depth of one
    // crossing (-ln(1 - opacity) in units of 1 / DEPTH_SCALE; OPAQUE for opaque casters).
    a: vec3<f32>,
    id: u32,
    b: vec3<f32>,
    closed: u32,
    c: vec3<f32>,
    optical_depth: u32,
}

const DEPTH_SCALE: f32 = 1048576.0;
const OPAQUE: u32 = 0xffffffffu;

const MAX_HULL: u32 = 28u;

struct Region {
    // Texel box (x0, y0, x1, y1), inclusive.
    bbox: vec4<i32>,
    // Hull vertex count (0 = culled), whole map flag, pad, pad.
    info: vec4<u32>,
    pts: array<vec2<f32>, 28>,
}

// Linear index of an invocation in a (possibly 2D-split) dispatch of 64-wide workgroups.
fn linear_index(g: vec3<u32>, n: vec3<u32>) -> u32 {
    return g.y * n.x * 64u + g.x;
}

// Projected map coordinates (before texel scaling) of a world point; z in w.
fn project(p: vec3<f32>) -> vec3<f32> {
    let q = p - P.center.xyz;
    let z = dot(q, P.axis_d.xyz);
    return vec3<f32>(dot(q, P.axis_u.xyz) / z, dot(q, P.axis_v.xyz) / z, z);
}

// Continuous texel coordinates of projected map coordinates.
fn to_texel(xy: vec2<f32>) -> vec2<f32> {
    return (xy - P.map.xy) * P.map.zw;
}

// Range of dot(m, y) over the light's surface (its support function both ways).
fn light_range(m: vec3<f32>) -> vec2<f32> {
    let c = dot(m, P.center.xyz);
    switch P.kind.y {
        case 1u: {
            // Disk: the component of m in the disk's plane, times the radius.
            let n = P.light_n.xyz;
            let t = m - dot(m, n) * n;
            let h = P.light_n.w * length(t);
            return vec2<f32>(c - h, c + h);
        }
        case 2u: {
            let h = P.light_n.w * length(m);
            return vec2<f32>(c - h, c + h);
        }
        case 3u: {
            return vec2<f32>(c, c);
        }
        default: {
            var lo = 3.4e38;
            var hi = -3.4e38;
            for (var k = 0u; k < P.kind.z; k++) {
                let d = dot(m, P.outline[k].xyz);
                lo = min(lo, d);
                hi = max(hi, d);
            }
            return vec2<f32>(lo, hi);
        }
    }
}

// Influence regions are covered by tiles of TILE x TILE texels (one workgroup's worth), on a
// grid fixed to the map so that a tile is also a cluster of view samples with its own bounds.
const TILE: i32 = 8;

// A float's bits reordered so that unsigned order is the float order (atomicMax then keeps
// the largest float; of the complement, the smallest), and back. 0 is no float's key.
fn order_key(f: f32) -> u32 {
    let b = bitcast<u32>(f);
    return select(b | 0x80000000u, ~b, (b & 0x80000000u) != 0u);
}

fn from_key(k: u32) -> f32 {
    return bitcast<f32>(select(~k, k & 0x7fffffffu, (k & 0x80000000u) != 0u));
}

// Tiles across the map's side.
fn tiles_per_side() -> u32 {
    return (P.dims.x + u32(TILE) - 1u) / u32(TILE);
}

// Tiles across and down a texel box (zero for an empty box): the map's tiles it touches.
fn tiles_across(bbox: vec4<i32>) -> vec2<u32> {
    if bbox.z < bbox.x || bbox.w < bbox.y {
        return vec2<u32>(0u);
    }
    return vec2<u32>(u32(bbox.z / TILE - bbox.x / TILE + 1), u32(bbox.w / TILE - bbox.y / TILE + 1));
}

// Up to 8 points whose convex hull holds the part of the light that can be seen through a
// point `vk` (section 4.1): the polygon's outline, the octagon around a disk, or the regular
// hexagon around a sphere's silhouette circle seen from `vk`; none for a point light. Returns
// how many, or -1 when `vk` lies inside the sphere (no bound).
fn light_points(vk: vec3<f32>, ys: ptr<function, array<vec3<f32>, 8>>) -> i32 {
    let c = P.center.xyz;
    switch P.kind.y {
        case 1u: {
            let rad = P.light_n.w / cos(3.14159265 / 8.0);
            for (var j = 0u; j < 8u; j++) {
                let a = f32(j) * 3.14159265 / 4.0;
                (*ys)[j] = c + rad * (cos(a) * P.light_u.xyz + sin(a) * P.light_v.xyz);
            }
            return 8;
        }
        case 2u: {
            // Silhouette circle of the sphere seen from vk (centre, radius, plane), and the
            // regular hexagon around it.
            let rs = P.light_n.w;
            let w = vk - c;
            let l2 = dot(w, w);
            if l2 <= rs * rs * 1.0001 {
                return -1;
            }
            let axis = w / sqrt(l2);
            let mid = c + (rs * rs / l2) * w;
            let rho = rs * sqrt(max(1.0 - rs * rs / l2, 0.0));
            var e1 = cross(axis, vec3<f32>(0.0, 1.0, 0.0));
            if dot(e1, e1) < 1e-6 {
                e1 = cross(axis, vec3<f32>(1.0, 0.0, 0.0));
            }
            e1 = normalize(e1);
            let e2 = cross(axis, e1);
            let rad = rho / cos(3.14159265 / 6.0);
            for (var j = 0u; j < 6u; j++) {
                let a = f32(j) * 3.14159265 / 3.0;
                (*ys)[j] = mid + rad * (cos(a) * e1 + sin(a) * e2);
            }
            return 6;
        }
        case 3u: {
            return 0;
        }
        default: {
            for (var j = 0u; j < P.kind.z; j++) {
                (*ys)[j] = P.outline[j].xyz;
            }
            return i32(P.kind.z);
        }
    }
}
