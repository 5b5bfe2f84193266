// Per tile: the texels that overlap the caster's region and hold a list (tally 0, texels
// visited), the pairs they hold (tally 1), and the chunks of 64 pairs the occlusion pass runs
// (`chunk_counts`, summed into tally 8).

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(4) var<storage, read_write> chunk_counts: array<u32>;
@group(0) @binding(5) var<storage, read_write> stats: array<atomic<u32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let u = linear_index(g, n);
    if u >= P.work.z {
        return;
    }
    let tl = tile_of(u);
    var visited = 0u;
    var pairs = 0u;
    for (var k = 0u; k < 64u; k++) {
        let len = tile_texel(tl, k).y;
        visited += u32(len > 0u);
        pairs += len;
    }
    let chunks = (pairs + 63u) / 64u;
    chunk_counts[u] = chunks;
    add64(0u, visited);
    add64(1u, pairs);
    add64(8u, chunks);
}
