// Section 3.1: the running sum (scan) of the list lengths gives each list's offset. One
// workgroup scans 512 values in shared memory (exclusive, in place) and writes its total;
// the host scans the totals the same way and adds them back (scan_add.wgsl).

struct ScanParams {
    n: vec4<u32>,
}

@group(0) @binding(0) var<uniform> S: ScanParams;
@group(0) @binding(1) var<storage, read_write> data: array<u32>;
@group(0) @binding(2) var<storage, read_write> sums: array<u32>;

var<workgroup> tile: array<u32, 512>;

@compute @workgroup_size(256)
fn main(@builtin(local_invocation_id) l: vec3<u32>, @builtin(workgroup_id) w: vec3<u32>,
        @builtin(num_workgroups) nw: vec3<u32>) {
    let block = w.y * nw.x + w.x;
    let base = block * 512u;
    let n = S.n.x;
    let i0 = base + 2u * l.x;
    let i1 = i0 + 1u;
    var a = 0u;
    var b = 0u;
    if i0 < n { a = data[i0]; }
    if i1 < n { b = data[i1]; }
    tile[2u * l.x] = a;
    tile[2u * l.x + 1u] = b;
    // Blelloch up-sweep.
    var offset = 1u;
    for (var d = 256u; d > 0u; d >>= 1u) {
        workgroupBarrier();
        if l.x < d {
            let ai = offset * (2u * l.x + 1u) - 1u;
            let bi = offset * (2u * l.x + 2u) - 1u;
            tile[bi] += tile[ai];
        }
        offset <<= 1u;
    }
    workgroupBarrier();
    if l.x == 0u {
        if block < arrayLength(&sums) {
            sums[block] = tile[511];
        }
        tile[511] = 0u;
    }
    // Down-sweep.
    for (var d = 1u; d < 512u; d <<= 1u) {
        offset >>= 1u;
        workgroupBarrier();
        if l.x < d {
            let ai = offset * (2u * l.x + 1u) - 1u;
            let bi = offset * (2u * l.x + 2u) - 1u;
            let t = tile[ai];
            tile[ai] = tile[bi];
            tile[bi] += t;
        }
    }
    workgroupBarrier();
    if i0 < n { data[i0] = tile[2u * l.x]; }
    if i1 < n { data[i1] = tile[2u * l.x + 1u]; }
}
