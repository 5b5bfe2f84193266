// Between caster ranges: how many of each texel's and each tile's view samples are already
// hidden from every light sample by opaque casters. Later casters cannot change their answer (masks only gain
// bits, and a hidden sample's optical depth is never read), so `tile_pairs` skips the texels
// and tiles whose every view sample is hidden. The counts are cleared before each refresh.

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> slots: array<vec2<u32>>;
@group(0) @binding(2) var<storage, read> masks: array<u32>;
@group(0) @binding(3) var<storage, read_write> texel_hidden: array<atomic<u32>>;
@group(0) @binding(4) var<storage, read_write> tile_hidden: array<atomic<u32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let i = linear_index(g, n);
    if i >= P.dims.y {
        return;
    }
    let n_samples = P.dims.z;
    for (var wd = 0u; wd < P.dims.w; wd++) {
        let rest = n_samples - wd * 32u;
        let full = select((1u << rest) - 1u, 0xffffffffu, rest >= 32u);
        if masks[i * P.dims.w + wd] != full {
            return;
        }
    }
    let texel = slots[i].x;
    atomicAdd(&texel_hidden[texel], 1u);
    let side = P.dims.x;
    let tile = (texel / side / u32(TILE)) * tiles_per_side() + (texel % side) / u32(TILE);
    atomicAdd(&tile_hidden[tile], 1u);
}
