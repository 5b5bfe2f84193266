// Per tile: the texels that overlap the caster's region and hold a list (tally 0, texels
// visited; their 64-bit mask is stored after the chunk counts, at T + 1 + 2u, so the
// occlusion pass does not redo the overlap tests), the pairs they hold (tally 1), and the
// chunks of 64 pairs the occlusion pass runs (`chunk_counts`, summed into tally 8).

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
    var mask = vec2<u32>(0u);
    for (var k = 0u; k < 64u; k++) {
        let len = tile_texel(tl, k).y;
        if len > 0u {
            visited++;
            pairs += len;
            mask[k / 32u] |= 1u << (k % 32u);
        }
    }
    let chunks = (pairs + 63u) / 64u;
    chunk_counts[u] = chunks;
    chunk_counts[P.work.z + 1u + 2u * u] = mask.x;
    chunk_counts[P.work.z + 2u + 2u * u] = mask.y;
    add64(0u, visited);
    add64(1u, pairs);
    add64(8u, chunks);
}
