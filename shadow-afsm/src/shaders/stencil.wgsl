// Section 4.3, restrict computations: penumbrae are cast only by silhouette edges (edges
// with a point of the light for which they are a silhouette; the host keeps the potential
// ones). Their influence regions, rasterised here, mark the texels where a view sample's
// visibility can vary over the light. Elsewhere every sample sees the same, so the occlusion
// pass tests one sample per pair ("a hard shadow from any sample point is enough").

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(4) var<storage, read_write> flags: array<u32>;
// The map's occupied tiles (`occupancy.wgsl`), for `tile_of`.
@group(0) @binding(5) var<storage, read> occupancy: array<u32>;
// The super-tiles kept per caster of the range (`tiles.wgsl`), for `tile_of`.
@group(0) @binding(6) var<storage, read> caster_masks: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let u = linear_index(g, n);
    if u >= P.work.z {
        return;
    }
    let tl = tile_of(u);
    for (var k = 0u; k < 64u; k++) {
        let tt = tile_texel(tl, k);
        if tt.y > 0u {
            flags[tt.x] = 1u;
        }
    }
}
