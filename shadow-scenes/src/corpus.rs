//! The corpus of real meshes as scenes (issue 49): every mesh committed in
//! `shadow-scenes/assets/models` (scans, CAD parts, character meshes, flat cut-outs; their sources
//! in that folder's `SOURCES.md`), each framed the same way with nothing tuned to one of them:
//! scaled to a largest extent of 1 m, resting on a 4 m floor (flat cut-outs held level 0.6 m
//! above it), under a tilted rectangle light or a disk light 2 m up, of a quarter or the whole
//! of the object's extent.
//!
//! Names are `corpus-<mesh>-<rect|disk>-<quarter|whole>` ([`corpus_scene_names`]);
//! [`crate::builtin`] resolves them too, so every command that takes a scene name runs
//! them. The meshes are read from the crate's folder at run time (they are not compiled into
//! the library), so the corpus needs the repository, not a packaged crate.

use std::path::PathBuf;
use std::sync::Arc;

use glam::{Affine3A, Vec3};
use shadow_core::camera::Camera;
use shadow_core::light::{DiskLight, Light, Radiance, RectLight};
use shadow_core::scene::{DegeneratePolicy, MeshDesc, SceneBuilder};
use shadow_io::load::{LoadError, LoadLimits, SceneSetup, read_obj_mesh};

use crate::procedural::floor;

/// The meshes of the corpus (file stems in `assets/models`).
pub const CORPUS_MESHES: [&str; 11] = [
    "alligator",
    "beetle-alt",
    "cheburashka",
    "cow",
    "fandisk",
    "rocker-arm",
    "spot",
    "stanford-bunny",
    "suzanne",
    "teapot",
    "woody",
];

/// The lights each mesh is shown under: shape and size (a quarter or the whole of the
/// object's 1 m extent).
pub const CORPUS_LIGHTS: [&str; 4] = ["rect-quarter", "rect-whole", "disk-quarter", "disk-whole"];

/// Every corpus scene name, mesh by mesh.
pub fn corpus_scene_names() -> Vec<String> {
    CORPUS_MESHES
        .iter()
        .flat_map(|m| CORPUS_LIGHTS.iter().map(move |l| format!("corpus-{m}-{l}")))
        .collect()
}

/// The small share of the corpus `cargo test` runs: every mesh once, under the lights taken in
/// turn (mesh k under `CORPUS_LIGHTS[k % 4]`), so each mesh and each light is in it.
pub fn corpus_share() -> Vec<String> {
    CORPUS_MESHES
        .iter()
        .enumerate()
        .map(|(k, m)| format!("corpus-{m}-{}", CORPUS_LIGHTS[k % CORPUS_LIGHTS.len()]))
        .collect()
}

/// Whether `name` is a corpus scene.
pub fn is_corpus_scene(name: &str) -> bool {
    split(name).is_some()
}

/// The mesh and light of a corpus scene name.
fn split(name: &str) -> Option<(&'static str, &'static str)> {
    let rest = name.strip_prefix("corpus-")?;
    CORPUS_MESHES.iter().find_map(|m| {
        let light = rest.strip_prefix(m)?.strip_prefix('-')?;
        CORPUS_LIGHTS
            .iter()
            .find(|l| **l == light)
            .map(|l| (*m, *l))
    })
}

/// The folder the corpus meshes are read from.
pub fn models_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/models")
}

/// The corpus scene `name`, or `None` when `name` is not one.
///
/// # Errors
/// [`LoadError`] when the mesh file is missing or invalid.
pub fn corpus_scene(name: &str) -> Option<Result<SceneSetup, LoadError>> {
    let (mesh, light) = split(name)?;
    Some(build(name, mesh, light))
}

fn build(name: &str, mesh: &str, light: &str) -> Result<SceneSetup, LoadError> {
    let light_err = |source| LoadError::Light {
        mesh: name.to_string(),
        source,
    };
    let path = models_dir().join(format!("{mesh}.obj"));
    let bytes = std::fs::read(&path).map_err(|source| LoadError::Io {
        path: path.display().to_string(),
        source,
    })?;
    let (positions, triangles) = read_obj_mesh(&bytes, &LoadLimits::default())?;
    // A flat mesh (a cut-out: one extent under 1% of the largest) is laid level and held
    // 0.6 m above the floor, so that the light shines past its outline; any other rests on
    // the floor.
    let e = shadow_core::geometry::Aabb::from_points(&positions).extent();
    let flat = e.min_element() < 0.01 * e.max_element();
    let level = if !flat {
        Affine3A::IDENTITY
    } else if e.x <= e.y && e.x <= e.z {
        Affine3A::from_rotation_z(std::f32::consts::FRAC_PI_2)
    } else if e.z <= e.y {
        Affine3A::from_rotation_x(-std::f32::consts::FRAC_PI_2)
    } else {
        Affine3A::IDENTITY
    };
    let positions: Vec<Vec3> = positions
        .iter()
        .map(|p| level.transform_point3(*p))
        .collect();
    // Largest extent 1 m, centred, turned a little so that no face is aligned with the
    // light's axes.
    let b = shadow_core::geometry::Aabb::from_points(&positions);
    let scale = 1.0 / b.extent().max_element();
    let c = b.center();
    let lift = if flat { 0.6 } else { 0.0 };
    let place = Affine3A::from_rotation_y(0.4)
        * Affine3A::from_translation(Vec3::new(0.0, lift, 0.0))
        * Affine3A::from_scale(Vec3::splat(scale))
        * Affine3A::from_translation(Vec3::new(-c.x, -b.min.y, -c.z));
    let mut builder = SceneBuilder::new().degenerate_policy(DegeneratePolicy::Drop);
    let (fp, ft) = floor(4.0, 0.0);
    builder.push_mesh(MeshDesc::new(fp, ft))?;
    builder.push_mesh(MeshDesc::new(positions, triangles).with_transform(place))?;
    let scene = builder.build()?;
    let side = if light.ends_with("quarter") {
        0.25
    } else {
        1.0
    };
    let centre = Vec3::new(0.3, 2.0, 0.2);
    let white = Radiance::Constant(Vec3::ONE);
    let light: Light = if light.starts_with("rect") {
        // Tilted, and longer one way than the other.
        let normal = Vec3::new(-0.15, -1.0, -0.1).normalize();
        Arc::new(RectLight::facing(centre, normal, side, 0.75 * side, white).map_err(light_err)?)
    } else {
        Arc::new(DiskLight::new(centre, Vec3::NEG_Y, 0.5 * side, white).map_err(light_err)?)
    };
    let camera = Camera::look_at(
        Vec3::new(1.4, 1.5, 2.0),
        Vec3::new(0.0, 0.35, 0.0),
        Vec3::Y,
        50f32.to_radians(),
    )?;
    let mut warnings = Vec::new();
    shadow_io::load::dropped_warning(&scene, &mut warnings);
    Ok(SceneSetup {
        name: name.to_string(),
        scene: Arc::new(scene),
        lights: vec![light],
        camera: Some(camera),
        aspect: None,
        warnings,
        punctual: Vec::new(),
        layouts: Vec::new(),
    })
}
