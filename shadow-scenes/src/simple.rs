//! The built-in scenes made of procedural meshes and the committed OBJ models: a floor,
//! occluders and one area light each, with a camera ([`crate::builtin`] lists them).

use std::sync::Arc;

use glam::Vec3;
use shadow_core::light::{DiskLight, LightError, Radiance, RectLight, SphereLight};

use crate::procedural::{self, cuboid, quad, uv_sphere};
use crate::quad_over_plane as q;
use crate::{
    BUNNY_OBJ, BuiltinError, Parts, SPOT_OBJ, cam, floor_mesh, folded_lamp, mesh, placed_obj,
    textured_pattern, white,
};

/// A rectangle light at `c`, `side` a side, facing down.
fn down(c: Vec3, side: f32, r: Radiance) -> Result<RectLight, LightError> {
    RectLight::new(
        c,
        Vec3::new(0.5 * side, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.5 * side),
        r,
    )
}

/// `quad-over-plane`.
pub(crate) fn quad_over_plane() -> Result<Parts, BuiltinError> {
    Ok(Parts {
        meshes: vec![
            floor_mesh(q::FLOOR_SIDE),
            mesh(quad(
                Vec3::new(0.0, q::OCCLUDER_HEIGHT, 0.0),
                Vec3::new(0.5 * q::OCCLUDER_SIDE, 0.0, 0.0),
                Vec3::new(0.0, 0.0, -0.5 * q::OCCLUDER_SIDE),
            )),
        ],
        light: Arc::new(down(
            Vec3::new(0.0, q::LIGHT_HEIGHT, 0.0),
            q::LIGHT_SIDE,
            white(1.0),
        )?),
        camera: cam(Vec3::new(0.0, 3.2, 3.6), Vec3::new(0.0, 0.2, 0.0), 50.0),
    })
}

/// `overlapping-occluders`.
pub(crate) fn overlapping_occluders() -> Result<Parts, BuiltinError> {
    Ok(Parts {
        meshes: vec![
            floor_mesh(6.0),
            mesh(quad(
                Vec3::new(-0.35, 1.3, 0.0),
                Vec3::new(0.5, 0.0, 0.0),
                Vec3::new(0.0, 0.0, -0.35),
            )),
            mesh(quad(
                Vec3::new(0.35, 0.7, 0.15),
                Vec3::new(0.45, 0.0, 0.0),
                Vec3::new(0.0, 0.0, -0.4),
            )),
            mesh(quad(
                Vec3::new(0.0, 1.0, -0.45),
                Vec3::new(0.3, 0.0, 0.0),
                Vec3::new(0.0, 0.0, -0.3),
            )),
        ],
        light: Arc::new(down(Vec3::new(0.0, 2.4, 0.0), 1.2, white(1.0))?),
        camera: cam(Vec3::new(0.0, 3.4, 3.4), Vec3::new(0.0, 0.3, 0.0), 50.0),
    })
}

/// `large-light-close`.
pub(crate) fn large_light_close() -> Result<Parts, BuiltinError> {
    Ok(Parts {
        meshes: vec![
            floor_mesh(6.0),
            mesh(cuboid(
                Vec3::new(-0.3, 0.35, -0.3),
                Vec3::new(0.3, 0.65, 0.3),
                false,
            )),
        ],
        light: Arc::new(down(Vec3::new(0.0, 1.1, 0.0), 2.0, white(1.0))?),
        camera: cam(Vec3::new(0.0, 2.6, 3.0), Vec3::new(0.0, 0.2, 0.0), 55.0),
    })
}

/// `bunny`.
pub(crate) fn bunny() -> Result<Parts, BuiltinError> {
    Ok(Parts {
        meshes: vec![floor_mesh(4.0), placed_obj(BUNNY_OBJ, 1.0, 0.0)?],
        light: Arc::new(down(Vec3::new(0.6, 2.5, 0.4), 0.8, white(1.0))?),
        camera: cam(Vec3::new(0.0, 1.4, 2.6), Vec3::new(0.0, 0.45, 0.0), 45.0),
    })
}

/// `spot-self-shadow`.
pub(crate) fn spot_self_shadow() -> Result<Parts, BuiltinError> {
    Ok(Parts {
        meshes: vec![floor_mesh(4.0), placed_obj(SPOT_OBJ, 1.2, 0.6)?],
        light: Arc::new(RectLight::facing(
            Vec3::new(-1.6, 2.0, 0.9),
            Vec3::new(1.6, -2.0, -0.9),
            0.7,
            0.7,
            white(1.0),
        )?),
        camera: cam(Vec3::new(1.2, 1.3, 2.3), Vec3::new(0.0, 0.5, 0.0), 45.0),
    })
}

/// `grass`.
pub(crate) fn grass() -> Result<Parts, BuiltinError> {
    Ok(Parts {
        meshes: vec![
            floor_mesh(4.0),
            mesh(procedural::grass(30_000, 0.75, 0.5, 0.05, 7)),
        ],
        light: Arc::new(RectLight::facing(
            Vec3::new(-4.0, 1.1, 0.0),
            Vec3::new(4.0, -1.1, 0.0),
            1.0,
            1.0,
            white(1.0),
        )?),
        camera: cam(Vec3::new(1.6, 1.6, 2.2), Vec3::new(0.0, 0.15, 0.0), 45.0),
    })
}

/// `contact`.
pub(crate) fn contact() -> Result<Parts, BuiltinError> {
    Ok(Parts {
        meshes: vec![
            floor_mesh(6.0),
            mesh(cuboid(
                Vec3::new(-0.9, 0.0, -0.3),
                Vec3::new(-0.3, 0.5, 0.3),
                false,
            )),
            mesh(uv_sphere(Vec3::new(0.5, 0.35, 0.0), 0.35, 24, 48)),
        ],
        light: Arc::new(DiskLight::new(
            Vec3::new(0.2, 2.0, 0.5),
            Vec3::new(0.0, -1.0, -0.2),
            0.4,
            white(1.0),
        )?),
        camera: cam(Vec3::new(0.0, 1.6, 2.8), Vec3::new(0.0, 0.25, 0.0), 45.0),
    })
}

/// `semi-opaque`.
pub(crate) fn semi_opaque() -> Result<Parts, BuiltinError> {
    Ok(Parts {
        meshes: vec![
            floor_mesh(6.0),
            mesh(quad(
                Vec3::new(-0.4, 1.2, 0.0),
                Vec3::new(0.45, 0.0, 0.0),
                Vec3::new(0.0, 0.0, -0.45),
            ))
            .with_opacity(0.3),
            mesh(quad(
                Vec3::new(0.2, 0.9, 0.2),
                Vec3::new(0.45, 0.0, 0.0),
                Vec3::new(0.0, 0.0, -0.45),
            ))
            .with_opacity(0.5),
            mesh(quad(
                Vec3::new(0.4, 0.6, -0.3),
                Vec3::new(0.35, 0.0, 0.0),
                Vec3::new(0.0, 0.0, -0.35),
            ))
            .with_opacity(0.7),
        ],
        light: Arc::new(down(Vec3::new(0.0, 2.2, 0.0), 1.0, white(1.0))?),
        camera: cam(Vec3::new(0.0, 3.2, 3.2), Vec3::new(0.0, 0.3, 0.0), 50.0),
    })
}

/// `textured-light`.
pub(crate) fn textured_light() -> Result<Parts, BuiltinError> {
    Ok(Parts {
        meshes: vec![
            floor_mesh(6.0),
            mesh(cuboid(
                Vec3::new(-0.25, 0.6, -0.25),
                Vec3::new(0.25, 0.9, 0.25),
                false,
            )),
        ],
        light: Arc::new(down(Vec3::new(0.0, 2.0, 0.0), 1.4, textured_pattern()?)?),
        camera: cam(Vec3::new(0.0, 3.0, 3.2), Vec3::new(0.0, 0.3, 0.0), 50.0),
    })
}

/// `sphere-light`.
pub(crate) fn sphere_light() -> Result<Parts, BuiltinError> {
    Ok(Parts {
        meshes: vec![
            mesh(cuboid(
                Vec3::new(-2.0, 0.0, -2.0),
                Vec3::new(2.0, 2.5, 2.0),
                true,
            )),
            mesh(cuboid(
                Vec3::new(-1.0, 0.0, -0.6),
                Vec3::new(-0.4, 0.8, 0.0),
                false,
            )),
            mesh(uv_sphere(Vec3::new(0.8, 0.4, 0.3), 0.4, 16, 32)),
            mesh(quad(
                Vec3::new(0.0, 1.2, 0.8),
                Vec3::new(0.4, 0.0, 0.0),
                Vec3::new(0.0, 0.0, -0.3),
            )),
        ],
        light: Arc::new(SphereLight::new(Vec3::new(0.0, 1.8, 0.0), 0.2, white(1.0))?),
        camera: cam(Vec3::new(1.6, 2.0, 1.9), Vec3::new(-0.2, 0.5, -0.3), 70.0),
    })
}

/// `mesh-light`.
pub(crate) fn mesh_light() -> Result<Parts, BuiltinError> {
    Ok(Parts {
        meshes: vec![
            floor_mesh(6.0),
            mesh(cuboid(
                Vec3::new(-0.3, 0.9, -0.3),
                Vec3::new(0.3, 1.1, 0.3),
                false,
            )),
            mesh(uv_sphere(Vec3::new(1.2, 0.35, 0.4), 0.35, 16, 32)),
        ],
        light: Arc::new(folded_lamp::light(white(1.0))?),
        camera: cam(Vec3::new(0.0, 3.2, 4.2), Vec3::new(0.0, 0.4, 0.0), 65.0),
    })
}
