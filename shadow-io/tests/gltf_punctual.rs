//! `KHR_lights_punctual` lights load as area lights (issue 52): point lights as spheres, spot
//! lights as disks facing their axis, directional lights as distant disks of the sun's size.

use base64::Engine;
use glam::Vec3;
use serde_json::{Value, json};
use shadow_core::light::{LightGeometry, LightKind};
use shadow_core::scene::Scene;
use shadow_io::load::punctual::{DIRECTIONAL_ANGLE_DEGREES, PunctualKind};
use shadow_io::load::{LoadError, LoadLimits, SceneSetup, load_gltf_slice};

/// A 6 m floor at y = 0 and the given punctual lights on the given nodes (after the floor's).
fn document(lights: Value, light_nodes: Value) -> Value {
    let p: [[f32; 3]; 4] = [
        [-3.0, 0.0, -3.0],
        [3.0, 0.0, -3.0],
        [3.0, 0.0, 3.0],
        [-3.0, 0.0, 3.0],
    ];
    let mut bin: Vec<u8> = p.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    bin.extend([0u32, 2, 1, 0, 3, 2].iter().flat_map(|i| i.to_le_bytes()));
    let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
    let mut nodes = vec![json!({"mesh": 0})];
    nodes.extend(light_nodes.as_array().unwrap().iter().cloned());
    json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": lights}},
        "scene": 0,
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{b64}")}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": 48, "byteLength": 24}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-3.0, 0.0, -3.0], "max": [3.0, 0.0, 3.0]},
            {"bufferView": 1, "componentType": 5125, "count": 6, "type": "SCALAR"}
        ]
    })
}

fn load(doc: &Value) -> Result<SceneSetup, LoadError> {
    load_gltf_slice(
        doc.to_string().as_bytes(),
        None,
        "t",
        &LoadLimits::default(),
    )
}

/// The node rotation that turns its `-Z` axis to `-Y` (down): -90 degrees about X.
const DOWN: [f32; 4] = [
    -std::f32::consts::FRAC_1_SQRT_2,
    0.0,
    0.0,
    std::f32::consts::FRAC_1_SQRT_2,
];

#[test]
fn punctual_lights_become_area_lights() {
    let doc = document(
        json!([
            {"type": "point", "color": [1.0, 0.5, 0.25], "intensity": 4.0, "name": "bulb"},
            {"type": "spot", "spot": {"outerConeAngle": 0.6}},
            {"type": "directional", "intensity": 2.0}
        ]),
        json!([
            {"translation": [0.0, 3.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"translation": [1.0, 2.0, 0.0], "rotation": DOWN, "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"rotation": DOWN, "extensions": {"KHR_lights_punctual": {"light": 2}}}
        ]),
    );
    let setup = load(&doc).unwrap();
    assert_eq!(setup.lights.len(), 3);
    let diagonal = setup.scene.bounds().diagonal();
    let r = 0.01 * diagonal;
    // Point: a sphere of a hundredth of the scene, colour times intensity.
    match setup.lights[0].geometry() {
        LightGeometry::Sphere { center, radius } => {
            assert!((center - Vec3::new(0.0, 3.0, 0.0)).length() < 1e-6);
            assert!((radius - r).abs() < 1e-6);
        }
        g => panic!("point light as {g:?}"),
    }
    assert!((setup.lights[0].radiance().mean() - Vec3::new(4.0, 2.0, 1.0)).length() < 1e-6);
    // Spot: a disk facing down at its node.
    match setup.lights[1].geometry() {
        LightGeometry::Disk {
            center,
            normal,
            radius,
        } => {
            assert!((center - Vec3::new(1.0, 2.0, 0.0)).length() < 1e-6);
            assert!((normal - Vec3::NEG_Y).length() < 1e-5, "{normal}");
            assert!((radius - r).abs() < 1e-6);
        }
        g => panic!("spot light as {g:?}"),
    }
    // Directional: a disk far above, facing down, subtending the sun's angle.
    match setup.lights[2].geometry() {
        LightGeometry::Disk {
            center,
            normal,
            radius,
        } => {
            assert!((normal - Vec3::NEG_Y).length() < 1e-5);
            assert!(center.y > 50.0 * diagonal, "{center}");
            let angle = (radius / center.y).atan().to_degrees();
            assert!((angle - DIRECTIONAL_ANGLE_DEGREES).abs() < 0.01, "{angle}");
        }
        g => panic!("directional light as {g:?}"),
    }
    // Each is named in a note, and recorded.
    let notes = setup.warnings.join("\n");
    assert!(
        notes.contains("'bulb'") && notes.contains("cone is not modelled"),
        "{notes}"
    );
    assert_eq!(setup.punctual.len(), 3);
    assert!(matches!(setup.punctual[1].kind, PunctualKind::Spot { .. }));
    assert_eq!(setup.punctual[2].light_index, 2);
    // The user's radius replaces the default for point and spot lights.
    let mut sized = setup.clone();
    sized.set_punctual_radius(0.25).unwrap();
    assert!(
        matches!(sized.lights[0].geometry(), LightGeometry::Sphere { radius, .. } if radius == 0.25)
    );
    assert!(
        matches!(sized.lights[1].geometry(), LightGeometry::Disk { radius, .. } if radius == 0.25)
    );
    assert_eq!(sized.lights[2].area(), setup.lights[2].area());
    assert!(sized.set_punctual_radius(-1.0).is_err());
    assert_eq!(setup.lights[0].kind(), LightKind::Sphere);
}

#[test]
fn bad_punctual_lights_are_errors_not_panics() {
    // A node naming a light the file does not have (gltf unwraps it).
    let missing = document(
        json!([{"type": "point"}]),
        json!([{"extensions": {"KHR_lights_punctual": {"light": 3}}}]),
    );
    let e = load(&missing).unwrap_err().to_string();
    assert!(e.contains("punctual light 3"), "{e}");
    // No light list at all.
    let mut no_list = missing.clone();
    no_list["extensions"] = json!({});
    assert!(load(&no_list).is_err());
    // A spot light without its cone, and an unknown type.
    for light in [json!({"type": "spot"}), json!({"type": "laser"})] {
        let doc = document(
            json!([light]),
            json!([{"extensions": {"KHR_lights_punctual": {"light": 0}}}]),
        );
        assert!(load(&doc).is_err(), "{light}");
    }
    // A negative intensity names the light.
    let negative = document(
        json!([{"type": "point", "intensity": -1.0, "name": "dark"}]),
        json!([{"translation": [0.0, 2.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}]),
    );
    let e = load(&negative).unwrap_err().to_string();
    assert!(e.contains("dark"), "{e}");
}
