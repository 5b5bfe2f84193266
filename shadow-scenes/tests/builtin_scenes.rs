//! Built-in scenes: each builds with a camera and a light and has the property it is named for.

use glam::{DVec3, Vec3};
use shadow_core::light::LightKind;
use shadow_core::prelude::*;
use shadow_scenes::{BUILTIN_SCENES, builtin, transformed};

/// `interior` is the multi-light interior: three lights of three shapes, none inside the
/// furniture or the room's shell (every light sample sees some receiver).
#[test]
fn interior_has_three_lights_of_three_shapes() {
    let s = builtin("interior").unwrap();
    let kinds: Vec<LightKind> = s.lights.iter().map(|l| l.kind()).collect();
    assert_eq!(
        kinds,
        [LightKind::Rectangle, LightKind::Disk, LightKind::Sphere]
    );
    let view = ViewSamples::render(s.scene.as_ref(), &s.camera.unwrap(), 64, 48).unwrap();
    for (i, l) in s.lights.iter().enumerate() {
        assert!(
            shadow_core::lights::reaches_any_receiver(l, &view),
            "light {i} reaches no receiver"
        );
    }
}

#[test]
fn every_builtin_scene_renders_view_samples() {
    for name in BUILTIN_SCENES {
        let s = builtin(name).unwrap();
        let lights = if name == "interior" { 3 } else { 1 };
        assert_eq!(s.lights.len(), lights, "{name}");
        let cam = s.camera.unwrap();
        let view = ViewSamples::render(s.scene.as_ref(), &cam, 64, 48).unwrap();
        assert!(
            view.valid_count() > 64 * 48 / 2,
            "{name}: {} valid pixels",
            view.valid_count()
        );
        // By index and by column and row: the same samples, at their own pixel.
        for y in 0..48u32 {
            for x in 0..64u32 {
                let by_index = view.get((y * 64 + x) as usize);
                assert_eq!(view.get_at(x, y), by_index, "{name} ({x}, {y})");
                if let Some(s) = by_index {
                    assert_eq!(s.pixel, glam::UVec2::new(x, y));
                }
            }
        }
    }
    assert!(
        builtin("nope")
            .unwrap_err()
            .to_string()
            .contains("quad-over-plane")
    );
}

/// Issue 51: the stress suite's Cornell box. A pixel on a room corner (floor meeting wall) is
/// lit like its neighbours: its view sample lay a float step outside the floor, behind the
/// wall, and every technique drew a line of false shadow along the corners.
#[test]
fn room_corners_are_not_shadowed_by_the_wall_they_meet() {
    let s = builtin("cornell-box").unwrap();
    let cam = s.camera.unwrap();
    let view = ViewSamples::render(s.scene.as_ref(), &cam, 192, 192).unwrap();
    for i in 0..view.len() {
        if let Some(v) = view.get(i) {
            // Every view sample lies inside the room's walls, never beyond them.
            let p = v.position;
            assert!(
                p.x >= -1.0 && p.x <= 1.0 && p.z >= -1.0 && p.y >= 0.0,
                "pixel {i} at {p:?}"
            );
        }
    }
}

#[test]
fn builtin_scenes_have_their_named_properties() {
    let bunny = builtin("bunny").unwrap();
    assert!(bunny.scene.triangle_count() > 69_000);
    assert!(!bunny.scene.topology().all_closed());
    let spot = builtin("spot-self-shadow").unwrap();
    let closed = spot
        .scene
        .topology()
        .components()
        .iter()
        .filter(|c| c.closed)
        .count();
    assert_eq!(closed, 1, "the welded Spot is one closed mesh");
    let semi = builtin("semi-opaque").unwrap();
    let ops: Vec<f32> = semi.scene.opacities().to_vec();
    assert!(ops.contains(&0.3) && ops.contains(&0.5) && ops.contains(&0.7));
    assert!(builtin("textured-light").unwrap().lights[0].is_textured());
    let room = builtin("sphere-light").unwrap();
    assert_eq!(room.lights[0].kind(), LightKind::Sphere);
    assert!(room.scene.is_closed_at(0), "the room is closed");
    let contact = builtin("contact").unwrap();
    assert_eq!(contact.lights[0].kind(), LightKind::Disk);
    // Contact: the box bottom lies exactly on the floor.
    assert!(
        contact
            .scene
            .positions()
            .iter()
            .filter(|p| p.y == 0.0)
            .count()
            > 4
    );
}

/// Number of triangles a segment crosses (brute force, f64).
fn crossings(scene: &dyn Scene, a: Vec3, b: Vec3) -> usize {
    let (o, d) = (a.as_dvec3(), (b - a).as_dvec3());
    (0..scene.triangle_count())
        .filter(|&t| {
            let [p0, p1, p2] = scene.triangle(t).map(|p| p.as_dvec3());
            let (e1, e2) = (p1 - p0, p2 - p0);
            let p = d.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-18 {
                return false;
            }
            let s = o - p0;
            let u = s.dot(p) / det;
            let q = s.cross(e1);
            let v = d.dot(q) / det;
            let t = e2.dot(q) / det;
            u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 1e-6 && t < 1.0 - 1e-6
        })
        .count()
}

#[test]
fn grass_depth_complexity_exceeds_255() {
    let g = builtin("grass").unwrap();
    let light = g.lights[0].center();
    let max = (0..9)
        .map(|k| {
            let p = Vec3::new(0.74, 0.001, -0.6 + 0.15 * k as f32);
            crossings(g.scene.as_ref(), p, light)
        })
        .max()
        .unwrap();
    assert!(max > 400, "grass depth complexity only {max}");
    eprintln!("grass: max depth complexity {max} toward the light centre");
    let _ = DVec3::ZERO;
}

#[test]
fn scaled_and_translated_variants_keep_their_shape() {
    let base = builtin("quad-over-plane").unwrap();
    for (scale, t) in [
        (1e-4, Vec3::ZERO),
        (1e5, Vec3::ZERO),
        (1.0, Vec3::splat(1e5)),
    ] {
        let v = transformed(&base, scale, t).unwrap();
        assert_eq!(v.scene.triangle_count(), base.scene.triangle_count());
        let ratio = v.lights[0].area() / base.lights[0].area();
        assert!(
            (ratio / (scale * scale) - 1.0).abs() < 1e-4,
            "{scale}: {ratio}"
        );
        let cam = v.camera.unwrap();
        let view = ViewSamples::render(v.scene.as_ref(), &cam, 32, 24).unwrap();
        let base_view =
            ViewSamples::render(base.scene.as_ref(), &base.camera.unwrap(), 32, 24).unwrap();
        // Same pixels see geometry, up to a few at silhouettes where rounding differs.
        let diff = (0..view.len())
            .filter(|&i| view.is_valid(i) != base_view.is_valid(i))
            .count();
        assert!(
            diff <= 4,
            "scale {scale} translate {t}: {diff} pixels differ"
        );
    }
}
