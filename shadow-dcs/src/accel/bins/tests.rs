//! The wedge search against brute force and its own unrolled forms.

use super::*;
use crate::accel::centred_wedges::wedges;
use crate::stages::edges::{Sides, Silhouettes, scene_edges, silhouettes};
use crate::stages::light_shape::LightShape;
use crate::stages::wedges::FOLD_SLACK;
use shadow_core::offset::RayOffset;
use shadow_core::prelude::*;

/// The box test keeps the same boxes whether it runs unrolled (up to 16 boxes) or over
/// all 64, and as [`Boxes::test_quads`] on every vector: the wedges of `bunny` against
/// boxes around its view samples, some of them empty.
#[test]
fn box_tests_agree_unrolled_and_not() {
    let setup = shadow_scenes::builtin("bunny").unwrap();
    let scene = setup.scene.as_ref();
    let (w, h) = (64, 48);
    let view = ViewSamples::render(scene, &setup.camera_or_default(), w, h).unwrap();
    let light = setup.lights[0].as_ref();
    let shape = LightShape::new(light, "test").unwrap();
    let (edges, _) = scene_edges(scene, &Sides::new(scene, &shape));
    let sil = silhouettes(&edges, &shape, Silhouettes::Accurate);
    let scan: Vec<ScanWedge> = wedges(&edges, &sil, &shape)
        .iter()
        .map(|w| ScanWedge::new(w, None).0)
        .collect();
    let c = shape.center.as_dvec3();
    let n = view.len();
    let mut centred = vec![Vec3::ZERO; n];
    let mut active = vec![false; n];
    for i in 0..n {
        if let Some(s) = view.get(i) {
            centred[i] = (s.position.as_dvec3() - c).as_vec3();
            active[i] = true;
        }
    }
    // Boxes of 4 x 4 pixels over the whole image: 192, shuffled (so that every vector
    // holds some the wedges meet), taken 16 and 64 at a time.
    let grid_boxes: Vec<ViewBox> = grid((0, w - 1), (0, h - 1), 4)
        .map(|r| rect_box(r, w, &centred, &active))
        .collect();
    let boxes: Vec<ViewBox> = (0..grid_boxes.len())
        .map(|i| grid_boxes[i * 37 % grid_boxes.len()])
        .collect();
    assert!(boxes.iter().any(Option::is_none), "some boxes are empty");
    let slack = 1e-6;
    let (mut kept, mut compared) = (0u32, 0u32);
    for big in boxes.chunks(BOXES) {
        let mut all = Boxes::default();
        all.set(big.iter().copied());
        for (g, small) in big.chunks(16).enumerate() {
            let mut few = Boxes::default();
            few.set(small.iter().copied());
            for sw in scan.iter().step_by(7) {
                let want = few.test(sw, slack);
                let got = all.test(sw, slack) >> (16 * g) & 0xffff;
                assert_eq!(got, want);
                assert_eq!(few.test_quads(sw, slack, 0xf), want);
                kept += want.count_ones();
                compared += 1;
            }
        }
    }
    assert!(
        compared > 1000 && kept > 100,
        "{kept} kept in {compared} tests"
    );
}

/// Uniform values in `[0, 1)` from a linear congruential sequence started at `seed`.
fn uniform(mut seed: u64) -> impl FnMut() -> f32 {
    move || {
        seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        (seed >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// A plane that [`ScanWedge::cut_planes`] leaves out is positive at every view sample of
/// the tile, far from the origin and with planes through a view sample (value zero up to
/// rounding); planes well clear of the box are left out.
#[test]
fn planes_left_out_of_a_tile_reject_none_of_its_view_samples() {
    let mut rand = uniform(0x9e37_79b9_7f4a_7c15u64);
    let (mut left_out, mut kept) = (0, 0);
    for round in 0..400 {
        let scale = [1e-3f32, 1.0, 1e3][round % 3];
        let centre = Vec3::new(rand(), rand(), rand()) * 2.0 * scale - scale;
        let extent = Vec3::new(rand(), rand(), rand()) * 0.01 * scale;
        let mut tile = TileLanes::at(centre);
        for j in 0..LANES {
            let p = centre + (Vec3::new(rand(), rand(), rand()) * 2.0 - 1.0) * extent;
            (tile.x[j], tile.y[j], tile.z[j]) = (p.x, p.y, p.z);
            tile.l1[j] = p.abs().element_sum();
        }
        tile.active = LaneMask::MAX;
        let quads = tile.quads();
        let mut planes = [OPEN; BOX_PLANES];
        for (k, plane) in planes.iter_mut().enumerate() {
            let n = (Vec3::new(rand(), rand(), rand()) * 2.0 - 1.0).normalize_or(Vec3::X);
            // Through a view sample, or at some distance from one (either side).
            let j = k % LANES;
            let at = n.dot(Vec3::new(tile.x[j], tile.y[j], tile.z[j]));
            let shift = if k % 3 == 0 {
                0.0
            } else {
                (rand() * 2.0 - 1.0) * extent.length() * 3.0
            };
            *plane = n.extend(-at + shift);
        }
        let w = ScanWedge {
            planes: std::array::from_fn(|g| PlaneGroup::new(&planes, g)),
            fold: [OPEN, OPEN],
            folded: false,
            used: BOX_PLANES as u32,
            edge: 0,
        };
        let bounds = tile.bounds();
        let cut = w.cut_planes(&TileExtent::new(bounds));
        for k in 0..BOX_PLANES {
            if cut >> k & 1 == 1 {
                kept += 1;
                continue;
            }
            left_out += 1;
            assert_eq!(
                w.inside(&quads, tile.active, 1 << k),
                tile.active,
                "round {round}, plane {k}: {:?} over {bounds:?}",
                planes[k]
            );
            assert!(k % 3 != 0, "a plane through a view sample is always tested");
        }
    }
    assert!(
        left_out > 500 && kept > 1000,
        "{left_out} left out, {kept} kept"
    );
}

/// A box test keeps exactly the boxes that reach the positive side of a plane (up to the
/// boxes' padding): the plane's largest value over a box, at the corner its normal's signs
/// pick, against the largest of the eight corners in double precision. Normal components of
/// `0.0` and `-0.0` (whose sign bit picks the other bound) are among the planes. Fails when
/// the pick takes the nearest corner instead of the farthest.
#[test]
fn box_tests_keep_the_boxes_a_plane_reaches() {
    let mut rand = uniform(0x2545_f491_4f6c_dd1du64);
    let (mut kept, mut rejected) = (0, 0);
    for round in 0..300 {
        let boxes: Vec<ViewBox> = (0..16)
            .map(|_| {
                let c = Vec3::new(rand(), rand(), rand()) * 2.0 - 1.0;
                let h = Vec3::new(rand(), rand(), rand()) * 0.3;
                Some((c - h, c + h))
            })
            .collect();
        let mut b = Boxes::default();
        b.set(boxes.iter().copied());
        let mut n = Vec3::new(rand(), rand(), rand()) * 2.0 - 1.0;
        // Some components exactly zero, of either sign.
        for k in 0..3 {
            match (round + k) % 5 {
                0 => n[k] = 0.0,
                1 => n[k] = -0.0,
                _ => {}
            }
        }
        let plane = n.extend(rand() * 2.0 - 1.0);
        let mut planes = [OPEN; BOX_PLANES];
        planes[0] = plane;
        let w = ScanWedge {
            planes: std::array::from_fn(|g| PlaneGroup::new(&planes, g)),
            fold: [OPEN, OPEN],
            folded: false,
            used: 1,
            edge: 0,
        };
        let mask = b.test(&w, 0.0);
        for (i, bx) in boxes.iter().enumerate() {
            let (lo, hi) = bx.unwrap();
            let largest = (0..8)
                .map(|c| {
                    let pick = |k: usize| if c >> k & 1 == 1 { hi[k] } else { lo[k] };
                    let x = DVec3::new(pick(0).into(), pick(1).into(), pick(2).into());
                    plane.truncate().as_dvec3().dot(x) + f64::from(plane.w)
                })
                .fold(f64::NEG_INFINITY, f64::max);
            let keeps = mask >> i & 1 == 1;
            if largest >= 0.0 {
                assert!(keeps, "round {round}, box {i}: {bx:?} reaches {plane:?}");
                kept += 1;
            } else if largest < -1e-4 {
                assert!(!keeps, "round {round}, box {i}: {bx:?} misses {plane:?}");
                rejected += 1;
            }
        }
    }
    assert!(
        kept > 500 && rejected > 500,
        "{kept} kept, {rejected} rejected"
    );
}

/// The box hierarchy finds exactly the (pixel, wedge, weight) pairs of a brute-force scan
/// of every view sample against every wedge (inside the bounding planes, non-zero exact
/// weight): no box test drops a pair.
#[test]
fn the_hierarchy_finds_every_pair_of_the_brute_force_scan() {
    for (name, w, h) in [("bunny", 40, 30), ("overlapping-occluders", 70, 52)] {
        let setup = shadow_scenes::builtin(name).unwrap();
        let scene = setup.scene.as_ref();
        let view = ViewSamples::render(scene, &setup.camera_or_default(), w, h).unwrap();
        let light = setup.lights[0].as_ref();
        let shape = LightShape::new(light, "test").unwrap();
        let (edges, _) = scene_edges(scene, &Sides::new(scene, &shape));
        let sil = silhouettes(&edges, &shape, Silhouettes::Accurate);
        let ws = wedges(&edges, &sil, &shape);
        let (scan, lanes): (Vec<ScanWedge>, Vec<WedgeLanes>) =
            ws.iter().map(|w| ScanWedge::new(w, None)).unzip();
        // The weights take the fold test's values wherever the wedge has fold planes
        // (most of `bunny`'s; `overlapping-occluders`' open quads have none).
        let folded = scan.iter().filter(|s| s.folded).count();
        assert_eq!(folded, ws.iter().filter(|w| w.fold.is_some()).count());
        assert!(
            name != "bunny" || folded * 10 > scan.len() * 9,
            "{name}: {folded} of {}",
            scan.len()
        );
        let extent = scene.bounds().union(light.bounds()).diagonal();
        let offset = RayOffset::for_light(light);
        let c = shape.center.as_dvec3();
        let n = view.len();
        let (mut origins, mut centred, mut active) =
            (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n], vec![false; n]);
        for i in 0..n {
            if let Some(s) = view.get(i) {
                origins[i] = offset.offset(s.position, s.geometric_normal);
                centred[i] = (origins[i].as_dvec3() - c).as_vec3();
                active[i] = true;
            }
        }
        let input = ScanInput {
            edges: &edges,
            wedges: &scan,
            lanes: &lanes,
            c,
            width: w,
            origins: &origins,
            centred: &centred,
            active: &active,
            slack: (FOLD_SLACK * extent as f64) as f32,
            planar: None,
        };
        let blocks = blocks(w, h);
        let levels = BlockWedges::new(&input, &blocks);
        let mut found = Vec::new();
        let mut chunked = false;
        let (mut pairs, mut scratch) = (SquarePairs::default(), SquareScratch::default());
        for (bi, (_, squares)) in blocks.iter().enumerate() {
            let (lists, kept) = levels.square_lists(&input, bi, squares);
            // `bunny` keeps wedges enough for several parallel chunks, joined in order.
            chunked |= kept > LIST_CHUNK;
            for (r, list) in squares.iter().zip(&lists) {
                assert!(
                    list.is_sorted_by(|a, b| a < b),
                    "a square's wedges in order"
                );
                square_pairs(&input, list, *r, &mut pairs, &mut scratch);
                for (j, x, y) in pairs.pixels() {
                    let i = (y * w + x) as usize;
                    found.extend(pairs.of(j).0.iter().map(|p| (i, p.edge, p.k)));
                }
            }
        }
        // Brute force: every active view sample against every wedge.
        let mut want = Vec::new();
        for i in 0..n {
            if !active[i] {
                continue;
            }
            let q = TileLanes::at(centred[i]).quads();
            for (wi, sw) in scan.iter().enumerate() {
                if sw.inside(&q, 1, (1 << sw.used) - 1) == 0 {
                    continue;
                }
                let e = &edges[sw.edge as usize];
                match e.sweep_weight(origins[i].as_dvec3(), c, false) {
                    Some(k) if k != 0 => want.push((i, wi as u32, k as i32)),
                    _ => {}
                }
            }
        }
        found.sort_unstable();
        want.sort_unstable();
        assert!(want.len() > 500, "{name}: {} pairs", want.len());
        assert_eq!(found, want, "{name}");
        assert!(
            chunked || name != "bunny",
            "bunny's block in parallel chunks"
        );
    }
}
