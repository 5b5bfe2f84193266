// The map's occupied tiles (those holding a view sample, `count.wgsl`), row by row, so that
// caster ranges number only the tiles of their regions that hold view samples
// (`tiles.wgsl`, `tile_of` in `tiling.wgsl`): per row of tiles, the running count of occupied
// tiles before each column (tiles per side + 1 values), then per row the occupied tiles'
// columns in order (tiles per side values, the first ones used). One invocation per row.

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> tile_count: array<u32>;
@group(0) @binding(2) var<storage, read_write> occupancy: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let y = linear_index(g, n);
    let side = tiles_per_side();
    if y >= side {
        return;
    }
    let prefix = y * (side + 1u);
    let columns = side * (side + 1u) + y * side;
    var seen = 0u;
    for (var x = 0u; x < side; x++) {
        occupancy[prefix + x] = seen;
        if tile_count[y * side + x] > 0u {
            occupancy[columns + seen] = x;
            seen++;
        }
    }
    occupancy[prefix + side] = seen;
}
