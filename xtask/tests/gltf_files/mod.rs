//! Small glTF files written by the xtask tests.

/// A mesh for [`gltf_of`]: its positions (non-indexed triangles) and its emission, if any.
pub type TestMesh = (Vec<[f32; 3]>, Option<[f32; 3]>);

/// A glTF file of non-indexed triangle meshes (positions only), each emissive when it has an
/// emission.
pub fn gltf_of(meshes: &[TestMesh]) -> String {
    use base64::Engine;
    let mut bytes = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut mesh_list = Vec::new();
    let mut materials = Vec::new();
    let mut nodes = Vec::new();
    for (k, (pos, emission)) in meshes.iter().enumerate() {
        let offset = bytes.len();
        for v in pos {
            for c in v {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
        let lo = (0..3).map(|i| pos.iter().map(|v| v[i]).fold(f32::INFINITY, f32::min));
        let hi = (0..3).map(|i| pos.iter().map(|v| v[i]).fold(f32::NEG_INFINITY, f32::max));
        views.push(
            serde_json::json!({"buffer": 0, "byteOffset": offset, "byteLength": pos.len() * 12}),
        );
        accessors.push(
            serde_json::json!({"bufferView": k, "componentType": 5126, "count": pos.len(),
            "type": "VEC3", "min": lo.collect::<Vec<_>>(), "max": hi.collect::<Vec<_>>()}),
        );
        let material = match emission {
            Some(e) => serde_json::json!({"emissiveFactor": e}),
            None => serde_json::json!({}),
        };
        materials.push(material);
        mesh_list.push(
            serde_json::json!({"primitives": [{"attributes": {"POSITION": k}, "material": k}]}),
        );
        nodes.push(serde_json::json!({"mesh": k}));
    }
    let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
    serde_json::json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": bytes.len(), "uri": format!("data:application/octet-stream;base64,{data}")}],
        "bufferViews": views, "accessors": accessors, "meshes": mesh_list,
        "materials": materials, "nodes": nodes,
        "scenes": [{"nodes": (0..meshes.len()).collect::<Vec<_>>()}], "scene": 0
    })
    .to_string()
}

/// A square at height `y` of half side `h`, facing `down` or up, as two triangles.
pub fn square_at(y: f32, h: f32, x: f32, down: bool) -> Vec<[f32; 3]> {
    let (a, b, c, d) = ([x - h, y, -h], [x + h, y, -h], [x + h, y, h], [x - h, y, h]);
    if down {
        vec![a, b, c, a, c, d]
    } else {
        vec![a, c, b, a, d, c]
    }
}
