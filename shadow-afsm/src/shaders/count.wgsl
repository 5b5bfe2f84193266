// Section 3.1, construction: each listed view sample is projected into the shadow map and
// takes the next slot of its texel's list with an atomic increment.

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> receivers: array<Receiver>;
@group(0) @binding(2) var<storage, read_write> counts: array<atomic<u32>>;
@group(0) @binding(3) var<storage, read_write> slots: array<vec2<u32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let i = linear_index(g, n);
    if i >= P.dims.y {
        return;
    }
    let side = P.dims.x;
    let t = to_texel(project(receivers[i].origin).xy);
    let tx = u32(clamp(floor(t.x), 0.0, f32(side - 1u)));
    let ty = u32(clamp(floor(t.y), 0.0, f32(side - 1u)));
    let texel = ty * side + tx;
    let local = atomicAdd(&counts[texel], 1u);
    slots[i] = vec2<u32>(texel, local);
}
