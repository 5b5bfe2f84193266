// Section 3.1, construction: each listed view sample is projected into the shadow map and
// takes the next slot of its texel's list with an atomic increment. Each texel and each tile
// of the map (a cluster of view samples) also keeps its farthest view sample's depth, the
// bound that cluster culling tests casters against (`tile_pairs.wgsl`), and each tile the box
// of its view samples' ray origins (six keys: the complements of the smallest x, y, z, then the
// largest), and how many view samples it holds; 0 marks none. Each texel and each tile keeps its
// nearest view sample's depth too (as the complement of its bits; 0 marks none), and each
// super-tile of 4 x 4 tiles its depths and origin box, for the penumbra-volume tests.

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> receivers: array<Receiver>;
@group(0) @binding(2) var<storage, read_write> counts: array<atomic<u32>>;
@group(0) @binding(3) var<storage, read_write> slots: array<vec2<u32>>;
@group(0) @binding(4) var<storage, read_write> texel_depth: array<atomic<u32>>;
@group(0) @binding(5) var<storage, read_write> tile_depth: array<atomic<u32>>;
@group(0) @binding(6) var<storage, read_write> tile_box: array<atomic<u32>>;
@group(0) @binding(7) var<storage, read_write> tile_count: array<atomic<u32>>;
@group(0) @binding(8) var<storage, read_write> texel_near: array<atomic<u32>>;
@group(0) @binding(9) var<storage, read_write> tile_near: array<atomic<u32>>;
// Per super-tile of 4 x 4 tiles (`tiles.wgsl`): farthest depth, complement of the nearest,
// then the six keys of its origin box.
@group(0) @binding(10) var<storage, read_write> super_bounds: array<atomic<u32>>;
// Per tile, two words of bits: its texels that hold a view sample (row-major).
@group(0) @binding(11) var<storage, read_write> texel_bits: array<atomic<u32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let i = linear_index(g, n);
    if i >= P.dims.y {
        return;
    }
    let side = P.dims.x;
    let q = project(receivers[i].origin);
    let t = to_texel(q.xy);
    let tx = u32(clamp(floor(t.x), 0.0, f32(side - 1u)));
    let ty = u32(clamp(floor(t.y), 0.0, f32(side - 1u)));
    let texel = ty * side + tx;
    let local = atomicAdd(&counts[texel], 1u);
    slots[i] = vec2<u32>(texel, local);
    // Positive floats order as their bits; the floor keeps a listed sample's bound above 0.
    let z = bitcast<u32>(max(q.z, 1e-30));
    atomicMax(&texel_depth[texel], z);
    atomicMax(&texel_near[texel], ~z);
    let tile = (ty / u32(TILE)) * tiles_per_side() + tx / u32(TILE);
    atomicMax(&tile_depth[tile], z);
    atomicAdd(&tile_count[tile], 1u);
    atomicMax(&tile_near[tile], ~z);
    let k = (ty % u32(TILE)) * u32(TILE) + tx % u32(TILE);
    atomicOr(&texel_bits[2u * tile + k / 32u], 1u << (k % 32u));
    let supers = (tiles_per_side() + 3u) / 4u;
    let st = 8u * ((ty / u32(TILE) / 4u) * supers + tx / u32(TILE) / 4u);
    atomicMax(&super_bounds[st], z);
    atomicMax(&super_bounds[st + 1u], ~z);
    let o = receivers[i].origin;
    for (var k = 0u; k < 3u; k++) {
        atomicMax(&tile_box[6u * tile + k], ~order_key(o[k]));
        atomicMax(&tile_box[6u * tile + 3u + k], order_key(o[k]));
        atomicMax(&super_bounds[st + 2u + k], ~order_key(o[k]));
        atomicMax(&super_bounds[st + 5u + k], order_key(o[k]));
    }
}
