//! Issue 52 item 7: base-colour textures give the albedo of shaded and direct output. Issue 67:
//! a mesh's `TEXCOORD_0` is its lightmap layout (`bake --mesh NAME`), in world space, one per
//! node that shows the mesh.

mod common;

use common::{Writer, load, square};
use glam::{Vec2, Vec3};
use serde_json::json;
use shadow_core::prelude::*;
use shadow_io::image_io::shaded_image;

#[test]
fn a_base_colour_texture_colours_the_albedo() {
    let mut w = Writer::default();
    // Red on the left half of the image, blue on the right; the factor halves green-free red.
    let image = w.png_image(2, 1, &[[255, 0, 0], [0, 0, 255]]);
    let floor_material = w.material(json!({"name": "checker", "pbrMetallicRoughness": {
        "baseColorFactor": [0.5, 1.0, 1.0, 1.0], "baseColorTexture": {"index": image}}}));
    let lamp = w.material(json!({"emissiveFactor": [1.0, 1.0, 1.0]}));
    let (fp, fi) = square(3.0);
    // The floor faces up: reverse the square's downward winding. u runs along x.
    let up: Vec<u32> = fi.chunks(3).flat_map(|c| [c[0], c[2], c[1]]).collect();
    let uv: Vec<Vec2> = fp
        .iter()
        .map(|p| Vec2::new((p.x + 3.0) / 6.0, 0.5))
        .collect();
    w.mesh("floor", &fp, &up, Some(&uv), floor_material);
    let (lp, li) = square(0.5);
    w.mesh("lamp", &lp, &li, None, lamp);
    let doc = w.document(
        json!([{"mesh": 0}, {"mesh": 1, "translation": [0.0, 3.0, 0.0]}]),
        json!([]),
    );
    let setup = load(&doc).unwrap();
    assert!(
        !setup.warnings.iter().any(|w| w.contains("base-colour")),
        "{:?}",
        setup.warnings
    );
    let scene = setup.scene.as_ref();
    // Texel centres at x = -1.5 (red) and x = 1.5 (blue); the factor scales red by 0.5.
    let t = (0..scene.triangle_count())
        .find(|&t| scene.triangle(t).iter().all(|p| p.y == 0.0))
        .unwrap();
    let at = |x: f32| {
        let t = (0..scene.triangle_count())
            .find(|&k| {
                let [a, b, c] = scene.triangle(k);
                let n = (b - a).cross(c - a);
                let p = Vec3::new(x, 0.0, 0.1);
                n.y != 0.0
                    && [(a, b), (b, c), (c, a)]
                        .iter()
                        .all(|(u, v)| (*v - *u).cross(p - *u).y * n.y >= 0.0)
            })
            .unwrap_or(t);
        scene.albedo_at(t, Vec3::new(x, 0.0, 0.1))
    };
    assert!(
        (at(-1.5) - Vec3::new(0.5, 0.0, 0.0)).length() < 1e-3,
        "{}",
        at(-1.5)
    );
    assert!(
        (at(1.5) - Vec3::new(0.0, 0.0, 1.0)).length() < 1e-3,
        "{}",
        at(1.5)
    );
    // The shaded view shows both colours.
    let cam = Camera::look_at(Vec3::new(0.0, 4.0, 4.0), Vec3::ZERO, Vec3::Y, 0.9).unwrap();
    let view = ViewSamples::render(scene, &cam, 32, 24).unwrap();
    let mut v = shadow_core::visibility::VisibilityImage::scalar(&view);
    v.scalars_mut().fill(1.0);
    let img = shaded_image(scene, &view, setup.lights[0].as_ref(), &v).unwrap();
    let (reds, blues) = img.pixels().fold((0, 0), |(r, b), p| {
        (
            // The ambient term lifts every channel a little; between the texel centres the
            // bilinear filter blends the two colours.
            r + usize::from(i32::from(p.0[0]) > i32::from(p.0[2]) + 60),
            b + usize::from(i32::from(p.0[2]) > i32::from(p.0[0]) + 60),
        )
    });
    assert!(reds > 20 && blues > 20, "{reds} {blues}");
}

#[test]
fn texcoord_0_gives_each_node_of_a_mesh_its_layout() {
    let mut w = Writer::default();
    let grey = w.material(json!({"name": "grey"}));
    let lamp = w.material(json!({"emissiveFactor": [1.0, 1.0, 1.0]}));
    let (fp, fi) = square(2.0);
    let up: Vec<u32> = fi.chunks(3).flat_map(|c| [c[0], c[2], c[1]]).collect();
    let uv: Vec<Vec2> = fp
        .iter()
        .map(|p| Vec2::new((p.x + 2.0) / 4.0, (p.z + 2.0) / 4.0))
        .collect();
    w.mesh("floor", &fp, &up, Some(&uv), grey);
    let (lp, li) = square(0.5);
    w.mesh("lamp", &lp, &li, None, lamp);
    let doc = w.document(
        json!([
            {"mesh": 0},
            {"mesh": 0, "translation": [10.0, 0.0, 0.0]},
            {"mesh": 1, "translation": [0.0, 3.0, 0.0]}
        ]),
        json!([]),
    );
    let setup = load(&doc).unwrap();
    let names: Vec<&str> = setup.layouts.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["floor", "floor#1"]);
    let moved = setup.layout("floor#1").unwrap();
    assert_eq!(moved.texcoords, uv);
    for (p, q) in moved.positions.iter().zip(&fp) {
        assert!((*p - (*q + Vec3::new(10.0, 0.0, 0.0))).length() < 1e-5);
    }
    let e = setup.layout("lamp").unwrap_err();
    assert!(e.contains("meshes with them: floor, floor#1"), "{e}");
}
