//! Validation of the reference before anything is checked against it: closed forms, brute
//! force, convergence, acne and leaks.

use std::sync::Arc;

use glam::{DVec2, UVec2, Vec3};
use shadow_core::prelude::*;
use shadow_io::SceneSetup;
use shadow_ref::Reference;
use shadow_ref::statistics::RefCounter;
use shadow_ref::watertight::ShearedRay;
use shadow_scenes::procedural::{floor, quad, uv_sphere};
use shadow_scenes::{BUILTIN_SCENES, builtin, quad_over_plane as q};

fn run(r: &Reference, setup: &SceneSetup, view: &ViewSamples) -> VisibilityImage {
    let r_prepared = r
        .prepare_reference(setup.scene.clone(), setup.lights[0].clone())
        .unwrap();
    r_prepared
        .estimate(view, Outputs::VISIBILITY)
        .unwrap()
        .visibility
}

/// Area of the intersection of the interval `[a0, a1]` with `[b0, b1]`.
fn overlap(a0: f64, a1: f64, b0: f64, b1: f64) -> f64 {
    (a1.min(b1) - a0.max(b0)).max(0.0)
}

/// Closed form for `quad-over-plane`: V(p) = 1 - |proj(occluder) ∩ light| / |light|, with the
/// occluder projected from p onto the light's plane (scale h_l / h_o about p).
fn quad_closed_form(p: Vec3) -> f64 {
    let (hl, ho) = (q::LIGHT_HEIGHT as f64, q::OCCLUDER_HEIGHT as f64);
    let k = (hl - p.y as f64) / (ho - p.y as f64);
    let (px, pz) = (p.x as f64, p.z as f64);
    let half_o = 0.5 * q::OCCLUDER_SIDE as f64 * k;
    let (cx, cz) = (px + (0.0 - px) * k, pz + (0.0 - pz) * k);
    let half_l = 0.5 * q::LIGHT_SIDE as f64;
    let covered = overlap(cx - half_o, cx + half_o, -half_l, half_l)
        * overlap(cz - half_o, cz + half_o, -half_l, half_l);
    1.0 - covered / (q::LIGHT_SIDE as f64).powi(2)
}

fn floor_errors(setup: &SceneSetup, view: &ViewSamples, v: &VisibilityImage) -> (f64, f64, usize) {
    let (mut sq, mut max, mut n) = (0.0, 0.0f64, 0);
    for i in 0..view.len() {
        let Some(s) = view.get(i) else { continue };
        if s.position.y.abs() > 1e-6 {
            continue; // not the floor
        }
        let e = v.value(i) as f64 - quad_closed_form(s.position);
        sq += e * e;
        max = max.max(e.abs());
        n += 1;
    }
    let _ = setup;
    ((sq / n as f64).sqrt(), max, n)
}

#[test]
fn square_occluder_closed_form() {
    let setup = builtin("quad-over-plane").unwrap();
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera.unwrap(), 64, 48).unwrap();
    let v = run(&Reference::stratified(1024, 3).unwrap(), &setup, &view);
    let (rmse, max, n) = floor_errors(&setup, &view, &v);
    assert!(n > 1000);
    assert!(rmse < 4e-3, "rmse {rmse}");
    assert!(max < 0.03, "max {max}");
}

#[test]
fn error_falls_at_the_stratified_rate() {
    let setup = builtin("quad-over-plane").unwrap();
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera.unwrap(), 48, 36).unwrap();
    let counts = [16u32, 64, 256, 1024];
    let errs: Vec<f64> = counts
        .iter()
        .map(|&n| {
            floor_errors(
                &setup,
                &view,
                &run(&Reference::stratified(n, 11).unwrap(), &setup, &view),
            )
            .0
        })
        .collect();
    // Least-squares slope of log(error) against log(N): plain Monte Carlo gives -0.5, jittered
    // stratification -0.75 for an edge crossing the light.
    let xs: Vec<f64> = counts.iter().map(|&n| (n as f64).ln()).collect();
    let ys: Vec<f64> = errs.iter().map(|e| e.ln()).collect();
    let (mx, my) = (xs.iter().sum::<f64>() / 4.0, ys.iter().sum::<f64>() / 4.0);
    let slope = xs
        .iter()
        .zip(&ys)
        .map(|(x, y)| (x - mx) * (y - my))
        .sum::<f64>()
        / xs.iter().map(|x| (x - mx).powi(2)).sum::<f64>();
    eprintln!("errors {errs:?}, slope {slope:.3}");
    assert!(errs.windows(2).all(|w| w[1] < w[0]), "{errs:?}");
    assert!(slope < -0.6, "slope {slope} (errors {errs:?})");
}

/// Area of a convex polygon clipped to the axis-aligned square `[-h, h]^2` (Sutherland-Hodgman).
fn clipped_area(poly: &[DVec2], h: f64) -> f64 {
    let mut p = poly.to_vec();
    for (axis, sign) in [(0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0)] {
        let inside = |v: DVec2| sign * v[axis] <= h;
        let mut out = Vec::new();
        for i in 0..p.len() {
            let (a, b) = (p[i], p[(i + 1) % p.len()]);
            if inside(a) {
                out.push(a);
            }
            if inside(a) != inside(b) {
                let t = (sign * h - a[axis]) / (b[axis] - a[axis]);
                out.push(a + (b - a) * t);
            }
        }
        p = out;
        if p.is_empty() {
            return 0.0;
        }
    }
    let mut s = 0.0;
    for i in 0..p.len() {
        s += p[i].perp_dot(p[(i + 1) % p.len()]);
    }
    0.5 * s.abs()
}

#[test]
fn single_triangle_occluder_closed_form() {
    let tri = [
        Vec3::new(-0.4, 0.9, -0.3),
        Vec3::new(0.5, 1.1, -0.1),
        Vec3::new(-0.1, 1.0, 0.5),
    ];
    let mut b = SceneBuilder::new();
    let f = floor(6.0, 0.0);
    b.push_mesh(MeshDesc::new(f.0, f.1)).unwrap();
    b.push_mesh(MeshDesc::new(tri.to_vec(), vec![[0, 1, 2]]))
        .unwrap();
    let light: Light = Arc::new(
        RectLight::new(
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.5, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 0.5),
            Radiance::Constant(Vec3::ONE),
        )
        .unwrap(),
    );
    let setup = SceneSetup {
        name: "tri".into(),
        scene: Arc::new(b.build().unwrap()),
        lights: vec![light],
        camera: None,
        aspect: None,
        warnings: vec![],
        punctual: vec![],
        layouts: vec![],
    };
    let cam = Camera::look_at(Vec3::new(0.0, 3.0, 3.0), Vec3::ZERO, Vec3::Y, 0.9).unwrap();
    let view = ViewSamples::render(setup.scene.as_ref(), &cam, 64, 48).unwrap();
    let v = run(&Reference::stratified(1024, 5).unwrap(), &setup, &view);
    let (mut sq, mut n, mut max) = (0.0, 0, 0.0f64);
    for i in 0..view.len() {
        let Some(s) = view.get(i) else { continue };
        if s.position.y.abs() > 1e-6 {
            continue;
        }
        let p = s.position.as_dvec3();
        let proj: Vec<DVec2> = tri
            .iter()
            .map(|t| {
                let t = t.as_dvec3();
                let k = (2.0 - p.y) / (t.y - p.y);
                let x = p + (t - p) * k;
                DVec2::new(x.x, x.z)
            })
            .collect();
        let expected = 1.0 - clipped_area(&proj, 0.5) / 1.0;
        let e = v.value(i) as f64 - expected;
        sq += e * e;
        max = max.max(e.abs());
        n += 1;
    }
    let rmse = (sq / n as f64).sqrt();
    assert!(
        n > 1000 && rmse < 4e-3 && max < 0.03,
        "rmse {rmse} max {max}"
    );
}

/// Lambert's point-to-polygon form factor for a receiver at `p` with normal `n`.
fn lambert_form_factor(p: Vec3, n: Vec3, poly: &[Vec3]) -> f64 {
    let mut s = 0.0;
    for i in 0..poly.len() {
        let a = (poly[i] - p).as_dvec3().normalize();
        let b = (poly[(i + 1) % poly.len()] - p).as_dvec3().normalize();
        let gamma = a.cross(b).normalize();
        s += a.angle_between(b) * gamma.dot(n.as_dvec3());
    }
    (s / (2.0 * std::f64::consts::PI)).abs()
}

#[test]
fn unoccluded_direct_illumination_equals_the_form_factor() {
    let mut b = SceneBuilder::new();
    let f = floor(6.0, 0.0);
    b.push_mesh(MeshDesc::new(f.0, f.1).with_albedo(Vec3::splat(0.5)))
        .unwrap();
    let rect = RectLight::new(
        Vec3::new(0.3, 1.5, 0.0),
        Vec3::new(0.6, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.4),
        Radiance::Constant(Vec3::new(2.0, 1.0, 0.5)),
    )
    .unwrap();
    let corners = rect.corners();
    let setup = SceneSetup {
        name: "ff".into(),
        scene: Arc::new(b.build().unwrap()),
        lights: vec![Arc::new(rect)],
        camera: None,
        aspect: None,
        warnings: vec![],
        punctual: vec![],
        layouts: vec![],
    };
    let cam = Camera::look_at(Vec3::new(0.0, 3.0, 3.0), Vec3::ZERO, Vec3::Y, 0.9).unwrap();
    let view = ViewSamples::render(setup.scene.as_ref(), &cam, 48, 36).unwrap();
    let r = Reference::stratified(1024, 2).unwrap();
    let r_prepared = r
        .prepare_reference(setup.scene.clone(), setup.lights[0].clone())
        .unwrap();
    let direct = r_prepared.direct_illumination(&view);
    let mut worst = 0.0f64;
    for i in 0..view.len() {
        let Some(s) = view.get(i) else { continue };
        let ff = lambert_form_factor(s.position, s.shading_normal, &corners);
        let expected = 0.5 * ff * 2.0; // albedo * L * F (red channel)
        let got = direct[i].x as f64;
        worst = worst.max((got - expected).abs() / expected.max(1e-3));
        assert!((direct[i].y as f64 - 0.5 * ff).abs() <= 0.02 * 0.5 * ff + 1e-6);
    }
    assert!(worst < 0.02, "relative error {worst}");
}

/// Brute-force per-sample visibility: every triangle tested for every ray.
#[test]
fn bvh_equals_brute_force_on_builtin_scenes() {
    for name in BUILTIN_SCENES {
        let setup = builtin(name).unwrap();
        let view =
            ViewSamples::render(setup.scene.as_ref(), &setup.camera.unwrap(), 12, 9).unwrap();
        let sampler = LightSampler::new(SamplingStrategy::Stratified, 16, 4).unwrap();
        let r = Reference::same_samples(sampler.clone());
        let r_prepared = r
            .prepare_reference(setup.scene.clone(), setup.lights[0].clone())
            .unwrap();
        let est = r_prepared
            .estimate(&view, Outputs::VISIBILITY)
            .unwrap()
            .visibility;
        let ps = est.per_sample().unwrap();
        let scene = setup.scene.as_ref();
        let tris: Vec<[glam::Vec3A; 3]> = (0..scene.triangle_count())
            .map(|t| scene.triangle(t).map(glam::Vec3A::from))
            .collect();
        let mut units = Vec::new();
        let mut checked = 0;
        for i in 0..view.len() {
            let Some(s) = view.get(i) else { continue };
            sampler.unit_samples(s.pixel, &mut units);
            for (k, u) in units.iter().enumerate() {
                let y = setup.lights[0].sample(*u);
                let free = match r_prepared.segment(&s, &y) {
                    None => false,
                    Some((o, d, t)) => {
                        let ray = ShearedRay::new(o.into(), d.into());
                        !tris
                            .iter()
                            .any(|[a, b, c]| ray.intersect(*a, *b, *c, 0.0, t).is_some())
                    }
                };
                assert_eq!(
                    ps.visible(i, k as u32),
                    free,
                    "{name}: pixel {i} sample {k}"
                );
                checked += 1;
            }
        }
        assert!(checked > 500, "{name}: {checked}");
    }
}

#[test]
fn no_acne_on_flat_and_curved_receivers() {
    // A lone sphere under a small light, and a floor beside it: every sample above the tangent
    // plane must be visible (nothing else is in the scene). Scales 1e-4 and 1e5, and a translation
    // by 1e5 (with geometry 100 m across: a 1 m sphere there is quantised to 8 mm by f32 and
    // really does shadow itself).
    for (offset, scale) in [
        (Vec3::ZERO, 1.0f32),
        (Vec3::splat(1e5), 100.0),
        (Vec3::ZERO, 1e-4),
        (Vec3::ZERO, 1e5),
    ] {
        let mut b = SceneBuilder::new();
        let s = uv_sphere(Vec3::ZERO, 0.5, 24, 48);
        b.push_mesh(MeshDesc::new(s.0, s.1).with_transform(
            glam::Affine3A::from_translation(offset)
                * glam::Affine3A::from_scale(Vec3::splat(scale)),
        ))
        .unwrap();
        let f = quad(
            Vec3::new(3.0, -0.5, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, -1.0),
        );
        b.push_mesh(MeshDesc::new(f.0, f.1).with_transform(
            glam::Affine3A::from_translation(offset)
                * glam::Affine3A::from_scale(Vec3::splat(scale)),
        ))
        .unwrap();
        let light: Light = Arc::new(
            DiskLight::new(
                offset + Vec3::new(0.0, 3.0, 0.0) * scale,
                Vec3::NEG_Y,
                0.05 * scale,
                Radiance::Constant(Vec3::ONE),
            )
            .unwrap(),
        );
        let setup = SceneSetup {
            name: "acne".into(),
            scene: Arc::new(b.build().unwrap()),
            lights: vec![light.clone()],
            camera: None,
            aspect: None,
            warnings: vec![],
            punctual: vec![],
            layouts: vec![],
        };
        let cam = Camera::look_at(
            offset + Vec3::new(1.0, 2.0, 2.0) * scale,
            offset + Vec3::new(1.0, 0.0, 0.0) * scale,
            Vec3::Y,
            1.0,
        )
        .unwrap()
        .with_near(1e-3 * scale)
        .unwrap();
        let view = ViewSamples::render(setup.scene.as_ref(), &cam, 48, 36).unwrap();
        let sampler = LightSampler::new(SamplingStrategy::Stratified, 16, 1).unwrap();
        let r = Reference::same_samples(sampler.clone());
        let r_prepared = r
            .prepare_reference(setup.scene.clone(), light.clone())
            .unwrap();
        let est = r_prepared
            .estimate(&view, Outputs::VISIBILITY)
            .unwrap()
            .visibility;
        let ps = est.per_sample().unwrap();
        let mut units = Vec::new();
        let mut tested = 0;
        for i in 0..view.len() {
            let Some(s) = view.get(i) else { continue };
            sampler.unit_samples(s.pixel, &mut units);
            for (k, u) in units.iter().enumerate() {
                let y = light.sample(*u).position;
                // Above the tangent plane by a clear margin: must see the light.
                if (y - s.position).normalize().dot(s.geometric_normal) > 0.05 {
                    assert!(
                        ps.visible(i, k as u32),
                        "acne at pixel {i} (offset {offset}, scale {scale})"
                    );
                    tested += 1;
                }
            }
        }
        assert!(tested > 1000, "{tested}");
    }
}

#[test]
fn no_leak_through_shared_edges_and_vertices() {
    // Rays aimed exactly at the vertices and edge midpoints of a closed sphere, through its
    // centre: every one must be blocked.
    let (p, t) = uv_sphere(Vec3::new(0.1, 1.0, -0.2), 0.5, 12, 24);
    let scene = Arc::new(TriangleScene::new(p.clone(), t.clone()).unwrap());
    let light: Light = Arc::new(
        PointLight::new(Vec3::new(0.1, 3.0, -0.2), Radiance::Constant(Vec3::ONE)).unwrap(),
    );
    let r = Reference::hard();
    let r_prepared = r.prepare_reference(scene.clone(), light).unwrap();
    let bvh = r_prepared.bvh();
    let centre = Vec3::new(0.1, 1.0, -0.2);
    let mut targets: Vec<Vec3> = p.clone();
    for tri in &t {
        for k in 0..3 {
            targets.push(0.5 * (p[tri[k] as usize] + p[tri[(k + 1) % 3] as usize]));
        }
    }
    for target in targets {
        let dir = (target - centre).normalize();
        let origin = target + dir * 2.0;
        assert!(
            bvh.occluded(origin, -dir, 2.5, u32::MAX),
            "leak through {target:?}"
        );
        assert!(
            bvh.occluded_cwbvh(origin, -dir, 2.5, u32::MAX),
            "leak through {target:?} (CWBVH)"
        );
    }
}

#[test]
fn output_is_identical_whatever_the_thread_count() {
    let setup = builtin("overlapping-occluders").unwrap();
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera.unwrap(), 40, 30).unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let a = one.install(|| run(&Reference::stratified(64, 9).unwrap(), &setup, &view));
    let three = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap();
    let b = three.install(|| run(&Reference::stratified(64, 9).unwrap(), &setup, &view));
    assert_eq!(a.coefficients(), b.coefficients());
}

#[test]
fn point_light_gives_the_hard_shadow_and_textured_lights_give_rgb() {
    let setup = builtin("quad-over-plane").unwrap();
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera.unwrap(), 40, 30).unwrap();
    let v = run(&Reference::hard(), &setup, &view);
    for i in 0..view.len() {
        let Some(s) = view.get(i) else { continue };
        if s.position.y.abs() > 1e-6 {
            continue;
        }
        // Hard shadow of the centre: inside the occluder's projection from (0, 2, 0).
        let k = 2.0 / (2.0 - 1.0);
        let inside = s.position.x.abs() < 0.5 * q::OCCLUDER_SIDE * k - 1e-3
            && s.position.z.abs() < 0.5 * q::OCCLUDER_SIDE * k - 1e-3;
        let outside = s.position.x.abs() > 0.5 * q::OCCLUDER_SIDE * k + 1e-3
            || s.position.z.abs() > 0.5 * q::OCCLUDER_SIDE * k + 1e-3;
        if inside {
            assert_eq!(v.value(i), 0.0);
        } else if outside {
            assert_eq!(v.value(i), 1.0);
        }
    }
    let tex = builtin("textured-light").unwrap();
    let view = ViewSamples::render(tex.scene.as_ref(), &tex.camera.unwrap(), 24, 18).unwrap();
    let v = run(&Reference::stratified(64, 1).unwrap(), &tex, &view);
    assert!(v.is_rgb());
    // A fully lit pixel sees the mean radiance of the texture.
    let mean = tex.lights[0].radiance().mean();
    let lit = (0..view.len())
        .find(|&i| v.class(i) == Some(PixelClass::Lit))
        .unwrap();
    assert!(
        (v.rgb(lit) - mean).length() < 0.05 * mean.length(),
        "{:?} vs {mean:?}",
        v.rgb(lit)
    );
}

#[test]
fn semi_opaque_occluders_multiply_transmittances() {
    // Two stacked panels of opacity 0.3 and 0.5 over the floor under a tiny light: the floor
    // beneath both sees 0.7 * 0.5 = 0.35 of the light.
    let mut b = SceneBuilder::new();
    let f = floor(6.0, 0.0);
    b.push_mesh(MeshDesc::new(f.0, f.1)).unwrap();
    let p1 = quad(
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -1.0),
    );
    b.push_mesh(MeshDesc::new(p1.0, p1.1).with_opacity(0.3))
        .unwrap();
    let p2 = quad(
        Vec3::new(0.0, 1.5, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -1.0),
    );
    b.push_mesh(MeshDesc::new(p2.0, p2.1).with_opacity(0.5))
        .unwrap();
    let light: Light = Arc::new(
        DiskLight::new(
            Vec3::new(0.0, 3.0, 0.0),
            Vec3::NEG_Y,
            0.01,
            Radiance::Constant(Vec3::ONE),
        )
        .unwrap(),
    );
    let setup = SceneSetup {
        name: "semi".into(),
        scene: Arc::new(b.build().unwrap()),
        lights: vec![light],
        camera: None,
        aspect: None,
        warnings: vec![],
        punctual: vec![],
        layouts: vec![],
    };
    let cam = Camera::look_at(
        Vec3::new(0.0, 0.5, 0.0) + Vec3::new(0.0, -0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.01),
        Vec3::Z,
        0.3,
    )
    .unwrap();
    let view = ViewSamples::render(setup.scene.as_ref(), &cam, 8, 8).unwrap();
    let v = run(&Reference::stratified(16, 1).unwrap(), &setup, &view);
    let centre = view.get((4 * 8 + 4) as usize).unwrap();
    assert!(centre.position.y.abs() < 1e-6);
    assert!(
        (v.value(4 * 8 + 4) - 0.35).abs() < 1e-5,
        "{}",
        v.value(4 * 8 + 4)
    );
    let _ = UVec2::ZERO;
}

#[test]
fn beam_culling_changes_nothing_but_time() {
    // Per-sample answers and coefficients with and without beam culling, on every built-in
    // scene (semi-opaque transmittance and the sphere light's no-beam path included).
    for name in BUILTIN_SCENES {
        let setup = builtin(name).unwrap();
        let view =
            ViewSamples::render(setup.scene.as_ref(), &setup.camera.unwrap(), 32, 24).unwrap();
        let sampler = LightSampler::new(SamplingStrategy::Stratified, 64, 8).unwrap();
        let with = run(&Reference::same_samples(sampler.clone()), &setup, &view);
        let plain = Reference::same_samples(sampler).with_beam(false);
        let without = run(&plain, &setup, &view);
        assert_eq!(with.coefficients(), without.coefficients(), "{name}");
        assert_eq!(with.per_sample(), without.per_sample(), "{name}");
    }
}

#[test]
fn wide_tree_equals_the_cwbvh() {
    // The single-ray query on the project's wide tree and on `obvhs`'s CWBVH give the same
    // answer on every segment the reference casts on every built-in scene, and on axis-aligned
    // segments (zero direction components, infinite slab inverses) through each scene's box.
    for name in BUILTIN_SCENES {
        let setup = builtin(name).unwrap();
        let view =
            ViewSamples::render(setup.scene.as_ref(), &setup.camera.unwrap(), 32, 24).unwrap();
        let r = Reference::stratified(16, 3).unwrap();
        let r_prepared = r
            .prepare_reference(setup.scene.clone(), setup.lights[0].clone())
            .unwrap();
        let bvh = r_prepared.bvh();
        let mut segs = r_prepared.segments(&view);
        let b = setup.scene.bounds();
        let (lo, hi) = (b.min, b.max);
        let size = hi - lo;
        for i in 0..=16 {
            for j in 0..=16 {
                let (u, v) = (i as f32 / 16.0, j as f32 / 16.0);
                for axis in 0..3 {
                    let mut o = lo + size * Vec3::new(u, v, u * v);
                    o[axis] = hi[axis] + 1.0;
                    let mut d = Vec3::ZERO;
                    d[axis] = -1.0;
                    segs.push((o, d, size[axis] + 2.0, u32::MAX));
                }
            }
        }
        let mut blocked = 0;
        for (o, d, t, ignore) in &segs {
            let wide = bvh.occluded(*o, *d, *t, *ignore);
            assert_eq!(
                wide,
                bvh.occluded_cwbvh(*o, *d, *t, *ignore),
                "{name}: {o:?} {d:?} {t}"
            );
            blocked += usize::from(wide);
        }
        assert!(segs.len() > 1000, "{name}: {}", segs.len());
        assert!(blocked > 0, "{name}: nothing blocked");
    }
}

#[test]
fn beams_prove_lit_receivers_clear() {
    // On `quad-over-plane` most floor receivers see the whole light past the occluder: their
    // beams must come out clear, with no ray cast, even though a leaf of the tree holds the
    // floor's triangles together with the occluder's (each triangle's own box is tested).
    let setup = builtin("quad-over-plane").unwrap();
    let view = ViewSamples::render(setup.scene.as_ref(), &setup.camera.unwrap(), 32, 24).unwrap();
    let r = Reference::stratified(64, 1).unwrap();
    let r_prepared = r
        .prepare_reference(setup.scene.clone(), setup.lights[0].clone())
        .unwrap();
    let est = r_prepared.estimate(&view, Outputs::VISIBILITY).unwrap();
    let clear = est.stats.counter(RefCounter::PixelsBeamClear).unwrap();
    let pixels = est.stats.counter(RefCounter::Pixels).unwrap();
    assert!(2 * clear > pixels, "{clear} clear beams of {pixels} pixels");
}

/// The direct light every sample-based technique gets for `Outputs::direct`
/// (`direct_from_per_sample`, from binary per-sample visibility) equals the reference's own
/// eq. 6 on an opaque scene, where the reference's transmittances are binary too.
#[test]
fn direct_light_from_per_sample_bits_equals_the_references_own() {
    for name in ["bunny", "sphere-light", "textured-light"] {
        let setup = builtin(name).unwrap();
        let view =
            ViewSamples::render(setup.scene.as_ref(), &setup.camera_or_default(), 40, 30).unwrap();
        let sampler = LightSampler::new(SamplingStrategy::Stratified, 32, 9).unwrap();
        let r = Reference::same_samples(sampler.clone())
            .prepare_reference(setup.scene.clone(), setup.lights[0].clone())
            .unwrap();
        let est = r
            .estimate(
                &view,
                Outputs {
                    per_sample: true,
                    direct: true,
                },
            )
            .unwrap();
        let own = est.direct.clone().unwrap();
        let from_bits = shadow_core::technique::direct_from_per_sample(
            setup.scene.as_ref(),
            setup.lights[0].as_ref(),
            &sampler,
            &view,
            &est.visibility,
        )
        .unwrap();
        let mut lit = 0;
        for (a, b) in own.iter().zip(&from_bits) {
            assert!(
                (*a - *b).abs().max_element() <= 1e-6 * (1.0 + a.max_element()),
                "{name}"
            );
            lit += (a.max_element() > 0.0) as u32;
        }
        assert!(lit > 100, "{name}: {lit} lit pixels");
        // Without per-sample data there is nothing to shade from: an error, not zeros.
        let plain = Reference::stratified(32, 9)
            .unwrap()
            .prepare_reference(setup.scene.clone(), setup.lights[0].clone())
            .unwrap()
            .estimate(&view, Outputs::VISIBILITY)
            .unwrap();
        assert!(plain.visibility.per_sample().is_none());
        assert!(
            shadow_core::technique::direct_from_per_sample(
                setup.scene.as_ref(),
                setup.lights[0].as_ref(),
                &sampler,
                &view,
                &plain.visibility,
            )
            .is_err()
        );
    }
}

/// Issue 51, item 4: the largest coordinate a scene accepts builds a BVH and traces without a
/// panic or a non-finite value (above it the scene itself refuses, see `shadow-core`).
#[test]
fn the_largest_accepted_coordinate_traces_without_panic() {
    let big = shadow_core::scene::MAX_COORDINATE;
    let mut b = SceneBuilder::new();
    let f = floor(3.0, 0.0);
    b.push_mesh(MeshDesc::new(f.0, f.1)).unwrap();
    let o = quad(Vec3::new(0.0, 1.0, 0.0), Vec3::X * 0.5, Vec3::Z * 0.5);
    b.push_mesh(MeshDesc::new(o.0, o.1)).unwrap();
    b.push_mesh(MeshDesc::new(
        vec![
            Vec3::new(big, 0.0, 0.0),
            Vec3::new(big, 0.0, 1.0),
            Vec3::new(big, 1.0, 0.0),
        ],
        vec![[0, 1, 2]],
    ))
    .unwrap();
    let scene: SceneRef = Arc::new(b.build().unwrap());
    let light: Light = Arc::new(
        RectLight::new(
            Vec3::new(0.0, 3.0, 0.0),
            Vec3::X * 0.4,
            Vec3::Z * 0.4,
            Radiance::Constant(Vec3::ONE),
        )
        .unwrap(),
    );
    let camera = Camera::look_at(Vec3::new(0.0, 4.0, 4.0), Vec3::ZERO, Vec3::Y, 0.9).unwrap();
    let view = ViewSamples::render(scene.as_ref(), &camera, 24, 24).unwrap();
    let est = Reference::stratified(16, 1)
        .unwrap()
        .prepare(scene, light)
        .unwrap()
        .estimate(&view, Outputs::VISIBILITY)
        .unwrap();
    est.visibility.validate().unwrap();
}
