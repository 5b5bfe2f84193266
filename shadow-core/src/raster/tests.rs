//! Unit tests of the rasterizer: layer order, view validation, coverage rules, chunking.

use super::*;

#[test]
fn layer_insertion_keeps_strict_order() {
    let mut t = [NO_TRIANGLE; 3];
    let mut d = [f32::INFINITY; 3];
    for (id, depth) in [(0, 5.0), (1, 2.0), (2, 5.0), (3, 9.0), (4, 1.0)] {
        insert_layer(&mut t, &mut d, id, depth);
    }
    assert_eq!(t, [4, 1, 0]);
    assert_eq!(d, [1.0, 2.0, 5.0]);
}

#[test]
fn invalid_views_are_errors() {
    let view = RasterView {
        width: 0,
        height: 4,
        view_from_world: Affine3A::IDENTITY,
        projection: Projection::Orthographic {
            left: -1.0,
            right: 1.0,
            bottom: -1.0,
            top: 1.0,
            near: 0.0,
        },
    };
    assert!(rasterize(&[], &[], &view, 1).is_err());
    let v = RasterView {
        width: 4,
        projection: Projection::Perspective {
            left: 1.0,
            right: -1.0,
            bottom: -1.0,
            top: 1.0,
            near: 0.1,
        },
        ..view
    };
    assert!(matches!(
        rasterize(&[], &[], &v, 1),
        Err(RasterError::Projection(_))
    ));
}

/// Triangles are set up a chunk at a time; the layers must not see the chunks: an equal
/// depth keeps the earlier triangle and a nearer one goes first, across chunk borders too.
#[test]
fn chunks_keep_triangle_order_and_layers() {
    let view = ortho_view();
    // Two copies of one square at depth 2, the second in the next chunk, one at depth 1 in
    // the chunk after, and off-screen triangles in between.
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let square = |positions: &mut Vec<Vec3>, z: f32| {
        let b = positions.len() as u32;
        positions.extend([
            Vec3::new(4.0, 4.0, z),
            Vec3::new(28.0, 4.0, z),
            Vec3::new(28.0, 28.0, z),
            Vec3::new(4.0, 28.0, z),
        ]);
        [[b, b + 1, b + 2], [b, b + 2, b + 3]]
    };
    triangles.extend(square(&mut positions, -2.0));
    let off = positions.len() as u32;
    positions.extend([
        Vec3::new(100.0, 100.0, -2.0),
        Vec3::new(101.0, 100.0, -2.0),
        Vec3::new(100.0, 101.0, -2.0),
    ]);
    triangles.resize(RASTER_CHUNK + 3, [off, off + 1, off + 2]);
    let second = triangles.len() as u32;
    triangles.extend(square(&mut positions, -2.0));
    triangles.resize(2 * RASTER_CHUNK + 7, [off, off + 1, off + 2]);
    let third = triangles.len() as u32;
    triangles.extend(square(&mut positions, -1.0));
    let f = rasterize(&positions, &triangles, &view, 3).unwrap();
    for (x, y) in [(10, 10), (20, 25), (5, 27)] {
        let t = f.triangle_at(x, y, 0);
        assert!(t == third || t == third + 1, "({x}, {y}): {t}");
        assert_eq!(f.depth_at(x, y, 0), 1.0);
        assert!(
            f.triangle_at(x, y, 1) < 2,
            "({x}, {y}): {}",
            f.triangle_at(x, y, 1)
        );
        assert_eq!(f.depth_at(x, y, 1), 2.0);
        assert_eq!(f.triangle_at(x, y, 2), NO_TRIANGLE);
    }
    assert!(second > RASTER_CHUNK as u32 && third > 2 * RASTER_CHUNK as u32);
}

/// A perspective view of 37 x 29 pixels with the near plane at 0.1.
fn persp_view() -> RasterView {
    RasterView {
        width: 37,
        height: 29,
        view_from_world: Affine3A::IDENTITY,
        projection: Projection::Perspective {
            left: -1.0,
            right: 1.0,
            bottom: -0.8,
            top: 0.8,
            near: 0.1,
        },
    }
}

/// An orthographic view of 32 x 32 pixels over `[0, 32]^2`.
fn ortho_view() -> RasterView {
    RasterView {
        width: 32,
        height: 32,
        view_from_world: Affine3A::IDENTITY,
        projection: Projection::Orthographic {
            left: 0.0,
            right: 32.0,
            bottom: 0.0,
            top: 32.0,
            near: 0.1,
        },
    }
}

/// Visiting a triangle band by band reports the same pixels, once each, as one visit of
/// the whole image, a triangle clipped by the near plane included.
/// 300 random triangles in front of [`persp_view`]'s eye, some crossing the near plane, some
/// thin; `salt` picks another set.
fn random_triangles(salt: &[u64]) -> impl Iterator<Item = [Vec3; 3]> + '_ {
    let r = move |k: u64, i: u64| {
        let words: Vec<u64> = [k, i].iter().chain(salt).copied().collect();
        crate::sampling::unit_float(crate::sampling::hash_words(&words)) * 2.0 - 1.0
    };
    (0..300u64).map(move |k| {
        std::array::from_fn(|v| {
            let v = v as u64;
            Vec3::new(
                r(k, 3 * v) * 2.0,
                r(k, 3 * v + 1) * 2.0,
                -2.0 + 1.8 * r(k, 3 * v + 2),
            )
        })
    })
}

#[test]
fn covered_pixels_by_bands_equal_the_whole_visit() {
    let view = persp_view();
    // Random triangles too, some crossing the near plane, some thin.
    let random = random_triangles(&[]);
    let fixed = [
        [
            Vec3::new(-3.0, -2.0, -4.0),
            Vec3::new(2.5, -1.0, -3.0),
            Vec3::new(0.2, 3.0, -5.0),
        ],
        // Crosses the near plane.
        [
            Vec3::new(-0.5, -0.5, 1.0),
            Vec3::new(0.7, -0.2, -2.0),
            Vec3::new(0.1, 0.9, -2.5),
        ],
        // A sliver.
        [
            Vec3::new(-2.0, -1.0, -3.0),
            Vec3::new(2.0, 1.0, -3.0),
            Vec3::new(2.0, 1.01, -3.0),
        ],
    ];
    let mut covered = 0;
    for (t, tri) in fixed.into_iter().chain(random).enumerate() {
        let mut whole = Vec::new();
        for_each_covered_pixel(&view, tri, |x, y| whole.push((x, y)));
        let cover = CoveredPixels::new(&view, tri);
        let Some((lo, hi)) = cover.rows() else {
            assert!(t >= 3 && whole.is_empty(), "triangle {t}");
            continue;
        };
        let mut banded = Vec::new();
        for y0 in (0..view.height).step_by(4) {
            cover.for_each_in_rows(y0, y0 + 3, |x, y| {
                assert!((y0..y0 + 4).contains(&y) && (lo..=hi).contains(&y));
                banded.push((x, y));
            });
        }
        assert!(t >= 3 || !whole.is_empty());
        covered += usize::from(!whole.is_empty());
        whole.sort_unstable();
        banded.sort_unstable();
        let n = banded.len();
        banded.dedup();
        assert_eq!(n, banded.len(), "a pixel reported twice");
        assert_eq!(whole, banded);
        // The same pixels as runs.
        let mut spans = Vec::new();
        cover.for_each_span_in_rows(0, view.height, |y, x0, x1| {
            spans.extend((x0..=x1).map(|x| (x, y)));
        });
        spans.sort_unstable();
        assert_eq!(whole, spans, "runs of triangle {t}");
    }
    assert!(covered > 100, "{covered}");
}

/// Rows whose pixel centres lie exactly on triangle edges (an orthographic view of 32 x 32
/// pixels over `[0, 32]^2`, vertices on the half-pixel grid): runs equal the per-pixel
/// visit, ties included.
#[test]
fn row_runs_settle_ties_like_the_pixel_test() {
    let view = ortho_view();
    let mut ties = 0;
    for k in 0..400u64 {
        let r = |i: u64| crate::sampling::hash_words(&[k, i]) % 65;
        // Vertices on multiples of a half pixel, some outside the image.
        let tri: [Vec3; 3] = std::array::from_fn(|v| {
            let v = v as u64;
            Vec3::new(
                r(2 * v) as f32 * 0.5 - 0.25,
                r(2 * v + 1) as f32 * 0.5 - 0.25,
                -1.0,
            )
        });
        let mut whole = Vec::new();
        for_each_covered_pixel(&view, tri, |x, y| whole.push((x, y)));
        let mut spans = Vec::new();
        CoveredPixels::new(&view, tri).for_each_span_in_rows(0, 31, |y, x0, x1| {
            spans.extend((x0..=x1).map(|x| (x, y)));
        });
        whole.sort_unstable();
        spans.sort_unstable();
        assert_eq!(whole, spans, "triangle {k}: {tri:?}");
        // Count pixels whose centre lies on an edge line.
        ties += whole
            .iter()
            .filter(|(x, y)| {
                let c = glam::Vec2::new(*x as f32 + 0.5, 31.5 - *y as f32);
                (0..3).any(|i| {
                    let (a, b) = (tri[i].truncate(), tri[(i + 1) % 3].truncate());
                    (b - a).perp_dot(c - a) == 0.0
                })
            })
            .count();
    }
    assert!(ties > 50, "{ties} pixels on an edge");
}

/// The pixels `CoveredPixels` reports for the fan triangles of `outline`.
fn fan_pixels(view: &RasterView, outline: &[Vec3]) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for j in 1..outline.len() - 1 {
        let tri = [outline[0], outline[j], outline[j + 1]];
        CoveredPixels::new(view, tri).for_each_in_rows(0, u32::MAX, |x, y| out.push((x, y)));
    }
    out.sort_unstable();
    out
}

/// The runs of `outline` as a whole polygon, checked against its per-pixel test.
fn polygon_pixels(view: &RasterView, outline: &[Vec3]) -> Vec<(u32, u32)> {
    let cover = CoveredPolygon::new(view, outline);
    let mut out = Vec::new();
    cover.for_each_span_in_rows(0, view.height, |y, x0, x1| {
        out.extend((x0..=x1).map(|x| (x, y)));
    });
    out.sort_unstable();
    let mut tested: Vec<(u32, u32)> = (0..view.height)
        .flat_map(|y| (0..view.width).map(move |x| (x, y)))
        .filter(|&(x, y)| cover.covers(x, y))
        .collect();
    tested.sort_unstable();
    assert_eq!(out, tested, "runs and the pixel test of {outline:?}");
    out
}

/// A whole convex polygon covers the pixels of its fan triangles, each once: random
/// planar quads and pentagons in perspective (some crossing the near plane, some thin), and
/// quads with vertices on the half-pixel grid, whose pixel centres lie on edges (the
/// top-left rule settles them as for the triangles). Such a quad and a triangle sharing one of
/// its edges cover each pixel of their union once.
#[test]
fn repeated_vertices_do_not_empty_a_covered_polygon() {
    // Clipping at a box corner repeats a vertex, exactly or to the last bits; the repeat
    // made every pixel fail the edge test of the zero-length edge (DCS's shadow-volume
    // quads on the Cornell box counted nowhere).
    let persp = persp_view();
    let quad = vec![
        Vec3::new(-0.5, -0.4, -2.0),
        Vec3::new(0.6, -0.3, -2.0),
        Vec3::new(0.5, 0.5, -2.2),
        Vec3::new(-0.4, 0.4, -2.2),
    ];
    let clean = polygon_pixels(&persp, &quad);
    assert!(!clean.is_empty());
    let near = |v: Vec3| Vec3::new(v.x, f32::from_bits(v.y.to_bits() + 1), v.z);
    for repeated in [
        vec![quad[0], quad[1], quad[1], quad[2], quad[3]],
        vec![quad[0], quad[1], quad[2], quad[3], quad[3], quad[0]],
        vec![
            quad[0],
            quad[1],
            near(quad[1]),
            quad[2],
            quad[3],
            near(quad[3]),
        ],
    ] {
        assert_eq!(polygon_pixels(&persp, &repeated), clean, "{repeated:?}");
    }
}

#[test]
fn covered_polygons_equal_their_fan_triangles() {
    let persp = persp_view();
    let r = |k: u64, i: u64| {
        crate::sampling::unit_float(crate::sampling::hash_words(&[k, i])) * 2.0 - 1.0
    };
    let mut covered = 0;
    for k in 0..300u64 {
        // A convex outline: points on an ellipse at increasing angles, in a tilted plane.
        let n = 4 + (k % 2) as usize;
        let (cx, cy, cz) = (r(k, 0), r(k, 1), -2.0 + 1.8 * r(k, 2));
        let (ra, rb) = (0.2 + 2.0 * r(k, 3).abs(), 0.01 + 1.5 * r(k, 4).abs());
        let (tx, ty) = (r(k, 5), r(k, 6));
        let outline: Vec<Vec3> = (0..n)
            .map(|j| {
                let t = (j as f32 + 0.4 * r(k, 10 + j as u64)) * std::f32::consts::TAU / n as f32;
                let (u, v) = (ra * t.cos(), rb * t.sin());
                Vec3::new(cx + u, cy + v, cz + tx * u + ty * v)
            })
            .collect();
        let fan = fan_pixels(&persp, &outline);
        let whole = polygon_pixels(&persp, &outline);
        let mut dedup = fan.clone();
        dedup.dedup();
        assert_eq!(
            dedup.len(),
            fan.len(),
            "polygon {k}: a fan pixel reported twice"
        );
        assert_eq!(whole, fan, "polygon {k}: {outline:?}");
        covered += usize::from(!whole.is_empty());
    }
    assert!(covered > 100, "{covered}");
    let ortho = ortho_view();
    let (mut shared, mut on_edge) = (0, 0);
    for k in 0..400u64 {
        let g = |i: u64| (crate::sampling::hash_words(&[k, i]) % 65) as f32 * 0.5 - 0.25;
        // A convex quad on the half-pixel grid: a triangle's vertices and a fourth beyond
        // its first edge, kept when the outline stays convex.
        let (a, b, c) = (
            Vec3::new(g(0), g(1), -1.0),
            Vec3::new(g(2), g(3), -1.0),
            Vec3::new(g(4), g(5), -1.0),
        );
        let d = Vec3::new(g(6), g(7), -1.0);
        let turn = |p: Vec3, q: Vec3, s: Vec3| (q - p).truncate().perp_dot((s - q).truncate());
        let outline = [a, d, b, c];
        let signs = [turn(a, d, b), turn(d, b, c), turn(b, c, a), turn(c, a, d)];
        if !(signs.iter().all(|&t| t > 0.0) || signs.iter().all(|&t| t < 0.0)) {
            continue;
        }
        let whole = polygon_pixels(&ortho, &outline);
        assert_eq!(whole, fan_pixels(&ortho, &outline), "quad {k}: {outline:?}");
        // Its neighbour across the edge b c (the mirror of a and d through that edge's
        // midpoint): together they cover each pixel once.
        let m = (b + c) * 0.5;
        let other = [b, c, 2.0 * m - a];
        let mut both = whole.clone();
        both.extend(polygon_pixels(&ortho, &other));
        let n = both.len();
        both.sort_unstable();
        both.dedup();
        assert_eq!(n, both.len(), "quad {k} and its neighbour share a pixel");
        shared += 1;
        // Pixels whose centre lies on the shared edge (y flipped: row 0 is the top).
        on_edge += both
            .iter()
            .filter(|(x, y)| {
                let p = glam::Vec2::new(*x as f32 + 0.5, 31.5 - *y as f32);
                (c - b).truncate().perp_dot(p - b.truncate()) == 0.0
            })
            .count();
    }
    assert!(shared > 50, "{shared}");
    assert!(on_edge > 20, "{on_edge} pixels on a shared edge");
}

/// The depth from a triangle's plane ([`setup::ScreenTriangle::depth_on_plane`], the shadow
/// maps' runs) is the barycentric depth ([`setup::ScreenTriangle::depth_at_center`]) to f32
/// rounding on every covered pixel, slivers and triangles cut by the near plane included.
#[test]
fn plane_depths_equal_barycentric_depths() {
    let view = persp_view();
    let sliver = [
        Vec3::new(-2.0, -1.0, -3.0),
        Vec3::new(2.0, 1.0, -3.5),
        Vec3::new(2.0, 1.01, -2.5),
    ];
    let (mut pixels, mut equal) = (0usize, 0usize);
    for (k, tri) in random_triangles(&[7]).chain([sliver]).enumerate() {
        let v = tri.map(|p| view.view_from_world.transform_point3(p));
        for s in setup::setup_triangle(v, &view) {
            let g = s.depth_gradient();
            for y in s.ymin..=s.ymax {
                for x in s.xmin..=s.xmax {
                    let Some(d) = s.depth_at_center(x, y) else {
                        continue;
                    };
                    let p = s
                        .depth_on_plane(g, x, y)
                        .expect("a covered pixel has a depth");
                    assert!(
                        (p - d).abs() <= 2.0 * f32::EPSILON * d.abs(),
                        "{k}: {p} {d}"
                    );
                    pixels += 1;
                    equal += usize::from(p == d);
                }
            }
        }
    }
    assert!(pixels > 10_000, "{pixels}");
    // Rounded to f32, the two f64 forms almost never differ.
    assert!(equal as f64 > 0.999 * pixels as f64, "{equal} of {pixels}");
}
