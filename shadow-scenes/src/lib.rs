//! # shadow-scenes: the built-in scenes and the corpus of real meshes
//!
//! Built-in scenes, each with a camera and a light, selectable by name ([`builtin`]), plus
//! scaled and translated variants for the stress suite; the corpus of real meshes framed under
//! area lights ([`corpus`]); the procedural meshes they are made of ([`procedural`]). Each
//! built-in scene is a known hard case of the literature or of users' scenes (DESIGN section
//! 6):
//!
//! | name | what it exercises |
//! |---|---|
//! | `quad-over-plane` | square light over a parallel square occluder: a closed form exists |
//! | `overlapping-occluders` | penumbra fusion of overlapping occluders (survey Fig. 6) |
//! | `large-light-close` | a large light close to a small occluder: single-sample silhouette failure (survey Fig. 7) |
//! | `bunny` | the Stanford bunny (69k triangles, open) on a plane |
//! | `spot-self-shadow` | a closed mesh (Spot, welded) shadowing itself |
//! | `grass` | thousands of thin open blades under a low light: depth complexity far above 255 |
//! | `contact` | a box and a sphere resting on the floor: contact shadows, touching geometry |
//! | `semi-opaque` | overlapping panels with opacity 0.3 to 0.7 |
//! | `textured-light` | an RGB image on a rectangle light |
//! | `sphere-light` | an omni-directional sphere light inside a closed room |
//! | `cornell-box` | an open five-wall room, the light recessed in a ceiling fixture, two spheres: receivers level with and behind the light, walls touching its fixture |
//! | `spot-lamp` | a glTF file's `KHR_lights_punctual` spot light (a disk of radius 0.25 m) over a table on legs and a ball, loaded like a user's file |
//! | `mesh-light` | a folded lamp (a mesh light, its two faces emitting from their undersides) over a box and a sphere: receivers that see one face, both or none |
//! | `interior` | a furnished room (table, chairs, shelves of books, a sofa, Spot on the table; 7.4k triangles) under a 1.2 x 0.6 m ceiling panel (light 0): a large light over many occluders, walls up to the light's plane; a disk pendant over the sofa (light 1) and a bare sphere bulb by the shelves (light 2) make it the multi-light interior |
//! | `interior-window` | the same room lit by a window-sized light in a wall: receivers level with the light and behind it |

pub mod corpus;
mod interior;
pub mod procedural;
mod simple;

use std::sync::Arc;

use glam::{Affine2, Affine3A, Vec3};
use shadow_core::camera::Camera;
use shadow_core::lightmap::{LightmapError, UvLayout};
use shadow_core::scene::{MeshDesc, SceneBuilder};
use shadow_io::load::punctual::PunctualLight;
use shadow_io::load::{LoadError, LoadLimits, SceneSetup};

use crate::procedural::{Mesh, floor, quad, uv_sphere};
use shadow_core::light::{
    AreaLight, DiskLight, Light, LightError, LightGeometry, MeshLight, PointLight, PolygonLight,
    Radiance, RectLight, SphereLight, TexturedRadiance,
};

pub use interior::ROOM_HALF;

/// Names of the built-in scenes, in a stable order.
pub const BUILTIN_SCENES: [&str; 15] = [
    "quad-over-plane",
    "overlapping-occluders",
    "large-light-close",
    "bunny",
    "spot-self-shadow",
    "grass",
    "contact",
    "semi-opaque",
    "textured-light",
    "sphere-light",
    "cornell-box",
    "spot-lamp",
    "mesh-light",
    "interior",
    "interior-window",
];

/// Whether `name` is a built-in scene or a scene of the corpus of real meshes
/// ([`crate::corpus`]): the scenes the presets' budgets speak for.
pub fn is_named_scene(name: &str) -> bool {
    BUILTIN_SCENES.contains(&name) || crate::corpus::is_corpus_scene(name)
}

const BUNNY_OBJ: &[u8] = include_bytes!("../assets/models/stanford-bunny.obj");
const SPOT_OBJ: &[u8] = include_bytes!("../assets/models/spot.obj");
/// Written by `scripts/make_spot_lamp_gltf.py`.
const SPOT_LAMP_GLTF: &[u8] = include_bytes!("../assets/scenes/spot-lamp.gltf");
/// The radius `spot-lamp` gives its file's spot light.
pub const SPOT_LAMP_RADIUS: f32 = 0.25;

/// Geometry of `quad-over-plane`, exposed for closed-form checks: light and occluder are
/// squares centred on the Y axis, parallel to the floor at y = 0.
pub mod quad_over_plane {
    /// Side of the square light.
    pub const LIGHT_SIDE: f32 = 1.0;
    /// Height of the light.
    pub const LIGHT_HEIGHT: f32 = 2.0;
    /// Side of the square occluder.
    pub const OCCLUDER_SIDE: f32 = 0.6;
    /// Height of the occluder.
    pub const OCCLUDER_HEIGHT: f32 = 1.0;
    /// Side of the floor.
    pub const FLOOR_SIDE: f32 = 6.0;
}

/// Why a built-in scene could not be made.
#[derive(Debug, thiserror::Error)]
pub enum BuiltinError {
    /// The name is not a built-in scene.
    #[error(
        "unknown scene `{name}`; valid names: {}",
        BUILTIN_SCENES.join(", ")
    )]
    Unknown {
        /// The name asked for.
        name: String,
    },
    /// Building failed (a bug, or an invalid variant transform).
    #[error("building scene: {0}")]
    Load(#[from] LoadError),
    /// A light could not be built.
    #[error("building light: {0}")]
    Light(#[from] LightError),
    /// A mesh's texture layout is invalid.
    #[error("texture layout: {0}")]
    Layout(#[from] LightmapError),
}

fn white(v: f32) -> Radiance {
    Radiance::Constant(Vec3::splat(v))
}

struct Parts {
    meshes: Vec<MeshDesc>,
    light: Light,
    camera: Camera,
}

fn mesh(m: Mesh) -> MeshDesc {
    MeshDesc::new(m.0, m.1)
}

/// A square floor of `side` at y = 0 named `floor`, its texture layout (`TEXCOORD_0`) the
/// square itself: `u` along +x and `v` along +z, each from 0 to 1 (`bake --mesh floor`).
fn floor_mesh(side: f32) -> MeshDesc {
    let (positions, triangles) = floor(side, 0.0);
    let uv = positions
        .iter()
        .map(|p| glam::Vec2::new(p.x / side + 0.5, p.z / side + 0.5))
        .collect();
    MeshDesc::new(positions, triangles)
        .with_name("floor")
        .with_texcoords(uv)
}

fn finish(name: &str, parts: Parts) -> Result<SceneSetup, BuiltinError> {
    let mut b = SceneBuilder::new();
    let mut layouts = Vec::new();
    for (i, m) in parts.meshes.iter().enumerate() {
        if m.texcoords.is_some() {
            layouts.push(UvLayout::of(m, &format!("mesh {i}"))?);
        }
    }
    for m in parts.meshes {
        b.push_mesh(m).map_err(LoadError::from)?;
    }
    let scene = b.build().map_err(LoadError::from)?;
    Ok(SceneSetup {
        name: name.to_string(),
        scene: Arc::new(scene),
        lights: vec![parts.light],
        camera: Some(parts.camera),
        aspect: None,
        warnings: Vec::new(),
        punctual: Vec::new(),
        layouts,
    })
}

fn cam(eye: Vec3, target: Vec3, fov_deg: f32) -> Camera {
    Camera::look_at(eye, target, Vec3::Y, fov_deg.to_radians()).expect("built-in camera is valid")
}

/// A mesh loaded from committed OBJ text, scaled so that its largest extent is `size`, resting
/// on y = 0 and centred on x = z = 0, rotated by `yaw` radians about Y.
fn placed_obj(bytes: &[u8], size: f32, yaw: f32) -> Result<MeshDesc, BuiltinError> {
    let (positions, triangles) = shadow_io::load::read_obj_mesh(bytes, &LoadLimits::default())?;
    let b = shadow_core::geometry::Aabb::from_points(&positions);
    let s = size / b.extent().max_element();
    let c = b.center();
    let t = Affine3A::from_rotation_y(yaw)
        * Affine3A::from_scale(Vec3::splat(s))
        * Affine3A::from_translation(Vec3::new(-c.x, -b.min.y, -c.z));
    Ok(MeshDesc::new(positions, triangles).with_transform(t))
}

/// Builds a built-in scene, or a corpus scene of real meshes ([`crate::corpus`]), by name.
///
/// # Errors
/// [`BuiltinError::Unknown`] listing the valid names.
pub fn builtin(name: &str) -> Result<SceneSetup, BuiltinError> {
    // The corpus of real meshes (`crate::corpus`) answers to its own names.
    if let Some(corpus) = crate::corpus::corpus_scene(name) {
        return corpus.map_err(BuiltinError::from);
    }
    if name == "spot-lamp" {
        let mut setup =
            shadow_io::load::load_gltf_slice(SPOT_LAMP_GLTF, None, name, &LoadLimits::default())?;
        setup.set_punctual_radius(SPOT_LAMP_RADIUS)?;
        return Ok(setup);
    }
    let parts = match name {
        "quad-over-plane" => simple::quad_over_plane()?,
        "overlapping-occluders" => simple::overlapping_occluders()?,
        "large-light-close" => simple::large_light_close()?,
        "bunny" => simple::bunny()?,
        "spot-self-shadow" => simple::spot_self_shadow()?,
        "grass" => simple::grass()?,
        "contact" => simple::contact()?,
        "semi-opaque" => simple::semi_opaque()?,
        "textured-light" => simple::textured_light()?,
        "sphere-light" => simple::sphere_light()?,
        "cornell-box" => cornell_box()?,
        "interior" => interior::ceiling_panel()?,
        "interior-window" => interior::window()?,
        "mesh-light" => simple::mesh_light()?,
        _ => {
            return Err(BuiltinError::Unknown {
                name: name.to_string(),
            });
        }
    };
    let mut setup = finish(name, parts)?;
    if name == "interior" {
        setup.lights.extend(interior::lamps()?);
    }
    Ok(setup)
}

/// The lamp of `mesh-light` (issue 52), exposed for checks against its faces as separate
/// lights: a roof over the scene, its ridge at y = 2.2 along z, each face 0.4 m wide down to
/// y = 1.8 and 1 m long, emitting from its underside (the left face toward +x, the right face
/// toward -x).
pub mod folded_lamp {
    use glam::Vec3;

    use shadow_core::light::{LightError, MeshLight, Radiance, RectLight};

    /// The two faces as rectangle lights (left, right).
    ///
    /// # Errors
    /// Never for the constant radiances the scenes use; a texture is kept as given.
    pub fn faces(radiance: Radiance) -> Result<[RectLight; 2], LightError> {
        let along = Vec3::new(0.0, 0.0, 0.5);
        Ok([
            RectLight::new(
                Vec3::new(-0.2, 2.0, 0.0),
                along,
                Vec3::new(-0.2, -0.2, 0.0),
                radiance.clone(),
            )?,
            RectLight::new(
                Vec3::new(0.2, 2.0, 0.0),
                Vec3::new(0.2, -0.2, 0.0),
                along,
                radiance.clone(),
            )?,
        ])
    }

    /// The lamp as one mesh light: each face split into two triangles in its winding.
    ///
    /// # Errors
    /// As [`faces`].
    pub fn light(radiance: Radiance) -> Result<MeshLight, LightError> {
        let tris: Vec<[Vec3; 3]> = faces(radiance.clone())?
            .iter()
            .flat_map(|f| {
                let c = f.corners();
                [[c[0], c[1], c[2]], [c[0], c[2], c[3]]]
            })
            .collect();
        MeshLight::new(&tris, None, radiance)
    }
}

/// `cornell-box` (issue 51): a 2 m room open at the front (+z), the ceiling at y = 2 with a
/// 0.5 m square hole, a 0.1 m deep fixture above it whose top holds a 0.4 m square light 1 cm
/// below it, facing down, and two spheres on the floor. The ceiling lies in front of the
/// light's plane but has the light behind its own tangent plane; the fixture's walls see the
/// light at grazing angles; its top is behind the light.
fn cornell_box() -> Result<Parts, BuiltinError> {
    let (h, hole, top) = (2.0f32, 0.25f32, 2.1f32);
    let rect = |c: Vec3, u: Vec3, v: Vec3| mesh(quad(c, u, v));
    let mut meshes = vec![
        floor_mesh(2.0),
        // Back, left and right walls.
        rect(
            Vec3::new(0.0, 1.0, -1.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ),
        rect(
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ),
        rect(
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 0.0),
        ),
    ];
    // The ceiling around the hole: two full-depth strips and two between them.
    let side = 0.5 * (1.0 - hole);
    for sx in [-1.0f32, 1.0] {
        meshes.push(rect(
            Vec3::new(sx * (hole + side), h, 0.0),
            Vec3::new(side, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ));
        meshes.push(rect(
            Vec3::new(0.0, h, sx * (hole + side)),
            Vec3::new(hole, 0.0, 0.0),
            Vec3::new(0.0, 0.0, side),
        ));
    }
    // The fixture: four walls from the ceiling up to its top, and the top.
    let mid = 0.5 * (h + top);
    let half = 0.5 * (top - h);
    for sx in [-1.0f32, 1.0] {
        meshes.push(rect(
            Vec3::new(sx * hole, mid, 0.0),
            Vec3::new(0.0, half, 0.0),
            Vec3::new(0.0, 0.0, hole),
        ));
        meshes.push(rect(
            Vec3::new(0.0, mid, sx * hole),
            Vec3::new(hole, 0.0, 0.0),
            Vec3::new(0.0, half, 0.0),
        ));
    }
    meshes.push(rect(
        Vec3::new(0.0, top, 0.0),
        Vec3::new(hole, 0.0, 0.0),
        Vec3::new(0.0, 0.0, hole),
    ));
    meshes.push(mesh(uv_sphere(Vec3::new(-0.4, 0.35, -0.3), 0.35, 24, 48)));
    meshes.push(mesh(uv_sphere(Vec3::new(0.45, 0.3, 0.3), 0.3, 24, 48)));
    Ok(Parts {
        meshes,
        light: Arc::new(RectLight::new(
            Vec3::new(0.0, top - 0.01, 0.0),
            Vec3::new(0.2, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 0.2),
            white(1.0),
        )?),
        camera: cam(Vec3::new(0.0, 1.0, 3.6), Vec3::new(0.0, 1.0, 0.0), 45.0),
    })
}

/// The 4x4 RGB pattern of `textured-light`: red, green and blue bands with a white corner.
fn textured_pattern() -> Result<Radiance, LightError> {
    let mut texels = Vec::with_capacity(16);
    for y in 0..4 {
        for x in 0..4 {
            texels.push(match (x, y) {
                (3, 3) => Vec3::splat(1.5),
                (0 | 1, _) => Vec3::new(1.6, 0.2, 0.1),
                (2, _) => Vec3::new(0.1, 1.4, 0.2),
                _ => Vec3::new(0.1, 0.3, 1.8),
            });
        }
    }
    Ok(Radiance::Textured(TexturedRadiance::new(
        4,
        4,
        texels,
        Vec3::ONE,
        Affine2::IDENTITY,
    )?))
}

/// The same light moved by `x -> scale * x + translation`.
///
/// # Errors
/// [`LightError`] when the transformed light is invalid (e.g. a scale that overflows).
pub fn transform_light(
    light: &dyn AreaLight,
    scale: f32,
    translation: Vec3,
) -> Result<Light, LightError> {
    let m = |p: Vec3| p * scale + translation;
    let r = light.radiance().clone();
    Ok(match light.geometry() {
        LightGeometry::Rectangle {
            center,
            half_u,
            half_v,
            ..
        } => Arc::new(RectLight::new(
            m(center),
            half_u * scale,
            half_v * scale,
            r,
        )?),
        LightGeometry::Disk {
            center,
            normal,
            radius,
        } => Arc::new(DiskLight::new(m(center), normal, radius * scale, r)?),
        LightGeometry::Polygon { outline, .. } => Arc::new(PolygonLight::new(
            outline.iter().map(|p| m(*p)).collect(),
            r,
        )?),
        LightGeometry::Sphere { center, radius } => {
            Arc::new(SphereLight::new(m(center), radius * scale, r)?)
        }
        LightGeometry::Point { position } => Arc::new(PointLight::new(m(position), r)?),
        LightGeometry::Mesh {
            triangles,
            texcoords,
        } => {
            let moved: Vec<[Vec3; 3]> = triangles.iter().map(|t| t.map(m)).collect();
            Arc::new(MeshLight::new(&moved, texcoords, r)?)
        }
    })
}

/// A scaled and translated copy of a scene setup: geometry, lights and camera move together, so
/// every shadow should stay the same (the stress suite's invariance check).
///
/// # Errors
/// [`BuiltinError`] when the transformed scene or light is invalid.
pub fn transformed(
    setup: &SceneSetup,
    scale: f32,
    translation: Vec3,
) -> Result<SceneSetup, BuiltinError> {
    let mut out = moved(setup, scale, translation, Some(1e-4 * scale.max(1e-30)))?;
    out.name = format!("{}@scale={scale:e},translate={}", setup.name, translation);
    Ok(out)
}

/// `setup` moved so that its bounds' centre is at the origin, and the shift that was added to
/// every position (scene, lights, camera), when the scene sits farther from the origin than its
/// own size; otherwise `None`.
///
/// Every technique works in the scene's single-precision coordinates, whose spacing grows with
/// their magnitude: a 10 m room at 1e6 m from the origin has positions 6 cm apart and shadow-ray
/// origins that must move a quarter metre to clear their own rounding, so contact shadows and
/// small occluders vanish (issue 51 item 11). Subtracting the centre keeps the stored geometry
/// (the difference of two nearby floats is exact or rounded at the small result's spacing) and
/// gives back every bit of precision the scene's size allows. Renderers call this once after
/// loading and add the shift back to any world position they output.
///
/// # Errors
/// [`BuiltinError`] when a moved light or camera is invalid.
pub fn recentred(setup: &SceneSetup) -> Result<Option<(SceneSetup, Vec3)>, BuiltinError> {
    use shadow_core::scene::Scene;
    let b = setup.scene.bounds();
    let c = b.center();
    if !c.is_finite() || c.abs().max_element() <= b.diagonal() {
        return Ok(None);
    }
    let near = setup.camera.map(|cam| cam.near());
    Ok(Some((moved(setup, 1.0, -c, near)?, -c)))
}

fn moved(
    setup: &SceneSetup,
    scale: f32,
    translation: Vec3,
    near: Option<f32>,
) -> Result<SceneSetup, BuiltinError> {
    let t = Affine3A::from_translation(translation) * Affine3A::from_scale(Vec3::splat(scale));
    let scene = setup.scene.transformed(t).map_err(LoadError::from)?;
    let lights = setup
        .lights
        .iter()
        .map(|l| transform_light(l.as_ref(), scale, translation))
        .collect::<Result<Vec<_>, _>>()?;
    let camera = match setup.camera {
        Some(c) => {
            let w = c.world_from_camera();
            let moved = Affine3A::from_cols(
                w.matrix3.x_axis,
                w.matrix3.y_axis,
                w.matrix3.z_axis,
                (Vec3::from(w.translation) * scale + translation).into(),
            );
            let mut cam = Camera::from_world_transform(moved, c.yfov()).map_err(LoadError::from)?;
            if let Some(n) = near {
                cam = cam.with_near(n).map_err(LoadError::from)?;
            }
            if let Some(f) = c.far() {
                cam = cam.with_far(f * scale).map_err(LoadError::from)?;
            }
            Some(cam)
        }
        None => None,
    };
    Ok(SceneSetup {
        name: setup.name.clone(),
        scene: Arc::new(scene),
        lights,
        camera,
        aspect: setup.aspect,
        warnings: setup.warnings.clone(),
        punctual: setup
            .punctual
            .iter()
            .map(|p| PunctualLight {
                position: p.position * scale + translation,
                radius: p.radius * scale,
                ..p.clone()
            })
            .collect(),
        layouts: setup
            .layouts
            .iter()
            .map(|l| UvLayout {
                positions: l
                    .positions
                    .iter()
                    .map(|p| *p * scale + translation)
                    .collect(),
                ..l.clone()
            })
            .collect(),
    })
}
