//! The rasterizer against ray casting: at pixel centres away from edges the G-buffer holds
//! exactly the nearest ray-triangle hit (triangle, position, normal); depth-peeling layers are
//! strictly ordered and equal the sorted hits; the result does not depend on the thread count.

use glam::{Affine3A, DVec3, Vec3};
use shadow_core::prelude::*;
use shadow_core::raster::{NO_TRIANGLE, Projection, RasterView, rasterize, rasterize_depth};
use shadow_scenes::procedural::{cuboid, quad, uv_sphere};

/// Moller-Trumbore in f64: distance and barycentrics (u, v).
fn hit(o: DVec3, d: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<(f64, f64, f64)> {
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-14 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - a;
    let u = s.dot(p) * inv;
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    let t = e2.dot(q) * inv;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0).then_some((t, u, v))
}

fn test_scene() -> TriangleScene {
    let mut b = SceneBuilder::new();
    let f = quad(
        Vec3::ZERO,
        Vec3::new(0.0, 0.0, 2.0),
        Vec3::new(2.0, 0.0, 0.0),
    );
    b.push_mesh(MeshDesc::new(f.0, f.1)).unwrap();
    let c = cuboid(Vec3::new(-0.5, 0.0, -0.5), Vec3::new(0.0, 0.6, 0.2), false);
    b.push_mesh(MeshDesc::new(c.0, c.1).with_transform(Affine3A::from_rotation_y(0.4)))
        .unwrap();
    let s = uv_sphere(Vec3::new(0.6, 0.4, 0.1), 0.35, 10, 16);
    b.push_mesh(MeshDesc::new(s.0, s.1)).unwrap();
    b.build().unwrap()
}

fn check_against_rays(scene: &TriangleScene, view: &RasterView) {
    let vs = ViewSamples::render_view(scene, view).unwrap();
    let mut checked = 0;
    for y in 0..view.height {
        for x in 0..view.width {
            let i = (y * view.width + x) as usize;
            let (o, d) = view.pixel_ray(x, y);
            let (o, d) = (o.as_dvec3(), d.as_dvec3());
            let mut best: Option<(f64, usize, f64)> = None;
            let mut second = f64::INFINITY;
            for t in 0..scene.triangle_count() {
                let [a, b, c] = scene.triangle(t).map(|p| p.as_dvec3());
                if let Some((dist, u, v)) = hit(o, d, a, b, c) {
                    let edge = u.min(v).min(1.0 - u - v);
                    if best.is_none_or(|(bd, _, _)| dist < bd) {
                        if let Some((bd, _, _)) = best {
                            second = second.min(bd);
                        }
                        best = Some((dist, t, edge));
                    } else {
                        second = second.min(dist);
                    }
                }
            }
            match best {
                None => assert!(!vs.is_valid(i), "pixel ({x},{y}) should be background"),
                Some((dist, t, edge)) => {
                    // Skip pixels whose ray passes within 1e-4 of an edge or hits two surfaces at
                    // almost the same distance: either answer is right there.
                    if edge < 1e-4 || (second - dist) < 1e-4 * dist {
                        continue;
                    }
                    let s = vs
                        .get(i)
                        .unwrap_or_else(|| panic!("pixel ({x},{y}) missed triangle {t}"));
                    assert_eq!(s.triangle as usize, t, "pixel ({x},{y})");
                    let expected = o + d * dist;
                    let err = (s.position.as_dvec3() - expected).length();
                    assert!(
                        err < 1e-5 * (1.0 + expected.length()),
                        "pixel ({x},{y}) position off by {err}"
                    );
                    let n = scene.geometric_normal(t).as_dvec3();
                    let n = if n.dot(d) > 0.0 { -n } else { n };
                    assert!((s.geometric_normal.as_dvec3() - n).length() < 1e-5);
                    assert!(
                        s.depth > 0.0 || matches!(view.projection, Projection::Orthographic { .. })
                    );
                    checked += 1;
                }
            }
        }
    }
    assert!(
        checked > (view.width * view.height / 3) as usize,
        "only {checked} pixels checked"
    );
}

#[test]
fn perspective_gbuffer_equals_ray_casting() {
    let scene = test_scene();
    let cam = Camera::look_at(
        Vec3::new(0.3, 1.5, 2.2),
        Vec3::new(0.0, 0.2, 0.0),
        Vec3::Y,
        0.9,
    )
    .unwrap();
    check_against_rays(&scene, &cam.raster_view(48, 36));
}

#[test]
fn orthographic_and_off_centre_views_equal_ray_casting() {
    let scene = test_scene();
    let cam = Camera::look_at(Vec3::new(0.0, 3.0, 0.5), Vec3::ZERO, Vec3::Y, 0.9).unwrap();
    let view_from_world = cam.world_from_camera().inverse();
    check_against_rays(
        &scene,
        &RasterView {
            width: 40,
            height: 40,
            view_from_world,
            projection: Projection::Orthographic {
                left: -1.2,
                right: 1.0,
                bottom: -1.0,
                top: 1.3,
                near: 0.0,
            },
        },
    );
    check_against_rays(
        &scene,
        &RasterView {
            width: 40,
            height: 30,
            view_from_world,
            projection: Projection::Perspective {
                left: -0.2,
                right: 0.6,
                bottom: -0.5,
                top: 0.1,
                near: 0.01,
            },
        },
    );
}

#[test]
fn camera_inside_geometry_clips_at_the_near_plane() {
    // The camera stands inside a closed room: every pixel sees a wall, none is lost to clipping.
    let (p, t) = cuboid(Vec3::splat(-1.0), Vec3::splat(1.0), true);
    let scene = TriangleScene::new(p, t).unwrap();
    let cam = Camera::look_at(
        Vec3::new(0.2, 0.1, 0.3),
        Vec3::new(1.0, 0.2, -1.0),
        Vec3::Y,
        1.5,
    )
    .unwrap();
    let view = cam.raster_view(32, 32);
    let vs = ViewSamples::render_view(&scene, &view).unwrap();
    assert_eq!(vs.valid_count(), 32 * 32);
    check_against_rays(&scene, &view);
}

#[test]
fn shared_edges_leave_no_holes_and_no_double_coverage() {
    // A fan of thin triangles around a centre: every covered pixel gets exactly one triangle,
    // and the union covers the disk (no pixel of the interior missed).
    let n = 37;
    let mut p = vec![Vec3::ZERO];
    let mut t = Vec::new();
    for i in 0..n {
        let a = std::f32::consts::TAU * i as f32 / n as f32;
        p.push(Vec3::new(a.cos(), a.sin(), 0.0));
        t.push([0, 1 + i, 1 + (i + 1) % n]);
    }
    let view = RasterView {
        width: 64,
        height: 64,
        view_from_world: Affine3A::from_translation(Vec3::new(0.0, 0.0, -1.0)),
        projection: Projection::Orthographic {
            left: -1.0,
            right: 1.0,
            bottom: -1.0,
            top: 1.0,
            near: 0.0,
        },
    };
    let frags = rasterize(&p, &t, &view, 2).unwrap();
    for y in 0..64 {
        for x in 0..64 {
            let c = glam::Vec2::new(
                -1.0 + (x as f32 + 0.5) / 32.0,
                1.0 - (y as f32 + 0.5) / 32.0,
            );
            let first = frags.triangle_at(x, y, 0);
            // Two coplanar triangles never both cover a pixel: the second layer stays empty.
            assert_eq!(frags.triangle_at(x, y, 1), NO_TRIANGLE);
            if c.length() < 0.95 {
                assert_ne!(first, NO_TRIANGLE, "hole at ({x},{y})");
            }
        }
    }
}

#[test]
fn depth_peeling_layers_are_strictly_ordered_sorted_hits() {
    // Five stacked horizontal quads seen from above: three layers hold the three nearest.
    let mut b = SceneBuilder::new();
    for k in 0..5 {
        let q = quad(
            Vec3::new(0.1 * k as f32, 0.2 * k as f32, 0.0),
            Vec3::new(0.0, 0.0, 0.8),
            Vec3::new(0.8, 0.0, 0.0),
        );
        b.push_mesh(MeshDesc::new(q.0, q.1)).unwrap();
    }
    let scene = b.build().unwrap();
    let cam = Camera::look_at(
        Vec3::new(0.2, 3.0, 0.1),
        Vec3::new(0.2, 0.0, 0.0),
        Vec3::Y,
        0.9,
    )
    .unwrap();
    let view = cam.raster_view(40, 40);
    let frags = rasterize(scene.positions(), scene.triangles(), &view, 3).unwrap();
    // The depth-only rasterizer keeps the same layers.
    let depths = rasterize_depth(scene.positions(), scene.triangles(), &view, 3).unwrap();
    assert_eq!(depths, frags.depth);
    let mut multi = 0;
    for y in 0..40 {
        for x in 0..40 {
            let (o, d) = view.pixel_ray(x, y);
            let mut hits: Vec<f64> = (0..scene.triangle_count())
                .filter_map(|t| {
                    let [a, b, c] = scene.triangle(t).map(|p| p.as_dvec3());
                    hit(o.as_dvec3(), d.as_dvec3(), a, b, c).map(|h| h.0)
                })
                .collect();
            hits.sort_by(f64::total_cmp);
            hits.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
            let mut prev = f32::NEG_INFINITY;
            for layer in 0..3 {
                let depth = frags.depth_at(x, y, layer);
                if frags.triangle_at(x, y, layer) == NO_TRIANGLE {
                    assert_eq!(depth, f32::INFINITY);
                    continue;
                }
                assert!(depth > prev, "layers not strictly ordered at ({x},{y})");
                prev = depth;
                if let Some(&h) = hits.get(layer as usize) {
                    // Ray distance to linear depth: multiply by cos of the angle to the axis.
                    let expected = h * d.as_dvec3().dot(cam.forward().as_dvec3());
                    assert!(
                        (depth as f64 - expected).abs() < 1e-4,
                        "({x},{y}) layer {layer}: {depth} vs {expected}"
                    );
                }
                if layer == 2 {
                    multi += 1;
                }
            }
        }
    }
    assert!(multi > 100, "too few pixels with three layers: {multi}");
}

#[test]
fn output_does_not_depend_on_thread_count() {
    let scene = test_scene();
    let cam = Camera::look_at(
        Vec3::new(0.3, 1.5, 2.2),
        Vec3::new(0.0, 0.2, 0.0),
        Vec3::Y,
        0.9,
    )
    .unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let a = one.install(|| ViewSamples::render(&scene, &cam, 61, 47).unwrap());
    let b = ViewSamples::render(&scene, &cam, 61, 47).unwrap();
    assert_eq!(a, b);
}

#[test]
fn covered_pixels_equal_the_rasterizer_coverage() {
    // Big, thin, clipped and tiny triangles: the span walk must visit exactly the pixels the
    // rasterizer covers.
    let cam = Camera::look_at(Vec3::new(0.3, 1.0, 4.0), Vec3::ZERO, Vec3::Y, 0.9).unwrap();
    let view = cam.raster_view(97, 61);
    let tris = [
        [
            Vec3::new(-3.0, -2.0, 0.0),
            Vec3::new(3.0, -1.5, -1.0),
            Vec3::new(0.1, 2.5, 0.5),
        ],
        [
            Vec3::new(-0.5, 0.0, 0.0),
            Vec3::new(0.5, 0.01, 0.0),
            Vec3::new(0.4, 0.03, 0.2),
        ],
        [
            Vec3::new(-1.0, 0.0, 6.0),
            Vec3::new(1.0, 0.0, -3.0),
            Vec3::new(0.0, 1.0, -3.0),
        ],
        [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.001, 0.0, 0.0),
            Vec3::new(0.0, 0.001, 0.0),
        ],
        [
            Vec3::new(-40.0, -30.0, -50.0),
            Vec3::new(40.0, -30.0, -50.0),
            Vec3::new(0.0, 60.0, -50.0),
        ],
    ];
    for tri in tris {
        let frags = rasterize(&tri, &[[0, 1, 2]], &view, 1).unwrap();
        let mut visited = vec![false; (view.width * view.height) as usize];
        shadow_core::raster::for_each_covered_pixel(&view, tri, |x, y| {
            let i = (y * view.width + x) as usize;
            assert!(!visited[i], "pixel visited twice");
            visited[i] = true;
        });
        for (i, v) in visited.iter().enumerate() {
            assert_eq!(*v, frags.triangle[i] != NO_TRIANGLE, "{tri:?} pixel {i}");
        }
    }
}

/// Issue 51, item 14: 16384x16384 was accepted and grew to 15.7 GB before it was killed; a
/// view above `MAX_VIEW_PIXELS` is refused at once with the limit, and one at the limit's side
/// lengths is accepted by the check.
#[test]
fn views_above_the_pixel_cap_are_refused_before_allocating() {
    use shadow_core::raster::RasterError;
    use shadow_core::view_samples::MAX_VIEW_PIXELS;
    let setup = shadow_scenes::builtin("quad-over-plane").unwrap();
    let camera = setup.camera_or_default();
    let t0 = std::time::Instant::now();
    match ViewSamples::render(setup.scene.as_ref(), &camera, 16384, 16384) {
        Err(RasterError::TooManyPixels { limit, .. }) => assert_eq!(limit, MAX_VIEW_PIXELS),
        other => panic!("{:?}", other.map(|v| v.len())),
    }
    assert!(t0.elapsed().as_secs_f64() < 1.0, "refused without work");
    let e = ViewSamples::render(setup.scene.as_ref(), &camera, u32::MAX, 2).unwrap_err();
    assert!(e.to_string().contains("largest supported view"), "{e}");
}

/// Every k-th view sample sits on its reduced view's pixel ray: the same camera rays (for odd
/// and even k, and sizes that do not divide), so a technique given the reduced view (DCS
/// rasterizes shadow volumes through its pixel centres) sees the same geometry.
#[test]
fn every_kth_view_sample_lies_on_its_reduced_pixel_ray() {
    let setup = shadow_scenes::builtin("bunny").unwrap();
    let full =
        ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 67, 50).unwrap();
    for k in [1u32, 2, 3, 4, 7] {
        let small = full.every_kth(k);
        assert_eq!((small.width(), small.height()), (67 / k, 50 / k), "k {k}");
        let view = small.raster_view().expect("a rendered view has a camera");
        let mut checked = 0;
        for y in 0..small.height() {
            for x in 0..small.width() {
                let s = small.get_at(x, y);
                let f = full.get_at(k * x + k / 2, k * y + k / 2);
                assert_eq!(
                    s,
                    f.map(|f| shadow_core::view_samples::ViewSample {
                        pixel: glam::UVec2::new(x, y),
                        ..f
                    })
                );
                let Some(s) = s else { continue };
                let (o, d) = view.pixel_ray(x, y);
                let along = (s.position - o).dot(d);
                let off = (s.position - o - along * d).length();
                assert!(off <= 1e-5 * along.max(1.0), "k {k} ({x}, {y}): {off}");
                checked += 1;
            }
        }
        assert!(checked > 0, "k {k}");
    }
}
