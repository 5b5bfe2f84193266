// Section 3.1: each view sample's final index into the global list array is its list's offset
// plus its slot; the array holds the receiver index (world data stays in `receivers`, the
// shadow state in the separate bitmask array, as the paper separates them).

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> slots: array<vec2<u32>>;
@group(0) @binding(2) var<storage, read> offsets: array<u32>;
@group(0) @binding(3) var<storage, read_write> lists: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let i = linear_index(g, n);
    if i >= P.dims.y {
        return;
    }
    let s = slots[i];
    lists[offsets[s.x] + s.y] = i;
}
