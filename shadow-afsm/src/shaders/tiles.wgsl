// Tiles per caster of the current range (the caster's texel box in 8 x 8 tiles), summed into
// 64-bit tally 7 so the host can size (or split) the range before the tiles are numbered.

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> regions: array<Region>;
@group(0) @binding(2) var<storage, read_write> tile_counts: array<u32>;
@group(0) @binding(3) var<storage, read_write> stats: array<atomic<u32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let i = linear_index(g, n);
    if i >= P.work.y {
        return;
    }
    let a = tiles_across(regions[P.work.x + i].bbox);
    let c = a.x * a.y;
    tile_counts[i] = c;
    add64(7u, c);
}
