// Section 4.2, final step: a light sample is visible when it lies above the receiver's
// tangent plane (the reference's rule, from the surface point and from the offset origin) and
// no caster set its bit. The visible bits replace the occlusion bits (for per-sample output),
// and their count (and radiance sum for textured lights, DCS eq. 2) is written per receiver.

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> receivers: array<Receiver>;
@group(0) @binding(2) var<storage, read> samples: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> radiance: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> masks: array<u32>;
@group(0) @binding(5) var<storage, read_write> result: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) g: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    let i = linear_index(g, n);
    if i >= P.dims.y {
        return;
    }
    let r = receivers[i];
    let nrm = r.normal;
    let p = r.position;
    let o = r.origin;
    let n_samples = P.dims.z;
    let words = P.dims.w;
    let first = r.set_index * n_samples;
    let textured = P.lut.w == 1u;
    var count = 0u;
    var rgb = vec3<f32>(0.0);
    for (var wd = 0u; wd < words; wd++) {
        let occluded = masks[i * words + wd];
        var vis = 0u;
        let k0 = wd * 32u;
        let k1 = min(k0 + 32u, n_samples);
        for (var k = k0; k < k1; k++) {
            let bit = 1u << (k - k0);
            if (occluded & bit) != 0u {
                continue;
            }
            let y = samples[first + k].xyz;
            if dot(y - p, nrm) > 0.0 && dot(y - o, nrm) > 0.0 {
                vis |= bit;
                if textured {
                    rgb += radiance[first + k].xyz;
                }
            }
        }
        masks[i * words + wd] = vis;
        count += countOneBits(vis);
    }
    result[i] = vec4<f32>(rgb, f32(count));
}
