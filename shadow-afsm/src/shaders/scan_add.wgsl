// Adds each block's scanned total back to its 512 values (second half of scan_block.wgsl).

struct ScanParams {
    n: vec4<u32>,
}

@group(0) @binding(0) var<uniform> S: ScanParams;
@group(0) @binding(1) var<storage, read_write> data: array<u32>;
@group(0) @binding(2) var<storage, read_write> sums: array<u32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let i = g.y * n.x * 64u + g.x;
    if i < S.n.x {
        data[i] += sums[i / 512u];
    }
}
