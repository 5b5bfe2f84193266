// Penumbra volumes (`volume.rs`): per caster, planes that every point the caster shadows from
// some light point lies inside of; and the tests of a box of ray origins and of a piece of the
// light's frustum (texels between two depths) against them, for cluster culling
// (`tiles.wgsl`, `tile_pairs.wgsl`).

const VOLUME_PLANES: u32 = 12u;

struct Volume {
    planes: array<vec4<f32>, 12>,
}

// The rounding margin of the volume tests (the planes are rounded from double precision, the
// pair test is in f32).
fn volume_margin() -> f32 {
    return 1e-5 * P.axis_d.w;
}

// The volume's planes in the light frame: a point c + z (x u + y v + d) of map coordinates
// (x, y) and depth z has f = p.x + z (x p.y + y p.z + p.w).
fn frame_planes(vol: ptr<function, Volume>) -> array<vec4<f32>, 12> {
    var out: array<vec4<f32>, 12>;
    for (var k = 0u; k < VOLUME_PLANES; k++) {
        let pl = (*vol).planes[k];
        out[k] = vec4<f32>(dot(pl.xyz, P.center.xyz) - pl.w, dot(pl.xyz, P.axis_u.xyz),
                           dot(pl.xyz, P.axis_v.xyz), dot(pl.xyz, P.axis_d.xyz));
    }
    return out;
}

// Whether the light frustum's piece over the `size` texels from `texel`, between depths z0
// and z1 (> 0), lies outside one of the planes (`frame_planes`), with pads of 0.02 texels and
// 1e-5 of the depths for rounding.
fn piece_outside(fp: ptr<function, array<vec4<f32>, 12>>, texel: vec2<i32>, size: vec2<f32>,
                 z0: f32, z1: f32) -> bool {
    let lo = (vec2<f32>(texel) - 0.02) / P.map.zw + P.map.xy;
    let hi = (vec2<f32>(texel) + size + 0.02) / P.map.zw + P.map.xy;
    let eps = volume_margin();
    let near = z0 * (1.0 - 1e-5);
    let far = z1 * (1.0 + 1e-5);
    for (var k = 0u; k < VOLUME_PLANES; k++) {
        let p = (*fp)[k];
        // The largest slope over the texel's corners, then over the depths.
        let g = max(lo.x * p.y, hi.x * p.y) + max(lo.y * p.z, hi.y * p.z) + p.w;
        if p.x + select(near, far, g > 0.0) * g < -eps {
            return true;
        }
    }
    return false;
}

// Whether the box (lo, hi) lies outside one of the volume's planes by more than the margin
// for rounding (the planes are rounded from double precision, the pair test is in f32).
fn box_outside(vol: ptr<function, Volume>, lo: vec3<f32>, hi: vec3<f32>) -> bool {
    let centre = 0.5 * (lo + hi);
    let half = 0.5 * (hi - lo);
    let eps = volume_margin();
    for (var k = 0u; k < VOLUME_PLANES; k++) {
        let pl = (*vol).planes[k];
        if dot(pl.xyz, centre) + dot(abs(pl.xyz), half) - pl.w < -eps {
            return true;
        }
    }
    return false;
}
