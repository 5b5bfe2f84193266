// Section 4.2, final step: a light sample is visible when it lies above the receiver's
// tangent plane (the reference's rule, from the surface point and from the offset origin) and
// no opaque caster set its bit. Behind semi-opaque casters its weight is the transmittance
// exp(-optical depth) (section 6's transparency, kept per sample); its visible bit is set only
// when nothing at all lies in the way, as the reference counts it. The visible bits replace the
// occlusion bits (for per-sample output), and the summed weights (and radiance-weighted sums for
// textured lights, DCS eq. 2) are written per receiver.

@group(0) @binding(0) var<uniform> P: Params;
@group(0) @binding(1) var<storage, read> receivers: array<Receiver>;
@group(0) @binding(2) var<storage, read> samples: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> radiance: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> masks: array<u32>;
@group(0) @binding(5) var<storage, read_write> result: array<vec4<f32>>;
@group(0) @binding(6) var<storage, read> depths: array<u32>;

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
    let semi = P.options.y == 1u;
    var sum = 0.0;
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
                var t = 1.0;
                if semi {
                    let d = depths[i * n_samples + k];
                    t = select(exp(-f32(d) / DEPTH_SCALE), 0.0, d == OPAQUE);
                }
                if t == 1.0 {
                    vis |= bit;
                }
                sum += t;
                if textured {
                    rgb += t * radiance[first + k].xyz;
                }
            }
        }
        masks[i * words + wd] = vis;
    }
    result[i] = vec4<f32>(rgb, sum);
}
