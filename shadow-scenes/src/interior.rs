//! The furnished room of `interior` (a ceiling panel light) and `interior-window` (a
//! window-sized light in a wall), issue 48: a large light over many occluders at every depth,
//! receivers all around the light (walls up to the ceiling, the ceiling itself behind the
//! light's plane), thin table and chair legs, shelves of books and a scanned mesh (Spot) on the
//! table. Every mesh is closed, the room's shell facing inward. `interior` has two more lights
//! ([`lamps`]): the multi-light interior (issue 67).

use glam::{Affine3A, Vec3};
use std::sync::Arc;

use shadow_core::light::{DiskLight, Light, Radiance, RectLight, SphereLight};
use shadow_core::scene::MeshDesc;

use super::{BuiltinError, Parts, SPOT_OBJ, cam, mesh, placed_obj, white};
use crate::procedural::{Mesh, cuboid, uv_sphere};

/// Half extents of the room: x from -2.5 to 2.5, z from -2 to 2, the floor at y = 0 and the
/// ceiling at y = 2.6.
pub const ROOM_HALF: Vec3 = Vec3::new(2.5, 1.3, 2.0);

/// A box of `size` whose base centre is `base`.
fn block(base: Vec3, size: Vec3) -> Mesh {
    let h = 0.5 * Vec3::new(size.x, 0.0, size.z);
    cuboid(base - h, base + h + Vec3::Y * size.y, false)
}

/// A table or a chair's legs: four square posts of side `t` and height `h` under the corners
/// of a `w` x `d` top centred on `c` (on the floor).
fn legs(c: Vec3, w: f32, d: f32, t: f32, h: f32) -> Vec<Mesh> {
    let (x, z) = (0.5 * w - t, 0.5 * d - t);
    [(-x, -z), (x, -z), (x, z), (-x, z)]
        .iter()
        .map(|&(dx, dz)| block(c + Vec3::new(dx, 0.0, dz), Vec3::new(t, h, t)))
        .collect()
}

/// The room's furniture: a table with Spot and a bowl on it, two chairs, a bookshelf with
/// books against the back wall and a sofa.
fn furniture() -> Result<Vec<MeshDesc>, BuiltinError> {
    let mut m: Vec<Mesh> = Vec::new();
    // The table: a 1.4 x 0.8 top 0.76 m high on legs.
    let table = Vec3::new(-0.3, 0.0, -0.3);
    m.push(block(table + Vec3::Y * 0.72, Vec3::new(1.4, 0.04, 0.8)));
    m.extend(legs(table, 1.4, 0.8, 0.05, 0.72));
    // Two chairs facing the table from either end, their backs away from it.
    for side in [-1.0f32, 1.0] {
        let c = table + Vec3::new(side * 1.0, 0.0, 0.0);
        m.push(block(c + Vec3::Y * 0.44, Vec3::new(0.44, 0.04, 0.44)));
        m.extend(legs(c, 0.44, 0.44, 0.04, 0.44));
        m.push(block(
            c + Vec3::new(side * 0.2, 0.48, 0.0),
            Vec3::new(0.04, 0.5, 0.44),
        ));
    }
    // The bookshelf: two sides, five shelves and books of varied sizes.
    let shelf = Vec3::new(-1.7, 0.0, -1.8);
    for dx in [-0.5f32, 0.5] {
        m.push(block(shelf + Vec3::X * dx, Vec3::new(0.03, 1.8, 0.3)));
    }
    for k in 0..5 {
        let y = 0.02 + 0.44 * k as f32;
        m.push(block(shelf + Vec3::Y * y, Vec3::new(1.0, 0.03, 0.3)));
        if k < 4 {
            let mut x = -0.45f32;
            for b in 0..7 {
                let w = 0.05 + 0.02 * ((b * 3 + k) % 4) as f32;
                let h = 0.22 + 0.04 * ((b + 2 * k) % 3) as f32;
                m.push(block(
                    shelf + Vec3::new(x + 0.5 * w, y + 0.03, 0.0),
                    Vec3::new(w, h, 0.22),
                ));
                x += w + 0.04;
            }
        }
    }
    // The sofa: a base, a back and two arms.
    let sofa = Vec3::new(1.5, 0.0, 1.45);
    m.push(block(sofa, Vec3::new(1.5, 0.42, 0.8)));
    m.push(block(
        sofa + Vec3::new(0.0, 0.42, 0.32),
        Vec3::new(1.5, 0.45, 0.16),
    ));
    for dx in [-0.68f32, 0.68] {
        m.push(block(
            sofa + Vec3::new(dx, 0.42, 0.0),
            Vec3::new(0.14, 0.2, 0.8),
        ));
    }
    // A bowl (a ball) on the table.
    m.push(uv_sphere(table + Vec3::new(0.4, 0.86, 0.15), 0.1, 16, 32));
    let mut out: Vec<MeshDesc> = m.into_iter().map(mesh).collect();
    // Spot on the table, 0.35 m long, turned toward the window.
    let spot = placed_obj(SPOT_OBJ, 0.35, 0.6)?;
    let on_table = Affine3A::from_translation(table + Vec3::new(-0.25, 0.76, 0.0));
    let t = on_table * spot.transform;
    out.push(spot.with_transform(t));
    Ok(out)
}

/// The room: its shell (facing inward) and its furniture, lit by `light`, seen from a corner.
fn room(light: RectLight) -> Result<Parts, BuiltinError> {
    let c = Vec3::Y * ROOM_HALF.y;
    let mut meshes = vec![mesh(cuboid(c - ROOM_HALF, c + ROOM_HALF, true))];
    meshes.extend(furniture()?);
    Ok(Parts {
        meshes,
        light: std::sync::Arc::new(light),
        camera: cam(Vec3::new(2.2, 1.75, 1.0), Vec3::new(-0.6, 0.6, -0.6), 75.0),
    })
}

/// `interior`: a 1.2 x 0.6 m ceiling panel 2 cm below the ceiling, facing down.
pub(super) fn ceiling_panel() -> Result<Parts, BuiltinError> {
    let top = 2.0 * ROOM_HALF.y - 0.02;
    room(RectLight::facing(
        Vec3::new(-0.3, top, -0.3),
        Vec3::NEG_Y,
        1.2,
        0.6,
        white(1.0),
    )?)
}

/// The lights `interior` has besides its ceiling panel (issue 67): a warm disk pendant 0.15 m
/// in radius hanging 1.7 m above the floor over the sofa, facing down, and a bare bulb (a sphere
/// 0.08 m in radius) 1.9 m high between the table and the shelves. With the panel, three lights
/// of three shapes: the multi-light interior of the conformance suite.
pub(super) fn lamps() -> Result<Vec<Light>, BuiltinError> {
    let warm = Radiance::constant(Vec3::new(3.0, 2.4, 1.6))?;
    let cool = Radiance::constant(Vec3::new(1.6, 1.8, 2.0))?;
    Ok(vec![
        Arc::new(DiskLight::new(
            Vec3::new(1.5, 1.7, 1.3),
            Vec3::NEG_Y,
            0.15,
            warm,
        )?),
        Arc::new(SphereLight::new(Vec3::new(-0.6, 1.9, -1.3), 0.08, cool)?),
    ])
}

/// `interior-window`: a 1.0 m wide, 1.2 m high light 1 cm in front of the left wall (x =
/// -2.5), facing into the room, like daylight through a window.
pub(super) fn window() -> Result<Parts, BuiltinError> {
    room(RectLight::facing(
        Vec3::new(-ROOM_HALF.x + 0.01, 1.4, 0.6),
        Vec3::X,
        1.0,
        1.2,
        white(1.0),
    )?)
}
