//! Stress scenes of lights in, half in and flush with a closed mesh (issue 69 item 1).

use std::sync::Arc;

use glam::Vec3;
use shadow_core::prelude::*;
use shadow_io::SceneSetup;
use shadow_scenes::procedural::{cuboid, floor};

use super::{mesh, setup_of, stress_camera};

/// Issue 69 item 1: lights inside, half inside and set flush into a closed mesh (a lamp in a
/// closed housing, a light through a housing's wall, a panel flush with a slab's face), one
/// scene per light shape; every one must agree with the reference.
pub(super) fn enclosed_light_scenes() -> Vec<(&'static str, SceneSetup)> {
    let cam = stress_camera();
    let housing = || {
        vec![
            mesh(floor(6.0, 0.0)),
            mesh(cuboid(
                Vec3::new(-0.5, 0.4, -0.5),
                Vec3::new(0.5, 1.4, 0.5),
                false,
            )),
        ]
    };
    let one = Radiance::Constant(Vec3::ONE);
    let shapes = |c: Vec3| -> [(&'static str, Light); 4] {
        [
            (
                "rectangle",
                Arc::new(RectLight::facing(c, Vec3::NEG_Y, 0.4, 0.3, one.clone()).expect("valid")),
            ),
            (
                "disk",
                Arc::new(DiskLight::new(c, Vec3::NEG_Y, 0.2, one.clone()).expect("valid")),
            ),
            (
                "polygon",
                Arc::new(
                    PolygonLight::new(
                        vec![
                            c + Vec3::new(0.2, 0.0, -0.15),
                            c + Vec3::new(0.0, 0.0, 0.2),
                            c + Vec3::new(-0.2, 0.0, -0.15),
                        ],
                        one.clone(),
                    )
                    .expect("valid"),
                ),
            ),
            (
                "sphere",
                Arc::new(SphereLight::new(c, 0.15, one.clone()).expect("valid")),
            ),
        ]
    };
    let mut out = Vec::new();
    let places: [(&[&'static str; 4], Vec3); 3] = [
        (
            &[
                "light-in-closed-mesh-rectangle",
                "light-in-closed-mesh-disk",
                "light-in-closed-mesh-polygon",
                "light-in-closed-mesh-sphere",
            ],
            Vec3::new(0.0, 0.9, 0.0),
        ),
        (
            &[
                "light-half-in-closed-mesh-rectangle",
                "light-half-in-closed-mesh-disk",
                "light-half-in-closed-mesh-polygon",
                "light-half-in-closed-mesh-sphere",
            ],
            Vec3::new(0.5, 0.9, 0.0),
        ),
        (
            &[
                "light-flush-with-closed-mesh-rectangle",
                "light-flush-with-closed-mesh-disk",
                "light-flush-with-closed-mesh-polygon",
                "light-flush-with-closed-mesh-sphere",
            ],
            Vec3::new(0.45, 0.4, 0.1),
        ),
    ];
    for (names, c) in places {
        for (name, (_, light)) in names.iter().zip(shapes(c)) {
            out.push((*name, setup_of(name, housing(), light, cam)));
        }
    }
    out
}
